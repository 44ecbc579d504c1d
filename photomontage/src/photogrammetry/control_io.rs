//! Readers for control-point files: OpenDroneMap's `gcp_list.txt` (format documented at
//! <https://docs.opendronemap.org/gcp/>: a header line naming the coordinate reference system,
//! then rows `geo_x geo_y geo_z im_x im_y image_name [gcp_name] [extras…]`, whitespace
//! separated), a plain CSV `id,X,Y,Z,x,y[,sigma_px]` with an optional header row, and a
//! control-point list `id,X,Y,Z[,sigma_m]` (world coordinates only).
//!
//! All three report the 1-based line of any error, never panic, and cap the number of rows.
//!
//! # Known limitations
//! The CRS header is parsed and the list reprojected in [`super::control_crs`]. ODM pixel coordinates are taken as
//! given (ODM uses the same top-left-pixel-centre convention as ours to within its own
//! rounding). Rows without a gcp name get an id made from their coordinates, so rows with
//! identical coordinates are one point, as in ODM.

use nalgebra::{Point2, Point3};

use super::{ControlPoint, ImageObservation};

/// Upper bound on rows in one file (a site has hundreds; this only stops runaway input).
pub const MAX_ROWS: usize = 1_000_000;

/// Errors of the control-file readers.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum ControlIoError {
    #[error("line {line}: {message}")]
    Parse { line: usize, message: String },
    #[error("the file has no header line")]
    Empty,
    #[error("more than {limit} rows")]
    TooManyRows { limit: usize },
    #[error("line {line}: point {id} was given different coordinates earlier")]
    ConflictingCoordinates { id: String, line: usize },
    #[error("line {line}: duplicate id {id} (first on line {first_line})")]
    DuplicateId {
        id: String,
        line: usize,
        first_line: usize,
    },
    #[error(
        "line {line}: {reason}; an OpenDroneMap GCP list starts with a line naming the coordinate system (e.g. EPSG:32632)"
    )]
    NotOdmHeader { line: usize, reason: String },
    #[error(
        "line {line}: the coordinate system `{header}` cannot be used: {source} (give WGS84, EPSG:4326, `WGS84 UTM 32N`, a supported EPSG code or a PROJ.4 string)"
    )]
    Crs {
        line: usize,
        header: String,
        source: crate::geo::GeoError,
    },
    #[error("line {line}: cannot reproject ({x}, {y}) into {target}: {source}")]
    Reprojection {
        line: usize,
        x: f64,
        y: f64,
        target: String,
        source: crate::geo::GeoError,
    },
}

/// Refuses a first line that cannot be an ODM CRS header: a GCP row (the header was left out,
/// and the row would be lost) or a tab-separated table header (a TSV points file is not a GCP
/// list).
fn check_odm_header(line: usize, header: &str) -> Result<(), ControlIoError> {
    let tokens: Vec<&str> = header.split_whitespace().collect();
    let numeric = tokens
        .iter()
        .take(5)
        .filter(|t| t.parse::<f64>().is_ok())
        .count();
    if tokens.len() >= 6 && numeric == 5 {
        return Err(ControlIoError::NotOdmHeader {
            line,
            reason: "the first line is a GCP row, not a header".to_owned(),
        });
    }
    if header.trim().contains('\t') {
        return Err(ControlIoError::NotOdmHeader {
            line,
            reason: format!(
                "the first line `{}` is tab-separated, like a table header (for points use a comma-separated id,X,Y,Z,x,y file)",
                header.trim().chars().take(80).collect::<String>()
            ),
        });
    }
    Ok(())
}

/// One row of an ODM GCP list.
#[derive(Debug, Clone, PartialEq)]
pub struct OdmGcpRow {
    /// 1-based line number in the file.
    pub line: usize,
    pub point_in_world: Point3<f64>,
    pub pixel: Point2<f64>,
    pub image: String,
    pub gcp_id: String,
}

/// A parsed ODM `gcp_list.txt`.
#[derive(Debug, Clone, PartialEq)]
pub struct OdmGcpList {
    /// The header line (proj string, `EPSG:…` or `WGS84 UTM 17N`), trimmed.
    pub crs: String,
    /// 1-based line of the header.
    pub crs_line: usize,
    pub rows: Vec<OdmGcpRow>,
}

