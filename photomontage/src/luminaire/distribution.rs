//! The photometric web: luminous intensity I in candela over a grid of angles, expanded to the
//! full sphere from the symmetry the file declares, with bilinear interpolation, total flux by
//! exact integration of that interpolant (the positioned, aimed source is in [`super::source`]).
//!
//! Sources: IES LM-63-2002 §§ on photometric types and angle ranges (via the summary in
//! `reference/lighting.md` §4.1); CIE 121:1996 / EN 13032-1 for the A, B and C coordinate
//! systems; EULUMDAT symmetry codes (lighting.md §4.2).
//!
//! # Luminaire frame
//! Right-handed, z up, the luminaire hanging in its photometric position: nadir is −z, the C0
//! plane contains +x and C90 contains +y (C angles counter-clockwise seen from above).
//! - **Type C** (polar axis vertical): `d = (sin γ cos C, sin γ sin C, −cos γ)`.
//! - **Type B** (polar axis horizontal, +y): the aiming direction H = V = 0 is nadir; V rotates
//!   the plane about +y towards +x, H is the angle out of that plane towards +y:
//!   `d = (cos H sin V, sin H, −cos H cos V)`, so dΩ = cos H dH dV.
//! - **Type A** (polar axis +x, "Type B turned 90° about the vertical"):
//!   `d = (sin V, cos V sin H, −cos V cos H)`, so dΩ = cos V dV dH.
//!
//! # Flux quadrature
//! The web is interpolated linearly between stored angles (bilinear on the grid), and
//! [`PhotometricWeb::total_flux_lm`] integrates *that interpolant* exactly: along the polar
//! ("latitude") angle each segment's integral of `(linear I) × sin γ` (Type C) or
//! `(linear I) × cos` (Types A/B) is evaluated in closed form; across planes the interpolant is
//! linear and the weight does not depend on the plane angle, so the trapezoidal rule is exact.
//! Intensity outside the stored vertical range is zero (e.g. nothing above 90° for a file that
//! stops there). An isotropic source therefore gives exactly 4πI.
//!
//! # Known limitations
//! Type A/B files are evaluated in their own frame (never resampled to C/γ), with mirroring only
//! for lateral symmetry (horizontal angles starting at 0); vertical angles starting at 0 are taken
//! literally (no light below V = 0). Tilt multipliers depend only on the luminaire's tilt from
//! its photometric position (the angle between its nadir axis and the world's downward
//! vertical) for all three lamp-to-luminaire geometries; the geometry code is kept, not used.
//! Interpolation is linear, not the cubic spline some tools offer (the echowuzangye table shows
//! the two differ by < 0.01 % in flux).

use nalgebra::Vector3;
use serde::Serialize;
use thiserror::Error;

mod quadrature;

use quadrature::{Kernel, cyclic_trapezoid_weights, linear_quadrature_weights, trapezoid_weights};

/// Angles closer than this (degrees) are the same angle when planes are mirrored and merged.
const SAME_ANGLE_DEG: f64 = 1e-6;

/// The photometric coordinate system of a measurement (LM-63 record 1 field 6; CIE 121).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
pub enum PhotometricType {
    /// Type A: polar axis horizontal along the luminaire (automotive).
    A,
    /// Type B: polar axis horizontal across the luminaire (floodlights).
    B,
    /// Type C: polar axis vertical (the usual C–γ system).
    C,
}

/// The symmetry of the stored data, which decides how it is mirrored to the full sphere.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
pub enum Symmetry {
    /// No symmetry: all planes stored.
    None,
    /// Rotational symmetry about the vertical axis: one plane stored.
    Axial,
    /// Mirror symmetry about the C0–C180 plane: C0…C180 stored.
    C0C180,
    /// Mirror symmetry about the C90–C270 plane: C90…C270 stored.
    C90C270,
    /// Symmetry about both planes: C0…C90 stored.
    Quadrant,
    /// Types A/B: mirror symmetry H → −H (horizontal angles stored from 0).
    Lateral,
}

