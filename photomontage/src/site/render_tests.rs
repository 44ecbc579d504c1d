#![allow(clippy::float_cmp)] // weights and materials are copied, not computed: they must be equal bit for bit

use super::*;
use crate::scene::ObjectKind;
use crate::site::{
    Atmosphere, ControlPoint, Exterior, Interior, Location, Photo, Polygon, Site, SunManual,
};
use crate::site::{ModelUnits, ModelUpAxis};
use crate::sun::{SpaParams, solar_position};
use std::path::Path;

/// Σ L_i Δω_i cos Z_i is normalised to k_h by construction; only rounding remains.
const NORMALISATION_REL_TOL: f64 = 1e-12;
/// Durisch rings are equal steps in cos Z with centres at the midpoint, and the midpoint rule is
/// exact for the linear integrand u = cos Z of a uniform sky: only rounding remains.
const UNIFORM_FACET_REL_TOL: f64 = 1e-12;
/// Overcast sky (quadratic in cos Z) on an m_h = 64 dome: the midpoint rule's error on ∫u² is
/// h²/12 with h = 1/64, 2e-5 of the integral; 1e-4 leaves room.
const OVERCAST_FACET_REL_TOL: f64 = 1e-4;
/// Our SPA at the NREL test instant with standard pressure/temperature and ΔT = 69 s instead of
/// the test's 820 mbar, 11 °C, ΔT = 67 s: 2 s of Earth rotation move the azimuth by < 0.01°.
const SPA_AZIMUTH_TOL_DEG: f64 = 0.02;
/// Same direction computed two ways in f64.
const DIRECTION_TOL: f64 = 1e-12;

const BOX_OBJ: &str = "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 0 0 1\nv 1 0 1\nv 1 1 1\nv 0 1 1\n\
f 1 4 3 2\nf 5 6 7 8\nf 1 2 6 5\nf 2 3 7 6\nf 3 4 8 7\nf 4 1 5 8\n";

/// Zürich (47.37° N, 8.54° E, 400 m), no CRS, no time zone.
pub(crate) fn zurich() -> Location {
    Location {
        latitude_deg: 47.37,
        longitude_deg: 8.54,
        elevation_m: 400.0,
        crs: None,
        grid_convergence_deg: 0.0,
        time_zone: None,
    }
}

/// The fixture lit by the sun of Zürich on 2024-08-21, p1 taken at 10:44 and p2 at `p2_time`,
/// p2 solved 4 m above the ground south of p1's frame, looking straight down: it sees ground p1
/// does not, and nothing p1 sees (so its exposure is not checked against p1's).
pub(crate) fn fixture_with_photo_from_above(dir: &std::path::Path, p2_time: &str) -> SiteDocument {
    let mut doc = fixture(dir);
    doc.site.render.radiosity = true;
    doc.site.lighting.sun_manual = None;
    doc.site.location = Some(zurich());
    doc.site.photos[0].taken_at = Some("2024-08-21T10:44:00+02:00".into());
    doc.site.photos[1].taken_at = Some(format!("2024-08-21T{p2_time}:00+02:00"));
    doc.site.photos[1].exterior = Some(crate::site::Exterior {
        camera_center: [0.5, -8.5, 4.0],
        rotation_world_from_camera: [[1.0, 0.0, 0.0], [0.0, -1.0, 0.0], [0.0, 0.0, -1.0]],
        rms_px: 0.1,
        sigma_center_m: [0.0; 3],
        solved_by: "resection".into(),
    });
    doc
}

