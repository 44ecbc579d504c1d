//! The sample sites solved with the sparse bundle adjustment and with the dense reference it
//! replaced give the same cameras and points.

use std::path::PathBuf;

use super::*;
use crate::photogrammetry::bundle::bundle_adjust_dense_reference;

/// Sparse and dense paths solve the same normal equations and differ only in the order of
/// floating-point sums; both stop when every step is below 1e-10 σ. 1e-9 relative to the
/// quantity's magnitude (≥ 1 m for centres, 1 for rotations, ~3000 px for focal lengths) is far
/// above that and far below any precision the sites report.
const SPARSE_DENSE_RELATIVE: f64 = 1e-9;

fn sample_site(name: &str) -> SiteDocument {
    let path = PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("../sample_sites")
        .join(name)
        .join("site.toml");
    SiteDocument::load(&path).unwrap_or_else(|e| panic!("{}: {e}", path.display()))
}

fn close(a: f64, b: f64, scale: f64) -> bool {
    (a - b).abs() <= SPARSE_DENSE_RELATIVE * a.abs().max(b.abs()).max(scale)
}

fn assert_same_solution(name: &str) {
    let doc = sample_site(name);
    let sparse = solve_site_with(&doc, pg::bundle_adjust);
    let dense = solve_site_with(&doc, bundle_adjust_dense_reference);
    assert!(sparse.failures.is_empty(), "{name}: {:?}", sparse.failures);
    assert!(
        sparse.bundle_rms_px.is_some(),
        "{name}: no bundle adjustment ran"
    );
    assert!(
        sparse.photos.len() >= 2,
        "{name}: {} photos",
        sparse.photos.len()
    );
    assert_eq!(sparse.photos.len(), dense.photos.len());
    for (s, d) in sparse.photos.iter().zip(&dense.photos) {
        assert_eq!(s.id, d.id);
        let (cs, cd) = (&s.camera, &d.camera);
        for axis in 0..3 {
            let (a, b) = (
                cs.pose.camera_center_in_world[axis],
                cd.pose.camera_center_in_world[axis],
            );
            assert!(close(a, b, 1.0), "{name} {}: centre {a} vs {b}", s.id);
            let (a, b) = (s.sigma_center_m[axis], d.sigma_center_m[axis]);
            assert!(close(a, b, 0.0), "{name} {}: σ centre {a} vs {b}", s.id);
        }
        let rs = cs.pose.rotation_world_from_camera.matrix();
        let rd = cd.pose.rotation_world_from_camera.matrix();
        for (a, b) in rs.iter().zip(rd.iter()) {
            assert!(close(*a, *b, 1.0), "{name} {}: rotation {a} vs {b}", s.id);
        }
        let (a, b) = (cs.intrinsics.focal_px, cd.intrinsics.focal_px);
        assert!(close(a, b, 1.0), "{name} {}: focal {a} vs {b}", s.id);
    }
    assert_eq!(sparse.points.len(), dense.points.len());
    for (s, d) in sparse.points.iter().zip(&dense.points) {
        assert_eq!(s.id, d.id);
        for axis in 0..3 {
            let (a, b) = (s.point_in_world[axis], d.point_in_world[axis]);
            assert!(close(a, b, 1.0), "{name} {}: {a} vs {b}", s.id);
            let (a, b) = (s.sigma_m[axis], d.sigma_m[axis]);
            assert!(
                close(a, b, 0.0) || (a.is_nan() && b.is_nan()),
                "{name} {}: σ {a} vs {b}",
                s.id
            );
        }
    }
}

#[test]
fn courtyard_sparse_bundle_matches_the_dense_reference() {
    assert_same_solution("courtyard");
}

#[test]
fn street_sparse_bundle_matches_the_dense_reference() {
    assert_same_solution("street");
}
