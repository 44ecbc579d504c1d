//! Luminaires in the Site & light tab (issue 17 item 1): add an IES LM-63 or EULUMDAT file
//! (read and checked by `photomontage::luminaire::PhotometricFile` before anything is written),
//! place it by clicking the photo (the ray through the clicked pixel of the photo's solved
//! camera hits the site's natural polygons, `photomontage::fit::pick::PolygonPicker`, the
//! picker of the Fit tab; the luminaire goes the typed mounting height above that point), aim
//! it (rotation about Z, tilt), dim it (scale), enable or remove it. The selected luminaire's
//! polar intensity diagram (C0–C180 red, C90–C270 blue) is
//! `photomontage::luminaire::polar_plot::polar_plot` of its photometric web.
//!
//! Each addition, move or change is one undoable `Command::Light`; drags of one value are one
//! undo step.
//!
//! # Known limitations
//! Files are typed paths (relative to the site file, or absolute); there is no file dialog.
//! Placing needs a solved photo and a scene polygon under the click.

use eframe::egui;
use photomontage::fit::pick::PolygonPicker;
use photomontage::luminaire::PhotometricFile;
use photomontage::luminaire::polar_plot::{PolarPlotOptions, nice_scale, polar_plot};
use photomontage::site::{SiteDocument, SiteLuminaire, stored_camera};
use std::collections::HashMap;

use crate::commands::Command;
use crate::fit_commands::next_id;
use crate::light_commands::LightCommand;
use crate::light_panel::{LightPanel, edit};
use crate::panel::Action;
use crate::viewport::ViewTransform;
use crate::widgets::name_widget;

/// Default dimming of a new luminaire (photo linear units × m² per candela).
pub const DEFAULT_SCALE: f64 = 1e-3;
/// Side of the polar diagram, pixels.
const PLOT_SIZE_PX: u32 = 256;

/// What the next click on the photo does.
#[derive(Debug, Clone, PartialEq)]
pub enum Placing {
    /// Adds a new luminaire of this file.
    New { file: String },
    /// Moves the luminaire with this id.
    Move { id: String },
}

/// A polar diagram ready to show, or why not.
type Plot = Result<(egui::TextureHandle, f64), String>;

/// The luminaire part of the tab.
pub struct LuminairesState {
    /// Photometric file to add (typed).
    pub file: String,
    /// Height of a placed luminaire above the clicked surface, metres.
    pub mount_height_m: f64,
    /// What the next click on the photo does, if anything.
    pub placing: Option<Placing>,
    /// The luminaire whose polar diagram is shown.
    pub selected: Option<String>,
    plots: HashMap<std::path::PathBuf, Plot>,
}

impl Default for LuminairesState {
    fn default() -> Self {
        Self {
            file: String::new(),
            mount_height_m: 4.0,
            placing: None,
            selected: None,
            plots: HashMap::new(),
        }
    }
}

/// Reads and checks a photometric file as the renderer will.
///
/// # Errors
/// A sentence naming the file and what is wrong with it.
pub fn check_photometric_file(doc: &SiteDocument, file: &str) -> Result<PhotometricFile, String> {
    let file = file.trim();
    if file.is_empty() {
        return Err("luminaire file: type the path of an IES or LDT file".into());
    }
    let path = doc.resolve(file);
    let data = PhotometricFile::read(&path)
        .map_err(|e| format!("luminaire file {}: {e}", path.display()))?;
    data.distribution()
        .map_err(|e| format!("luminaire file {}: {e}", path.display()))?;
    Ok(data)
}

fn plot_of(ctx: &egui::Context, doc: &SiteDocument, file: &str) -> Plot {
    let data = check_photometric_file(doc, file)?;
    let web = data.distribution().map_err(|e| e.to_string())?;
    let img = polar_plot(
        &web,
        &PolarPlotOptions {
            size_px: PLOT_SIZE_PX,
            scale_cd: None,
        },
    )
    .map_err(|e| e.to_string())?;
    let size = [img.width() as usize, img.height() as usize];
    let image = egui::ColorImage::from_rgb(size, img.as_raw());
    let texture = ctx.load_texture(
        format!("polar plot {file}"),
        image,
        egui::TextureOptions::LINEAR,
    );
    Ok((texture, nice_scale(web.max_intensity_cd())))
}

