//! The `photomontage` command line on the bundled sample site: JSON fields, exit codes, errors.
#![allow(clippy::unwrap_used)] // test helpers outside #[test] functions

use std::path::PathBuf;
use std::process::Command;

fn bin() -> Command {
    Command::new(env!("CARGO_BIN_EXE_photomontage"))
}

fn courtyard() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../sample_sites/courtyard/site.toml")
}

fn json_of(cmd: &mut Command) -> serde_json::Value {
    let out = cmd.output().unwrap();
    assert!(
        out.status.success(),
        "stderr: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    serde_json::from_slice(&out.stdout).unwrap()
}

#[test]
fn info_lists_photos_points_and_polygons() {
    let v = json_of(bin().arg("info").arg(courtyard()).arg("--json"));
    let photos = v["photos"].as_array().unwrap();
    assert_eq!(photos.len(), 3);
    for p in photos {
        assert!(p["id"].is_string() && p["file"].is_string());
        assert_eq!(p["size_px"], serde_json::json!([1600, 1200]));
        assert_eq!(p["exists"], true);
    }
    assert_eq!(v["polygons"].as_array().unwrap().len(), 5);
    assert!(v["control_points"].as_array().unwrap().len() >= 20);
}

#[test]
fn solve_json_has_every_documented_field() {
    let v = json_of(
        bin()
            .arg("solve")
            .arg(courtyard())
            .args(["--json", "--no-write"]),
    );
    let photos = v["photos"].as_array().unwrap();
    assert_eq!(photos.len(), 3);
    for p in photos {
        for field in [
            "id",
            "camera_center",
            "rotation_world_from_camera",
            "focal_px",
            "principal_point_px",
            "distortion",
            "rms_px",
            "sigma_center_m",
            "outliers",
            "warnings",
        ] {
            assert!(!p[field].is_null(), "missing {field}");
        }
        assert_eq!(p["rotation_world_from_camera"].as_array().unwrap().len(), 3);
        assert!(p["rms_px"].as_f64().unwrap() < 1.0);
    }
    assert!(v["written_to"].is_null());
}

#[test]
fn solve_writes_atomically_to_out() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("solved.toml");
    let status = bin()
        .arg("solve")
        .arg(courtyard())
        .arg("--out")
        .arg(&out)
        .output()
        .unwrap();
    assert!(status.status.success());
    let text = std::fs::read_to_string(&out).unwrap();
    assert!(text.contains("[photos.exterior]"));
    let info = json_of(bin().arg("info").arg(&out).arg("--json"));
    assert!(
        info["photos"]
            .as_array()
            .unwrap()
            .iter()
            .all(|p| p["solved"] == true)
    );
}

/// Writes a resection CSV for one photo from the sample site's observations.
fn csv_for(photo: &str, dir: &std::path::Path, keep: usize) -> PathBuf {
    let doc = photomontage::site::SiteDocument::load(&courtyard()).unwrap();
    let mut text = String::from("id,X,Y,Z,x,y,sigma_px\n");
    let mut n = 0;
    for o in doc.site.observations.iter().filter(|o| o.photo == photo) {
        if let Some(c) = doc.site.control_points.iter().find(|c| c.id == o.point)
            && n < keep
        {
            text += &format!(
                "{},{},{},{},{},{},{}\n",
                c.id, c.xyz[0], c.xyz[1], c.xyz[2], o.x_px, o.y_px, o.sigma_px
            );
            n += 1;
        }
    }
    let path = dir.join(format!("{photo}.csv"));
    std::fs::write(&path, text).unwrap();
    path
}

