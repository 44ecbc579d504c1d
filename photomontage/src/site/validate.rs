//! Semantic checks of a parsed site: unique ids, references that resolve, finite numbers,
//! positive standard deviations.

use super::Site;
use std::collections::HashSet;

/// One problem found in a site, with the field path it concerns (e.g. `observations[3].photo`).
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct SiteIssue {
    pub field: String,
    pub message: String,
}

fn issue(field: String, message: impl Into<String>) -> SiteIssue {
    SiteIssue {
        field,
        message: message.into(),
    }
}

fn check_finite(issues: &mut Vec<SiteIssue>, field: String, values: &[f64]) {
    if values.iter().any(|v| !v.is_finite()) {
        issues.push(issue(
            field,
            "must be a finite number (not NaN or infinite)",
        ));
    }
}

/// The focal length and principal point of `photos[i]` within the solver's sane range for its
/// image size (see [`crate::photogrammetry::MIN_FOCAL_FRACTION_OF_IMAGE`]); non-finite values
/// are reported by the finiteness checks.
fn check_interior_ranges(
    issues: &mut Vec<SiteIssue>,
    i: usize,
    interior: &super::Interior,
    [w, h]: [u32; 2],
) {
    use crate::photogrammetry::{
        MAX_FOCAL_MULTIPLE_OF_IMAGE, MIN_FOCAL_FRACTION_OF_IMAGE, PRINCIPAL_POINT_MARGIN_IMAGES,
    };
    let side = f64::from(w.max(h));
    let (lo, hi) = (
        MIN_FOCAL_FRACTION_OF_IMAGE * side,
        MAX_FOCAL_MULTIPLE_OF_IMAGE * side,
    );
    let f = interior.focal_px;
    if f.is_finite() && f > 0.0 && !(lo..=hi).contains(&f) {
        issues.push(issue(
            format!("photos[{i}].interior.focal_px"),
            format!("{f:e} px is outside {lo}…{hi} px, the sane range for a {w}×{h} px image"),
        ));
    }
    if let Some(pp) = interior.principal_point_px {
        for (axis, (value, size)) in pp.iter().zip([w, h]).enumerate() {
            let size = f64::from(size);
            let (lo, hi) = (
                -PRINCIPAL_POINT_MARGIN_IMAGES * size,
                (1.0 + PRINCIPAL_POINT_MARGIN_IMAGES) * size,
            );
            if value.is_finite() && !(lo..=hi).contains(value) {
                issues.push(issue(
                    format!("photos[{i}].interior.principal_point_px[{axis}]"),
                    format!("{value:e} px is outside {lo}…{hi} px for a {w}×{h} px image"),
                ));
            }
        }
    }
}