/// Draws the luminaire list, the add row and the selected luminaire's polar diagram.
pub fn luminaires_ui(
    panel: &mut LightPanel,
    ui: &mut egui::Ui,
    doc: &SiteDocument,
    out: &mut Vec<Action>,
) {
    ui.strong("Luminaires");
    ui.horizontal(|ui| {
        let r = ui.add(
            egui::TextEdit::singleline(&mut panel.luminaires.file)
                .hint_text("IES or LDT file")
                .desired_width(200.0),
        );
        name_widget(ui, &r, "luminaire file");
        ui.label("height above surface");
        let r = ui.add(
            egui::DragValue::new(&mut panel.luminaires.mount_height_m)
                .range(0.0..=100.0)
                .speed(0.05)
                .suffix(" m"),
        );
        name_widget(ui, &r, "mount height");
        if ui.button("Add luminaire").clicked() {
            match check_photometric_file(doc, &panel.luminaires.file) {
                Ok(_) => {
                    panel.error = None;
                    panel.luminaires.placing = Some(Placing::New {
                        file: panel.luminaires.file.trim().to_owned(),
                    });
                }
                Err(e) => panel.error = Some(e),
            }
        }
    });
    if let Some(p) = &panel.luminaires.placing {
        let text = match p {
            Placing::New { file } => format!("click the photo to place {file}"),
            Placing::Move { id } => format!("click the photo to move {id}"),
        };
        ui.horizontal(|ui| {
            ui.label(text);
            if ui.button("Cancel placing").clicked() {
                panel.luminaires.placing = None;
            }
        });
    }
    let mut changes = Vec::new();
    egui::Grid::new("luminaires").striped(true).show(ui, |ui| {
        if !doc.site.luminaires.is_empty() {
            for h in ["id", "on", "rotation", "tilt", "scale (dim)", ""] {
                ui.label(h);
            }
            ui.end_row();
        }
        for l in &doc.site.luminaires {
            let mut new = l.clone();
            let selected = panel.luminaires.selected.as_deref() == Some(l.id.as_str());
            if ui.selectable_label(selected, &l.id).clicked() {
                panel.luminaires.selected = Some(l.id.clone());
            }
            let r = ui.checkbox(&mut new.enabled, "");
            name_widget(ui, &r, &format!("enable {}", l.id));
            let mut key = None;
            for (name, value, range, speed, suffix) in [
                (
                    "rotation",
                    &mut new.rotation_z_deg,
                    -360.0..=360.0,
                    0.5,
                    "°",
                ),
                ("tilt", &mut new.tilt_deg, 0.0..=180.0, 0.5, "°"),
                ("scale", &mut new.scale, 0.0..=1e6, 1e-5, ""),
            ] {
                let r = ui.add(
                    egui::DragValue::new(value)
                        .range(range)
                        .speed(speed)
                        .max_decimals(6)
                        .suffix(suffix),
                );
                let label = format!("{name} {}", l.id);
                name_widget(ui, &r, &label);
                if r.changed() {
                    key = Some(panel.gesture_key(&label, &r));
                }
            }
            ui.horizontal(|ui| {
                if ui.button(format!("Place {}", l.id)).clicked() {
                    panel.luminaires.placing = Some(Placing::Move { id: l.id.clone() });
                }
                if ui.button(format!("Remove {}", l.id)).clicked() {
                    changes.push((LightCommand::RemoveLuminaire { id: l.id.clone() }, None));
                }
            });
            ui.end_row();
            if new != *l {
                changes.push((
                    LightCommand::PutLuminaire {
                        luminaire: Box::new(new),
                        at: None,
                    },
                    key,
                ));
            }
        }
    });
    for (c, key) in changes {
        out.push(edit(c, key));
    }
    let shown = panel
        .luminaires
        .selected
        .as_deref()
        .and_then(|id| doc.site.luminaires.iter().find(|l| l.id == id))
        .or_else(|| doc.site.luminaires.last());
    if let Some(l) = shown {
        let path = doc.resolve(&l.file);
        let ctx = ui.ctx().clone();
        let plot = panel
            .luminaires
            .plots
            .entry(path)
            .or_insert_with(|| plot_of(&ctx, doc, &l.file));
        ui.label(format!("polar intensity of {} ({})", l.id, l.file));
        match plot {
            Ok((texture, scale_cd)) => {
                let r = ui.add(
                    egui::Image::from_texture(egui::load::SizedTexture::from_handle(texture))
                        .max_width(200.0),
                );
                name_widget(ui, &r, &format!("polar plot {}", l.id));
                ui.horizontal(|ui| {
                    crate::light_panel::sky_map::legend_swatch(
                        ui,
                        false,
                        egui::Color32::from_rgb(200, 30, 30),
                    );
                    ui.label("C0–C180");
                    crate::light_panel::sky_map::legend_swatch(
                        ui,
                        false,
                        egui::Color32::from_rgb(30, 60, 200),
                    );
                    ui.label("C90–C270");
                    ui.label(format!("outer circle {scale_cd} cd"));
                });
            }
            Err(e) => {
                ui.colored_label(egui::Color32::from_rgb(230, 80, 60), e.clone());
            }
        }
    }
}