impl Symmetry {
    /// A short lower-case label, as written in the CLI's JSON.
    #[must_use]
    pub fn label(self) -> &'static str {
        match self {
            Self::None => "none",
            Self::Axial => "axial",
            Self::C0C180 => "c0-c180",
            Self::C90C270 => "c90-c270",
            Self::Quadrant => "quadrant",
            Self::Lateral => "lateral",
        }
    }
}

/// Why a photometric web could not be built.
#[derive(Debug, Clone, PartialEq, Error)]
pub enum DistributionError {
    /// An angle axis has no angles.
    #[error("the {axis} angle list is empty")]
    Empty {
        /// "horizontal" or "vertical".
        axis: &'static str,
    },
    /// Angles must be strictly increasing.
    #[error("{axis} angles must increase strictly, but {previous_deg}° is followed by {next_deg}°")]
    NotIncreasing {
        /// "horizontal" or "vertical".
        axis: &'static str,
        /// The earlier angle.
        previous_deg: f64,
        /// The angle that does not exceed it.
        next_deg: f64,
    },
    /// An angle lies outside what its photometric type allows.
    #[error("{axis} angle {angle_deg}° lies outside {min_deg}°…{max_deg}°")]
    OutOfRange {
        /// "horizontal" or "vertical".
        axis: &'static str,
        /// The offending angle.
        angle_deg: f64,
        /// Smallest allowed.
        min_deg: f64,
        /// Largest allowed.
        max_deg: f64,
    },
    /// The intensity table does not have horizontal × vertical values.
    #[error("expected {expected} intensity values, found {found}")]
    WrongCount {
        /// horizontal count × vertical count.
        expected: usize,
        /// Values given.
        found: usize,
    },
    /// An angle or intensity is NaN or infinite.
    #[error("a non-finite {what} value")]
    NonFinite {
        /// "angle" or "intensity".
        what: &'static str,
    },
}

/// Lamp-to-luminaire geometry of an LM-63 tilt table (TILT=INCLUDE, first record).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
pub enum LampGeometry {
    /// 1: lamp vertical, base up or down, whatever the tilt.
    Vertical,
    /// 2: lamp horizontal and stays horizontal as the luminaire tilts (tilt about the lamp axis).
    HorizontalFixed,
    /// 3: lamp horizontal and tilts with the luminaire.
    HorizontalTilting,
}

/// Candela multipliers as a function of the luminaire's tilt from its photometric position
/// (LM-63 TILT=INCLUDE or a TILT file).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct TiltTable {
    /// How the lamp sits in the luminaire.
    pub geometry: LampGeometry,
    /// Tilt angles in degrees, increasing.
    pub angles_deg: Vec<f64>,
    /// Multiplier at each angle.
    pub multipliers: Vec<f64>,
}

impl TiltTable {
    /// The multiplier at `tilt_deg`, linear between table entries and held constant beyond them.
    #[must_use]
    pub fn multiplier_at(&self, tilt_deg: f64) -> f64 {
        let n = self.angles_deg.len().min(self.multipliers.len());
        if n == 0 {
            return 1.0;
        }
        if tilt_deg <= self.angles_deg[0] {
            return self.multipliers[0];
        }
        for i in 1..n {
            let (a0, a1) = (self.angles_deg[i - 1], self.angles_deg[i]);
            if tilt_deg <= a1 {
                let t = if a1 > a0 {
                    (tilt_deg - a0) / (a1 - a0)
                } else {
                    1.0
                };
                return self.multipliers[i - 1]
                    + t * (self.multipliers[i] - self.multipliers[i - 1]);
            }
        }
        self.multipliers[n - 1]
    }
}

/// Intensity I (cd) on a grid of angles covering the sphere (or the part that was measured).
///
/// For Type C the horizontal (C) axis is cyclic over [0°, 360°); for Types A and B both axes
/// lie in [−90°, 90°] (the rear hemisphere of a Type A/B measurement is not representable).
#[derive(Debug, Clone, PartialEq)]
pub struct PhotometricWeb {
    photometric_type: PhotometricType,
    symmetry: Symmetry,
    horizontal_deg: Vec<f64>,
    vertical_deg: Vec<f64>,
    /// `intensity_cd[h * vertical_deg.len() + v]`.
    intensity_cd: Vec<f64>,
}