/// A 64 × 48 photo looking north from (0, −10, 1.5) at a unit box on a 20 m ground square.
pub(crate) fn fixture(dir: &Path) -> SiteDocument {
    image::RgbImage::from_pixel(64, 48, image::Rgb([120, 110, 100]))
        .save(dir.join("p1.png"))
        .unwrap();
    std::fs::write(dir.join("box.obj"), BOX_OBJ).unwrap();
    std::fs::write(
        dir.join("materials.toml"),
        "[[material]]\nname = \"asphalt\"\ndiffuse_rgb = [0.2, 0.2, 0.2]\n",
    )
    .unwrap();
    let cp = |id: &str, xyz| ControlPoint {
        id: id.into(),
        xyz,
        sigma_m: [0.01; 3],
        crs: None,
        enabled: true,
    };
    let photo = |id: &str, solved: bool| Photo {
        id: id.into(),
        file: "p1.png".into(),
        taken_at: None,
        profile: None,
        interior: Some(Interior {
            focal_px: 60.0,
            principal_point_px: None,
            distortion: crate::camera::BrownConrady::default(),
            image_size_px: Some([64, 48]),
        }),
        self_calibration: crate::site::SelfCalibrationFlags::default(),
        exterior: solved.then(|| Exterior {
            camera_center: [0.5, -10.0, 1.5],
            rotation_world_from_camera: [[1.0, 0.0, 0.0], [0.0, 0.0, 1.0], [0.0, -1.0, 0.0]],
            rms_px: 0.1,
            sigma_center_m: [0.0; 3],
            solved_by: "resection".into(),
        }),
    };
    let mut site = Site {
        photos: vec![photo("p1", true), photo("p2", false)],
        control_points: vec![
            cp("a", [-10.0, -10.0, 0.0]),
            cp("b", [10.0, -10.0, 0.0]),
            cp("c", [10.0, 10.0, 0.0]),
            cp("d", [-10.0, 10.0, 0.0]),
            cp("e", [-10.0, 10.0, 3.0]),
            cp("f", [10.0, 10.0, 3.0]),
        ],
        polygons: vec![
            Polygon {
                id: "ground".into(),
                vertices: ["a", "b", "c", "d"].map(String::from).to_vec(),
                material: "asphalt".into(),
                image: Some("p1".into()),
            },
            Polygon {
                id: "wall".into(),
                vertices: ["d", "c", "f", "e"].map(String::from).to_vec(),
                material: "brick".into(),
                image: None,
            },
        ],
        models: vec![crate::site::CadModel {
            id: "box".into(),
            file: "box.obj".into(),
            units: ModelUnits::Metre,
            up_axis: ModelUpAxis::Z,
            placement: crate::site::Placement::default(),
            visible: true,
        }],
        ..Site::default()
    };
    site.lighting.material_library = Some("materials.toml".into());
    site.lighting.sky_model = SkyModelName::Uniform;
    site.lighting.sun_manual = Some(SunManual {
        azimuth_deg: 135.0,
        elevation_deg: 40.0,
    });
    SiteDocument {
        path: dir.join("site.toml"),
        site,
    }
}

fn rel(a: f64, b: f64) -> f64 {
    (a - b).abs() / b.abs()
}

#[test]
fn polygons_map_to_natural_objects_with_library_materials() {
    let dir = tempfile::tempdir().unwrap();
    let doc = fixture(dir.path());
    let s = site_scene(&doc).unwrap();
    assert_eq!(
        s.object_sources,
        vec![
            ObjectSource::Polygon("ground".into()),
            ObjectSource::Polygon("wall".into()),
            ObjectSource::Model("box".into()),
        ]
    );
    let objects = s.scene.objects();
    assert_eq!(objects[0].kind, ObjectKind::Natural);
    assert_eq!(objects[0].image_attribute.as_deref(), Some("p1"));
    assert_eq!(objects[1].image_attribute, None);
    assert_eq!(objects[2].kind, ObjectKind::Artificial);
    // Ground: 2 triangles of asphalt (0.2); wall: 2 of the default 0.5 named brick; box: 12.
    let tris = s.scene.triangles();
    assert_eq!(tris.len(), 2 + 2 + 12);
    let mat = |i: usize| &s.scene.materials()[tris[i].material.0 as usize];
    assert_eq!(mat(0).name, "asphalt");
    assert_eq!(mat(0).diffuse_rgb, [0.2; 3]);
    assert_eq!(mat(2).name, "brick");
    assert_eq!(mat(2).diffuse_rgb, DEFAULT_POLYGON_ALBEDO);
    // The missing polygon material, and the box's faces without any material (no MTL).
    assert_eq!(
        s.warnings,
        vec![
            SiteWarning::MissingMaterial {
                material: "brick".into(),
                polygons: vec!["wall".into()],
            },
            SiteWarning::Import {
                model: "box".into(),
                message: "12 triangles without a material get the default (ρ_d = 0.5)".into(),
            },
        ]
    );
    assert!(s.warnings[0].to_string().contains("brick"));
}

