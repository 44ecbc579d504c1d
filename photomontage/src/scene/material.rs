//! Materials and the material library file (TOML, documented in `docs/material-library.md`).
//!
//! Durisch 1992 §7 keeps "tabulated physical data … in an extendable library"; this is that
//! library. Each material has a diffuse reflectance ρ_d (RGB or spectral samples), an optional
//! microfacet specular lobe (GGX / Trowbridge–Reitz normal distribution, Walter et al. 2007, with
//! Schlick's Fresnel approximation and F0), an optional ideal mirror, an optional glass layer (IOR,
//! transmittance; exact dielectric Fresnel), an optional emitted radiance, and an optional
//! solid-texture normal perturbation for water (Durisch 1992 §7 example 2, after Haruyama & Barsky
//! 1984 extended to 3-D as a solid texture, Peachey 1985 / Perlin 1985; here Perlin's gradient
//! noise, summed over octaves).
//!
//! # Known limitations
//! Spectral reflectances are reduced to RGB by averaging over three fixed bands (400–500, 500–600,
//! 600–700 nm); a proper colour-matching reduction belongs to the colour module. Textures (image
//! maps) are not supported. The water perturbation is isotropic noise, not a wave spectrum.

use std::path::Path;

use nalgebra::Vector3;
use rand::{SeedableRng, seq::SliceRandom};
use rand_chacha::ChaCha8Rng;
use serde::{Deserialize, Serialize};

/// Most spectral samples accepted for one curve (keeps parsing bounded).
pub const MAX_SPECTRAL_SAMPLES: usize = 1000;

/// Errors reading or validating a material library.
#[derive(Debug, thiserror::Error)]
pub enum MaterialError {
    /// The file could not be read.
    #[error("cannot read material library {path}: {source}")]
    Io {
        /// File path.
        path: String,
        /// Underlying error.
        source: std::io::Error,
    },
    /// The TOML is malformed or has unknown keys.
    #[error("material library parse error: {message}")]
    Parse {
        /// The TOML parser's message (with line and column).
        message: String,
    },
    /// A value is physically impossible.
    #[error("material '{material}': {reason}")]
    Invalid {
        /// Material name.
        material: String,
        /// What is wrong.
        reason: String,
    },
    /// Two materials share a name.
    #[error("material '{name}' is defined twice")]
    DuplicateName {
        /// The name.
        name: String,
    },
}

/// A reflectance curve sampled at increasing wavelengths.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Spectrum {
    /// Wavelengths in nanometres, strictly increasing.
    pub wavelengths_nm: Vec<f64>,
    /// Values at those wavelengths (reflectance 0–1).
    pub values: Vec<f64>,
}

impl Spectrum {
    /// Linear interpolation, clamped to the end values outside the sampled range.
    #[must_use]
    pub fn at(&self, wavelength_nm: f64) -> f64 {
        let w = &self.wavelengths_nm;
        let (Some(&first), Some(&last)) = (w.first(), w.last()) else {
            return 0.0;
        };
        if wavelength_nm <= first {
            return self.values[0];
        }
        if wavelength_nm >= last {
            return self.values[w.len() - 1];
        }
        let i = w.partition_point(|&x| x <= wavelength_nm).max(1) - 1;
        let f = (wavelength_nm - w[i]) / (w[i + 1] - w[i]);
        self.values[i] * (1.0 - f) + self.values[i + 1] * f
    }

    /// Mean over `[lo_nm, hi_nm]` (1 nm trapezoid steps).
    #[must_use]
    pub fn band_mean(&self, lo_nm: f64, hi_nm: f64) -> f64 {
        let steps = 100;
        let h = (hi_nm - lo_nm) / f64::from(steps);
        let mut sum = 0.5 * (self.at(lo_nm) + self.at(hi_nm));
        for k in 1..steps {
            sum += self.at(lo_nm + h * f64::from(k));
        }
        sum / f64::from(steps)
    }