fn check_axis(axis: &'static str, angles: &[f64]) -> Result<(), DistributionError> {
    if angles.is_empty() {
        return Err(DistributionError::Empty { axis });
    }
    if angles.iter().any(|a| !a.is_finite()) {
        return Err(DistributionError::NonFinite { what: "angle" });
    }
    for w in angles.windows(2) {
        if w[1] <= w[0] {
            return Err(DistributionError::NotIncreasing {
                axis,
                previous_deg: w[0],
                next_deg: w[1],
            });
        }
    }
    Ok(())
}

fn check_range(
    axis: &'static str,
    angles: &[f64],
    min_deg: f64,
    max_deg: f64,
) -> Result<(), DistributionError> {
    for &a in angles {
        if a < min_deg - SAME_ANGLE_DEG || a > max_deg + SAME_ANGLE_DEG {
            return Err(DistributionError::OutOfRange {
                axis,
                angle_deg: a,
                min_deg,
                max_deg,
            });
        }
    }
    Ok(())
}

impl PhotometricWeb {
    /// Builds a web from the stored planes of a file and expands `symmetry` to the full range.
    ///
    /// `planes_deg` are the stored horizontal angles (C for Type C, H for Types A/B),
    /// `vertical_deg` the angles within each plane (γ from nadir, or V), and `intensity_cd` the
    /// values plane by plane (`intensity_cd[plane * vertical_deg.len() + v]`).
    ///
    /// # Errors
    /// Empty, unsorted or out-of-range angles, a wrong value count, or non-finite numbers.
    pub fn from_planes(
        photometric_type: PhotometricType,
        symmetry: Symmetry,
        planes_deg: &[f64],
        vertical_deg: &[f64],
        intensity_cd: &[f64],
    ) -> Result<Self, DistributionError> {
        check_axis("horizontal", planes_deg)?;
        check_axis("vertical", vertical_deg)?;
        let nv = vertical_deg.len();
        let expected = planes_deg.len().saturating_mul(nv);
        if intensity_cd.len() != expected {
            return Err(DistributionError::WrongCount {
                expected,
                found: intensity_cd.len(),
            });
        }
        if intensity_cd.iter().any(|v| !v.is_finite()) {
            return Err(DistributionError::NonFinite { what: "intensity" });
        }
        let row = |p: usize| &intensity_cd[p * nv..(p + 1) * nv];
        // (angle, source plane) pairs after mirroring.
        let mut planes: Vec<(f64, usize)> = Vec::new();
        match photometric_type {
            PhotometricType::C => {
                check_range("vertical", vertical_deg, 0.0, 180.0)?;
                check_range("horizontal", planes_deg, -360.0, 720.0)?;
                for (p, &c) in planes_deg.iter().enumerate() {
                    let mirrored: &[f64] = match symmetry {
                        Symmetry::Axial => &[0.0],
                        Symmetry::None | Symmetry::Lateral => &[c],
                        Symmetry::C0C180 => &[c, 360.0 - c],
                        Symmetry::C90C270 => &[c, 540.0 - c],
                        Symmetry::Quadrant => &[c, 180.0 - c, 180.0 + c, 360.0 - c],
                    };
                    for &m in mirrored {
                        planes.push((m.rem_euclid(360.0), p));
                    }
                    if symmetry == Symmetry::Axial {
                        break;
                    }
                }
            }
            PhotometricType::A | PhotometricType::B => {
                check_range("vertical", vertical_deg, -90.0, 90.0)?;
                check_range("horizontal", planes_deg, -90.0, 90.0)?;
                for (p, &h) in planes_deg.iter().enumerate() {
                    planes.push((h, p));
                    if symmetry == Symmetry::Lateral && h > SAME_ANGLE_DEG {
                        planes.push((-h, p));
                    }
                }
            }
        }
        planes.sort_by(|a, b| a.0.total_cmp(&b.0));
        planes.dedup_by(|b, a| (b.0 - a.0).abs() < SAME_ANGLE_DEG);
        let mut horizontal = Vec::with_capacity(planes.len());
        let mut values = Vec::with_capacity(planes.len() * nv);
        for &(angle, p) in &planes {
            horizontal.push(angle);
            values.extend_from_slice(row(p));
        }
        Ok(Self {
            photometric_type,
            symmetry,
            horizontal_deg: horizontal,
            vertical_deg: vertical_deg.to_vec(),
            intensity_cd: values,
        })
    }

