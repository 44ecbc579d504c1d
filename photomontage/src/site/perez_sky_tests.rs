//! The Perez sky named in a site file (`sky_model = "perez"`, `[lighting.perez]`): the one
//! builder gives the library's `PerezSky`, the renderer's dome and the radiosity lighting carry
//! it, and bad inputs are errors naming the field.

use super::*;
use crate::render::{DifferentialTracer, render_view};
use crate::site::{PerezInputs, SkyModelName, SunManual};
use crate::sky::perez::PerezSky;
use std::sync::atomic::AtomicBool;

/// The same f64 formula evaluated twice (through the site and directly): only rounding.
const SAME_FORMULA_REL_TOL: f64 = 1e-12;
/// Facet radiances are normalised to k_h by a sum over 256 facets: rounding of that sum.
const NORMALISED_RATIO_REL_TOL: f64 = 1e-10;

fn indices(clearness: f64, brightness: f64) -> PerezInputs {
    PerezInputs {
        clearness: Some(clearness),
        brightness: Some(brightness),
        ..PerezInputs::default()
    }
}

fn perez_site(dir: &std::path::Path) -> SiteDocument {
    let mut doc = super::tests::fixture(dir);
    doc.site.lighting.sky_model = SkyModelName::Perez;
    doc.site.lighting.perez = Some(indices(4.7, 0.25));
    doc.site.lighting.sun_manual = Some(SunManual {
        azimuth_deg: 135.0,
        elevation_deg: 40.0,
    });
    doc
}

fn rel(a: f64, b: f64) -> f64 {
    (a - b).abs() / b.abs()
}

#[test]
fn the_site_perez_sky_is_the_library_perez_sky() {
    let dir = tempfile::tempdir().unwrap();
    let doc = perez_site(dir.path());
    let sun = site_sun_dir(&doc, "p1").unwrap();
    let zenith = 50.0_f64.to_radians();
    assert!((sun.z.acos() - zenith).abs() < 1e-12);
    let model = site_sky_model(&doc, "p1", &sun).unwrap();
    let direct = PerezSky::from_indices(4.7, 0.25, sun.z.acos());
    assert_eq!(model, SkyModel::Perez(direct));
    // Luminance at a few directions (elevation, azimuth east of north, degrees) equals the
    // library's lv(ζ, γ)/lv(0, Z) computed from the angles.
    for (el, az) in [
        (90.0, 0.0),
        (10.0, 135.0),
        (40.0, 150.0),
        (30.0, 315.0),
        (5.0, 45.0),
    ] {
        let dir =
            crate::sky::direction_from_elevation_azimuth(f64::to_radians(el), f64::to_radians(az));
        let gamma = dir.dot(&sun).clamp(-1.0, 1.0).acos();
        let want = direct.lv(dir.z, gamma) / direct.lv(1.0, zenith);
        let got = model.relative_luminance(&dir, &sun);
        assert!(
            rel(got, want) < SAME_FORMULA_REL_TOL,
            "({el}, {az}): {got} vs {want}"
        );
    }
}

#[test]
fn the_irradiance_form_takes_the_day_from_the_site_time() {
    let dir = tempfile::tempdir().unwrap();
    let mut doc = perez_site(dir.path());
    doc.site.lighting.perez = Some(PerezInputs {
        direct_normal_w_m2: Some(600.0),
        diffuse_horizontal_w_m2: Some(150.0),
        ..PerezInputs::default()
    });
    doc.site.lighting.time = Some("2026-06-21T12:00:00+02:00".into());
    let sun = site_sun_dir(&doc, "p1").unwrap();
    let model = site_sky_model(&doc, "p1", &sun).unwrap();
    let direct = PerezSky::from_irradiance(600.0, 150.0, sun.z.acos(), 172).unwrap();
    assert_eq!(model, SkyModel::Perez(direct));
    // Without any time the irradiance form cannot know the day: the error says so.
    doc.site.lighting.time = None;
    let e = site_sky_model(&doc, "p1", &sun).unwrap_err().to_string();
    assert!(
        e.contains("lighting.perez") && e.contains("day of the year"),
        "{e}"
    );
}

