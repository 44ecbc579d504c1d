//! The control-point table (egui_extras `TableBuilder`): id, world X/Y/Z editable, σ, enabled,
//! and the point's observation in the current photo (position, on/off, delete); plus importing
//! control points from a CSV (`id,X,Y,Z[,σ]`, or `id,X,Y,Z,x,y[,σ_px]` with observations in the
//! current photo) or an OpenDroneMap `gcp_list.txt` (observations matched to photos by file
//! name; a list in another CRS, WGS 84 included, is reprojected into the site's `location.crs`;
//! a WGS 84 list imported into a site without `[location]` goes to its centroid's UTM zone and
//! fills `[location]` from the control points, in the same undoable batch).
//! The table only emits [`Command`]s; `crate::Studio` applies them.
//!
//! File formats: `photomontage::photogrammetry::control_io` (ODM's documented GCP format).
//!
//! # Known limitations
//! Files are chosen by typing a path (no native file dialog yet). ODM rows name images by file
//! name only, so two photos with the same file name in different folders are ambiguous (the
//! first is used).

use eframe::egui;
use egui_extras::{Column, TableBuilder};
use photomontage::geo::{ProjectedCrs, SourceCrs};
use photomontage::photogrammetry::control_io::{
    ControlIoError, parse_control_points_csv, parse_odm_gcp_list, parse_points_csv,
};
use photomontage::site::control_location::location_from_points;
use photomontage::site::{ControlPoint, Observation, Site};
use std::path::Path;

use crate::commands::Command;
use crate::panel::{Action, Panel, PanelContext};
use crate::widgets::name_widget;

/// σ given to imported control points that carry none (1 cm per axis, the site default).
pub const DEFAULT_SIGMA_M: [f64; 3] = [0.01; 3];
/// σ given to imported observations that carry none (the site file's default).
pub const DEFAULT_SIGMA_PX: f64 = 0.5;

/// What can go wrong importing.
#[derive(Debug, thiserror::Error)]
pub enum ImportError {
    #[error("cannot read {path}: {source}")]
    Read {
        path: String,
        source: std::io::Error,
    },
    #[error("{path}: {source}")]
    Parse {
        path: String,
        source: ControlIoError,
    },
    #[error("{path}: observations need a photo; select one first")]
    NoPhoto { path: String },
    #[error("the site's location.crs `{name}` cannot be used to reproject {path}: {source}")]
    SiteCrs {
        path: String,
        name: String,
        source: photomontage::geo::GeoError,
    },
    #[error(
        "{path}: the control points are geographic (`{header}`); set the site's location.crs (e.g. EPSG:32633) so they can be reprojected"
    )]
    NoSiteCrs { path: String, header: String },
    #[error("{path}: cannot place the site by its control points: {source}")]
    Location {
        path: String,
        source: photomontage::site::control_location::ControlLocationError,
    },
}

