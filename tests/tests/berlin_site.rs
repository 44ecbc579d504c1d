//! End to end over the real-photo sample site `sample_sites/berlin` (OpenSfM's "berlin" photos,
//! © 2014 Mapillary, BSD-2-Clause; issue 15): the site's control is the shipped WGS 84
//! `gcp_list.txt` reprojected by the library, its `[location]` is the one the library derives from
//! that control, the capture time comes from the photos' Mapillary metadata, the three cameras
//! solve with self-calibrated focal length within the acceptance bounds, the daylight fit runs on
//! the photo samples, the renderer's sun is pvlib's at photo 02's time, and the pavilion is
//! rendered into photo 02 (box-filtered 8 × 8, the site's 4–8 rays per pixel).
//!
//! Measured (2026-11-24, debug build): bundle RMS 0.139 px; focal 3102.1 / 3106.6 px (01, 02;
//! 03 kept at 3104 px, its six GCPs cannot separate focal length from distance); camera centres
//! 2.2 / 3.9 / 1.3 m from the EXIF GPS positions horizontally.
#![allow(clippy::unwrap_used)] // test helpers outside #[test] functions

use std::sync::atomic::AtomicBool;

use chrono::DateTime;
use photomontage::fit::site::{SiteFitOptions, fit_site};
use photomontage::geo::ProjectedCrs;
use photomontage::photo::{self, CaptureTimeSource};
use photomontage::photogrammetry::control_io::parse_odm_gcp_list;
use photomontage::render::{DifferentialTracer, render_view};
use photomontage::site::control_location::location_from_control;
use photomontage::site::render::prepare_view;
use photomontage::site::{SiteDocument, apply_solution, solve_site};
use photomontage_tests::sample_site;
use photomontage_tests::street::downscale;

/// Issue 15 acceptance: bundle RMS at most 2 px.
const BUNDLE_RMS_MAX_PX: f64 = 2.0;
/// Issue 15 acceptance: camera centres within 5 m of the EXIF GPS (the phone's stated accuracy,
/// `MAPGPSAccuracyMeters` 5; the GCPs themselves are only ±5 m absolute). Horizontal: the
/// GPS altitude (27–39 m) is in another vertical frame than the GCP heights (square ≈ 0 m).
const GPS_HORIZONTAL_MAX_M: f64 = 5.0;
/// The site's control is written to the millimetre; proj4rs agrees with PROJ far below that.
const CONTROL_TEXT_TOL_M: f64 = 6e-4;
/// `[location]` is written to 1e-6° (0.1 m) and the convergence to 1e-4°.
const LOCATION_TEXT_TOL_DEG: f64 = 6e-7;
const CONVERGENCE_TEXT_TOL_DEG: f64 = 6e-5;
/// EXIF's 35 mm tag gives 3300.5 px on the diagonal; a focal length that moved less than this
/// was not estimated. The free solves give 3102–3107 px (6 % shorter).
const FOCAL_MOVED_MIN_PX: f64 = 100.0;
/// Box-filter factor of the test render (3264 × 2448 → 408 × 306).
const RENDER_SCALE: u32 = 8;
/// The sun at 12:56 UTC by pvlib (the dataset's README, to 0.1°): azimuth 225.5°, elevation
/// 51.9°. Photo 02 is 11 s later (≈ 0.05° of sun motion) and its values are rounded to 0.05°.
const PVLIB_SUN_AZIMUTH_DEG: f64 = 225.5;
const PVLIB_SUN_ELEVATION_DEG: f64 = 51.9;
const PVLIB_SUN_TOL_DEG: f64 = 0.15;

fn load() -> SiteDocument {
    SiteDocument::load(&sample_site("berlin").join("site.toml")).unwrap()
}

