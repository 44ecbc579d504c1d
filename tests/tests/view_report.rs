//! The view geometry report (`photomontage::verified::geometry`) against the sample sites'
//! generators: the cameras of `truth.json` put into the site as if solved, and the expected
//! bearing, pitch, roll, fields of view, heights and distances computed here from the generators'
//! own parameters (`VIEWS` / `CAMERAS`, `FOCAL_PX`, `W`, `H`, `K1`, `K2` in
//! `sample_sites/*/generate.py`), not from the code under test. Then the same report on the
//! street site as `solve` leaves it, within the solve's own σ; and the 35 mm equivalent of real
//! camera JPEGs against their EXIF.
#![allow(clippy::unwrap_used)] // test helpers outside #[test] functions

use nalgebra::{Matrix3, Point3, Vector3};
use photomontage::site::{SiteDocument, apply_solution, solve_site};
use photomontage::verified::geometry::{GroundSource, focal_35mm_equiv_mm};
use photomontage::verified::{ViewGeometryOptions, view_geometry};
use photomontage_tests::truth::{true_rotation_rows, truth, vec3};
use photomontage_tests::{sample_site, shared_file};

/// The bound on bearing, pitch, roll and HFoV against the generator (the formulas are
/// exact, so this only has to absorb round-off and truth.json's 16-digit matrices).
const ANGLE_TOL_DEG: f64 = 0.01;
/// The bound on the camera height. The street's ground polygon has the generator's
/// 1 cm survey noise on its corners (G1–G4, rounded to 1 mm); under the cameras it is 6.5 mm off.
const HEIGHT_TOL_M: f64 = 0.01;
/// Distances to the planned building: the OBJ and its placement are exact, so round-off only.
const DISTANCE_TOL_M: f64 = 1e-6;
/// Solved cameras: within this many of the solve's reported σ of the truth (as street_solve.rs).
const SIGMA_BOUND: f64 = 5.0;
/// Real cameras: our 35 mm equivalent against EXIF `FocalLengthIn35mmFilm` (the 1 %).
const FOCAL_35MM_REL_TOL: f64 = 0.01;

