//! The Variants tab's editor of the selected variant: its name (Rename, with empty and taken
//! names refused before anything changes), Duplicate and Delete, which models it shows, the
//! placements it gives them, and the scene materials it recolours. Every change is one
//! `VariantCommand::Put` (or `Rename`/`Remove`) through the studio's command path; a drag of a
//! placement value is one undo step. A variant naming a model the site no longer has shows the
//! library's message (`find_variant`) and a button that drops those names, as one undoable
//! edit; nothing is removed silently.

use std::collections::HashMap;

use eframe::egui;
use photomontage::colour::designer::{hex_from_linear, parse_colour, srgb8_from_linear};
use photomontage::scene::Material;
use photomontage::site::variants::{VariantError, find_variant};
use photomontage::site::{SiteDocument, Variant, VariantPlacement};

use super::{VariantsPanel, edit_action};
use crate::panel::Action;
use crate::variant_commands::{VariantCommand, next_variant_name};
use crate::widgets::{ERROR, name_widget};

/// The scene's materials (for "Override material"), rebuilt when the models or materials
/// change, and the colour text typed per override.
#[derive(Default)]
pub(crate) struct EditorCache {
    key: String,
    scene_materials: Vec<Material>,
    scene_error: Option<String>,
    material_pick: String,
    colour_text: HashMap<(String, String), String>,
}

impl EditorCache {
    fn refresh(&mut self, doc: &SiteDocument) {
        crate::materials_panel::refresh_scene_materials(
            doc,
            &mut self.key,
            &mut self.scene_materials,
            &mut self.scene_error,
            // The variant editor shows its own problems; the Materials tab shows these.
            &mut Vec::new(),
        );
    }
}

/// Why a variant name is refused, if it is.
fn name_problem(doc: &SiteDocument, from: &str, to: &str) -> Option<String> {
    if to.trim().is_empty() {
        return Some("a variant name must not be empty".into());
    }
    (to != from && doc.site.variants.iter().any(|v| v.name == to))
        .then(|| format!("a variant named `{to}` exists already"))
}

/// `variant` without the models the site does not have.
fn without_missing_models(doc: &SiteDocument, variant: &Variant) -> Variant {
    let has = |id: &str| doc.site.models.iter().any(|m| m.id == id);
    let mut v = variant.clone();
    if let Some(list) = v.visible_models.as_mut() {
        list.retain(|id| has(id));
    }
    v.placements.retain(|p| has(&p.model));
    v
}

/// The variant with model `id` shown or hidden (starting from the site's visibility).
fn with_visibility(doc: &SiteDocument, variant: &Variant, id: &str, show: bool) -> Variant {
    let mut v = variant.clone();
    let current: Vec<String> = v.visible_models.clone().unwrap_or_else(|| {
        doc.site
            .models
            .iter()
            .filter(|m| m.visible)
            .map(|m| m.id.clone())
            .collect()
    });
    // In the site's model order.
    let list = doc
        .site
        .models
        .iter()
        .map(|m| m.id.clone())
        .filter(|m| if m == id { show } else { current.contains(m) })
        .collect();
    v.visible_models = Some(list);
    v
}

fn put(variant: Variant) -> VariantCommand {
    VariantCommand::Put { variant, at: None }
}

impl VariantsPanel {
    /// Sets the colour text typed for `material` in `variant` (what a user types; tests).
    pub fn set_colour_text(&mut self, variant: &str, material: &str, text: &str) {
        self.edit
            .colour_text
            .insert((variant.to_owned(), material.to_owned()), text.to_owned());
    }

    pub(super) fn editor_ui(
        &mut self,
        ui: &mut egui::Ui,
        doc: &SiteDocument,
        actions: &mut Vec<Action>,
    ) {
        let Some(variant) = self
            .selected
            .as_ref()
            .and_then(|s| doc.site.variants.iter().find(|v| &v.name == s))
            .cloned()
        else {
            ui.label("Select a variant to edit it.");
            return;
        };
        if self.name_field_for.as_deref() != Some(variant.name.as_str()) {
            self.name_field.clone_from(&variant.name);
            self.name_field_for = Some(variant.name.clone());
        }
        ui.strong(format!("Editing {}", variant.name));
        self.name_row(ui, doc, &variant, actions);
        if let Err(e) = find_variant(&doc.site, &variant.name) {
            ui.colored_label(ERROR, e.to_string());
            if matches!(e, VariantError::UnknownModel { .. }) {
                let r = ui.button("Drop missing models");
                name_widget(ui, &r, "Drop missing models");
                if r.clicked() {
                    actions.push(edit_action(
                        put(without_missing_models(doc, &variant)),
                        None,
                    ));
                }
            }
        }
        self.models_ui(ui, doc, &variant, actions);
        self.materials_ui(ui, doc, &variant, actions);
    }