impl Site {
    /// Every semantic problem in the site, in file order. Empty when the site is valid.
    #[must_use]
    pub fn validate(&self) -> Vec<SiteIssue> {
        let mut issues = Vec::new();
        let mut photo_ids = HashSet::new();
        for (i, photo) in self.photos.iter().enumerate() {
            if photo.id.trim().is_empty() {
                issues.push(issue(format!("photos[{i}].id"), "must not be empty"));
            }
            if !photo_ids.insert(photo.id.as_str()) {
                issues.push(issue(
                    format!("photos[{i}].id"),
                    format!("duplicate photo id `{}`", photo.id),
                ));
            }
            if photo.file.trim().is_empty() {
                issues.push(issue(format!("photos[{i}].file"), "must not be empty"));
            }
            if let Some(t) = &photo.taken_at
                && chrono::DateTime::parse_from_rfc3339(t).is_err()
            {
                issues.push(issue(
                    format!("photos[{i}].taken_at"),
                    format!("`{t}` is not an RFC 3339 time with offset"),
                ));
            }
            if let Some(interior) = &photo.interior {
                if !(interior.focal_px.is_finite() && interior.focal_px > 0.0) {
                    issues.push(issue(
                        format!("photos[{i}].interior.focal_px"),
                        "must be a positive number",
                    ));
                }
                if let Some(pp) = interior.principal_point_px {
                    check_finite(
                        &mut issues,
                        format!("photos[{i}].interior.principal_point_px"),
                        &pp,
                    );
                }
                let d = interior.distortion;
                check_finite(
                    &mut issues,
                    format!("photos[{i}].interior.distortion"),
                    &[d.k1, d.k2, d.k3, d.p1, d.p2],
                );
                if let Some([w, h]) = interior.image_size_px
                    && (w == 0 || h == 0)
                {
                    issues.push(issue(
                        format!("photos[{i}].interior.image_size_px"),
                        "width and height must be positive",
                    ));
                }
                let max_pixels = crate::photo::DecodeLimits::default().max_pixels;
                if let Some([w, h]) = interior.image_size_px
                    && u64::from(w) * u64::from(h) > max_pixels
                {
                    issues.push(issue(
                        format!("photos[{i}].interior.image_size_px"),
                        format!(
                            "{w}×{h} px is more than the {} MP a photo may have \
                             (--max-photo-megapixels)",
                            max_pixels as f64 / 1e6
                        ),
                    ));
                }
                if let Some(size) = interior.image_size_px
                    && size.iter().all(|s| *s > 0)
                {
                    check_interior_ranges(&mut issues, i, interior, size);
                }
            }
            if let Some(ext) = &photo.exterior {
                check_finite(
                    &mut issues,
                    format!("photos[{i}].exterior.camera_center"),
                    &ext.camera_center,
                );
                check_finite(
                    &mut issues,
                    format!("photos[{i}].exterior.rotation_world_from_camera"),
                    &ext.rotation_world_from_camera.concat(),
                );
            }
        }

        let mut point_ids = HashSet::new();
        for (i, cp) in self.control_points.iter().enumerate() {
            let field = format!("control_points[{i}]");
            if cp.id.trim().is_empty() {
                issues.push(issue(format!("{field}.id"), "must not be empty"));
            }
            if !point_ids.insert(cp.id.as_str()) {
                issues.push(issue(
                    format!("{field}.id"),
                    format!("duplicate point id `{}`", cp.id),
                ));
            }
            check_finite(&mut issues, format!("{field}.xyz"), &cp.xyz);
            if cp.sigma_m.iter().any(|s| !s.is_finite() || *s < 0.0) {
                issues.push(issue(
                    format!("{field}.sigma_m"),
                    "standard deviations must be finite and ≥ 0 (0 holds the axis fixed)",
                ));
            }
        }
        for (i, tp) in self.tie_points.iter().enumerate() {
            let field = format!("tie_points[{i}]");
            if !point_ids.insert(tp.id.as_str()) {
                issues.push(issue(
                    format!("{field}.id"),
                    format!(
                        "duplicate point id `{}` (also a control or tie point)",
                        tp.id
                    ),
                ));
            }
            check_finite(&mut issues, format!("{field}.xyz"), &tp.xyz);
        }

        let mut seen_obs = HashSet::new();
        for (i, obs) in self.observations.iter().enumerate() {
            let field = format!("observations[{i}]");
            if !photo_ids.contains(obs.photo.as_str()) {
                issues.push(issue(
                    format!("{field}.photo"),
                    format!("no photo has id `{}`", obs.photo),
                ));
            }
            if obs.point.trim().is_empty() {
                issues.push(issue(format!("{field}.point"), "must not be empty"));
            }
            if !seen_obs.insert((obs.photo.as_str(), obs.point.as_str())) {
                issues.push(issue(
                    format!("{field}.point"),
                    format!(
                        "point `{}` is observed twice in photo `{}`",
                        obs.point, obs.photo
                    ),
                ));
            }
            check_finite(&mut issues, format!("{field}.x_px"), &[obs.x_px]);
            check_finite(&mut issues, format!("{field}.y_px"), &[obs.y_px]);
            if !(obs.sigma_px.is_finite() && obs.sigma_px > 0.0) {
                issues.push(issue(
                    format!("{field}.sigma_px"),
                    "must be a positive number",
                ));
            }
        }

        let observed: HashSet<&str> = self.observations.iter().map(|o| o.point.as_str()).collect();
        let mut polygon_ids = HashSet::new();
        for (i, poly) in self.polygons.iter().enumerate() {
            let field = format!("polygons[{i}]");
            if !polygon_ids.insert(poly.id.as_str()) {
                issues.push(issue(
                    format!("{field}.id"),
                    format!("duplicate polygon id `{}`", poly.id),
                ));
            }
            if poly.vertices.len() < 3 {
                issues.push(issue(
                    format!("{field}.vertices"),
                    format!(
                        "a polygon needs at least 3 vertices, found {}",
                        poly.vertices.len()
                    ),
                ));
            }
            for v in &poly.vertices {
                if !point_ids.contains(v.as_str()) && !observed.contains(v.as_str()) {
                    issues.push(issue(
                        format!("{field}.vertices"),
                        format!("vertex `{v}` is neither a control point nor an observed point"),
                    ));
                }
            }
            if let Some(img) = &poly.image
                && !photo_ids.contains(img.as_str())
            {
                issues.push(issue(
                    format!("{field}.image"),
                    format!("image attribute `{img}` is not a photo id"),
                ));
            }
        }

        let mut model_ids = HashSet::new();
        for (i, model) in self.models.iter().enumerate() {
            let field = format!("models[{i}]");
            if !model_ids.insert(model.id.as_str()) {
                issues.push(issue(
                    format!("{field}.id"),
                    format!("duplicate model id `{}`", model.id),
                ));
            }
            let p = &model.placement;
            check_finite(
                &mut issues,
                format!("{field}.placement"),
                &[
                    p.translation[0],
                    p.translation[1],
                    p.translation[2],
                    p.rotation_z_deg,
                    p.scale,
                ],
            );
            if p.scale <= 0.0 {
                issues.push(issue(
                    format!("{field}.placement.scale"),
                    "must be positive",
                ));
            }
        }

        validate_luminaires(&self.luminaires, &mut issues);
        self.validate_fit_inputs(&mut issues, &photo_ids, &point_ids, &observed);

        let lighting = &self.lighting;
        if let Some(t) = &lighting.time
            && chrono::DateTime::parse_from_rfc3339(t).is_err()
        {
            issues.push(issue(
                "lighting.time".into(),
                format!("`{t}` is not an RFC 3339 time with offset"),
            ));
        }
        if lighting.sky_model == super::SkyModelName::Perez
            && let Err(e) = lighting.perez.clone().unwrap_or_default().form()
        {
            issues.push(issue(e.field.into(), e.reason));
        }
        let r = &self.render;
        if r.spp_min == 0 || r.spp_max < r.spp_min {
            issues.push(issue(
                "render.spp_max".into(),
                format!(
                    "need 1 ≤ spp_min ≤ spp_max, found spp_min = {}, spp_max = {}",
                    r.spp_min, r.spp_max
                ),
            ));
        }
        if r.max_depth > crate::render::MAX_DEPTH_LIMIT {
            issues.push(issue(
                "render.max_depth".into(),
                format!(
                    "{} is above the limit {} (deeper mirror recursion would overflow the stack)",
                    r.max_depth,
                    crate::render::MAX_DEPTH_LIMIT
                ),
            ));
        }
        if !(r.exposure.is_finite() && r.exposure > 0.0) {
            issues.push(issue(
                "render.exposure".into(),
                format!("{} must be a positive finite number", r.exposure),
            ));
        }
        if let Some(loc) = &self.location {
            if !(-90.0..=90.0).contains(&loc.latitude_deg) {
                issues.push(issue(
                    "location.latitude_deg".into(),
                    format!("{} is outside −90…90", loc.latitude_deg),
                ));
            }
            if !(-180.0..=180.0).contains(&loc.longitude_deg) {
                issues.push(issue(
                    "location.longitude_deg".into(),
                    format!("{} is outside −180…180", loc.longitude_deg),
                ));
            }
            if let Some(zone) = &loc.time_zone
                && let Err(e) = crate::time_zone::SiteTimeZone::parse(zone)
            {
                issues.push(issue("location.time_zone".into(), e.to_string()));
            }
        }
        issues.extend(super::variants::variant_issues(self));
        issues
    }
}