fn number(token: &str, line: usize, what: &str) -> Result<f64, ControlIoError> {
    let v: f64 = token.parse().map_err(|_| ControlIoError::Parse {
        line,
        message: format!("{what} {token:?} is not a number"),
    })?;
    if v.is_finite() {
        Ok(v)
    } else {
        Err(ControlIoError::Parse {
            line,
            message: format!("{what} {token:?} is not finite"),
        })
    }
}

/// Parses an OpenDroneMap GCP list.
///
/// # Errors
/// [`ControlIoError::Empty`] without a header, `Parse` with the line for a short row or a bad
/// number, `TooManyRows` past [`MAX_ROWS`].
pub fn parse_odm_gcp_list(text: &str) -> Result<OdmGcpList, ControlIoError> {
    let mut lines = text.lines().enumerate().filter(|(_, l)| {
        let t = l.trim();
        !t.is_empty() && !t.starts_with('#')
    });
    let (header_index, header) = lines.next().ok_or(ControlIoError::Empty)?;
    check_odm_header(header_index + 1, header)?;
    let mut rows = Vec::new();
    for (index, raw) in lines {
        let line = index + 1;
        if rows.len() >= MAX_ROWS {
            return Err(ControlIoError::TooManyRows { limit: MAX_ROWS });
        }
        let tokens: Vec<&str> = raw.split_whitespace().collect();
        if tokens.len() < 6 {
            return Err(ControlIoError::Parse {
                line,
                message: format!(
                    "expected `geo_x geo_y geo_z im_x im_y image [name]`, found {} fields",
                    tokens.len()
                ),
            });
        }
        let point_in_world = Point3::new(
            number(tokens[0], line, "geo_x")?,
            number(tokens[1], line, "geo_y")?,
            number(tokens[2], line, "geo_z")?,
        );
        let pixel = Point2::new(
            number(tokens[3], line, "im_x")?,
            number(tokens[4], line, "im_y")?,
        );
        let gcp_id = tokens.get(6).map_or_else(
            || format!("{} {} {}", tokens[0], tokens[1], tokens[2]),
            |s| (*s).to_owned(),
        );
        rows.push(OdmGcpRow {
            line,
            point_in_world,
            pixel,
            image: tokens[5].to_owned(),
            gcp_id,
        });
    }
    Ok(OdmGcpList {
        crs: header.trim().to_owned(),
        crs_line: header_index + 1,
        rows,
    })
}

impl OdmGcpList {
    /// Image names in order of first appearance.
    #[must_use]
    pub fn images(&self) -> Vec<String> {
        let mut out: Vec<String> = Vec::new();
        for r in &self.rows {
            if !out.contains(&r.image) {
                out.push(r.image.clone());
            }
        }
        out
    }

    /// One control point per distinct id, with the given per-axis σ.
    ///
    /// # Errors
    /// `ConflictingCoordinates` when one id appears with different coordinates.
    pub fn control_points(&self, sigma_m: [f64; 3]) -> Result<Vec<ControlPoint>, ControlIoError> {
        let mut out: Vec<ControlPoint> = Vec::new();
        for r in &self.rows {
            match out.iter().find(|c| c.id == r.gcp_id) {
                Some(c) if c.point_in_world != r.point_in_world => {
                    return Err(ControlIoError::ConflictingCoordinates {
                        id: r.gcp_id.clone(),
                        line: r.line,
                    });
                }
                Some(_) => {}
                None => out.push(ControlPoint {
                    id: r.gcp_id.clone(),
                    point_in_world: r.point_in_world,
                    sigma_m,
                }),
            }
        }
        Ok(out)
    }

    /// The observations in one image, each with `sigma_px`.
    #[must_use]
    pub fn observations(&self, image: &str, sigma_px: f64) -> Vec<ImageObservation> {
        self.rows
            .iter()
            .filter(|r| r.image == image)
            .map(|r| ImageObservation {
                point_id: r.gcp_id.clone(),
                pixel: r.pixel,
                sigma_px,
            })
            .collect()
    }
}

/// One row of a points CSV.
#[derive(Debug, Clone, PartialEq)]
pub struct PointRow {
    pub line: usize,
    pub id: String,
    pub point_in_world: Point3<f64>,
    pub pixel: Point2<f64>,
    pub sigma_px: Option<f64>,
}

/// A parsed `id,X,Y,Z,x,y[,sigma_px]` file (one photo).
#[derive(Debug, Clone, PartialEq)]
pub struct PointsCsv {
    pub rows: Vec<PointRow>,
}

