//! The Materials tab (colour and material design, Tonn & Donath): the scene's materials (from
//! `site_scene`, so polygons, CAD models, the library and the site's `[[materials]]` all show),
//! and for the selected one its colour as sRGB hex, CIE L\*a\*b\* or LCh (D65) or a RAL Design
//! code (filled with the nearest code of the current colour, or picked from a hue page of the
//! system, [`crate::ral_design_page`]) with a swatch,
//! its LRV, a warning when the colour is outside the sRGB gamut (clamped), the gloss (GGX
//! roughness, F0) and glass transmittance the renderer supports, and the site's palette
//! (`[[palette]]`), applied with one click. Every change is one undoable
//! `Command::Material` edit.
//!
//! # Known limitations
//! A material is picked from the list, or in "Pick from photo" mode by a click on the solved
//! photo (the camera ray cast into the one scene, `material_pick.rs`; Escape leaves the
//! mode). The "Unfolded elevation" section draws a model's façades on the worker
//! ([`crate::elevation_view`]).
//! The scene is rebuilt when the models, the site materials or the library path change.

use eframe::egui;
use photomontage::colour::designer::{
    ColourSpec, hex_from_linear, lab_from_lch, lab_from_linear_srgb, lch_from_lab, parse_colour,
    srgb8_from_linear, xyz_from_lab,
};
use photomontage::colour::ral_design::RalDesign;
use photomontage::scene::Material;
use photomontage::scene::material::Specular;
use photomontage::site::render::{SiteWarning, site_scene};
use photomontage::site::{PaletteColour, SiteDocument, SiteMaterial};

use crate::commands::Command;
use crate::material_commands::MaterialCommand;
use crate::panel::{Action, Panel, PanelContext};
use crate::widgets::name_widget;

/// The Materials tab.
#[derive(Debug, Default)]
pub struct MaterialsPanel {
    selected: Option<String>,
    loaded_for: Option<(String, String)>,
    hex: String,
    lab: [f64; 3],
    lch: [f64; 3],
    /// A RAL Design code (`RAL HHH LL CC`).
    ral: String,
    /// The RAL Design hue page shown.
    ral_page: crate::ral_design_page::RalDesignPage,
    gloss: Option<Specular>,
    glass_transmittance: Option<f64>,
    palette_name: String,
    error: Option<String>,
    cache_key: String,
    scene_materials: Vec<Material>,
    scene_error: Option<String>,
    /// The scene build's warnings about site materials (`[[materials]]`), by material name.
    scene_warnings: Vec<(String, String)>,
    /// "Pick from photo" mode: a click on the photo selects the material it shows.
    pick_mode: bool,
    /// What the last pick found (or that it found no surface).
    pick_result: Option<String>,
    /// The unfolded elevation section.
    elevation: crate::elevation_view::ElevationView,
    /// Open the elevation section on the next frame.
    open_elevation: bool,
}

/// The stored colour of `name`: the site entry's colour text, else the hex of its diffuse.
fn current_colour(doc: &SiteDocument, base: &Material) -> String {
    doc.site
        .materials
        .iter()
        .find(|m| m.material.name == base.name)
        .and_then(|m| m.colour.clone())
        .unwrap_or_else(|| hex_from_linear(base.diffuse_reflectance_rgb()))
}

/// The edit that sets material `base`'s colour to `text` (already parsed as `spec`), keeping
/// its other fields (the site entry's, else the scene's).
#[must_use]
pub fn set_colour_command(
    doc: &SiteDocument,
    base: &Material,
    text: &str,
    spec: ColourSpec,
) -> Command {
    let mut material = doc
        .site
        .materials
        .iter()
        .find(|m| m.material.name == base.name)
        .map_or_else(|| base.clone(), |m| m.material.clone());
    material.diffuse_rgb = spec.resolve().linear_rgb;
    material.diffuse_spectrum = None;
    Command::Material(MaterialCommand::PutMaterial {
        material: Box::new(SiteMaterial::new(material, Some(text.to_owned()))),
        at: None,
    })
}

