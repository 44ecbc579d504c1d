//! The sample sites' generator truth (`truth.json`) as the tests use it: the true cameras written
//! into a site as if `solve` had found them.

use photomontage::site::{Exterior, SiteDocument};

use crate::sample_site;

/// A sample site's `truth.json`.
///
/// # Panics
/// When the file cannot be read or parsed (a test helper).
#[must_use]
#[allow(clippy::unwrap_used)]
pub fn truth(site: &str) -> serde_json::Value {
    let text = std::fs::read_to_string(sample_site(site).join("truth.json")).unwrap();
    serde_json::from_str(&text).unwrap()
}

/// Three numbers of a JSON array.
///
/// # Panics
/// When `v` is not an array of at least three numbers (a test helper).
#[must_use]
#[allow(clippy::unwrap_used)]
pub fn vec3(v: &serde_json::Value) -> [f64; 3] {
    [0, 1, 2].map(|k| v[k].as_f64().unwrap())
}

/// The rows of the true `rotation_world_from_camera` of photo `id`.
///
/// # Panics
/// When truth.json has no such camera (a test helper).
#[must_use]
#[allow(clippy::unwrap_used)]
pub fn true_rotation_rows(truth: &serde_json::Value, id: &str) -> [[f64; 3]; 3] {
    let rows: Vec<[f64; 3]> = truth["cameras"][id]["rotation_world_from_camera"]
        .as_array()
        .unwrap()
        .iter()
        .map(vec3)
        .collect();
    [rows[0], rows[1], rows[2]]
}

/// The sample site with every camera of its truth.json written in as a solved exterior
/// (`solved_by = "truth"`, σ and RMS 0); interiors stay as the site file has them.
///
/// # Panics
/// When the site or its truth cannot be read (a test helper).
#[must_use]
#[allow(clippy::unwrap_used)]
pub fn site_with_true_cameras(site: &str) -> SiteDocument {
    let mut doc = SiteDocument::load(&sample_site(site).join("site.toml")).unwrap();
    let t = truth(site);
    for photo in &mut doc.site.photos {
        if t["cameras"].get(&photo.id).is_none() {
            continue;
        }
        photo.exterior = Some(Exterior {
            camera_center: vec3(&t["cameras"][&photo.id]["camera_center"]),
            rotation_world_from_camera: true_rotation_rows(&t, &photo.id),
            rms_px: 0.0,
            sigma_center_m: [0.0; 3],
            solved_by: "truth".into(),
        });
    }
    doc
}