    /// The coordinate system of the data.
    #[must_use]
    pub fn photometric_type(&self) -> PhotometricType {
        self.photometric_type
    }

    /// The symmetry the data were stored with.
    #[must_use]
    pub fn symmetry(&self) -> Symmetry {
        self.symmetry
    }

    /// Horizontal angles after expansion (C in [0°, 360°) for Type C; H for Types A/B).
    #[must_use]
    pub fn horizontal_deg(&self) -> &[f64] {
        &self.horizontal_deg
    }

    /// Vertical angles (γ from nadir for Type C; V for Types A/B).
    #[must_use]
    pub fn vertical_deg(&self) -> &[f64] {
        &self.vertical_deg
    }

    /// The expanded table, `[h * vertical_deg().len() + v]`, in cd.
    #[must_use]
    pub fn intensity_table_cd(&self) -> &[f64] {
        &self.intensity_cd
    }

    /// The largest tabulated intensity (cd).
    #[must_use]
    pub fn max_intensity_cd(&self) -> f64 {
        self.intensity_cd.iter().copied().fold(0.0, f64::max)
    }

    /// The same distribution with every intensity multiplied by `factor`.
    #[must_use]
    pub fn scaled(&self, factor: f64) -> Self {
        let mut out = self.clone();
        for v in &mut out.intensity_cd {
            *v *= factor;
        }
        out
    }

    fn value(&self, h: usize, v: usize) -> f64 {
        self.intensity_cd[h * self.vertical_deg.len() + v]
    }

    /// Linear interpolation along the vertical axis of plane `h`; zero outside the stored range.
    fn along_vertical(&self, h: usize, vertical_deg: f64) -> f64 {
        let vs = &self.vertical_deg;
        let n = vs.len();
        if vertical_deg < vs[0] - SAME_ANGLE_DEG || vertical_deg > vs[n - 1] + SAME_ANGLE_DEG {
            return 0.0;
        }
        if n == 1 {
            return self.value(h, 0);
        }
        let i = vs.partition_point(|&a| a <= vertical_deg).clamp(1, n - 1);
        let (a0, a1) = (vs[i - 1], vs[i]);
        let t = ((vertical_deg - a0) / (a1 - a0)).clamp(0.0, 1.0);
        self.value(h, i - 1) * (1.0 - t) + self.value(h, i) * t
    }

    /// Intensity (cd) at native angles: (C, γ) for Type C, (H, V) for Types A/B, bilinear.
    #[must_use]
    pub fn intensity_cd(&self, horizontal_deg: f64, vertical_deg: f64) -> f64 {
        let hs = &self.horizontal_deg;
        let n = hs.len();
        if n == 1 {
            return self.along_vertical(0, vertical_deg);
        }
        match self.photometric_type {
            PhotometricType::C => {
                let c = horizontal_deg.rem_euclid(360.0);
                let i = hs.partition_point(|&a| a <= c);
                // Segment from plane i-1 to plane i, cyclically.
                let (lo, hi) = if i == 0 || i == n {
                    (n - 1, 0)
                } else {
                    (i - 1, i)
                };
                let a0 = hs[lo];
                let mut a1 = hs[hi];
                if a1 <= a0 {
                    a1 += 360.0;
                }
                let mut x = c;
                if x < a0 {
                    x += 360.0;
                }
                let t = if a1 > a0 {
                    ((x - a0) / (a1 - a0)).clamp(0.0, 1.0)
                } else {
                    0.0
                };
                self.along_vertical(lo, vertical_deg) * (1.0 - t)
                    + self.along_vertical(hi, vertical_deg) * t
            }
            PhotometricType::A | PhotometricType::B => {
                if horizontal_deg < hs[0] - SAME_ANGLE_DEG
                    || horizontal_deg > hs[n - 1] + SAME_ANGLE_DEG
                {
                    return 0.0;
                }
                let i = hs.partition_point(|&a| a <= horizontal_deg).clamp(1, n - 1);
                let t = ((horizontal_deg - hs[i - 1]) / (hs[i] - hs[i - 1])).clamp(0.0, 1.0);
                self.along_vertical(i - 1, vertical_deg) * (1.0 - t)
                    + self.along_vertical(i, vertical_deg) * t
            }
        }
    }