fn swatch(ui: &mut egui::Ui, rgb8: [u8; 3], name: &str) {
    let (rect, r) = ui.allocate_exact_size(egui::vec2(36.0, 18.0), egui::Sense::hover());
    ui.painter().rect_filled(
        rect,
        2.0,
        egui::Color32::from_rgb(rgb8[0], rgb8[1], rgb8[2]),
    );
    name_widget(ui, &r, name);
}

impl MaterialsPanel {
    /// Opens the "Unfolded elevation" section and draws the first visible model there (with its
    /// irradiance from a radiosity solve when `irradiance`): the studio's `--elevation`.
    pub fn request_elevation(&mut self, irradiance: bool) {
        self.open_elevation = true;
        self.elevation.request_draw(irradiance);
    }

    /// Whether the elevation section is drawing (or about to).
    #[must_use]
    pub fn elevation_busy(&self) -> bool {
        self.elevation.busy()
    }

    /// Whether a click on the photo picks a material.
    #[must_use]
    pub fn pick_mode(&self) -> bool {
        self.pick_mode
    }

    /// The result of a pick: the material to select (`None`: no surface) and what to say.
    pub fn picked(&mut self, material: Option<&str>, text: String) {
        if let Some(name) = material {
            self.selected = Some(name.to_owned());
            self.error = None;
        }
        self.pick_result = Some(text);
    }

    fn pick_ui(&mut self, ui: &mut egui::Ui) {
        ui.horizontal(|ui| {
            let r = ui.selectable_label(self.pick_mode, "Pick from photo");
            name_widget(ui, &r, "Pick from photo");
            if r.clicked() {
                self.pick_mode = !self.pick_mode;
                self.pick_result = None;
            }
            if self.pick_mode {
                let r = ui.label("click a surface on the photo (Escape leaves)");
                name_widget(ui, &r, "picking materials");
            }
        });
        if self.pick_mode && ui.input(|i| i.key_pressed(egui::Key::Escape)) {
            self.pick_mode = false;
        }
        if let Some(text) = &self.pick_result {
            let r = ui.label(text);
            name_widget(ui, &r, &format!("pick result: {text}"));
        }
    }

    fn refresh(&mut self, doc: &SiteDocument) {
        refresh_scene_materials(
            doc,
            &mut self.cache_key,
            &mut self.scene_materials,
            &mut self.scene_error,
            &mut self.scene_warnings,
        );
    }

    fn load(&mut self, doc: &SiteDocument, base: &Material) {
        let colour = current_colour(doc, base);
        // Only this material's own values refill the fields: text typed but not applied
        // survives edits (and undos) of other materials, the palette or the rest of the site.
        let entry = doc
            .site
            .materials
            .iter()
            .find(|m| m.material.name == base.name);
        let key = (base.name.clone(), format!("{colour}{entry:?}{base:?}"));
        if self.loaded_for.as_ref() == Some(&key) {
            return;
        }
        let rgb = base.diffuse_reflectance_rgb();
        self.hex = hex_from_linear(rgb);
        self.lab = parse_colour(&colour).map_or_else(|_| lab_from_linear_srgb(rgb), |s| s.lab());
        self.lch = lch_from_lab(self.lab);
        self.ral = match parse_colour(&colour) {
            Ok(ColourSpec::RalDesign(code)) => code.to_string(),
            _ => RalDesign::nearest(xyz_from_lab(self.lab))
                .map_or_else(String::new, |c| c.to_string()),
        };
        self.gloss = base.specular;
        self.glass_transmittance = base.glass.map(|g| g.transmittance_rgb[1]);
        self.loaded_for = Some(key);
    }

    fn apply_colour(&mut self, doc: &SiteDocument, base: &Material, text: &str) -> Option<Action> {
        match parse_colour(text) {
            Ok(spec) => {
                self.error = None;
                Some(Action::Edit {
                    command: Box::new(set_colour_command(doc, base, text, spec)),
                    merge_key: None,
                })
            }
            Err(e) => {
                self.error = Some(e.to_string());
                None
            }
        }
    }