    fn validate(&self, material: &str) -> Result<(), MaterialError> {
        let invalid = |reason: String| MaterialError::Invalid {
            material: material.to_owned(),
            reason,
        };
        let n = self.wavelengths_nm.len();
        if n == 0 || n > MAX_SPECTRAL_SAMPLES || n != self.values.len() {
            return Err(invalid(format!(
                "a spectrum needs 1..={MAX_SPECTRAL_SAMPLES} wavelengths and as many values, got {n} and {}",
                self.values.len()
            )));
        }
        if self
            .wavelengths_nm
            .windows(2)
            .any(|w| w[1].partial_cmp(&w[0]) != Some(std::cmp::Ordering::Greater))
        {
            return Err(invalid(
                "wavelengths must be strictly increasing".to_owned(),
            ));
        }
        check_unit_interval(&self.values, "spectral reflectance").map_err(invalid)
    }
}

fn check_unit_interval(values: &[f64], what: &str) -> Result<(), String> {
    match values.iter().find(|v| !(0.0..=1.0).contains(*v)) {
        Some(v) => Err(format!("{what} {v} is outside [0, 1]")),
        None => Ok(()),
    }
}

/// A microfacet specular lobe: GGX distribution, Schlick Fresnel.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Specular {
    /// Perceptual roughness in (0, 1]; the GGX α is its square (Burley 2012).
    pub roughness: f64,
    /// Reflectance at normal incidence (0.04 for most dielectrics: glass, paint, stone).
    pub f0: f64,
}

impl Specular {
    /// GGX normal distribution D(h) for the cosine between the half vector and the normal.
    #[must_use]
    pub fn ggx_distribution(&self, cos_theta_h: f64) -> f64 {
        if cos_theta_h <= 0.0 {
            return 0.0;
        }
        let alpha2 = (self.roughness * self.roughness).powi(2);
        let c2 = cos_theta_h * cos_theta_h;
        let d = c2 * (alpha2 - 1.0) + 1.0;
        alpha2 / (std::f64::consts::PI * d * d)
    }

    /// Schlick's Fresnel approximation F(θ) = F0 + (1 − F0)(1 − cos θ)⁵.
    #[must_use]
    pub fn fresnel_schlick(&self, cos_theta: f64) -> f64 {
        self.f0 + (1.0 - self.f0) * (1.0 - cos_theta.clamp(0.0, 1.0)).powi(5)
    }
}

/// A glass layer (window panes): ideal refraction with exact Fresnel weights.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Glass {
    /// Index of refraction relative to air (≥ 1; float glass 1.52).
    pub ior: f64,
    /// Transmittance through the pane per RGB channel (0–1), absorption only.
    pub transmittance_rgb: [f64; 3],
}

impl Glass {
    /// Unpolarised Fresnel reflectance of a dielectric interface (air → glass) at incidence
    /// cosine `cos_theta_i`; 1 for total internal reflection.
    #[must_use]
    pub fn fresnel_reflectance(&self, cos_theta_i: f64) -> f64 {
        let cos_i = cos_theta_i.clamp(0.0, 1.0);
        let sin_t2 = (1.0 - cos_i * cos_i) / (self.ior * self.ior);
        if sin_t2 >= 1.0 {
            return 1.0;
        }
        let cos_t = (1.0 - sin_t2).sqrt();
        let rs = (cos_i - self.ior * cos_t) / (cos_i + self.ior * cos_t);
        let rp = (self.ior * cos_i - cos_t) / (self.ior * cos_i + cos_t);
        0.5 * (rs * rs + rp * rp)
    }
}

/// Solid-texture normal perturbation for water surfaces (Durisch 1992 example 2).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct WaterWaves {
    /// Size of the largest noise cell, metres.
    pub scale_m: f64,
    /// Slope amplitude: the tangential normal offset per unit of noise gradient (0 = flat).
    pub slope: f64,
    /// Octaves of noise (each half the size and half the amplitude of the previous), 1–8.
    pub octaves: u32,
    /// Seed of the noise permutation.
    #[serde(default)]
    pub seed: u64,
}

/// A surface material.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Material {
    /// Unique name (referenced from CAD files' material names).
    pub name: String,
    /// Diffuse reflectance ρ_d per RGB channel (linear, 0–1). Ignored if a spectrum is given.
    #[serde(default = "default_diffuse_rgb")]
    pub diffuse_rgb: [f64; 3],
    /// Diffuse reflectance ρ_dλ as spectral samples.
    #[serde(default)]
    pub diffuse_spectrum: Option<Spectrum>,
    /// Microfacet specular lobe.
    #[serde(default)]
    pub specular: Option<Specular>,
    /// Ideal mirror reflectance per RGB channel.
    #[serde(default)]
    pub mirror_rgb: Option<[f64; 3]>,
    /// Glass layer.
    #[serde(default)]
    pub glass: Option<Glass>,
    /// Emitted radiance, W·m⁻²·sr⁻¹ per RGB channel.
    #[serde(default)]
    pub emission_rgb_w_m2_sr: Option<[f64; 3]>,
    /// Water-surface normal perturbation.
    #[serde(default)]
    pub water: Option<WaterWaves>,
}

