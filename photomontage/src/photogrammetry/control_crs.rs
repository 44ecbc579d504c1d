//! Control in any CRS: the header of an OpenDroneMap `gcp_list.txt` (<https://docs.opendronemap.org/gcp/>)
//! names the coordinate system of its rows (`WGS84`/`EPSG:4326`, `WGS84 UTM 32N`, an EPSG code or a
//! PROJ.4 string); this module reprojects the rows into the site's projected CRS with
//! [`crate::geo::SourceCrs`] (proj4rs). Geographic rows are `longitude latitude height`, the
//! order ODM's and OpenSfM's readers use (OpenSfM's `berlin` sample list is `lon lat alt`).
//!
//! # Known limitations
//! Heights are kept as given: a GPS list's heights stay ellipsoidal (or whatever datum the list
//! used), there is no geoid model. Without a named target, a geographic list goes to the
//! standard UTM zone of its centroid (no Norway/Svalbard exceptions).

use super::control_io::{ControlIoError, OdmGcpList};
use crate::geo::{ProjectedCrs, SourceCrs};

impl OdmGcpList {
    /// The CRS the header names.
    ///
    /// # Errors
    /// [`ControlIoError::Crs`] naming the header line when `proj4rs` cannot use it.
    pub fn source_crs(&self) -> Result<SourceCrs, ControlIoError> {
        SourceCrs::from_header(&self.crs).map_err(|source| ControlIoError::Crs {
            line: self.crs_line,
            header: self.crs.clone(),
            source,
        })
    }

    /// The list with every point's x, y in `target` (heights as given). Without a target, a
    /// projected list is returned unchanged and a geographic one goes to the UTM zone of its
    /// points' centroid. The header of the result is `target`'s PROJ.4 definition; row ids
    /// made from coordinates keep the source's text, so the points stay the same points.
    ///
    /// # Errors
    /// [`ControlIoError::Crs`] for an unusable header, [`ControlIoError::Reprojection`] naming
    /// the line of a point that cannot be converted.
    pub fn reprojected(
        &self,
        target: Option<&ProjectedCrs>,
    ) -> Result<(OdmGcpList, ProjectedCrs), ControlIoError> {
        let source = self.source_crs()?;
        let target = match (target, &source) {
            (Some(t), _) => t.clone(),
            (None, SourceCrs::Projected(p)) => p.clone(),
            (None, SourceCrs::Geographic { .. }) => self.centroid_utm(&source)?,
        };
        let mut rows = self.rows.clone();
        for row in &mut rows {
            let (x, y) = (row.point_in_world.x, row.point_in_world.y);
            let (e, n) = source.to_projected(x, y, &target).map_err(|source| {
                ControlIoError::Reprojection {
                    line: row.line,
                    x,
                    y,
                    target: target.definition().to_owned(),
                    source,
                }
            })?;
            row.point_in_world.x = e;
            row.point_in_world.y = n;
        }
        let list = OdmGcpList {
            crs: target.definition().to_owned(),
            crs_line: self.crs_line,
            rows,
        };
        Ok((list, target))
    }