#[test]
fn control_and_location_come_from_the_shipped_gcp_list() {
    let doc = load();
    let text = std::fs::read_to_string(sample_site("berlin").join("photos/gcp_list.txt")).unwrap();
    let list = parse_odm_gcp_list(&text).unwrap();
    let (utm, crs) = list.reprojected(None).unwrap();
    // G01…G10 in the order the list first names them (as the dataset's README numbers them).
    let mut seen: Vec<&photomontage::photogrammetry::control_io::OdmGcpRow> = Vec::new();
    for row in &utm.rows {
        if !seen.iter().any(|s| s.gcp_id == row.gcp_id) {
            seen.push(row);
        }
    }
    assert_eq!(seen.len(), 10);
    for (k, row) in seen.iter().enumerate() {
        let id = format!("G{:02}", k + 1);
        let cp = doc.site.control_points.iter().find(|c| c.id == id).unwrap();
        for axis in 0..3 {
            assert!(
                (cp.xyz[axis] - row.point_in_world[axis]).abs() < CONTROL_TEXT_TOL_M,
                "{id} axis {axis}: {} vs {}",
                cp.xyz[axis],
                row.point_in_world[axis]
            );
        }
        // Every observation of the list is in the site, pixels as given (2 decimals).
        for r in utm.rows.iter().filter(|r| r.gcp_id == row.gcp_id) {
            let photo = r.image.trim_end_matches(".jpg");
            let o = doc
                .site
                .observations
                .iter()
                .find(|o| o.photo == photo && o.point == id)
                .unwrap_or_else(|| panic!("{id} in {photo}"));
            assert!((o.x_px - r.pixel.x).abs() < 5e-3 && (o.y_px - r.pixel.y).abs() < 5e-3);
        }
    }
    assert_eq!(doc.site.observations.len(), 26);
    // [location] is what the library derives from G01…G10 in the centroid's UTM zone.
    let control: Vec<_> = doc
        .site
        .control_points
        .iter()
        .filter(|c| c.id.starts_with('G'))
        .cloned()
        .collect();
    let expected = location_from_control(&control, &crs, &crs.site_name()).unwrap();
    let loc = doc.site.location.as_ref().unwrap();
    assert_eq!(loc.crs.as_deref(), Some("EPSG:32633"));
    assert_eq!(expected.crs, loc.crs);
    assert!((loc.latitude_deg - expected.latitude_deg).abs() < LOCATION_TEXT_TOL_DEG);
    assert!((loc.longitude_deg - expected.longitude_deg).abs() < LOCATION_TEXT_TOL_DEG);
    assert!(
        (loc.grid_convergence_deg - expected.grid_convergence_deg).abs() < CONVERGENCE_TEXT_TOL_DEG
    );
    assert!((loc.elevation_m - expected.elevation_m).abs() < 1e-3);
}

#[test]
fn capture_time_is_the_mapillary_time_in_utc() {
    let doc = load();
    for (id, stamp) in [
        ("01", "2014-05-26T12:56:02.384+00:00"),
        ("02", "2014-05-26T12:56:11.489+00:00"),
        ("03", "2014-05-26T12:56:30.953+00:00"),
    ] {
        let p = doc.site.photos.iter().find(|p| p.id == id).unwrap();
        assert!(
            p.taken_at.is_none(),
            "{id}: the site leaves the time to EXIF"
        );
        let exif = photo::read_exif(&doc.resolve(&p.file)).unwrap();
        // No DateTimeOriginal and no GPS time: Mapillary's is the only reading.
        assert!(exif.date_time_original.is_none() && exif.gps_date_time_utc.is_none());
        let t = exif.capture_time().unwrap();
        assert_eq!(t.source, CaptureTimeSource::MapillaryCaptureTime);
        assert_eq!(t.time, DateTime::parse_from_rfc3339(stamp).unwrap(), "{id}");
    }
}