/// Control points (and observations) of a file, as one undoable batch.
///
/// # Errors
/// [`ImportError`] naming the file and line.
pub fn import_file(
    site: &Site,
    path: &Path,
    current_photo: Option<&str>,
) -> Result<Command, ImportError> {
    let shown = path.display().to_string();
    let text = std::fs::read_to_string(path).map_err(|source| ImportError::Read {
        path: shown.clone(),
        source,
    })?;
    let parse_err = |source| ImportError::Parse {
        path: shown.clone(),
        source,
    };
    let is_gcp_list = path
        .extension()
        .and_then(|e| e.to_str())
        .is_some_and(|e| e.eq_ignore_ascii_case("txt"));
    let control;
    let mut observations = Vec::new();
    let mut location = None;
    if is_gcp_list {
        let mut list = parse_odm_gcp_list(&text).map_err(parse_err)?;
        // Control in any CRS: into the site's CRS when it names one.
        match site.location.as_ref().and_then(|l| l.crs.as_deref()) {
            Some(name) => {
                let target =
                    ProjectedCrs::from_name(name).map_err(|source| ImportError::SiteCrs {
                        path: shown.clone(),
                        name: name.to_owned(),
                        source,
                    })?;
                list = list.reprojected(Some(&target)).map_err(parse_err)?.0;
            }
            // A site without a location: a geographic list goes to its centroid's UTM zone
            // and the site's [location] is filled from the control points.
            None if site.location.is_none()
                && SourceCrs::from_header(&list.crs).is_ok_and(|c| c.is_geographic()) =>
            {
                let (utm, target) = list.reprojected(None).map_err(parse_err)?;
                list = utm;
                let points: Vec<[f64; 3]> = list
                    .rows
                    .iter()
                    .map(|r| r.point_in_world.coords.into())
                    .collect();
                location = Some(
                    location_from_points(&points, &target, &target.site_name()).map_err(
                        |source| ImportError::Location {
                            path: shown.clone(),
                            source,
                        },
                    )?,
                );
            }
            None if SourceCrs::from_header(&list.crs).is_ok_and(|c| c.is_geographic()) => {
                return Err(ImportError::NoSiteCrs {
                    path: shown.clone(),
                    header: list.crs.clone(),
                });
            }
            None => {}
        }
        control = list.control_points(DEFAULT_SIGMA_M).map_err(parse_err)?;
        for image in list.images() {
            let photo = site.photos.iter().find(|p| {
                Path::new(&p.file)
                    .file_name()
                    .is_some_and(|n| n.to_string_lossy() == image)
            });
            if let Some(photo) = photo {
                for o in list.observations(&image, DEFAULT_SIGMA_PX) {
                    observations.push((photo.id.clone(), o));
                }
            }
        }
    } else {
        match parse_control_points_csv(&text, DEFAULT_SIGMA_M) {
            Ok(c) => control = c,
            Err(first_error) => {
                // Six or seven columns: control points with their pixels in the current photo.
                let csv = parse_points_csv(&text).map_err(|_| parse_err(first_error))?;
                let photo = current_photo.ok_or_else(|| ImportError::NoPhoto {
                    path: shown.clone(),
                })?;
                let (c, obs) = csv.split(DEFAULT_SIGMA_M, DEFAULT_SIGMA_PX);
                control = c;
                observations = obs.into_iter().map(|o| (photo.to_owned(), o)).collect();
            }
        }
    }
    let mut batch: Vec<Command> = control
        .into_iter()
        .map(|c| {
            let existing = site.control_points.iter().find(|e| e.id == c.id);
            Command::PutControlPoint {
                point: ControlPoint {
                    id: c.id,
                    xyz: c.point_in_world.coords.into(),
                    sigma_m: c.sigma_m,
                    crs: existing.and_then(|e| e.crs.clone()),
                    enabled: existing.is_none_or(|e| e.enabled),
                },
                at: None,
            }
        })
        .collect();
    batch.extend(
        observations
            .into_iter()
            .map(|(photo, o)| Command::PutObservation {
                observation: Observation {
                    photo,
                    point: o.point_id,
                    x_px: o.pixel.x,
                    y_px: o.pixel.y,
                    sigma_px: o.sigma_px,
                    enabled: true,
                },
                at: None,
            }),
    );
    if let Some(location) = location {
        batch.push(Command::SetLocation(Some(location)));
    }
    Ok(Command::Batch(batch))
}