    fn name_row(
        &mut self,
        ui: &mut egui::Ui,
        doc: &SiteDocument,
        variant: &Variant,
        actions: &mut Vec<Action>,
    ) {
        ui.horizontal(|ui| {
            let r = ui.add(egui::TextEdit::singleline(&mut self.name_field).desired_width(160.0));
            name_widget(ui, &r, "Variant name");
            let r = ui.button("Rename");
            name_widget(ui, &r, "Rename");
            if r.clicked() {
                let to = self.name_field.trim().to_owned();
                match name_problem(doc, &variant.name, &to) {
                    Some(problem) => self.error = Some(problem),
                    None if to == variant.name => {}
                    None => {
                        actions.push(edit_action(
                            VariantCommand::Rename {
                                from: variant.name.clone(),
                                to: to.clone(),
                            },
                            None,
                        ));
                        self.selected = Some(to);
                        self.error = None;
                    }
                }
            }
            let r = ui.button("Duplicate");
            name_widget(ui, &r, "Duplicate");
            if r.clicked() {
                let mut copy = variant.clone();
                copy.name = next_variant_name(&doc.site, &format!("{} copy", variant.name));
                let at = doc
                    .site
                    .variants
                    .iter()
                    .position(|v| v.name == variant.name)
                    .map(|i| i + 1);
                self.selected = Some(copy.name.clone());
                actions.push(edit_action(VariantCommand::Put { variant: copy, at }, None));
                self.error = None;
            }
            let r = ui.button("Delete variant");
            name_widget(ui, &r, "Delete variant");
            if r.clicked() {
                actions.push(edit_action(
                    VariantCommand::Remove {
                        name: variant.name.clone(),
                    },
                    None,
                ));
                self.selected = None;
                self.error = None;
            }
        });
    }

    fn models_ui(
        &mut self,
        ui: &mut egui::Ui,
        doc: &SiteDocument,
        variant: &Variant,
        actions: &mut Vec<Action>,
    ) {
        ui.label("Models");
        if doc.site.models.is_empty() {
            ui.label("the site has no models");
        }
        if variant.visible_models.is_some() {
            let r = ui.button("Use the site's visibility");
            name_widget(ui, &r, "Use the site's visibility");
            if r.clicked() {
                let mut v = variant.clone();
                v.visible_models = None;
                actions.push(edit_action(put(v), None));
            }
        }
        for model in &doc.site.models {
            let id = &model.id;
            let mut shown = variant
                .visible_models
                .as_ref()
                .map_or(model.visible, |l| l.contains(id));
            let own = variant.placements.iter().find(|p| &p.model == id).cloned();
            ui.horizontal(|ui| {
                let r = ui.checkbox(&mut shown, format!("show {id}"));
                name_widget(ui, &r, &format!("Show {id}"));
                if r.changed() {
                    actions.push(edit_action(
                        put(with_visibility(doc, variant, id, shown)),
                        None,
                    ));
                }
                let mut has_own = own.is_some();
                let r = ui.checkbox(&mut has_own, "own placement");
                name_widget(ui, &r, &format!("Own placement of {id}"));
                if r.changed() {
                    let mut v = variant.clone();
                    if has_own {
                        v.placements.push(VariantPlacement {
                            model: id.clone(),
                            placement: model.placement.clone(),
                        });
                    } else {
                        v.placements.retain(|p| &p.model != id);
                    }
                    actions.push(edit_action(put(v), None));
                }
            });
            if let Some(mut p) = own {
                let before = p.clone();
                ui.horizontal(|ui| {
                    for (axis, value) in ["x", "y", "z"].iter().zip(&mut p.placement.translation) {
                        let r = ui.add(egui::DragValue::new(value).speed(0.1).suffix(" m"));
                        name_widget(ui, &r, &format!("{id} {axis}"));
                    }
                    let r = ui.add(
                        egui::DragValue::new(&mut p.placement.rotation_z_deg)
                            .speed(1.0)
                            .suffix("°"),
                    );
                    name_widget(ui, &r, &format!("{id} rotation"));
                    let r = ui.add(
                        egui::DragValue::new(&mut p.placement.scale)
                            .range(0.001..=1000.0)
                            .speed(0.01)
                            .prefix("×"),
                    );
                    name_widget(ui, &r, &format!("{id} scale"));
                });
                if p != before {
                    let mut v = variant.clone();
                    if let Some(slot) = v.placements.iter_mut().find(|q| &q.model == id) {
                        *slot = p;
                    }
                    let key = format!("variant {} placement {id}", variant.name);
                    actions.push(edit_action(put(v), Some(key)));
                }
            }
        }
    }