#[test]
fn a_perez_site_renders_with_the_perez_distribution_on_the_dome() {
    let dir = tempfile::tempdir().unwrap();
    let doc = perez_site(dir.path());
    let job = prepare_view(&doc, "p1").unwrap();
    let sun = job.sun_dir_in_world.unwrap();
    let perez = PerezSky::from_indices(4.7, 0.25, sun.z.acos());
    let dome = durisch_dome(SiteLightingOptions::default().sky_dome_m_h).unwrap();
    let sky = &job.lighting.daylight.sky;
    assert_eq!(sky.len(), dome.facets.len());
    // Facet radiance over the library's luminance is the same constant on every facet, and the
    // facets' horizontal irradiance is k_h.
    let k_h = doc.site.lighting.sky_weight[0];
    let mut ratio = None;
    let mut horizontal = 0.0;
    for (light, facet) in sky.iter().zip(&dome.facets) {
        let d = facet.centre_dir_in_world;
        let l = perez.relative_luminance(d.z, d.dot(&sun).clamp(-1.0, 1.0).acos());
        let radiance = light.normal_irradiance_rgb[0] / facet.solid_angle_sr;
        horizontal += light.normal_irradiance_rgb[0] * d.z;
        let r = radiance / l;
        let first = *ratio.get_or_insert(r);
        assert!(rel(r, first) < NORMALISED_RATIO_REL_TOL, "{r} vs {first}");
    }
    assert!(rel(horizontal, k_h) < NORMALISED_RATIO_REL_TOL);
    let tracer = DifferentialTracer::new(
        &job.scene.scene,
        &job.lighting,
        &job.camera,
        &job.photo_linear,
        job.settings.max_depth,
    )
    .unwrap();
    let img = render_view(&tracer, &job.settings, &|_| {}, &AtomicBool::new(false)).unwrap();
    assert!(img.rgba.iter().flatten().all(|c| c.is_finite()));
    assert!(img.changed_pixels > 0, "the box is rendered");
}

#[test]
fn the_radiosity_lighting_carries_the_perez_sky() {
    let dir = tempfile::tempdir().unwrap();
    let doc = perez_site(dir.path());
    let scene = site_scene(&doc).unwrap().scene;
    let (lighting, _) =
        crate::site::radiosity_lighting::site_transfer_lighting(&doc, &scene, "p1").unwrap();
    let sun = site_sun_dir(&doc, "p1").unwrap();
    let want = SkyModel::Perez(PerezSky::from_indices(4.7, 0.25, sun.z.acos()));
    assert_eq!(lighting.sky.map(|s| s.model), Some(want));
}

#[test]
fn bad_perez_inputs_name_the_field() {
    let dir = tempfile::tempdir().unwrap();
    let mut doc = perez_site(dir.path());
    let sun = site_sun_dir(&doc, "p1").unwrap();
    let mut error_for = |perez: Option<PerezInputs>| {
        doc.site.lighting.perez = perez;
        site_sky_model(&doc, "p1", &sun).unwrap_err().to_string()
    };
    for (perez, field) in [
        (None, "lighting.perez:"),
        (Some(indices(0.5, 0.2)), "lighting.perez.clearness"),
        (Some(indices(f64::NAN, 0.2)), "lighting.perez.clearness"),
        (Some(indices(3.0, -0.1)), "lighting.perez.brightness"),
        (
            Some(PerezInputs {
                clearness: Some(3.0),
                ..PerezInputs::default()
            }),
            "lighting.perez.brightness: missing",
        ),
        (
            Some(PerezInputs {
                direct_normal_w_m2: Some(-5.0),
                diffuse_horizontal_w_m2: Some(100.0),
                ..PerezInputs::default()
            }),
            "lighting.perez.direct_normal_w_m2",
        ),
        (
            Some(PerezInputs {
                direct_normal_w_m2: Some(500.0),
                diffuse_horizontal_w_m2: Some(0.0),
                ..PerezInputs::default()
            }),
            "lighting.perez.diffuse_horizontal_w_m2",
        ),
        (
            Some(PerezInputs {
                clearness: Some(3.0),
                brightness: Some(0.2),
                diffuse_horizontal_w_m2: Some(100.0),
                ..PerezInputs::default()
            }),
            "not both",
        ),
    ] {
        let e = error_for(perez);
        assert!(e.contains(field), "`{e}` should name {field}");
    }
    // The file reader knows the name and refuses unknown keys in the table.
    let text =
        "schema_version = 1\n[lighting]\nsky_model = \"perez\"\n[lighting.perez]\nclearnes = 2.0\n";
    let e = toml::from_str::<crate::site::Site>(text)
        .unwrap_err()
        .to_string();
    assert!(e.contains("clearnes"), "{e}");
    let ok = "schema_version = 1\n[lighting]\nsky_model = \"perez\"\n[lighting.perez]\nclearness = 2.0\nbrightness = 0.3\n";
    let site: crate::site::Site = toml::from_str(ok).unwrap();
    assert_eq!(site.lighting.sky_model, SkyModelName::Perez);
    assert_eq!(site.lighting.perez, Some(indices(2.0, 0.3)));
    // `validate` reports the same field.
    doc.site.lighting.perez = Some(indices(0.5, 0.3));
    let issues = doc.site.validate();
    assert!(
        issues
            .iter()
            .any(|i| i.field == "lighting.perez.clearness" && i.message.contains("below 1")),
        "{issues:?}"
    );
    // A sun below the horizon is refused with its elevation.
    let below = nalgebra::Vector3::new(0.0, 0.8, -0.6);
    doc.site.lighting.perez = Some(indices(2.0, 0.3));
    let e = site_sky_model(&doc, "p1", &below).unwrap_err().to_string();
    assert!(e.contains("perez") && e.contains("horizon"), "{e}");
}