    #[allow(clippy::too_many_lines)]
    fn editor(&mut self, ui: &mut egui::Ui, doc: &SiteDocument, base: &Material) -> Vec<Action> {
        let mut actions = Vec::new();
        self.load(doc, base);
        let colour = current_colour(doc, base);
        ui.heading(&base.name);
        ui.horizontal(|ui| {
            let rgb = base.diffuse_reflectance_rgb();
            swatch(ui, srgb8_from_linear(rgb), "Swatch");
            let lrv = photomontage::colour::designer::lrv(rgb);
            let r = ui.label(format!("{colour}   LRV {lrv:.1}"));
            name_widget(ui, &r, "Current colour");
        });
        match parse_colour(&colour) {
            Ok(spec) if spec.resolve().out_of_gamut => {
                let r = ui.colored_label(
                    egui::Color32::from_rgb(200, 120, 0),
                    format!(
                        "Outside the sRGB gamut: clamped to {}",
                        hex_from_linear(spec.resolve().linear_rgb)
                    ),
                );
                name_widget(ui, &r, "Gamut warning");
            }
            Ok(_) => {}
            Err(e) => {
                ui.colored_label(egui::Color32::RED, e.to_string());
            }
        }
        // What the scene build clamped (a reflectance above 1 typed into the site file); the
        // gamut warning above already covers a designer's colour.
        for (_, message) in self
            .scene_warnings
            .iter()
            .filter(|(m, text)| *m == base.name && !text.contains("sRGB gamut"))
        {
            let r = ui.colored_label(egui::Color32::from_rgb(200, 120, 0), message);
            name_widget(ui, &r, "Material warning");
        }
        ui.horizontal(|ui| {
            ui.label("Hex");
            let r = ui.add(egui::TextEdit::singleline(&mut self.hex).desired_width(80.0));
            name_widget(ui, &r, "Hex colour");
            let b = ui.button("Apply hex");
            name_widget(ui, &b, "Apply hex");
            if b.clicked() {
                let text = self.hex.trim().to_owned();
                actions.extend(self.apply_colour(doc, base, &text));
            }
        });
        if let Some(text) = triple_row(ui, "L*a*b*", "Lab", ["L*", "a*", "b*"], &mut self.lab) {
            actions.extend(self.apply_colour(doc, base, &text));
        }
        if let Some(text) = triple_row(ui, "LCh", "LCh", ["L*", "C*", "h"], &mut self.lch) {
            actions.extend(self.apply_colour(doc, base, &text));
        }
        let preview = lab_from_lch(self.lch);
        ui.small(format!(
            "LCh as L*a*b*: ({:.1}, {:.1}, {:.1})",
            preview[0], preview[1], preview[2]
        ));
        ui.horizontal(|ui| {
            ui.label("RAL Design");
            let r = ui.add(egui::TextEdit::singleline(&mut self.ral).desired_width(110.0));
            name_widget(ui, &r, "RAL Design code");
            let b = ui.button("Apply RAL Design");
            name_widget(ui, &b, "Apply RAL Design");
            if b.clicked() {
                let text = self.ral.trim().to_owned();
                actions.extend(self.apply_colour(doc, base, &text));
            }
        })
        .response
        .on_hover_text(
            "RAL Design System: hue, lightness, chroma in CIELCh (D65, 10° observer); \
             filled with the code nearest the current colour",
        );
        let r = egui::CollapsingHeader::new("RAL Design pages")
            .id_salt("ral design pages")
            .show(ui, |ui| self.ral_page.ui(ui));
        name_widget(ui, &r.header_response, "RAL Design pages");
        if let Some(code) = r.body_returned.flatten() {
            self.ral.clone_from(&code);
            actions.extend(self.apply_colour(doc, base, &code));
        }
        if let Some(e) = &self.error {
            let r = ui.colored_label(egui::Color32::RED, e);
            name_widget(ui, &r, "Colour error");
        }
        ui.separator();
        let mut changed = false;
        if let Some(s) = &mut self.gloss {
            changed |= ui
                .add(egui::Slider::new(&mut s.roughness, 0.02..=1.0).text("roughness"))
                .changed();
            changed |= ui
                .add(egui::Slider::new(&mut s.f0, 0.0..=1.0).text("specular F0"))
                .changed();
        } else if ui.button("Add gloss").clicked() {
            self.gloss = Some(Specular {
                roughness: 0.5,
                f0: 0.04,
            });
            changed = true;
        }
        if let Some(t) = &mut self.glass_transmittance {
            changed |= ui
                .add(egui::Slider::new(t, 0.0..=1.0).text("glass transmittance"))
                .changed();
        }
        if changed {
            let mut material = doc
                .site
                .materials
                .iter()
                .find(|m| m.material.name == base.name)
                .map_or_else(|| base.clone(), |m| m.material.clone());
            material.specular = self.gloss;
            if let (Some(g), Some(t)) = (&mut material.glass, self.glass_transmittance) {
                g.transmittance_rgb = [t; 3];
            }
            let colour = doc
                .site
                .materials
                .iter()
                .find(|m| m.material.name == base.name)
                .and_then(|m| m.colour.clone());
            actions.push(Action::Edit {
                command: Box::new(Command::Material(MaterialCommand::PutMaterial {
                    material: Box::new(SiteMaterial::new(material, colour)),
                    at: None,
                })),
                merge_key: Some(format!("gloss:{}", base.name)),
            });
        }
        if doc
            .site
            .materials
            .iter()
            .any(|m| m.material.name == base.name)
        {
            let b = ui.button("Remove site definition");
            name_widget(ui, &b, "Remove site definition");
            if b.clicked() {
                actions.push(Action::Edit {
                    command: Box::new(Command::Material(MaterialCommand::RemoveMaterial {
                        name: base.name.clone(),
                    })),
                    merge_key: None,
                });
            }
        }
        ui.separator();
        ui.strong("Palette");
        for p in &doc.site.palette {
            ui.horizontal(|ui| {
                if let Ok(spec) = parse_colour(&p.colour) {
                    swatch(
                        ui,
                        srgb8_from_linear(spec.resolve().linear_rgb),
                        &format!("Palette swatch {}", p.name),
                    );
                }
                ui.label(format!("{} {}", p.name, p.colour));
                let b = ui.button("Use");
                name_widget(ui, &b, &format!("Use {}", p.name));
                if b.clicked() {
                    let text = p.colour.clone();
                    actions.extend(self.apply_colour(doc, base, &text));
                }
            });
        }
        ui.horizontal(|ui| {
            let r = ui.add(egui::TextEdit::singleline(&mut self.palette_name).desired_width(100.0));
            name_widget(ui, &r, "Palette name");
            let b = ui.button("Add current colour");
            name_widget(ui, &b, "Add to palette");
            if b.clicked() && !self.palette_name.trim().is_empty() {
                let mut palette = doc.site.palette.clone();
                palette.push(PaletteColour {
                    name: self.palette_name.trim().to_owned(),
                    colour: colour.clone(),
                });
                actions.push(Action::Edit {
                    command: Box::new(Command::Material(MaterialCommand::SetPalette(palette))),
                    merge_key: None,
                });
                self.palette_name.clear();
            }
        });
        actions
    }
}