/// One generator view: id, camera centre (local m), look-at target (local m), roll (deg).
type View = (&'static str, [f64; 3], [f64; 3], f64);

/// `VIEWS` of sample_sites/street/generate.py.
const STREET_VIEWS: [View; 3] = [
    ("V1", [-3.0, -50.0, 1.6], [6.0, -2.0, 5.0], 0.0),
    ("V2", [-6.0, -44.0, 1.7], [9.0, -6.0, 5.5], 1.2),
    ("V3", [-5.0, -36.0, 9.0], [6.0, -6.0, 3.0], -0.8),
];
/// `CAMERAS` of sample_sites/courtyard/generate.py (no roll).
const COURTYARD_VIEWS: [View; 3] = [
    ("P1", [5.0, -22.0, 1.6], [20.0, 16.0, 5.0], 0.0),
    ("P2", [35.0, -20.0, 1.7], [18.0, 16.0, 5.0], 0.0),
    ("P3", [20.0, -34.0, 10.0], [20.0, 14.0, 3.0], 0.0),
];
/// The generators' local origins (`ORIGIN`) and ground heights (local Z = 0).
const STREET_ORIGIN: [f64; 3] = [2_683_400.0, 1_247_600.0, 408.0];
const COURTYARD_ORIGIN: [f64; 3] = [2_683_000.0, 1_247_000.0, 400.0];

/// The generators' `rotation_look_at` (world_from_camera), to check the constants above against
/// truth.json.
fn look_at(center: [f64; 3], target: [f64; 3], roll_deg: f64) -> Matrix3<f64> {
    let z = (Vector3::from(target) - Vector3::from(center)).normalize();
    let x = z.cross(&Vector3::z()).normalize();
    let y = z.cross(&x);
    let (s, c) = roll_deg.to_radians().sin_cos();
    Matrix3::from_columns(&[x, y, z]) * Matrix3::new(c, -s, 0.0, s, c, 0.0, 0.0, 0.0, 1.0)
}

/// The site with truth.json's cameras written in as solved exteriors, after checking that the
/// generator constants above give truth.json's rotations.
fn site_with_true_cameras(site: &str, views: &[View]) -> SiteDocument {
    let t = truth(site);
    for (id, center, target, roll) in views {
        let rows = true_rotation_rows(&t, id);
        let m = Matrix3::from_fn(|r, c| rows[r][c]);
        assert!(
            (m - look_at(*center, *target, *roll)).norm() < 1e-12,
            "{site} {id}: the generator constants here do not give truth.json's rotation"
        );
    }
    photomontage_tests::truth::site_with_true_cameras(site)
}

/// Bearing (clockwise from grid north), pitch, roll of a generator view.
fn expected_angles(center: [f64; 3], target: [f64; 3], roll: f64) -> [f64; 3] {
    let d: Vec<f64> = (0..3).map(|k| target[k] - center[k]).collect();
    [
        d[0].atan2(d[1]).to_degrees().rem_euclid(360.0),
        d[2].atan2(d[0].hypot(d[1])).to_degrees(),
        roll,
    ]
}

fn check_angles(id: &str, got: [f64; 3], want: [f64; 3], tol_deg: f64) {
    for (name, g, w) in [
        ("bearing", got[0], want[0]),
        ("pitch", got[1], want[1]),
        ("roll", got[2], want[2]),
    ] {
        println!("{id} {name}: {g:.5}° (truth {w:.5}°, Δ {:+.2e}°)", g - w);
        assert!((g - w).abs() < tol_deg, "{id} {name}: {g} vs {w}");
    }
}

#[test]
fn street_report_matches_the_generator() {
    let doc = site_with_true_cameras("street", &STREET_VIEWS);
    let t = truth("street");
    // The planned building: a 10 × 14 × 14 m box from its corners in truth.json.
    let corners: Vec<Point3<f64>> = t["planned_building"]["corners"]
        .as_array()
        .unwrap()
        .iter()
        .map(|c| Point3::from(vec3(c)))
        .collect();
    let centre = corners.iter().fold(Vector3::zeros(), |s, c| s + c.coords) / 8.0;
    let (u, v) = (corners[1] - corners[0], corners[3] - corners[0]);
    for (id, center, target, roll) in STREET_VIEWS {
        let r = view_geometry(&doc, id, &ViewGeometryOptions::default()).unwrap();
        let got = [r.bearing_grid_deg, r.pitch_deg, r.roll_deg];
        check_angles(
            id,
            got,
            expected_angles(center, target, roll),
            ANGLE_TOL_DEG,
        );
        // The site states grid convergence 0 (its generator's convention), so true = grid.
        assert!((r.bearing_true_deg - r.bearing_grid_deg).abs() < 1e-12);
        // generate.py: FOCAL_PX = 1100, W × H = 1280 × 960, centred principal point.
        let hfov = 2.0 * (1280.0_f64 / 2.0 / 1100.0).atan().to_degrees();
        let vfov = 2.0 * (960.0_f64 / 2.0 / 1100.0).atan().to_degrees();
        println!("{id} HFoV {:.6}° (truth {hfov:.6}°)", r.hfov_deg);
        assert!((r.hfov_deg - hfov).abs() < ANGLE_TOL_DEG);
        assert!((r.vfov_deg - vfov).abs() < ANGLE_TOL_DEG);
        let height = r.height_above_ground_m.unwrap();
        println!("{id} height {height:.4} m (truth {} m)", center[2]);
        assert!((height - center[2]).abs() < HEIGHT_TOL_M);
        assert_eq!(
            r.ground_level_source,
            Some(GroundSource::ScenePolygon("ground".into()))
        );
        // Nearest point of the box: the camera in the box's frame, clamped to it.
        let cam = Point3::new(
            STREET_ORIGIN[0] + center[0],
            STREET_ORIGIN[1] + center[1],
            STREET_ORIGIN[2] + center[2],
        );
        let local = cam - corners[0];
        let (a, b, z) = (
            local.dot(&u.normalize()),
            local.dot(&v.normalize()),
            local.z,
        );
        let clamped = [
            a.clamp(0.0, u.norm()),
            b.clamp(0.0, v.norm()),
            z.clamp(0.0, 14.0),
        ];
        let nearest =
            ((a - clamped[0]).powi(2) + (b - clamped[1]).powi(2) + (z - clamped[2]).powi(2)).sqrt();
        let to_centre = (cam.coords - centre).norm();
        let got_near = r.distance_to_proposal_nearest_m.unwrap();
        let got_centre = r.distance_to_proposal_centroid_m.unwrap();
        println!(
            "{id} proposal nearest {got_near:.6} m (truth {nearest:.6}), centroid {got_centre:.6} m (truth {to_centre:.6})"
        );
        assert!((got_near - nearest).abs() < DISTANCE_TOL_M);
        assert!((got_centre - to_centre).abs() < DISTANCE_TOL_M);
        // The sun at capture: generate.py quotes NREL SPA at 121.94°, 40.57° (to 0.01°).
        assert!((r.sun_azimuth_deg.unwrap() - 121.94).abs() < 0.006);
        assert!((r.sun_elevation_deg.unwrap() - 40.57).abs() < 0.006);
        assert!(r.latitude_deg.is_some() && r.longitude_deg.is_some());
        // 35 mm equivalent: 1100 px over a 1600 px diagonal.
        let f35 = 1100.0 * 43.266_615_305_567_87 / 1600.0;
        assert!((r.focal_35mm_equiv_mm - f35).abs() < 1e-9);
    }
}

#[test]
fn courtyard_report_matches_the_generator() {
    let mut doc = site_with_true_cameras("courtyard", &COURTYARD_VIEWS);
    // generate.py: FOCAL_PX = 1500, K1 = −0.04, K2 = 0.01, W × H = 1600 × 1200.
    for p in &mut doc.site.photos {
        let interior = p.interior.as_mut().unwrap();
        interior.focal_px = 1500.0;
        interior.principal_point_px = Some([799.5, 599.5]);
        interior.distortion.k1 = -0.04;
        interior.distortion.k2 = 0.01;
    }
    // The undistorted x of the image edge on the principal row: x (1 + K1 x² + K2 x⁴) = x_d.
    let edge = |xd: f64| {
        let (mut lo, mut hi) = (0.0, 2.0 * xd);
        for _ in 0..200 {
            let mid = 0.5 * (lo + hi);
            let f = mid * (1.0 - 0.04 * mid * mid + 0.01 * mid.powi(4));
            if f < xd { lo = mid } else { hi = mid }
        }
        0.5 * (lo + hi)
    };
    let hfov = 2.0 * edge(800.0 / 1500.0).atan().to_degrees();
    let vfov = 2.0 * edge(600.0 / 1500.0).atan().to_degrees();
    for (id, center, target, roll) in COURTYARD_VIEWS {
        // The cameras stand outside the courtyard's ground polygon: no height without a level.
        let r = view_geometry(&doc, id, &ViewGeometryOptions::default()).unwrap();
        assert!(r.height_above_ground_m.is_none());
        assert!(
            r.notes
                .iter()
                .any(|n| n.contains("no scene polygon lies below"))
        );
        // The generator's ground is local Z = 0.
        let options = ViewGeometryOptions {
            ground_level_m: Some(COURTYARD_ORIGIN[2]),
            ..ViewGeometryOptions::default()
        };
        let r = view_geometry(&doc, id, &options).unwrap();
        let got = [r.bearing_grid_deg, r.pitch_deg, r.roll_deg];
        check_angles(
            id,
            got,
            expected_angles(center, target, roll),
            ANGLE_TOL_DEG,
        );
        println!(
            "{id} HFoV {:.6}° (truth {hfov:.6}°), VFoV {:.6}° (truth {vfov:.6}°)",
            r.hfov_deg, r.vfov_deg
        );
        assert!((r.hfov_deg - hfov).abs() < ANGLE_TOL_DEG);
        assert!((r.vfov_deg - vfov).abs() < ANGLE_TOL_DEG);
        let height = r.height_above_ground_m.unwrap();
        assert!((height - center[2]).abs() < HEIGHT_TOL_M, "{id}: {height}");
        assert_eq!(r.ground_level_source, Some(GroundSource::Given));
        // No planned model on this site: distances unknown, said so.
        assert!(r.distance_to_proposal_nearest_m.is_none());
        assert!(r.notes.iter().any(|n| n.contains("no visible model")));
    }
}

#[test]
fn solved_street_report_within_the_solve_sigma() {
    let mut doc = SiteDocument::load(&sample_site("street").join("site.toml")).unwrap();
    let solution = solve_site(&doc);
    assert!(solution.failures.is_empty(), "{:?}", solution.failures);
    apply_solution(&mut doc.site, &solution);
    for (id, center, target, roll) in STREET_VIEWS {
        let s = solution.photos.iter().find(|p| p.id == id).unwrap();
        let sigma_max = s.sigma_angles_deg.iter().copied().fold(0.0, f64::max);
        let r = view_geometry(&doc, id, &ViewGeometryOptions::default()).unwrap();
        let got = [r.bearing_grid_deg, r.pitch_deg, r.roll_deg];
        let tol = SIGMA_BOUND * 3f64.sqrt() * sigma_max;
        check_angles(id, got, expected_angles(center, target, roll), tol);
        let height = r.height_above_ground_m.unwrap();
        let tol_m = SIGMA_BOUND * s.sigma_center_m[2] + HEIGHT_TOL_M;
        println!(
            "{id} solved height {height:.4} m (truth {}, bound {tol_m:.4})",
            center[2]
        );
        assert!((height - center[2]).abs() < tol_m);
        assert!((r.rms_px - s.rms_px).abs() < 1e-12);
        assert!(!r.residuals.is_empty());
    }
}

#[test]
fn unsolved_view_is_refused_by_name() {
    let doc = SiteDocument::load(&sample_site("street").join("site.toml")).unwrap();
    let err = view_geometry(&doc, "V2", &ViewGeometryOptions::default()).unwrap_err();
    assert!(
        err.to_string().contains("V2") && err.to_string().contains("not solved"),
        "{err}"
    );
}

/// Real camera JPEGs carrying EXIF `FocalLengthIn35mmFilm`: the focal length in pixels the site
/// starts from (`initial_focal_px`, from that tag when nothing better is in the file), turned back
/// into a 35 mm equivalent by the report's conversion, must give the camera's stated value. This
/// checks that the two conventions (diagonal of the 36 × 24 mm frame, image as displayed) agree
/// on real files of several aspect ratios; it is not an independent measurement of the lens,
/// since none of the shared photos carries both the 35 mm tag and sensor dimensions.
#[test]
fn thirty_five_mm_equivalent_of_real_cameras_matches_exif() {
    for name in [
        "DSCN0010.jpg",
        "Kodak_CX7530.jpg",
        "Panasonic_DMC-FZ30.jpg",
        "Samsung_Digimax_i50_MP3.jpg",
        "Nikon_D70.jpg",
    ] {
        let Some(path) = shared_file(&format!("data/real/exif/{name}")) else {
            return;
        };
        let exif = photomontage::photo::read_exif(&path).unwrap();
        let size = photomontage::photo::size_px(&path).unwrap();
        let start = photomontage::photo::initial_focal_px(&exif, size).unwrap();
        assert_eq!(
            start.source,
            photomontage::photo::FocalSource::Equivalent35mm
        );
        let f35 = focal_35mm_equiv_mm(start.focal_px, size).unwrap();
        let want = exif.focal_length_35mm.unwrap();
        println!(
            "{name}: {size:?} px, f {:.2} px → {f35:.3} mm (EXIF {want} mm)",
            start.focal_px
        );
        assert!((f35 / want - 1.0).abs() < FOCAL_35MM_REL_TOL, "{name}");
    }
}