impl Site {
    /// Checks `[[samples]]`, `[[horizon_samples]]` and `[[sun_shadow_pairs]]`; every message
    /// names the sample.
    fn validate_fit_inputs(
        &self,
        issues: &mut Vec<SiteIssue>,
        photo_ids: &HashSet<&str>,
        point_ids: &HashSet<&str>,
        observed: &HashSet<&str>,
    ) {
        let materials: HashSet<&str> = self.polygons.iter().map(|p| p.material.as_str()).collect();
        let mut ids = HashSet::new();
        for (i, s) in self.samples.iter().enumerate() {
            let field = format!("samples[{i}]");
            if s.id.trim().is_empty() {
                issues.push(issue(format!("{field}.id"), "must not be empty"));
            }
            if !ids.insert(s.id.as_str()) {
                issues.push(issue(
                    format!("{field}.id"),
                    format!("duplicate sample id `{}`", s.id),
                ));
            }
            if !photo_ids.contains(s.photo.as_str()) {
                issues.push(issue(
                    format!("{field}.photo"),
                    format!("sample `{}`: no photo has id `{}`", s.id, s.photo),
                ));
            }
            if !materials.contains(s.material.as_str()) {
                issues.push(issue(
                    format!("{field}.material"),
                    format!(
                        "sample `{}`: no polygon has material `{}`",
                        s.id, s.material
                    ),
                ));
            }
            match (s.point, s.x_px, s.y_px) {
                (Some(p), None, None) => check_finite(issues, format!("{field}.point"), &p),
                (None, Some(x), Some(y)) => check_finite(issues, format!("{field}.x_px"), &[x, y]),
                _ => issues.push(issue(
                    format!("{field}.point"),
                    format!(
                        "sample `{}`: give either `point` or both `x_px` and `y_px`",
                        s.id
                    ),
                )),
            }
            if s.window_px == 0 || s.window_px % 2 == 0 || s.window_px > 101 {
                issues.push(issue(
                    format!("{field}.window_px"),
                    format!(
                        "sample `{}`: window of {} px must be odd and 1–101",
                        s.id, s.window_px
                    ),
                ));
            }
        }
        let mut ids = HashSet::new();
        for (i, h) in self.horizon_samples.iter().enumerate() {
            let field = format!("horizon_samples[{i}]");
            if !ids.insert(h.id.as_str()) {
                issues.push(issue(
                    format!("{field}.id"),
                    format!("duplicate horizon sample id `{}`", h.id),
                ));
            }
            if !photo_ids.contains(h.photo.as_str()) {
                issues.push(issue(
                    format!("{field}.photo"),
                    format!("horizon sample `{}`: no photo has id `{}`", h.id, h.photo),
                ));
            }
            if h.size_px.iter().any(|s| *s == 0 || *s > 4096) {
                issues.push(issue(
                    format!("{field}.size_px"),
                    format!(
                        "horizon sample `{}`: width and height must be 1–4096 px",
                        h.id
                    ),
                ));
            }
        }
        let mut ids = HashSet::new();
        for (i, pair) in self.sun_shadow_pairs.iter().enumerate() {
            let field = format!("sun_shadow_pairs[{i}]");
            if !ids.insert(pair.id.as_str()) {
                issues.push(issue(
                    format!("{field}.id"),
                    format!("duplicate sun/shadow pair id `{}`", pair.id),
                ));
            }
            for (name, point) in [
                ("object_point", &pair.object_point),
                ("shadow_point", &pair.shadow_point),
            ] {
                if !point_ids.contains(point.as_str()) && !observed.contains(point.as_str()) {
                    issues.push(issue(
                        format!("{field}.{name}"),
                        format!(
                            "sun/shadow pair `{}`: `{point}` is neither a control point nor an observed point",
                            pair.id
                        ),
                    ));
                }
            }
            if pair.object_point == pair.shadow_point {
                issues.push(issue(
                    format!("{field}.shadow_point"),
                    format!(
                        "sun/shadow pair `{}`: object and shadow are the same point",
                        pair.id
                    ),
                ));
            }
            if !photo_ids.contains(pair.photo.as_str()) {
                issues.push(issue(
                    format!("{field}.photo"),
                    format!(
                        "sun/shadow pair `{}`: no photo has id `{}`",
                        pair.id, pair.photo
                    ),
                ));
            }
        }
    }
}