impl Panel for MaterialsPanel {
    fn ui(&mut self, ui: &mut egui::Ui, ctx: &PanelContext<'_>) -> Vec<Action> {
        let Some(doc) = ctx.doc else {
            ui.label("No site open.");
            return Vec::new();
        };
        // The editor and the unfolded elevation below it outgrow a small window: they scroll.
        egui::ScrollArea::vertical()
            .id_salt("materials tab")
            .show(ui, |ui| self.contents(ui, doc))
            .inner
    }
}

impl MaterialsPanel {
    fn contents(&mut self, ui: &mut egui::Ui, doc: &SiteDocument) -> Vec<Action> {
        self.refresh(doc);
        if let Some(e) = &self.scene_error {
            ui.colored_label(egui::Color32::RED, e);
        }
        self.pick_ui(ui);
        ui.label("Materials of the scene (polygons, CAD models, library, site):");
        for m in &self.scene_materials {
            let selected = self.selected.as_deref() == Some(m.name.as_str());
            ui.horizontal(|ui| {
                swatch(
                    ui,
                    srgb8_from_linear(m.diffuse_reflectance_rgb()),
                    &format!("Swatch {}", m.name),
                );
                let r = ui.selectable_label(selected, &m.name);
                name_widget(ui, &r, &format!("Material {}", m.name));
                if r.clicked() {
                    self.selected = Some(m.name.clone());
                    self.error = None;
                }
            });
        }
        ui.separator();
        let base = self
            .selected
            .as_ref()
            .and_then(|s| self.scene_materials.iter().find(|m| &m.name == s))
            .cloned();
        let actions = match base {
            Some(base) => self.editor(ui, doc, &base),
            None => {
                ui.label("Select a material.");
                Vec::new()
            }
        };
        ui.separator();
        let open = std::mem::take(&mut self.open_elevation).then_some(true);
        let r = egui::CollapsingHeader::new("Unfolded elevation")
            .default_open(false)
            .open(open)
            .show(ui, |ui| self.elevation.ui(ui, doc));
        name_widget(ui, &r.header_response, "Unfolded elevation");
        actions
    }
}