    /// The UTM zone of the centroid (in lon/lat) of a geographic list's points.
    fn centroid_utm(&self, source: &SourceCrs) -> Result<ProjectedCrs, ControlIoError> {
        let crs_error = |source| ControlIoError::Crs {
            line: self.crs_line,
            header: self.crs.clone(),
            source,
        };
        #[allow(clippy::cast_precision_loss)] // at most MAX_ROWS rows
        let count = self.rows.len().max(1) as f64;
        let (sum_x, sum_y) = self.rows.iter().fold((0.0, 0.0), |(sx, sy), r| {
            (sx + r.point_in_world.x, sy + r.point_in_world.y)
        });
        let (lat, lon) = source
            .to_lat_lon_deg(sum_x / count, sum_y / count)
            .map_err(crs_error)?;
        let (zone, hemisphere) = crate::geo::utm_zone_of(lat, lon).map_err(crs_error)?;
        ProjectedCrs::utm(zone, hemisphere).map_err(crs_error)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::photogrammetry::control_io::parse_odm_gcp_list;
    use nalgebra::Point2;

    /// proj4rs's transverse Mercator agrees with itself to far below a millimetre.
    const REPROJECTION_TOL_M: f64 = 1e-6;

    #[test]
    fn wgs84_list_goes_to_the_utm_zone_of_its_centroid() {
        // Two points in Berlin (zone 33N), lon lat order as ODM and OpenSfM write them.
        let text = "# comment\nWGS84\n13.40 52.52 12.5 100 200 a.jpg\n13.41 52.51 -3.25 300 400 a.jpg p2\n";
        let list = parse_odm_gcp_list(text).expect("valid");
        assert_eq!(list.crs_line, 2);
        assert!(list.source_crs().expect("known").is_geographic());
        let (utm, target) = list.reprojected(None).expect("converts");
        let zone33 = ProjectedCrs::utm(33, crate::geo::Hemisphere::North).expect("valid");
        assert_eq!(target.definition(), zone33.definition());
        assert_eq!(utm.crs, zone33.definition());
        for (row, (lat, lon, h)) in utm
            .rows
            .iter()
            .zip([(52.52, 13.40, 12.5), (52.51, 13.41, -3.25)])
        {
            let (e, n) = zone33.from_lat_lon_deg(lat, lon).expect("converts");
            assert!((row.point_in_world.x - e).abs() < REPROJECTION_TOL_M);
            assert!((row.point_in_world.y - n).abs() < REPROJECTION_TOL_M);
            // Heights kept as given.
            assert!((row.point_in_world.z - h).abs() < f64::EPSILON);
        }
        // Ids and pixels unchanged.
        assert_eq!(utm.rows[0].gcp_id, "13.40 52.52 12.5");
        assert_eq!(utm.rows[1].gcp_id, "p2");
        assert_eq!(utm.rows[1].pixel, Point2::new(300.0, 400.0));
        // An explicit target wins over the centroid's zone.
        let zone32 = ProjectedCrs::from_name("EPSG:32632").expect("valid");
        let (in32, _) = list.reprojected(Some(&zone32)).expect("converts");
        let (e, n) = zone32.from_lat_lon_deg(52.52, 13.40).expect("converts");
        assert!((in32.rows[0].point_in_world.x - e).abs() < REPROJECTION_TOL_M);
        assert!((in32.rows[0].point_in_world.y - n).abs() < REPROJECTION_TOL_M);
    }

    #[test]
    fn projected_list_stays_or_moves_to_the_target() {
        let text = "WGS84 UTM 32N\n500000 5200000 400 10 20 a.jpg g1\n";
        let list = parse_odm_gcp_list(text).expect("valid");
        let (same, target) = list.reprojected(None).expect("converts");
        assert_eq!(same.rows[0].point_in_world, list.rows[0].point_in_world);
        assert!(target.definition().contains("+zone=32"));
        let zone33 = ProjectedCrs::from_name("EPSG:32633").expect("valid");
        let (moved, _) = list.reprojected(Some(&zone33)).expect("converts");
        let zone32 = ProjectedCrs::from_name("EPSG:32632").expect("valid");
        let (lat, lon) = zone32
            .to_lat_lon_deg(500_000.0, 5_200_000.0)
            .expect("converts");
        let (e, n) = zone33.from_lat_lon_deg(lat, lon).expect("converts");
        assert!((moved.rows[0].point_in_world.x - e).abs() < 1e-3);
        assert!((moved.rows[0].point_in_world.y - n).abs() < 1e-3);
    }

    #[test]
    fn unusable_crs_names_the_header_line() {
        let list = parse_odm_gcp_list("\nGauss-Krüger zone 4\n1 2 3 4 5 a.jpg\n").expect("parses");
        let err = list.reprojected(None).unwrap_err();
        assert!(matches!(err, ControlIoError::Crs { line: 2, .. }), "{err}");
        assert!(
            err.to_string()
                .starts_with("line 2: the coordinate system `Gauss-Krüger zone 4`"),
            "{err}"
        );
        let bad = parse_odm_gcp_list("WGS84\n13.4 152.5 3 4 5 a.jpg\n").expect("parses");
        let zone33 = ProjectedCrs::from_name("EPSG:32633").expect("valid");
        let err = bad.reprojected(Some(&zone33)).unwrap_err();
        assert!(
            matches!(err, ControlIoError::Reprojection { line: 2, .. }),
            "{err}"
        );
    }
}