/// The data rows of a comma-separated list: blank lines and `#` comments skipped, a first row
/// whose second field is not a number taken as a header; each row `(line number, trimmed
/// fields)` with a field count in `field_counts` and a non-empty first field (the id).
///
/// # Errors
/// `Parse` naming the line for a wrong field count or an empty id; `TooManyRows`.
fn csv_records<'a>(
    text: &'a str,
    field_counts: std::ops::RangeInclusive<usize>,
    format: &str,
) -> Result<Vec<(usize, Vec<&'a str>)>, ControlIoError> {
    let mut records = Vec::new();
    let mut first = true;
    for (index, raw) in text.lines().enumerate() {
        let line = index + 1;
        let t = raw.trim();
        if t.is_empty() || t.starts_with('#') {
            continue;
        }
        let fields: Vec<&str> = t.split(',').map(str::trim).collect();
        let is_first = std::mem::replace(&mut first, false);
        if is_first && fields.get(1).is_some_and(|f| f.parse::<f64>().is_err()) {
            continue; // header
        }
        if records.len() >= MAX_ROWS {
            return Err(ControlIoError::TooManyRows { limit: MAX_ROWS });
        }
        if !field_counts.contains(&fields.len()) {
            return Err(ControlIoError::Parse {
                line,
                message: format!("expected `{format}`, found {} fields", fields.len()),
            });
        }
        if fields[0].is_empty() {
            return Err(ControlIoError::Parse {
                line,
                message: "empty id".to_owned(),
            });
        }
        records.push((line, fields));
    }
    Ok(records)
}

/// Parses `id,X,Y,Z,x,y[,sigma_px]`; a first row whose X is not a number is a header; blank
/// lines and lines starting with `#` are skipped.
///
/// # Errors
/// `Parse` with the line for a wrong field count, a bad number or σ ≤ 0; `DuplicateId` with
/// both lines; `TooManyRows`.
pub fn parse_points_csv(text: &str) -> Result<PointsCsv, ControlIoError> {
    let mut rows: Vec<PointRow> = Vec::new();
    let mut first_line_of = std::collections::HashMap::new();
    for (line, fields) in csv_records(text, 6..=7, "id,X,Y,Z,x,y[,sigma_px]")? {
        if let Some(&first_line) = first_line_of.get(fields[0]) {
            return Err(ControlIoError::DuplicateId {
                id: fields[0].to_owned(),
                line,
                first_line,
            });
        }
        first_line_of.insert(fields[0], line);
        let sigma_px = match fields.get(6) {
            Some(s) if !s.is_empty() => {
                let v = number(s, line, "sigma_px")?;
                if v <= 0.0 {
                    return Err(ControlIoError::Parse {
                        line,
                        message: format!("sigma_px {v} must be positive"),
                    });
                }
                Some(v)
            }
            _ => None,
        };
        rows.push(PointRow {
            line,
            id: fields[0].to_owned(),
            point_in_world: Point3::new(
                number(fields[1], line, "X")?,
                number(fields[2], line, "Y")?,
                number(fields[3], line, "Z")?,
            ),
            pixel: Point2::new(number(fields[4], line, "x")?, number(fields[5], line, "y")?),
            sigma_px,
        });
    }
    Ok(PointsCsv { rows })
}

impl PointsCsv {
    /// Control points (σ = `sigma_m` per axis) and observations (σ from the file or
    /// `default_sigma_px`).
    #[must_use]
    pub fn split(
        &self,
        sigma_m: [f64; 3],
        default_sigma_px: f64,
    ) -> (Vec<ControlPoint>, Vec<ImageObservation>) {
        let control = self
            .rows
            .iter()
            .map(|r| ControlPoint {
                id: r.id.clone(),
                point_in_world: r.point_in_world,
                sigma_m,
            })
            .collect();
        let observations = self
            .rows
            .iter()
            .map(|r| ImageObservation {
                point_id: r.id.clone(),
                pixel: r.pixel,
                sigma_px: r.sigma_px.unwrap_or(default_sigma_px),
            })
            .collect();
        (control, observations)
    }
}

