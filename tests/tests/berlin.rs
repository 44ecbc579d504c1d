//! The OpenSfM `berlin` sample (`../shared/data/real/gcp/opensfm_berlin`, BSD-2-Clause, see its
//! README): three iPhone 4S photos whose `gcp_list.txt` is in WGS 84 (`lon lat alt`). The list
//! is reprojected to UTM 33N and compared with the helper's pyproj/PROJ 9.5.1 coordinates in
//! `gcp_observations_utm33n.csv`.
#![allow(clippy::unwrap_used)] // test helpers outside #[test] functions

use photomontage::geo::ProjectedCrs;
use photomontage::photogrammetry::control_io::parse_odm_gcp_list;
use photomontage_tests::shared_file;

/// The CSV gives E/N to the millimetre (±0.5 mm rounding); proj4rs's extended transverse
/// Mercator and PROJ's agree to far below that inside a zone.
const UTM_AGREEMENT_TOL_M: f64 = 1e-3;

#[test]
// Pixels are matched by their identical decimal text, parsed the same way.
#[allow(clippy::float_cmp)]
fn wgs84_gcp_list_reprojects_to_the_pyproj_utm_coordinates() {
    let Some(list_path) = shared_file("data/real/gcp/opensfm_berlin/gcp_list.txt") else {
        return;
    };
    let Some(csv_path) = shared_file("data/real/gcp/opensfm_berlin/gcp_observations_utm33n.csv")
    else {
        return;
    };
    let list = parse_odm_gcp_list(&std::fs::read_to_string(list_path).unwrap()).unwrap();
    assert_eq!(list.crs, "WGS84");
    // No --crs: the UTM zone of the centroid, which is 33N for Berlin.
    let (utm, target) = list.reprojected(None).unwrap();
    let zone33 = ProjectedCrs::from_name("EPSG:32633").unwrap();
    assert_eq!(target.definition(), zone33.definition());
    let csv = std::fs::read_to_string(csv_path).unwrap();
    let mut compared = 0;
    for line in csv.lines().skip(1).filter(|l| !l.trim().is_empty()) {
        // image,gcp,px,py,lon,lat,alt,E_32633,N_32633
        let f: Vec<&str> = line.split(',').collect();
        let num = |i: usize| f[i].parse::<f64>().unwrap();
        let (px, py, alt, e, n) = (num(2), num(3), num(6), num(7), num(8));
        let row = utm
            .rows
            .iter()
            .find(|r| r.image == f[0] && r.pixel.x == px && r.pixel.y == py)
            .unwrap_or_else(|| panic!("no row for {line}"));
        assert!(
            (row.point_in_world.x - e).abs() < UTM_AGREEMENT_TOL_M
                && (row.point_in_world.y - n).abs() < UTM_AGREEMENT_TOL_M,
            "{}: ({}, {}) vs pyproj ({e}, {n})",
            f[1],
            row.point_in_world.x,
            row.point_in_world.y
        );
        // Heights are kept as given.
        assert!((row.point_in_world.z - alt).abs() < 1e-9, "{line}");
        compared += 1;
    }
    assert_eq!(compared, 26, "every observation compared");
    assert_eq!(utm.control_points([0.01; 3]).unwrap().len(), 10);
}