#[test]
fn uniform_sky_weight_is_horizontal_irradiance_and_radiance_k_over_pi() {
    let dome = durisch_dome(8).unwrap();
    let k = [0.3, 0.5, 0.9];
    let lights = sky_lights(&SkyModel::Uniform, &Vector3::z(), &dome, k).unwrap();
    for c in 0..3 {
        let horizontal: f64 = lights
            .iter()
            .map(|l| l.normal_irradiance_rgb[c] * l.dir_in_world.z)
            .sum();
        assert!(
            rel(horizontal, k[c]) < NORMALISATION_REL_TOL,
            "{horizontal}"
        );
        for (l, f) in lights.iter().zip(&dome.facets) {
            let radiance = l.normal_irradiance_rgb[c] / f.solid_angle_sr;
            assert!(
                rel(radiance, k[c] / std::f64::consts::PI) < UNIFORM_FACET_REL_TOL,
                "{radiance}"
            );
        }
    }
}

#[test]
fn overcast_sky_facets_follow_the_closed_form() {
    let dome = durisch_dome(64).unwrap();
    let k_h = 2.0;
    let lights = sky_lights(&SkyModel::CieOvercast, &Vector3::z(), &dome, [k_h; 3]).unwrap();
    // E_h = 7π/9 · L_z  ⇒  L(Z) = k_h · 9/(7π) · (1 + 2 cos Z)/3.
    let l_z = k_h * 9.0 / (7.0 * std::f64::consts::PI);
    for (l, f) in lights.iter().zip(&dome.facets) {
        let expected = l_z * (1.0 + 2.0 * f.centre_dir_in_world.z) / 3.0;
        let radiance = l.normal_irradiance_rgb[0] / f.solid_angle_sr;
        assert!(rel(radiance, expected) < OVERCAST_FACET_REL_TOL);
    }
}

#[test]
fn spa_sun_matches_crate_sun_and_nrel_test_case_with_grid_convergence() {
    let dir = tempfile::tempdir().unwrap();
    let mut doc = fixture(dir.path());
    doc.site.lighting.sun_manual = None;
    doc.site.lighting.time = Some("2003-10-17T12:30:30-07:00".into());
    doc.site.location = Some(Location {
        latitude_deg: 39.742_476,
        longitude_deg: -105.1786,
        elevation_m: 1830.14,
        crs: None,
        grid_convergence_deg: 0.0,
        time_zone: None,
    });
    let d = site_sun_dir(&doc, "p1").unwrap();
    let time = chrono::DateTime::parse_from_rfc3339("2003-10-17T12:30:30-07:00").unwrap();
    let params = SpaParams {
        elevation_m: 1830.14,
        ..SpaParams::at(39.742_476, -105.1786)
    };
    let pos = solar_position(&time, &params).unwrap();
    let enu = Vector3::from(pos.direction_enu());
    assert!((d - enu).norm() < DIRECTION_TOL);
    let azimuth_deg = d.x.atan2(d.y).to_degrees().rem_euclid(360.0);
    // NREL SPA paper (Reda & Andreas 2004) Table A5.1: azimuth 194.34024°.
    assert!((azimuth_deg - 194.340_24).abs() < SPA_AZIMUTH_TOL_DEG);

    // True north 2° clockwise of grid north: the grid azimuth is 2° larger.
    doc.site.location.as_mut().unwrap().grid_convergence_deg = 2.0;
    let g = site_sun_dir(&doc, "p1").unwrap();
    let grid_azimuth_deg = g.x.atan2(g.y).to_degrees().rem_euclid(360.0);
    assert!((grid_azimuth_deg - azimuth_deg - 2.0).abs() < 1e-9);
    assert!((g.z - d.z).abs() < DIRECTION_TOL);
}