/// Parses a control-point list `id,X,Y,Z[,sigma_m]` (world coordinates only, no pixels, as
/// surveyors deliver them); a first row whose X is not a number is a header; blank lines and
/// lines starting with `#` are skipped. Points without σ get `default_sigma_m` per axis; a
/// σ column applies to all three axes.
///
/// # Errors
/// `Parse` with the line for a wrong field count, a bad number, an empty id or σ < 0;
/// `ConflictingCoordinates` when an id repeats with other coordinates; `TooManyRows`.
pub fn parse_control_points_csv(
    text: &str,
    default_sigma_m: [f64; 3],
) -> Result<Vec<ControlPoint>, ControlIoError> {
    let mut points: Vec<ControlPoint> = Vec::new();
    for (line, fields) in csv_records(text, 4..=5, "id,X,Y,Z[,sigma_m]")? {
        let sigma_m = match fields.get(4) {
            Some(s) if !s.is_empty() => {
                let v = number(s, line, "sigma_m")?;
                if v < 0.0 {
                    return Err(ControlIoError::Parse {
                        line,
                        message: format!("sigma_m {v} must not be negative"),
                    });
                }
                [v; 3]
            }
            _ => default_sigma_m,
        };
        let point_in_world = Point3::new(
            number(fields[1], line, "X")?,
            number(fields[2], line, "Y")?,
            number(fields[3], line, "Z")?,
        );
        if let Some(earlier) = points.iter().find(|p| p.id == fields[0]) {
            if earlier.point_in_world != point_in_world {
                return Err(ControlIoError::ConflictingCoordinates {
                    id: fields[0].to_owned(),
                    line,
                });
            }
            continue;
        }
        points.push(ControlPoint {
            id: fields[0].to_owned(),
            point_in_world,
            sigma_m,
        });
    }
    Ok(points)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn duplicate_id_in_points_csv_names_both_lines() {
        let text = "id,X,Y,Z,x,y\nA,0,0,0,10,10\nB,1,0,0,20,10\nA,0,1,0,10,20\n";
        assert_eq!(
            parse_points_csv(text),
            Err(ControlIoError::DuplicateId {
                id: "A".to_owned(),
                line: 4,
                first_line: 2
            })
        );
    }

    #[test]
    fn odm_list_without_header_is_refused_not_shortened() {
        let text = "100 200 10 1500 900 p1.jpg gcp1\n101 200 10 1600 900 p1.jpg gcp2\n";
        let err = parse_odm_gcp_list(text).unwrap_err();
        assert!(
            matches!(err, ControlIoError::NotOdmHeader { line: 1, .. }),
            "{err}"
        );
    }

    #[test]
    fn tab_separated_table_is_not_an_odm_list() {
        let text = "id\tX\tY\tZ\tx\ty\nA\t0\t0\t0\t10\t10\n";
        let err = parse_odm_gcp_list(text).unwrap_err();
        assert!(
            matches!(err, ControlIoError::NotOdmHeader { line: 1, .. }),
            "{err}"
        );
        assert!(err.to_string().contains("tab-separated"), "{err}");
        // Tabs between the fields of the rows, and a trailing tab after the header (as in
        // ODM's own copr example), stay allowed.
        let odm = "EPSG:32632\t\n100\t200\t10\t1500\t900\tp1.jpg\tgcp1\n";
        assert_eq!(parse_odm_gcp_list(odm).unwrap().rows.len(), 1);
    }

    #[test]
    // Parsed decimal literals must equal the same literals exactly.
    #[allow(clippy::float_cmp)]
    fn control_points_csv_with_header_sigma_and_duplicates() {
        let text = "id,X,Y,Z\n# comment\nA1,1.5,2,3\nB2, 10, 20, 30, 0.05\nA1,1.5,2,3\n\n";
        let pts = parse_control_points_csv(text, [0.01; 3]).expect("valid");
        assert_eq!(pts.len(), 2);
        assert_eq!(pts[0].id, "A1");
        assert_eq!(pts[0].point_in_world, Point3::new(1.5, 2.0, 3.0));
        assert_eq!(pts[0].sigma_m, [0.01; 3]);
        assert_eq!(pts[1].sigma_m, [0.05; 3]);
    }

    #[test]
    fn control_points_csv_errors_name_the_line() {
        let bad_count = parse_control_points_csv("A1,1,2\n", [0.01; 3]);
        assert!(matches!(
            bad_count,
            Err(ControlIoError::Parse { line: 1, .. })
        ));
        let bad_number = parse_control_points_csv("id,X,Y,Z\nA1,1,2,x\n", [0.01; 3]);
        assert!(matches!(
            bad_number,
            Err(ControlIoError::Parse { line: 2, .. })
        ));
        let conflict = parse_control_points_csv("A1,1,2,3\nA1,1,2,4\n", [0.01; 3]);
        assert!(matches!(
            conflict,
            Err(ControlIoError::ConflictingCoordinates { line: 2, .. })
        ));
        let negative = parse_control_points_csv("A1,1,2,3,-1\n", [0.01; 3]);
        assert!(matches!(
            negative,
            Err(ControlIoError::Parse { line: 1, .. })
        ));
    }

    #[test]
    fn odm_list_with_and_without_names() {
        let text = "+proj=utm +zone=11 +datum=WGS84\t\n\
                    235269.88\t3811198.11\t0.0\t3609.37\t2293.79\tIMG_0037.jpg\tgcp02\n\
                    235269.88 3811198.11 0.0 589.5 1026 IMG_0121.jpg gcp02 extra\n\
                    441024.15 4564001.87 345.16 2648 2147 IMG_1356_RGB.jpg \n";
        let list = parse_odm_gcp_list(text).expect("valid");
        assert_eq!(list.crs, "+proj=utm +zone=11 +datum=WGS84");
        assert_eq!(list.rows.len(), 3);
        assert_eq!(list.rows[2].gcp_id, "441024.15 4564001.87 345.16");
        assert_eq!(list.rows[1].line, 3);
        assert_eq!(
            list.images(),
            ["IMG_0037.jpg", "IMG_0121.jpg", "IMG_1356_RGB.jpg"]
        );
        let control = list.control_points([0.02; 3]).expect("consistent");
        assert_eq!(control.len(), 2);
        assert_eq!(
            list.observations("IMG_0121.jpg", 1.0)[0].pixel,
            Point2::new(589.5, 1026.0)
        );
    }

    #[test]
    fn odm_errors_name_the_line() {
        assert_eq!(parse_odm_gcp_list("\n\n"), Err(ControlIoError::Empty));
        let e = parse_odm_gcp_list("EPSG:32611\n1 2 3 4 5 a.jpg\n1 2 x 4 5 b.jpg\n").unwrap_err();
        assert!(matches!(e, ControlIoError::Parse { line: 3, .. }), "{e}");
        let e = parse_odm_gcp_list("EPSG:32611\n1 2 3 4 5\n").unwrap_err();
        assert!(matches!(e, ControlIoError::Parse { line: 2, .. }), "{e}");
        let e = parse_odm_gcp_list("EPSG:32611\n1 2 NaN 4 5 a.jpg\n").unwrap_err();
        assert!(matches!(e, ControlIoError::Parse { line: 2, .. }), "{e}");
        let list = parse_odm_gcp_list("EPSG:32611\n1 2 3 4 5 a.jpg g\n1 2 4 4 5 b.jpg g\n")
            .expect("parses");
        assert_eq!(
            list.control_points([0.0; 3]),
            Err(ControlIoError::ConflictingCoordinates {
                id: "g".to_owned(),
                line: 3
            })
        );
    }

    #[test]
    fn points_csv_with_header_and_optional_sigma() {
        let text = "id,X,Y,Z,x,y,sigma_px\n# comment\nA,1,2,3,10.5,20,0.3\n\nB, 4,5,6, 11,21\n";
        let csv = parse_points_csv(text).expect("valid");
        assert_eq!(csv.rows.len(), 2);
        assert_eq!(csv.rows[1].line, 5);
        assert_eq!(csv.rows[0].sigma_px, Some(0.3));
        let (control, obs) = csv.split([0.0; 3], 1.0);
        assert_eq!(control[1].point_in_world, Point3::new(4.0, 5.0, 6.0));
        assert!((obs[1].sigma_px - 1.0).abs() < f64::EPSILON);
        let no_header = parse_points_csv("A,1,2,3,10,20\n").expect("valid");
        assert_eq!(no_header.rows.len(), 1);
    }

    #[test]
    fn points_csv_errors_name_the_line() {
        let e = parse_points_csv("A,1,2,3,10,20\nB,1,2\n").unwrap_err();
        assert!(matches!(e, ControlIoError::Parse { line: 2, .. }), "{e}");
        let e = parse_points_csv("A,1,2,3,10,20,-1\n").unwrap_err();
        assert!(matches!(e, ControlIoError::Parse { line: 1, .. }), "{e}");
        let e = parse_points_csv("id,X,Y,Z,x,y\nA,1,2,3,10,zz\n").unwrap_err();
        assert!(matches!(e, ControlIoError::Parse { line: 2, .. }), "{e}");
    }
}