#[test]
fn berlin_solves_fits_and_renders_the_pavilion() {
    let mut doc = load();
    // Solve: resections with focal free, then the bundle.
    let solution = solve_site(&doc);
    assert!(solution.failures.is_empty(), "{:?}", solution.failures);
    assert_eq!(solution.photos.len(), 3);
    let rms = solution.bundle_rms_px.unwrap();
    assert!(rms <= BUNDLE_RMS_MAX_PX, "bundle RMS {rms} px");
    let zone33 = ProjectedCrs::from_name("EPSG:32633").unwrap();
    for s in &solution.photos {
        let p = doc.site.photos.iter().find(|p| p.id == s.id).unwrap();
        let gps = photo::read_exif(&doc.resolve(&p.file))
            .unwrap()
            .gps
            .unwrap();
        let (e, n) = zone33
            .from_lat_lon_deg(gps.latitude_deg, gps.longitude_deg)
            .unwrap();
        let c = s.camera.pose.camera_center_in_world;
        let off = (c.x - e).hypot(c.y - n);
        eprintln!(
            "Berlin {}: {} RMS {:.3} px, focal {:.1} px, centre {off:.2} m from EXIF GPS",
            s.id, s.solved_by, s.rms_px, s.camera.intrinsics.focal_px
        );
        assert!(off <= GPS_HORIZONTAL_MAX_M, "{}: {off} m from GPS", s.id);
        if s.id != "03" {
            // Self-calibrated in the resection (EXIF's start is 3300.5 px).
            assert!(
                (s.camera.intrinsics.focal_px - 3300.5).abs() > FOCAL_MOVED_MIN_PX,
                "{}: focal {} px",
                s.id,
                s.camera.intrinsics.focal_px
            );
        }
    }
    apply_solution(&mut doc.site, &solution);

    // The daylight fit on the photo samples: a sun weight, every sample used or named.
    let report = fit_site(&doc, &SiteFitOptions::default(), None).unwrap();
    let sun = report.sun_weight.unwrap();
    assert!(sun.iter().all(|k| k.is_finite() && *k > 0.0), "{sun:?}");
    assert!(!report.residuals.is_empty(), "{:?}", report.warnings);

    // The montage at 1/8 size: the pavilion changes the pixels it covers and nothing at the top
    // of the photo (the mosaic and the arch are far above and behind it).
    let mut job = prepare_view(&doc, "02").unwrap();
    // The renderer's sun is the SPA sun at photo 02's Mapillary time (UTC) at [location],
    // turned into the grid by the convergence.
    let sun_dir = job.lighting.daylight.sun.as_ref().unwrap().dir_in_world;
    let convergence = doc.site.location.as_ref().unwrap().grid_convergence_deg;
    let azimuth_deg = (sun_dir.x.atan2(sun_dir.y).to_degrees() - convergence).rem_euclid(360.0);
    let elevation_deg = sun_dir.z.asin().to_degrees();
    eprintln!("Berlin sun for photo 02: azimuth {azimuth_deg:.3}°, elevation {elevation_deg:.3}°");
    assert!((azimuth_deg - PVLIB_SUN_AZIMUTH_DEG).abs() < PVLIB_SUN_TOL_DEG);
    assert!((elevation_deg - PVLIB_SUN_ELEVATION_DEG).abs() < PVLIB_SUN_TOL_DEG);
    let photo = downscale(&job.photo_linear, RENDER_SCALE);
    let s = f64::from(RENDER_SCALE);
    let k = &mut job.camera.intrinsics;
    k.focal_px /= s;
    k.principal_point_px = k.principal_point_px.map(|c| (c + 0.5) / s - 0.5);
    k.image_size_px = [photo.width(), photo.height()];
    let tracer = DifferentialTracer::new(
        &job.scene.scene,
        &job.lighting,
        &job.camera,
        &photo,
        job.settings.max_depth,
    )
    .unwrap();
    let out = render_view(&tracer, &job.settings, &|_| {}, &AtomicBool::new(false)).unwrap();
    assert_eq!(out.size_px, [photo.width(), photo.height()]);
    let pixel = |x: u32, y: u32| out.rgba[usize::try_from(y * out.size_px[0] + x).unwrap()];
    // Where the pavilion's roof projects in photo 02 (full-size pixel (1000, 1650)) and a
    // column ((1280, 2100)): covered by the pavilion.
    for (x, y) in [(1000, 1650), (1280, 2100)] {
        let a = pixel(x / RENDER_SCALE, y / RENDER_SCALE)[3];
        assert!(a > 0.5, "alpha {a} at ({x}, {y})");
    }
    // The top third of the photo (the mosaic and the arch, far above and behind the pavilion)
    // is the photo, untouched.
    for y in 0..photo.height() / 3 {
        for x in 0..photo.width() {
            let (a, b) = (pixel(x, y), photo.get_pixel(x, y).0);
            assert!(
                (0..3).all(|c| (a[c] - b[c]).abs() < 1e-6) && a[3] <= 0.0,
                "pixel ({x}, {y}) changed: {a:?} vs {b:?}"
            );
        }
    }
    eprintln!(
        "Berlin montage at 1/{RENDER_SCALE}: {} pixels traced",
        out.changed_pixels
    );
}