#[test]
fn lighting_uses_the_site_weights_and_drops_a_sun_below_the_horizon() {
    let dir = tempfile::tempdir().unwrap();
    let mut doc = fixture(dir.path());
    doc.site.lighting.sun_weight = [3.0, 2.0, 1.0];
    doc.site.lighting.ambient_weight = [0.1, 0.2, 0.3];
    doc.site.lighting.atmosphere = Atmosphere {
        extinction_per_m: [1e-4, 2e-4, 4e-4],
        horizon_colour: [0.7, 0.8, 0.9],
    };
    let (l, sun) = site_lighting(&doc, "p1", &SiteLightingOptions::default()).unwrap();
    let s = l.daylight.sun.unwrap();
    assert_eq!(s.normal_irradiance_rgb, [3.0, 2.0, 1.0]);
    let expected = survey_dir_from_true_azimuth(135.0, 40.0, 0.0);
    assert!((s.dir_in_world - expected).norm() < DIRECTION_TOL);
    assert_eq!(sun, Some(expected));
    assert_eq!(l.daylight.ambient_radiance_rgb, [0.1, 0.2, 0.3]);
    assert_eq!(l.daylight.sky.len(), 256);
    assert_eq!(l.horizon_rgb, [0.7, 0.8, 0.9]);
    // Transmission over 1 km is e^{−σ d} per channel (f32 storage of τ_a: 1e-6).
    let t = l.atmosphere.unwrap().transmission(1000.0);
    for (c, sigma) in [1e-4_f64, 2e-4, 4e-4].iter().enumerate() {
        assert!((f64::from(t.channels[c]) - (-sigma * 1000.0).exp()).abs() < 1e-6);
    }

    doc.site.lighting.sun_manual = Some(SunManual {
        azimuth_deg: 10.0,
        elevation_deg: -5.0,
    });
    let (l, sun) = site_lighting(&doc, "p1", &SiteLightingOptions::default()).unwrap();
    assert!(l.daylight.sun.is_none() && sun.is_none());
}

#[test]
fn camera_errors_name_the_view_and_the_fix() {
    let dir = tempfile::tempdir().unwrap();
    let doc = fixture(dir.path());
    let cam = site_camera(&doc, "p1").unwrap();
    assert_eq!(cam.intrinsics.image_size_px, [64, 48]);
    let err = site_camera(&doc, "nope").unwrap_err();
    assert!(matches!(err, SiteRenderError::UnknownView { .. }));
    assert!(err.to_string().contains("valid view ids: p1, p2"), "{err}");
    let err = site_camera(&doc, "p2").unwrap_err();
    assert_eq!(
        err.to_string(),
        "photo p2 is not solved; run `photomontage solve` first"
    );
}

#[test]
fn missing_time_or_location_is_a_clear_error() {
    let dir = tempfile::tempdir().unwrap();
    let mut doc = fixture(dir.path());
    doc.site.lighting.sun_manual = None;
    let err = site_lighting(&doc, "p1", &SiteLightingOptions::default()).unwrap_err();
    assert!(matches!(err, SiteRenderError::NoSunDirection { .. }));
    doc.site.lighting.time = Some("2024-06-21T12:00:00+02:00".into());
    let err = site_lighting(&doc, "p1", &SiteLightingOptions::default()).unwrap_err();
    assert!(err.to_string().contains("no [location]"), "{err}");
    // A uniform sky without sunlight needs no sun at all.
    doc.site.lighting.sun_weight = [0.0; 3];
    let (l, sun) = site_lighting(&doc, "p1", &SiteLightingOptions::default()).unwrap();
    assert!(l.daylight.sun.is_none() && sun.is_none() && !l.daylight.sky.is_empty());
}

#[test]
fn bad_models_are_errors_or_warnings() {
    let dir = tempfile::tempdir().unwrap();
    let mut doc = fixture(dir.path());
    std::fs::write(dir.path().join("empty.obj"), "v 0 0 0\n").unwrap();
    std::fs::write(
        dir.path().join("nan.obj"),
        "v 0 0 0\nv 1 0 0\nv nan 1 0\nf 1 2 3\n",
    )
    .unwrap();
    for (file, needle) in [("empty.obj", "no faces"), ("nan.obj", "non-finite")] {
        doc.site.models[0].file = file.into();
        let err = site_scene(&doc).unwrap_err();
        assert!(matches!(err, SiteRenderError::Model { .. }));
        assert!(err.to_string().contains(needle), "{err}");
        assert!(err.to_string().contains("box"), "{err}");
    }
    doc.site.models[0].file = "box.obj".into();
    for (scale, warn) in [(1e-4, true), (1.0, false), (2e4, true)] {
        doc.site.models[0].placement.scale = scale;
        let s = site_scene(&doc).unwrap();
        let scale_warnings = s
            .warnings
            .iter()
            .filter(|w| matches!(w, SiteWarning::ModelScale { .. }))
            .count();
        assert_eq!(scale_warnings, usize::from(warn), "scale {scale}");
    }
    doc.site.models[0].placement.scale = 1.0;
    doc.site.polygons[0].vertices[0] = "zz".into();
    let err = site_scene(&doc).unwrap_err();
    assert!(err.to_string().contains("`zz`"), "{err}");
}