/// The table. `selected` is the selected point id (highlighted); a click on a point's id sets
/// `chosen` (even when it is already selected: choosing arms it again for placing); edits come back
/// as commands.
pub fn table_ui(
    ui: &mut egui::Ui,
    site: &Site,
    current_photo: Option<&str>,
    selected: Option<&str>,
    chosen: &mut Option<String>,
    commands: &mut Vec<(Command, Option<String>)>,
) {
    let observation_of = |id: &str| {
        current_photo.and_then(|p| {
            site.observations
                .iter()
                .find(|o| o.photo == p && o.point == id)
        })
    };
    TableBuilder::new(ui)
        .id_salt("control points")
        .striped(true)
        .column(Column::auto().at_least(46.0))
        .columns(Column::auto().at_least(96.0), 3)
        .column(Column::auto().at_least(44.0))
        .column(Column::auto().at_least(28.0))
        .column(Column::remainder().at_least(150.0))
        .max_scroll_height(f32::INFINITY)
        .header(20.0, |mut h| {
            for t in ["id", "X m", "Y m", "Z m", "σ m", "on", "in this photo"] {
                h.col(|ui| {
                    ui.strong(t);
                });
            }
        })
        .body(|mut body| {
            for cp in &site.control_points {
                body.row(22.0, |mut row| {
                    row.col(|ui| {
                        let is_sel = selected == Some(cp.id.as_str());
                        let r = ui.selectable_label(is_sel, &cp.id);
                        if r.clicked() {
                            *chosen = Some(cp.id.clone());
                        }
                    });
                    for axis in 0..3 {
                        row.col(|ui| {
                            let mut v = cp.xyz[axis];
                            let r =
                                ui.add(egui::DragValue::new(&mut v).speed(0.001).fixed_decimals(3));
                            name_widget(ui, &r, &format!("{} {}", ["X", "Y", "Z"][axis], cp.id));
                            if r.changed() && v.is_finite() {
                                let mut p = cp.clone();
                                p.xyz[axis] = v;
                                commands.push((
                                    Command::PutControlPoint { point: p, at: None },
                                    Some(format!("xyz {}", cp.id)),
                                ));
                            }
                        });
                    }
                    row.col(|ui| {
                        ui.label(format!("{:.3}", cp.sigma_m[0]));
                    });
                    row.col(|ui| {
                        let mut on = cp.enabled;
                        let r = ui.checkbox(&mut on, "");
                        name_widget(ui, &r, &format!("use {}", cp.id));
                        if r.changed() {
                            let mut p = cp.clone();
                            p.enabled = on;
                            commands.push((Command::PutControlPoint { point: p, at: None }, None));
                        }
                    });
                    row.col(|ui| {
                        if let Some(o) = observation_of(&cp.id) {
                            let mut on = o.enabled;
                            let r = ui.checkbox(&mut on, format!("{:.2}, {:.2}", o.x_px, o.y_px));
                            name_widget(ui, &r, &format!("observation {}", cp.id));
                            if r.changed() {
                                let mut changed = o.clone();
                                changed.enabled = on;
                                commands.push((
                                    Command::PutObservation {
                                        observation: changed,
                                        at: None,
                                    },
                                    None,
                                ));
                            }
                            if ui
                                .small_button("del")
                                .on_hover_text("remove this observation")
                                .clicked()
                            {
                                commands.push((
                                    Command::RemoveObservation {
                                        photo: o.photo.clone(),
                                        point: o.point.clone(),
                                    },
                                    None,
                                ));
                            }
                        }
                    });
                });
            }
        });
}