    /// Intensity (cd) toward a direction given in the luminaire frame (module doc).
    #[must_use]
    pub fn intensity_toward_cd(&self, dir_in_luminaire: &Vector3<f64>) -> f64 {
        let Some(d) = dir_in_luminaire.try_normalize(1e-300) else {
            return 0.0;
        };
        match self.photometric_type {
            PhotometricType::C => {
                let gamma_deg = (-d.z).clamp(-1.0, 1.0).acos().to_degrees();
                let c_deg = d.y.atan2(d.x).to_degrees().rem_euclid(360.0);
                self.intensity_cd(c_deg, gamma_deg)
            }
            PhotometricType::B => {
                let h_deg = d.y.clamp(-1.0, 1.0).asin().to_degrees();
                let v_deg = d.x.atan2(-d.z).to_degrees();
                self.intensity_cd(h_deg, v_deg)
            }
            PhotometricType::A => {
                let v_deg = d.x.clamp(-1.0, 1.0).asin().to_degrees();
                let h_deg = d.y.atan2(-d.z).to_degrees();
                self.intensity_cd(h_deg, v_deg)
            }
        }
    }

    /// Intensity (cd) at C-plane `c_deg` and angle `gamma_deg` from nadir, whatever the type.
    #[must_use]
    pub fn intensity_c_gamma_cd(&self, c_deg: f64, gamma_deg: f64) -> f64 {
        if self.photometric_type == PhotometricType::C {
            return self.intensity_cd(c_deg, gamma_deg);
        }
        self.intensity_toward_cd(&direction_from_c_gamma(c_deg, gamma_deg))
    }

    /// Total luminous flux (lm): the exact integral of the bilinear interpolant over the sphere
    /// (see the module doc for the quadrature), evaluated as Σ_h Σ_v w_h · w_v · I[h][v] with
    /// weights that depend only on the angles.
    #[must_use]
    pub fn total_flux_lm(&self) -> f64 {
        let hs: Vec<f64> = self.horizontal_deg.iter().map(|a| a.to_radians()).collect();
        let vs: Vec<f64> = self.vertical_deg.iter().map(|a| a.to_radians()).collect();
        let (wh, wv) = match self.photometric_type {
            // Cyclic trapezoid over C, exact sin-weighted integral over γ.
            PhotometricType::C => (
                cyclic_trapezoid_weights(&hs),
                linear_quadrature_weights(&vs, Kernel::Sin),
            ),
            // Latitude is V (within each H plane); trapezoid over H.
            PhotometricType::A => (
                trapezoid_weights(&hs),
                linear_quadrature_weights(&vs, Kernel::Cos),
            ),
            // Latitude is H; trapezoid over V.
            PhotometricType::B => (
                linear_quadrature_weights(&hs, Kernel::Cos),
                trapezoid_weights(&vs),
            ),
        };
        let nv = vs.len();
        wh.iter()
            .zip(self.intensity_cd.chunks_exact(nv))
            .map(|(w, row)| w * row.iter().zip(&wv).map(|(i, wi)| i * wi).sum::<f64>())
            .sum()
    }
}

/// Unit direction in the luminaire frame of C-plane `c_deg`, angle `gamma_deg` from nadir.
#[must_use]
pub fn direction_from_c_gamma(c_deg: f64, gamma_deg: f64) -> Vector3<f64> {
    let (c, g) = (c_deg.to_radians(), gamma_deg.to_radians());
    Vector3::new(g.sin() * c.cos(), g.sin() * c.sin(), -g.cos())
}

#[cfg(test)]
#[path = "distribution_tests.rs"]
mod tests;