fn default_diffuse_rgb() -> [f64; 3] {
    [0.5; 3]
}

impl Default for Material {
    /// Mid-grey Lambertian, ρ_d = 0.5: what faces without a known material get.
    fn default() -> Self {
        Self::diffuse("default", default_diffuse_rgb())
    }
}

impl Material {
    /// A purely diffuse material.
    #[must_use]
    pub fn diffuse(name: &str, diffuse_rgb: [f64; 3]) -> Self {
        Self {
            name: name.to_owned(),
            diffuse_rgb,
            diffuse_spectrum: None,
            specular: None,
            mirror_rgb: None,
            glass: None,
            emission_rgb_w_m2_sr: None,
            water: None,
        }
    }

    /// Diffuse reflectance as RGB: the given triple, or the spectrum's band means
    /// (R 600–700 nm, G 500–600 nm, B 400–500 nm).
    #[must_use]
    pub fn diffuse_reflectance_rgb(&self) -> [f64; 3] {
        match &self.diffuse_spectrum {
            Some(s) => [
                s.band_mean(600.0, 700.0),
                s.band_mean(500.0, 600.0),
                s.band_mean(400.0, 500.0),
            ],
            None => self.diffuse_rgb,
        }
    }

    /// Checks physical plausibility (reflectances in [0, 1], energy conservation of diffuse +
    /// mirror, IOR ≥ 1, roughness in (0, 1], finite emission, sane water parameters).
    ///
    /// # Errors
    /// [`MaterialError::Invalid`] naming the material and the problem.
    pub fn validate(&self) -> Result<(), MaterialError> {
        let invalid = |reason: String| MaterialError::Invalid {
            material: self.name.clone(),
            reason,
        };
        check_unit_interval(&self.diffuse_rgb, "diffuse reflectance").map_err(invalid)?;
        if let Some(s) = &self.diffuse_spectrum {
            s.validate(&self.name)?;
        }
        if let Some(m) = self.mirror_rgb {
            check_unit_interval(&m, "mirror reflectance").map_err(invalid)?;
            let d = self.diffuse_reflectance_rgb();
            if (0..3).any(|c| d[c] + m[c] > 1.0 + 1e-9) {
                return Err(invalid("diffuse + mirror reflectance exceeds 1".to_owned()));
            }
        }
        if let Some(s) = self.specular {
            if !(s.roughness > 0.0 && s.roughness <= 1.0) {
                return Err(invalid(format!(
                    "roughness {} is outside (0, 1]",
                    s.roughness
                )));
            }
            check_unit_interval(&[s.f0], "specular f0").map_err(invalid)?;
        }
        if let Some(g) = self.glass {
            if !(g.ior >= 1.0 && g.ior.is_finite()) {
                return Err(invalid(format!("glass ior {} must be ≥ 1", g.ior)));
            }
            check_unit_interval(&g.transmittance_rgb, "glass transmittance").map_err(invalid)?;
        }
        if let Some(e) = self.emission_rgb_w_m2_sr
            && e.iter().any(|v| !(v.is_finite() && *v >= 0.0))
        {
            return Err(invalid(
                "emission must be finite and non-negative".to_owned(),
            ));
        }
        if let Some(w) = self.water
            && !(w.scale_m > 0.0
                && w.scale_m.is_finite()
                && w.slope.is_finite()
                && w.slope >= 0.0
                && (1..=8).contains(&w.octaves))
        {
            return Err(invalid(
                "water needs scale_m > 0, slope ≥ 0 and 1–8 octaves".to_owned(),
            ));
        }
        Ok(())
    }
}

/// A named set of materials read from a TOML file (`[[material]]` tables).
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct MaterialLibrary {
    /// The materials, in file order.
    #[serde(default, rename = "material")]
    pub materials: Vec<Material>,
}