/// A hint for the status line naming the import formats.
pub const IMPORT_HINT: &str =
    "CSV id,X,Y,Z[,σ] or id,X,Y,Z,x,y[,σpx] (current photo), or ODM gcp_list.txt";

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn csv_with_pixels_goes_to_the_current_photo_and_gcp_list_by_file_name() {
        let dir = tempfile::tempdir().expect("tempdir");
        let mut site = Site::default();
        site.photos.push(photomontage::site::Photo {
            id: "P1".into(),
            file: "photos/IMG_1.jpg".into(),
            taken_at: None,
            profile: None,
            interior: None,
            self_calibration: Default::default(),
            exterior: None,
        });
        let csv = dir.path().join("pts.csv");
        std::fs::write(&csv, "id,X,Y,Z,x,y\nA,1,2,3,10.5,20.5\n").expect("write");
        assert!(matches!(
            import_file(&site, &csv, None),
            Err(ImportError::NoPhoto { .. })
        ));
        let Command::Batch(b) = import_file(&site, &csv, Some("P1")).expect("import") else {
            panic!("a batch");
        };
        assert_eq!(b.len(), 2);
        assert!(matches!(&b[1], Command::PutObservation { observation, .. }
            if observation.photo == "P1" && (observation.x_px - 10.5).abs() < 1e-12));
        let gcp = dir.path().join("gcp_list.txt");
        std::fs::write(
            &gcp,
            "EPSG:2056\n1 2 3 40 50 IMG_1.jpg g1\n1 2 3 4 5 other.jpg g1\n",
        )
        .expect("write");
        let Command::Batch(b) = import_file(&site, &gcp, None).expect("import") else {
            panic!("a batch");
        };
        assert_eq!(
            b.len(),
            2,
            "one point, one observation (other.jpg is not in the site)"
        );
        let bad = dir.path().join("bad.csv");
        std::fs::write(&bad, "A,1,2\n").expect("write");
        let e = import_file(&site, &bad, Some("P1")).expect_err("bad");
        assert!(e.to_string().contains("line 1"), "{e}");
    }

    #[test]
    fn wgs84_gcp_list_is_reprojected_into_the_site_crs() {
        let dir = tempfile::tempdir().expect("tempdir");
        let mut site = Site::default();
        site.photos.push(photomontage::site::Photo {
            id: "P1".into(),
            file: "photos/01.jpg".into(),
            taken_at: None,
            profile: None,
            interior: None,
            self_calibration: Default::default(),
            exterior: None,
        });
        let gcp = dir.path().join("gcp_list.txt");
        std::fs::write(&gcp, "WGS84\n13.4 52.52 12.5 40 50 01.jpg g1\n").expect("write");
        // A site without [location]: the list goes to its centroid's UTM zone (33N) and the
        // location is filled from the control points, undoably in the same batch.
        let Command::Batch(b) = import_file(&site, &gcp, None).expect("import") else {
            panic!("a batch");
        };
        let Some(Command::SetLocation(Some(loc))) = b.last() else {
            panic!("the batch sets the location: {b:?}");
        };
        assert_eq!(loc.crs.as_deref(), Some("EPSG:32633"));
        assert!((loc.latitude_deg - 52.52).abs() < 1e-9 && (loc.longitude_deg - 13.4).abs() < 1e-9);
        let mut applied = site.clone();
        let undo = crate::commands::apply(&mut applied, Command::Batch(b)).expect("applies");
        assert!(applied.location.is_some() && applied.control_points.len() == 1);
        crate::commands::apply(&mut applied, undo).expect("undoes");
        assert_eq!(applied, site);
        // A location without a CRS: the geographic list is refused, naming what to set.
        site.location = Some(photomontage::site::Location {
            latitude_deg: 52.52,
            longitude_deg: 13.4,
            elevation_m: 0.0,
            crs: None,
            grid_convergence_deg: 0.0,
            time_zone: None,
        });
        let e = import_file(&site, &gcp, None).expect_err("no crs");
        assert!(e.to_string().contains("location.crs"), "{e}");
        site.location = Some(photomontage::site::Location {
            latitude_deg: 52.52,
            longitude_deg: 13.4,
            elevation_m: 0.0,
            crs: Some("EPSG:32633".into()),
            grid_convergence_deg: 0.0,
            time_zone: None,
        });
        let Command::Batch(b) = import_file(&site, &gcp, None).expect("import") else {
            panic!("a batch");
        };
        let zone33 = ProjectedCrs::from_name("EPSG:32633").expect("valid");
        let (e, n) = zone33.from_lat_lon_deg(52.52, 13.4).expect("converts");
        assert!(matches!(&b[0], Command::PutControlPoint { point, .. }
            if (point.xyz[0] - e).abs() < 1e-6 && (point.xyz[1] - n).abs() < 1e-6
                && (point.xyz[2] - 12.5).abs() < 1e-12));
        // A site CRS the library cannot use is named.
        site.location.as_mut().expect("set").crs = Some("EPSG:9999".into());
        let e = import_file(&site, &gcp, None).expect_err("bad crs");
        assert!(e.to_string().contains("EPSG:9999"), "{e}");
    }
}