    fn materials_ui(
        &mut self,
        ui: &mut egui::Ui,
        doc: &SiteDocument,
        variant: &Variant,
        actions: &mut Vec<Action>,
    ) {
        ui.label("Materials (recoloured in this variant)");
        let cache = &mut self.edit;
        for m in &variant.materials {
            let key = (variant.name.clone(), m.name.clone());
            let text = cache
                .colour_text
                .entry(key)
                .or_insert_with(|| hex_from_linear(m.diffuse_rgb));
            ui.horizontal(|ui| {
                let [r8, g8, b8] = srgb8_from_linear(m.diffuse_rgb);
                let (rect, _) =
                    ui.allocate_exact_size(egui::vec2(28.0, 16.0), egui::Sense::hover());
                ui.painter()
                    .rect_filled(rect, 2.0, egui::Color32::from_rgb(r8, g8, b8));
                ui.label(&m.name);
                let r = ui.add(egui::TextEdit::singleline(text).desired_width(120.0));
                name_widget(ui, &r, &format!("Colour of {}", m.name));
                let r = ui.button("Set");
                name_widget(ui, &r, &format!("Set colour of {}", m.name));
                if r.clicked() {
                    match parse_colour(text.trim()) {
                        Ok(spec) => {
                            let mut v = variant.clone();
                            if let Some(slot) = v.materials.iter_mut().find(|x| x.name == m.name) {
                                slot.diffuse_rgb = spec.resolve().linear_rgb;
                                slot.diffuse_spectrum = None;
                            }
                            actions.push(edit_action(put(v), None));
                            self.error = None;
                        }
                        Err(e) => {
                            self.error = Some(format!("material {}: {e}", m.name));
                        }
                    }
                }
                let r = ui.button("Remove");
                name_widget(ui, &r, &format!("Remove override {}", m.name));
                if r.clicked() {
                    let mut v = variant.clone();
                    v.materials.retain(|x| x.name != m.name);
                    actions.push(edit_action(put(v), None));
                }
            });
        }
        cache.refresh(doc);
        if let Some(e) = &cache.scene_error {
            ui.colored_label(ERROR, format!("scene materials: {e}"));
        }
        ui.horizontal(|ui| {
            let r = egui::ComboBox::from_id_salt("variant material pick")
                .selected_text(if cache.material_pick.is_empty() {
                    "material…"
                } else {
                    cache.material_pick.as_str()
                })
                .show_ui(ui, |ui| {
                    for m in &cache.scene_materials {
                        let r = ui.selectable_value(
                            &mut cache.material_pick,
                            m.name.clone(),
                            m.name.as_str(),
                        );
                        name_widget(ui, &r, &format!("Pick material {}", m.name));
                    }
                });
            name_widget(ui, &r.response, "Material to override");
            let pick = cache
                .scene_materials
                .iter()
                .find(|m| m.name == cache.material_pick)
                .filter(|m| !variant.materials.iter().any(|x| x.name == m.name));
            let r = ui.add_enabled(pick.is_some(), egui::Button::new("Override material"));
            name_widget(ui, &r, "Override material");
            if r.clicked()
                && let Some(m) = pick
            {
                let mut v = variant.clone();
                v.materials.push(m.clone());
                actions.push(edit_action(put(v), None));
            }
        });
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use photomontage::site::CadModel;

    fn doc_with_models(ids: &[(&str, bool)]) -> SiteDocument {
        let mut doc = SiteDocument {
            path: "site.toml".into(),
            site: photomontage::site::Site::default(),
        };
        for (id, visible) in ids {
            doc.site.models.push(CadModel {
                id: (*id).into(),
                file: format!("{id}.obj"),
                units: photomontage::site::ModelUnits::default(),
                up_axis: photomontage::site::ModelUpAxis::default(),
                placement: photomontage::site::Placement::default(),
                visible: *visible,
            });
        }
        doc
    }

    #[test]
    fn visibility_starts_from_the_site_and_keeps_model_order() {
        let doc = doc_with_models(&[("a", true), ("b", false), ("c", true)]);
        let v = Variant::named("v");
        let shown = with_visibility(&doc, &v, "b", true);
        assert_eq!(
            shown.visible_models,
            Some(vec!["a".into(), "b".into(), "c".into()])
        );
        let hidden = with_visibility(&doc, &shown, "a", false);
        assert_eq!(hidden.visible_models, Some(vec!["b".into(), "c".into()]));
    }

    #[test]
    fn missing_models_are_dropped_and_bad_names_refused() {
        let mut doc = doc_with_models(&[("a", true)]);
        let mut v = Variant::named("v");
        v.visible_models = Some(vec!["a".into(), "gone".into()]);
        v.placements.push(VariantPlacement {
            model: "gone".into(),
            placement: photomontage::site::Placement::default(),
        });
        let fixed = without_missing_models(&doc, &v);
        assert_eq!(fixed.visible_models, Some(vec!["a".into()]));
        assert!(fixed.placements.is_empty());
        doc.site.variants = vec![v, Variant::named("w")];
        assert!(name_problem(&doc, "v", " ").is_some());
        assert!(name_problem(&doc, "v", "w").is_some());
        assert!(name_problem(&doc, "v", "v").is_none());
        assert!(name_problem(&doc, "v", "x").is_none());
    }
}