#[test]
fn prepare_view_loads_the_linear_photo_and_checks_its_size() {
    let dir = tempfile::tempdir().unwrap();
    let mut doc = fixture(dir.path());
    let job = prepare_view(&doc, "p1").unwrap();
    let p = job.photo_linear.get_pixel(3, 4).0;
    let expected = crate::colour::rgb::srgb_decode(120.0 / 255.0);
    assert!((f64::from(p[0]) - expected).abs() < 1e-6);
    assert_eq!(job.settings.min_rays_per_pixel, 4);
    assert_eq!(job.settings.max_rays_per_pixel, 16);

    doc.site.photos[0].interior.as_mut().unwrap().image_size_px = Some([640, 480]);
    assert!(matches!(
        prepare_view(&doc, "p1").unwrap_err(),
        SiteRenderError::SizeMismatch { .. }
    ));
    doc.site.photos[0].interior.as_mut().unwrap().image_size_px = Some([64, 48]);
    doc.site.models[0].visible = false;
    assert!(matches!(
        prepare_view(&doc, "p1").unwrap_err(),
        SiteRenderError::NoVisibleModel
    ));
}

#[test]
fn render_settings_round_to_multiples_of_four() {
    let r = crate::site::RenderSettings {
        spp_min: 3,
        spp_max: 10,
        ..crate::site::RenderSettings::default()
    };
    let (s, w) = site_render_settings(&r);
    assert_eq!((s.min_rays_per_pixel, s.max_rays_per_pixel), (4, 12));
    assert_eq!(w.len(), 1);
    let (s, w) = site_render_settings(&crate::site::RenderSettings::default());
    assert_eq!((s.min_rays_per_pixel, s.max_rays_per_pixel), (4, 16));
    assert!(w.is_empty());
}

/// A kept photo ([`KeptPhoto`]) is handed out again while its file is unchanged (the kept
/// pixels, not a new decode), and read again once the file changed.
#[test]
fn a_kept_photo_is_reused_until_its_file_changes() {
    let dir = tempfile::tempdir().unwrap();
    let doc = fixture(dir.path());
    let camera = site_camera(&doc, "p1").unwrap();
    let fresh = site_photo_linear(&doc, "p1", &camera).unwrap();
    let mut kept = None;
    let first = site_photo_linear_kept(&doc, "p1", &camera, Some(&mut kept)).unwrap();
    assert!(*first == fresh);
    // Mark the kept pixels: a reuse hands out the mark.
    let mark = image::Rgb([9.0_f32; 3]);
    std::sync::Arc::make_mut(&mut kept.as_mut().unwrap().photo_linear).put_pixel(0, 0, mark);
    let again = site_photo_linear_kept(&doc, "p1", &camera, Some(&mut kept)).unwrap();
    assert_eq!(*again.get_pixel(0, 0), mark);
    // Another photo in the same file (other pixels, so another length): read again.
    std::thread::sleep(std::time::Duration::from_millis(20));
    image::RgbImage::from_fn(64, 48, |x, y| {
        #[allow(clippy::cast_possible_truncation)]
        image::Rgb([(x * 4) as u8, (y * 5) as u8, 100])
    })
    .save(dir.path().join("p1.png"))
    .unwrap();
    let changed = site_photo_linear_kept(&doc, "p1", &camera, Some(&mut kept)).unwrap();
    assert!(*changed == site_photo_linear(&doc, "p1", &camera).unwrap());
    assert!(*changed != fresh && *changed.get_pixel(0, 0) != mark);
}