fn validate_luminaires(luminaires: &[super::SiteLuminaire], issues: &mut Vec<SiteIssue>) {
    let mut ids = HashSet::new();
    for (i, l) in luminaires.iter().enumerate() {
        let field = format!("luminaires[{i}]");
        if l.id.trim().is_empty() {
            issues.push(issue(format!("{field}.id"), "must not be empty"));
        }
        if !ids.insert(l.id.as_str()) {
            issues.push(issue(
                format!("{field}.id"),
                format!("duplicate luminaire id `{}`", l.id),
            ));
        }
        if l.file.trim().is_empty() {
            issues.push(issue(
                format!("{field}.file"),
                format!("luminaire `{}`: must not be empty", l.id),
            ));
        }
        for (name, values) in [
            ("position_m", &l.position_m[..]),
            ("rotation_z_deg", &[l.rotation_z_deg][..]),
            ("tilt_deg", &[l.tilt_deg][..]),
        ] {
            if values.iter().any(|v| !v.is_finite()) {
                issues.push(issue(
                    format!("{field}.{name}"),
                    format!("luminaire `{}`: must be finite (not NaN or infinite)", l.id),
                ));
            }
        }
        if !l.colour_rgb.iter().all(|c| c.is_finite() && *c >= 0.0) {
            issues.push(issue(
                format!("{field}.colour_rgb"),
                format!("luminaire `{}`: must be finite and ≥ 0", l.id),
            ));
        }
        if !(l.scale.is_finite() && l.scale >= 0.0) {
            issues.push(issue(
                format!("{field}.scale"),
                format!("luminaire `{}`: must be finite and ≥ 0", l.id),
            ));
        }
    }
}