impl crate::Studio {
    /// Site & light tab interaction on the photo: while placing, a click puts the luminaire
    /// the mounting height above the scene point under it (one undoable edit).
    pub(crate) fn light_pick_interaction(
        &mut self,
        response: &egui::Response,
        t: &ViewTransform,
        photo: &str,
    ) {
        if self.light.luminaires.placing.is_none() || !response.clicked() {
            return;
        }
        if let Some(p) = response.interact_pointer_pos() {
            self.place_luminaire_at(photo, t.photo_from_screen(p));
        }
    }

    /// Places the armed luminaire at the scene point shown at `pixel_px` of `photo` (plus the
    /// mounting height), or says why not.
    pub fn place_luminaire_at(&mut self, photo: &str, pixel_px: [f64; 2]) {
        let (Some(doc), Some(placing)) = (self.doc.as_ref(), self.light.luminaires.placing.clone())
        else {
            return;
        };
        let site = &doc.site;
        if stored_camera(site, photo).is_none() {
            self.say(
                format!("photo {photo} is not solved: solve it before placing luminaires on it"),
                true,
            );
            return;
        }
        let hit = match PolygonPicker::new(site, None).and_then(|p| p.pick(site, photo, pixel_px)) {
            Ok(hit) => hit,
            Err(e) => {
                self.say(format!("no scene surface to place on: {e}"), true);
                return;
            }
        };
        let h = self.light.luminaires.mount_height_m;
        let position_m = [
            hit.point_in_world_m[0],
            hit.point_in_world_m[1],
            hit.point_in_world_m[2] + h,
        ];
        let luminaire = match placing {
            Placing::New { file } => SiteLuminaire {
                id: next_id("L", site.luminaires.iter().map(|l| l.id.as_str())),
                file,
                position_m,
                rotation_z_deg: 0.0,
                tilt_deg: 0.0,
                colour_rgb: [1.0; 3],
                scale: DEFAULT_SCALE,
                enabled: true,
            },
            Placing::Move { id } => {
                let Some(l) = site.luminaires.iter().find(|l| l.id == id) else {
                    self.light.luminaires.placing = None;
                    return;
                };
                SiteLuminaire {
                    position_m,
                    ..l.clone()
                }
            }
        };
        let text = format!(
            "luminaire {} at ({:.3}, {:.3}, {:.3}) m, {h} m above polygon {}",
            luminaire.id, position_m[0], position_m[1], position_m[2], hit.polygon
        );
        self.light.luminaires.selected = Some(luminaire.id.clone());
        self.light.luminaires.placing = None;
        self.pending.push((
            Command::Light(LightCommand::PutLuminaire {
                luminaire: Box::new(luminaire),
                at: None,
            }),
            None,
        ));
        self.say(text, false);
    }
}