impl MaterialLibrary {
    /// Parses and validates a library from TOML text.
    ///
    /// # Errors
    /// Parse errors, invalid values and duplicate names.
    pub fn from_toml_str(text: &str) -> Result<Self, MaterialError> {
        let lib: Self = toml::from_str(text).map_err(|e| MaterialError::Parse {
            message: e.to_string(),
        })?;
        let mut names = std::collections::HashSet::new();
        for m in &lib.materials {
            m.validate()?;
            if !names.insert(m.name.as_str()) {
                return Err(MaterialError::DuplicateName {
                    name: m.name.clone(),
                });
            }
        }
        Ok(lib)
    }

    /// Reads a library file.
    ///
    /// # Errors
    /// I/O errors and those of [`Self::from_toml_str`].
    pub fn load(path: &Path) -> Result<Self, MaterialError> {
        let text = std::fs::read_to_string(path).map_err(|source| MaterialError::Io {
            path: path.display().to_string(),
            source,
        })?;
        Self::from_toml_str(&text)
    }

    /// The material with this name.
    #[must_use]
    pub fn get(&self, name: &str) -> Option<&Material> {
        self.materials.iter().find(|m| m.name == name)
    }
}

/// Perlin's improved gradient noise (Perlin 2002) with a seeded permutation.
#[derive(Debug, Clone)]
pub struct GradientNoise {
    permutation: [u8; 512],
}

impl GradientNoise {
    /// Noise with a permutation shuffled by a seeded ChaCha8 generator.
    #[must_use]
    pub fn new(seed: u64) -> Self {
        let mut p: Vec<u8> = (0..=255).collect();
        p.shuffle(&mut ChaCha8Rng::seed_from_u64(seed));
        let mut permutation = [0u8; 512];
        for i in 0..512 {
            permutation[i] = p[i % 256];
        }
        Self { permutation }
    }

    fn grad(hash: u8, x: f64, y: f64, z: f64) -> f64 {
        let h = hash & 15;
        let u = if h < 8 { x } else { y };
        let v = if h < 4 {
            y
        } else if h == 12 || h == 14 {
            x
        } else {
            z
        };
        (if h & 1 == 0 { u } else { -u }) + (if h & 2 == 0 { v } else { -v })
    }

    /// Noise value at a point (zero at every integer lattice point, roughly in [−1, 1]).
    #[must_use]
    pub fn value(&self, p: Vector3<f64>) -> f64 {
        let fade = |t: f64| t * t * t * (t * (t * 6.0 - 15.0) + 10.0);
        let lerp = |t: f64, a: f64, b: f64| a + t * (b - a);
        let (fx, fy, fz) = (p.x.floor(), p.y.floor(), p.z.floor());
        // Wrapping to 0..=255 is intended: the lattice repeats every 256 cells.
        #[allow(clippy::cast_possible_truncation, clippy::cast_sign_loss)]
        let (xi, yi, zi) = (
            (fx.rem_euclid(256.0) as usize),
            (fy.rem_euclid(256.0) as usize),
            (fz.rem_euclid(256.0) as usize),
        );
        let (x, y, z) = (p.x - fx, p.y - fy, p.z - fz);
        let (u, v, w) = (fade(x), fade(y), fade(z));
        let pm = &self.permutation;
        let a = pm[xi] as usize + yi;
        let (aa, ab) = (pm[a] as usize + zi, pm[a + 1] as usize + zi);
        let b = pm[xi + 1] as usize + yi;
        let (ba, bb) = (pm[b] as usize + zi, pm[b + 1] as usize + zi);
        lerp(
            w,
            lerp(
                v,
                lerp(
                    u,
                    Self::grad(pm[aa], x, y, z),
                    Self::grad(pm[ba], x - 1.0, y, z),
                ),
                lerp(
                    u,
                    Self::grad(pm[ab], x, y - 1.0, z),
                    Self::grad(pm[bb], x - 1.0, y - 1.0, z),
                ),
            ),
            lerp(
                v,
                lerp(
                    u,
                    Self::grad(pm[aa + 1], x, y, z - 1.0),
                    Self::grad(pm[ba + 1], x - 1.0, y, z - 1.0),
                ),
                lerp(
                    u,
                    Self::grad(pm[ab + 1], x, y - 1.0, z - 1.0),
                    Self::grad(pm[bb + 1], x - 1.0, y - 1.0, z - 1.0),
                ),
            ),
        )
    }
}