/// The Points tab: import of control points, picking a point to place, the control-point table.
#[derive(Debug, Default)]
pub struct PointsPanel {
    /// Control-point file typed by the user (CSV or OpenDroneMap `gcp_list.txt`).
    pub import_path: String,
    /// A tie point id typed by the user (a point without survey).
    pub new_point_id: String,
}

impl Panel for PointsPanel {
    fn ui(&mut self, ui: &mut egui::Ui, ctx: &PanelContext<'_>) -> Vec<Action> {
        let mut actions = Vec::new();
        ui.horizontal(|ui| {
            let r = ui.add(
                egui::TextEdit::singleline(&mut self.import_path)
                    .hint_text(IMPORT_HINT)
                    .desired_width(330.0),
            );
            name_widget(ui, &r, "import path");
            if ui.button("Import").clicked() {
                actions.push(Action::ImportPoints);
            }
        });
        ui.horizontal(|ui| {
            let r = ui.add(
                egui::TextEdit::singleline(&mut self.new_point_id)
                    .hint_text("tie point id (no survey)")
                    .desired_width(160.0),
            );
            name_widget(ui, &r, "point id");
            let id = self.new_point_id.trim();
            if ui.button("Pick id").clicked() && !id.is_empty() {
                actions.push(Action::SelectPoint(id.to_owned()));
            }
            // Points observed but not surveyed (tie points) are listed for picking too.
            if let Some(doc) = ctx.doc {
                let mut ties: Vec<&str> = doc
                    .site
                    .observations
                    .iter()
                    .map(|o| o.point.as_str())
                    .filter(|p| !doc.site.control_points.iter().any(|c| c.id == *p))
                    .collect();
                ties.sort_unstable();
                ties.dedup();
                for t in ties {
                    let sel = ctx.selected_point == Some(t);
                    let r = ui.selectable_label(sel, t);
                    name_widget(ui, &r, &format!("tie {t}"));
                    if r.clicked() {
                        actions.push(Action::SelectPoint(t.to_owned()));
                    }
                }
            }
        });
        match (ctx.armed_point, ctx.selected_point) {
            (Some(armed), _) => {
                ui.colored_label(
                    crate::widgets::WARNING,
                    format!("placing {armed}: click the photo to put it there (Esc cancels)"),
                );
            }
            (None, Some(sel)) => {
                ui.horizontal(|ui| {
                    ui.label(format!(
                        "selected: {sel} — drag its mark to move it, Delete removes it"
                    ));
                    let r = ui.button("Place again");
                    name_widget(ui, &r, "place selected point");
                    if r.clicked() {
                        actions.push(Action::SelectPoint(sel.to_owned()));
                    }
                });
            }
            (None, None) => {
                ui.label("choose a point in the table to place it on the photo");
            }
        }
        let Some(doc) = ctx.doc else {
            return actions;
        };
        let mut commands = Vec::new();
        let mut chosen = None;
        egui::ScrollArea::horizontal().show(ui, |ui| {
            table_ui(
                ui,
                &doc.site,
                ctx.current_photo,
                ctx.selected_point,
                &mut chosen,
                &mut commands,
            );
        });
        if let Some(id) = chosen {
            actions.push(Action::SelectPoint(id));
        }
        actions.extend(
            commands
                .into_iter()
                .map(|(command, merge_key)| Action::Edit {
                    command: Box::new(command),
                    merge_key,
                }),
        );
        actions
    }
}