#[test]
fn resect_csv_reports_pose_and_residuals() {
    let dir = tempfile::tempdir().unwrap();
    let csv = csv_for("P3", dir.path(), usize::MAX);
    let v = json_of(bin().arg("resect").arg(&csv).args([
        "--image-size",
        "1600",
        "1200",
        "--focal-px",
        "1500",
        "--json",
    ]));
    let c = v["camera_center"].as_array().unwrap();
    // Truth: (20, -34, 10) + origin (2683000, 1247000, 400); with k1 left at 0 the pose is a
    // few decimetres off, far less than a metre.
    let truth = [2_683_020.0, 1_246_966.0, 410.0];
    for axis in 0..3 {
        assert!(
            (c[axis].as_f64().unwrap() - truth[axis]).abs() < 1.0,
            "{c:?}"
        );
    }
    assert!(v["residuals"].as_array().unwrap().len() >= 15);
}

#[test]
fn resect_with_too_few_points_names_the_counts() {
    let dir = tempfile::tempdir().unwrap();
    let csv = csv_for("P3", dir.path(), 3);
    let out = bin()
        .arg("resect")
        .arg(&csv)
        .args(["--image-size", "1600", "1200", "--focal-px", "1500"])
        .output()
        .unwrap();
    assert!(!out.status.success());
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(err.contains('4') && err.contains('3'), "{err}");
}

#[test]
fn missing_site_is_a_clear_error() {
    let out = bin()
        .args(["solve", "/nonexistent/site.toml"])
        .output()
        .unwrap();
    assert!(!out.status.success());
    assert!(String::from_utf8_lossy(&out.stderr).contains("/nonexistent/site.toml"));
}

#[test]
fn help_states_the_pixel_convention() {
    let out = bin().arg("--help").output().unwrap();
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(text.contains("centre of the top-left pixel"), "{text}");
}

#[test]
fn resect_reprojects_a_wgs84_gcp_list() {
    // The courtyard's LV95 control points written as a WGS 84 gcp_list.txt (lon lat height).
    let doc = photomontage::site::SiteDocument::load(&courtyard()).unwrap();
    let lv95 = photomontage::geo::ProjectedCrs::from_name("EPSG:2056").unwrap();
    let mut text = String::from("WGS84\n");
    for o in doc.site.observations.iter().filter(|o| o.photo == "P3") {
        if let Some(c) = doc.site.control_points.iter().find(|c| c.id == o.point) {
            let (lat, lon) = lv95.to_lat_lon_deg(c.xyz[0], c.xyz[1]).unwrap();
            text += &format!(
                "{lon:.12} {lat:.12} {} {} {} P3.jpg {}\n",
                c.xyz[2], o.x_px, o.y_px, c.id
            );
        }
    }
    let dir = tempfile::tempdir().unwrap();
    let list = dir.path().join("gcp_list.txt");
    std::fs::write(&list, text).unwrap();
    let args = [
        "--image",
        "P3.jpg",
        "--image-size",
        "1600",
        "1200",
        "--focal-px",
        "1500",
        "--json",
    ];
    // Back into LV95 with --crs: the pose of `resect_csv_reports_pose_and_residuals`.
    let v = json_of(
        bin()
            .arg("resect")
            .arg(&list)
            .args(args)
            .args(["--crs", "EPSG:2056"]),
    );
    let c = v["camera_center"].as_array().unwrap();
    let truth = [2_683_020.0, 1_246_966.0, 410.0];
    for axis in 0..3 {
        assert!(
            (c[axis].as_f64().unwrap() - truth[axis]).abs() < 1.0,
            "{c:?}"
        );
    }
    let note = v["control_crs"].as_str().unwrap();
    assert!(note.contains("somerc") && note.contains("--crs"), "{note}");
    // Without --crs: the UTM zone of the centroid (Zurich area: 32N), stated.
    let v = json_of(bin().arg("resect").arg(&list).args(args));
    let note = v["control_crs"].as_str().unwrap();
    assert!(
        note.contains("+zone=32") && note.contains("centroid"),
        "{note}"
    );
    // A header proj4rs cannot use is named with its line.
    std::fs::write(&list, "Gauss-Krüger 4\n1 2 3 4 5 P3.jpg\n").unwrap();
    let out = bin().arg("resect").arg(&list).args(args).output().unwrap();
    assert!(!out.status.success());
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        err.contains("line 1") && err.contains("Gauss-Krüger 4"),
        "{err}"
    );
}