impl WaterWaves {
    /// Gradient (per metre) of the fractal noise height field at a world point, by central
    /// differences with a step of 1/1000 of the finest octave's cell.
    #[must_use]
    pub fn height_gradient(
        &self,
        noise: &GradientNoise,
        point_in_world_m: Vector3<f64>,
    ) -> Vector3<f64> {
        let mut grad = Vector3::zeros();
        let mut cell_m = self.scale_m;
        let mut amplitude = 1.0;
        for _ in 0..self.octaves {
            let h = cell_m * 1e-3;
            let q = point_in_world_m / cell_m;
            let d = |e: Vector3<f64>| {
                (noise.value(q + e * (h / cell_m)) - noise.value(q - e * (h / cell_m))) / (2.0 * h)
            };
            grad += amplitude
                * cell_m
                * Vector3::new(d(Vector3::x()), d(Vector3::y()), d(Vector3::z()));
            cell_m *= 0.5;
            amplitude *= 0.5;
        }
        grad
    }

    /// The unit normal perturbed by the tangential part of the noise gradient, scaled by
    /// `slope` (Blinn 1978 bump mapping on a solid texture).
    #[must_use]
    pub fn perturb_normal(
        &self,
        noise: &GradientNoise,
        normal: Vector3<f64>,
        point_in_world_m: Vector3<f64>,
    ) -> Vector3<f64> {
        let g = self.height_gradient(noise, point_in_world_m);
        let tangential = g - normal * g.dot(&normal);
        (normal - self.slope * tangential).normalize()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Numerical integration with 20 000 midpoint steps: error well below 1e-3 for these smooth
    /// integrands.
    const QUADRATURE_TOL: f64 = 1e-3;

    #[test]
    fn ggx_is_normalised_over_projected_hemisphere() {
        // ∫ D(h) cos θ_h dω_h = 1 for any roughness (Walter et al. 2007, eq. 4).
        for roughness in [0.3, 0.6, 1.0] {
            let s = Specular {
                roughness,
                f0: 0.04,
            };
            let n = 20_000;
            let mut sum = 0.0;
            for k in 0..n {
                let theta = (f64::from(k) + 0.5) / f64::from(n) * std::f64::consts::FRAC_PI_2;
                sum += s.ggx_distribution(theta.cos()) * theta.cos() * theta.sin();
            }
            let integral =
                sum * 2.0 * std::f64::consts::PI * std::f64::consts::FRAC_PI_2 / f64::from(n);
            assert!(
                (integral - 1.0).abs() < QUADRATURE_TOL,
                "roughness {roughness}: {integral}"
            );
        }
    }

    #[test]
    fn fresnel_known_values() {
        let g = Glass {
            ior: 1.5,
            transmittance_rgb: [1.0; 3],
        };
        // Normal incidence: ((n − 1)/(n + 1))² = 0.04 exactly for n = 1.5.
        assert!((g.fresnel_reflectance(1.0) - 0.04).abs() < 1e-12);
        // Brewster's angle tan θ_B = n: p-polarised reflectance vanishes, R = Rs/2.
        let theta_b = 1.5f64.atan();
        let (ci, si) = (theta_b.cos(), theta_b.sin());
        let ct = (1.0 - (si / 1.5).powi(2)).sqrt();
        let rs = ((ci - 1.5 * ct) / (ci + 1.5 * ct)).powi(2);
        assert!((g.fresnel_reflectance(ci) - rs / 2.0).abs() < 1e-12);
        assert!(
            (g.fresnel_reflectance(0.0) - 1.0).abs() < 1e-12,
            "grazing incidence"
        );
        let s = Specular {
            roughness: 0.5,
            f0: 0.04,
        };
        assert!((s.fresnel_schlick(1.0) - 0.04).abs() < 1e-15);
        assert!((s.fresnel_schlick(0.0) - 1.0).abs() < 1e-15);
    }

    #[test]
    fn library_parses_and_rejects_bad_values() {
        let text = r#"
            [[material]]
            name = "brick"
            diffuse_rgb = [0.35, 0.18, 0.12]
            specular = { roughness = 0.8, f0 = 0.04 }

            [[material]]
            name = "flat_grey_spectrum"
            diffuse_spectrum = { wavelengths_nm = [400.0, 700.0], values = [0.3, 0.3] }

            [[material]]
            name = "window"
            diffuse_rgb = [0.0, 0.0, 0.0]
            glass = { ior = 1.52, transmittance_rgb = [0.85, 0.88, 0.86] }

            [[material]]
            name = "lake"
            diffuse_rgb = [0.05, 0.07, 0.06]
            mirror_rgb = [0.3, 0.3, 0.3]
            water = { scale_m = 2.0, slope = 0.3, octaves = 4, seed = 7 }
        "#;
        let lib = MaterialLibrary::from_toml_str(text).unwrap();
        assert_eq!(lib.materials.len(), 4);
        let grey = lib
            .get("flat_grey_spectrum")
            .unwrap()
            .diffuse_reflectance_rgb();
        assert!(grey.iter().all(|v| (v - 0.3).abs() < 1e-12), "{grey:?}");
        assert!(lib.get("window").unwrap().glass.is_some());

        let bad_ior = "[[material]]\nname = \"x\"\nglass = { ior = 0.5, transmittance_rgb = [1.0, 1.0, 1.0] }\n";
        assert!(
            matches!(MaterialLibrary::from_toml_str(bad_ior), Err(MaterialError::Invalid { material, .. }) if material == "x")
        );
        let too_bright = "[[material]]\nname = \"y\"\ndiffuse_rgb = [0.8, 0.8, 0.8]\nmirror_rgb = [0.5, 0.5, 0.5]\n";
        assert!(matches!(
            MaterialLibrary::from_toml_str(too_bright),
            Err(MaterialError::Invalid { .. })
        ));
        let dup = "[[material]]\nname = \"z\"\n[[material]]\nname = \"z\"\n";
        assert!(
            matches!(MaterialLibrary::from_toml_str(dup), Err(MaterialError::DuplicateName { name }) if name == "z")
        );
        let typo = "[[material]]\nname = \"t\"\ndifuse_rgb = [0.1, 0.1, 0.1]\n";
        assert!(matches!(
            MaterialLibrary::from_toml_str(typo),
            Err(MaterialError::Parse { .. })
        ));
    }

    #[test]
    fn gradient_noise_vanishes_on_lattice_and_is_seeded() {
        let a = GradientNoise::new(1);
        let b = GradientNoise::new(2);
        for p in [Vector3::new(0.0, 0.0, 0.0), Vector3::new(3.0, -7.0, 12.0)] {
            assert!(a.value(p).abs() < 1e-12);
        }
        let p = Vector3::new(0.37, 1.61, 2.23);
        assert!(
            (a.value(p) - GradientNoise::new(1).value(p)).abs() < 1e-15,
            "deterministic"
        );
        assert!((a.value(p) - b.value(p)).abs() > 1e-6, "seed matters");
    }

    #[test]
    fn water_perturbation_tilts_normals_by_the_slope() {
        let up = Vector3::z();
        let noise = GradientNoise::new(7);
        let flat = WaterWaves {
            scale_m: 2.0,
            slope: 0.0,
            octaves: 3,
            seed: 7,
        };
        let p = Vector3::new(600_010.3, 200_004.1, 401.0);
        assert!(
            (flat.perturb_normal(&noise, up, p) - up).norm() < 1e-15,
            "zero slope is flat"
        );
        let waves = WaterWaves { slope: 0.5, ..flat };
        let mut mean = Vector3::zeros();
        let mut max_tilt: f64 = 0.0;
        for k in 0..400 {
            let q = Vector3::new(0.173 * f64::from(k), 0.311 * f64::from(k % 37), 0.0);
            let n = waves.perturb_normal(&noise, up, q);
            assert!((n.norm() - 1.0).abs() < 1e-12);
            mean += n;
            max_tilt = max_tilt.max(n.z.acos());
        }
        mean /= 400.0;
        // Noise gradients average out: the mean normal stays close to vertical, yet normals tilt.
        assert!(mean.x.abs() < 0.1 && mean.y.abs() < 0.1, "{mean}");
        assert!(max_tilt > 0.05, "{max_tilt}");
    }
}
