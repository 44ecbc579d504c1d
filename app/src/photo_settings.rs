//! The camera settings of a photo (a window opened from the photo strip): its interior
//! orientation as the site file stores it (`[photos.interior]`: focal length in pixels, principal
//! point — the image centre or given —, Brown–Conrady k1, k2, k3, p1, p2; see
//! `photomontage::camera` for the pixel convention) and which of them the solve may estimate
//! (`[photos.self_calibration]`). Every change is a command through the one command path:
//! the interior with [`Command::SetOrientation`] (the exterior kept), the flags with
//! [`Command::SetSelfCalibration`]; a drag of one value is one undo step.
//!
//! A photo without an interior (the solve then starts from EXIF) gets one with "Enter by hand",
//! started at the image diagonal (the library's `site::new::FALLBACK_FOCAL_PER_DIAGONAL`).
//!
//! # Known limitations
//! Editing the interior does not clear the photo's solved exterior; press Solve again. The
//! image size is not editable (it is read from the file).

use eframe::egui;
use photomontage::site::{Interior, Photo, SelfCalibrationFlags};

use crate::commands::Command;
use crate::panel::{Action, Panel, PanelContext};
use crate::widgets::name_widget;

/// Which photo's camera settings are shown.
#[derive(Debug, Default)]
pub struct PhotoSettings {
    /// The photo whose window is open.
    pub photo: Option<String>,
    /// That photo's decoded size, set by the studio each frame (`None` until it is decoded).
    pub size_px: Option<[u32; 2]>,
}

fn drag(
    ui: &mut egui::Ui,
    label: &str,
    name: &str,
    value: &mut f64,
    speed: f64,
    decimals: usize,
) -> bool {
    ui.label(label);
    let r = ui.add(
        egui::DragValue::new(value)
            .speed(speed)
            .max_decimals(decimals),
    );
    name_widget(ui, &r, name);
    r.changed() && value.is_finite()
}

/// Draws the settings of `photo`; edits come back as commands. `size_px`: the decoded image
/// size, when known (used when the interior states none).
fn settings_ui(
    ui: &mut egui::Ui,
    photo: &Photo,
    size_px: Option<[u32; 2]>,
    commands: &mut Vec<(Command, Option<String>)>,
) {
    let id = &photo.id;
    let size = photo
        .interior
        .as_ref()
        .and_then(|i| i.image_size_px)
        .or(size_px);
    match &photo.interior {
        None => {
            ui.label("No interior orientation: the solve starts from the EXIF focal length.");
            if let Some([w, h]) = size
                && ui.button("Enter by hand").clicked()
            {
                let diagonal = f64::from(w).hypot(f64::from(h));
                let interior = Interior {
                    focal_px: photomontage::site::new::FALLBACK_FOCAL_PER_DIAGONAL * diagonal,
                    principal_point_px: None,
                    distortion: photomontage::camera::BrownConrady::default(),
                    image_size_px: Some([w, h]),
                };
                commands.push((
                    Command::SetOrientation {
                        photo: id.clone(),
                        interior: Some(interior),
                        exterior: photo.exterior.clone(),
                    },
                    None,
                ));
            }
        }
        Some(interior) => {
            let mut i = interior.clone();
            // Drags of one value merge into one undo step; the centre toggle is a step of its own.
            let mut changed = false;
            let mut toggled = false;
            if let Some([w, h]) = size {
                ui.label(format!("image {w} × {h} px"));
            }
            egui::Grid::new(("interior", id)).show(ui, |ui| {
                let mut f = i.focal_px;
                if drag(ui, "focal length px", "focal px", &mut f, 0.5, 3) && f > 0.0 {
                    i.focal_px = f;
                    changed = true;
                }
                ui.end_row();
                let mut centred = i.principal_point_px.is_none();
                ui.label("principal point");
                let r = ui.checkbox(&mut centred, "image centre");
                name_widget(ui, &r, "principal point at centre");
                if r.changed() {
                    i.principal_point_px = if centred {
                        None
                    } else {
                        let [w, h] = size.unwrap_or([0, 0]);
                        Some([f64::from(w) / 2.0, f64::from(h) / 2.0])
                    };
                    toggled = true;
                }
                ui.end_row();
                if let Some(pp) = i.principal_point_px.as_mut() {
                    changed |= drag(
                        ui,
                        "principal x px",
                        "principal point x",
                        &mut pp[0],
                        0.1,
                        3,
                    );
                    ui.end_row();
                    changed |= drag(
                        ui,
                        "principal y px",
                        "principal point y",
                        &mut pp[1],
                        0.1,
                        3,
                    );
                    ui.end_row();
                }
                let d = &mut i.distortion;
                for (name, v) in [
                    ("k1", &mut d.k1),
                    ("k2", &mut d.k2),
                    ("k3", &mut d.k3),
                    ("p1", &mut d.p1),
                    ("p2", &mut d.p2),
                ] {
                    changed |= drag(ui, name, &format!("distortion {name}"), v, 1e-4, 8);
                    ui.end_row();
                }
            });
            if changed || toggled {
                commands.push((
                    Command::SetOrientation {
                        photo: id.clone(),
                        interior: Some(i),
                        exterior: photo.exterior.clone(),
                    },
                    (!toggled).then(|| format!("interior {id}")),
                ));
            }
        }
    }
    ui.separator();
    ui.label("The solve may estimate:");
    let mut flags: SelfCalibrationFlags = photo.self_calibration;
    let mut changed = false;
    ui.horizontal(|ui| {
        for (label, v) in [
            ("focal length", &mut flags.focal),
            ("principal point", &mut flags.principal_point),
            ("k1", &mut flags.k1),
            ("k2", &mut flags.k2),
        ] {
            let r = ui.checkbox(v, label);
            name_widget(ui, &r, &format!("estimate {label}"));
            changed |= r.changed();
        }
    });
    if changed {
        commands.push((
            Command::SetSelfCalibration {
                photo: id.clone(),
                flags,
            },
            None,
        ));
    }
}

impl crate::Studio {
    /// Opens the camera settings window of photo `id`.
    pub fn open_photo_settings(&mut self, id: &str) {
        self.photo_settings.photo = Some(id.to_owned());
    }
}

impl Panel for PhotoSettings {
    /// Shows the window of [`PhotoSettings::photo`] (when set) over `ui`'s context; its edits
    /// come back as [`Action::Edit`]s.
    fn ui(&mut self, ui: &mut egui::Ui, ctx: &PanelContext<'_>) -> Vec<Action> {
        let Some(id) = self.photo.clone() else {
            return Vec::new();
        };
        let Some(photo) = ctx
            .doc
            .and_then(|d| d.site.photos.iter().find(|p| p.id == id))
        else {
            self.photo = None;
            return Vec::new();
        };
        let mut open = true;
        let mut close = false;
        let mut commands = Vec::new();
        egui::Window::new(format!("Camera of {id}"))
            .id(egui::Id::unique("photo settings"))
            .open(&mut open)
            .collapsible(false)
            // Right of the photo strip, below the toolbar (Undo stays reachable).
            .default_pos(egui::pos2(170.0, 60.0))
            .show(ui.ctx(), |ui| {
                settings_ui(ui, photo, self.size_px, &mut commands);
                ui.separator();
                let r = ui.button("Close");
                name_widget(ui, &r, "Close camera settings");
                close = r.clicked();
            });
        if !open || close {
            self.photo = None;
        }
        commands
            .into_iter()
            .map(|(command, merge_key)| Action::Edit {
                command: Box::new(command),
                merge_key,
            })
            .collect()
    }
}
