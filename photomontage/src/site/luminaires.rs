//! The site's `[[luminaires]]` as artificial lights of the renderer (Durisch 1992 §3.2 light
//! sources; §6.2 case C on artificial surfaces, case D1 on photographed ones): each enabled entry
//! reads its photometric file (IES LM-63-2002 or EULUMDAT, [`crate::luminaire`]), is placed at
//! `position_m` and aimed by `rotation_z_deg` / `tilt_deg`, and becomes a
//! [`LuminaireLight`] whose `rgb_per_cd = colour_rgb · scale`.
//!
//! # Units
//! `scale` converts candela to the photo's linear units so that a surface facing a luminaire of
//! intensity I (cd) at distance d (m) receives the irradiance `I · scale · colour / d²` in the
//! same units as `lighting.sun_weight` (the sun's normal irradiance k_s). To choose it: if the
//! photo's daylight is known in lux (E_sun ≈ 80 000 lx facing the sun) and the site uses k_s for
//! it, `scale = k_s / E_sun` (lx is cd/m², so candela then maps exactly like the sun).
//!
//! # Frame
//! Both angles 0: nadir (γ = 0) straight down, C0 half-plane towards world +X, C90 towards +Y.
//! `world_from_luminaire = R_z(rotation_z_deg) · R_y(−tilt_deg)`: the tilt swings the nadir up
//! towards the C0 direction, then the whole luminaire turns about the vertical.
//!
//! # Known limitations
//! Point sources (no soft shadows; near-field error within ~5 opening sizes). An IES
//! `TILT=INCLUDE` table is read at tilt 0 (the multiplier for the actual aim is not applied).
//! EULUMDAT files use their first lamp set. The luminaires are not visible themselves.

use nalgebra::{Point3, Rotation3, Vector3};

use super::render_error::{SiteRenderError, SiteWarning};
use super::{Site, SiteDocument, SiteLuminaire};
use crate::luminaire::{Luminaire, PhotometricFile};
use crate::render::{ArtificialLight, LuminaireLight};

/// Rotation taking luminaire-frame directions to world directions for the site's aim angles
/// (module doc, "Frame").
#[must_use]
pub fn world_from_luminaire(rotation_z_deg: f64, tilt_deg: f64) -> Rotation3<f64> {
    Rotation3::from_axis_angle(&Vector3::z_axis(), rotation_z_deg.to_radians())
        * Rotation3::from_axis_angle(&Vector3::y_axis(), -tilt_deg.to_radians())
}

fn light_of(doc: &SiteDocument, entry: &SiteLuminaire) -> Result<ArtificialLight, SiteRenderError> {
    let setting = |field: &'static str, reason: &str| SiteRenderError::LuminaireSetting {
        luminaire: entry.id.clone(),
        field,
        reason: reason.to_owned(),
    };
    if !entry.position_m.iter().all(|v| v.is_finite()) {
        return Err(setting(
            "position_m",
            "must be finite (not NaN or infinite)",
        ));
    }
    if !(entry.rotation_z_deg.is_finite() && entry.tilt_deg.is_finite()) {
        return Err(setting("rotation_z_deg/tilt_deg", "must be finite"));
    }
    if !(entry.scale.is_finite() && entry.scale >= 0.0) {
        return Err(setting("scale", "must be finite and ≥ 0"));
    }
    if !entry.colour_rgb.iter().all(|c| c.is_finite() && *c >= 0.0) {
        return Err(setting("colour_rgb", "must be finite and ≥ 0"));
    }
    let path = doc.resolve(&entry.file);
    let file_error = |reason: String| SiteRenderError::LuminaireFile {
        luminaire: entry.id.clone(),
        path: path.display().to_string(),
        reason,
    };
    let web = PhotometricFile::read(&path)
        .and_then(|f| f.distribution())
        .map_err(|e| file_error(e.to_string()))?;
    let mut luminaire = Luminaire::new(web, Point3::from(entry.position_m));
    luminaire.world_from_luminaire = world_from_luminaire(entry.rotation_z_deg, entry.tilt_deg);
    Ok(ArtificialLight::from(LuminaireLight {
        luminaire,
        rgb_per_cd: entry.colour_rgb.map(|c| c * entry.scale),
    }))
}

/// The artificial lights of the site's enabled luminaires, in file order.
///
/// # Errors
/// [`SiteRenderError::LuminaireFile`] naming the luminaire and the file when it is missing or
/// cannot be parsed; [`SiteRenderError::LuminaireSetting`] for a non-finite position or angle,
/// or a negative or non-finite scale or colour.
pub fn site_luminaire_lights(doc: &SiteDocument) -> Result<Vec<ArtificialLight>, SiteRenderError> {
    doc.site
        .luminaires
        .iter()
        .filter(|l| l.enabled)
        .map(|l| light_of(doc, l))
        .collect()
}

/// Warnings about the site's luminaires that do not stop a render: an enabled luminaire whose
/// `scale` or `colour_rgb` is zero gives no light.
#[must_use]
pub fn luminaire_warnings(site: &Site) -> Vec<SiteWarning> {
    site.luminaires
        .iter()
        .filter(|l| l.enabled)
        .filter(|l| l.scale == 0.0 || l.colour_rgb.iter().all(|&c| c == 0.0))
        .map(|l| SiteWarning::Luminaire {
            luminaire: l.id.clone(),
            message: "scale or colour_rgb is 0: it gives no light (set `enabled = false` to \
                      switch it off on purpose)"
                .into(),
        })
        .collect()
}

#[cfg(test)]
#[path = "luminaires_tests.rs"]
mod tests;