/// One row of three numbers and an Apply button (`label`; widgets named `"{prefix} {name}"` and
/// `"Apply {prefix}"`); on a click, the colour text `"{prefix lowercase}(v0, v1, v2)"`.
fn triple_row(
    ui: &mut egui::Ui,
    label: &str,
    prefix: &str,
    names: [&str; 3],
    values: &mut [f64; 3],
) -> Option<String> {
    ui.horizontal(|ui| {
        ui.label(label);
        for (k, name) in names.iter().enumerate() {
            let r = ui.add(
                egui::DragValue::new(&mut values[k])
                    .speed(0.5)
                    .max_decimals(2),
            );
            name_widget(ui, &r, &format!("{prefix} {name}"));
        }
        let b = ui.button(format!("Apply {label}"));
        name_widget(ui, &b, &format!("Apply {prefix}"));
        b.clicked().then(|| {
            format!(
                "{}({:.2}, {:.2}, {:.2})",
                prefix.to_lowercase(),
                values[0],
                values[1],
                values[2]
            )
        })
    })
    .inner
}

/// Refills `materials` (the one scene's materials by name, or `error` when the scene cannot be
/// built) and `warnings` (the build's site-material warnings: material name, message) when the
/// site's models, materials, library or polygon count changed since `key`.
pub(crate) fn refresh_scene_materials(
    doc: &SiteDocument,
    key: &mut String,
    materials: &mut Vec<Material>,
    error: &mut Option<String>,
    warnings: &mut Vec<(String, String)>,
) {
    let now = format!(
        "{:?}{:?}{:?}{}",
        doc.site.models,
        doc.site.materials,
        doc.site.lighting.material_library,
        doc.site.polygons.len()
    );
    if now == *key {
        return;
    }
    *key = now;
    match site_scene(doc) {
        Ok(s) => {
            let mut m = s.scene.materials().to_vec();
            m.sort_by(|a, b| a.name.cmp(&b.name));
            m.dedup_by(|a, b| a.name == b.name);
            *materials = m;
            *error = None;
            *warnings = s
                .warnings
                .iter()
                .filter_map(|w| match w {
                    SiteWarning::SiteMaterial { material, message } => {
                        Some((material.clone(), message.clone()))
                    }
                    _ => None,
                })
                .collect();
        }
        Err(e) => {
            materials.clear();
            warnings.clear();
            *error = Some(e.to_string());
        }
    }
}
