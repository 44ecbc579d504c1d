//! The Materials tab's "Pick from photo" mode on the photo view: a click on the solved photo
//! casts the camera ray through the clicked pixel into the one scene every renderer uses
//! (`photomontage::site::material_pick`, built on `site_scene`) and selects the hit triangle's
//! material in the tab; a click on the sky says "no surface here".
//!
//! # Known limitations
//! The scene is built for each click (a click is rare; a cached scene would have to follow every
//! edit of models, polygons and materials).

use eframe::egui::{self, PointerButton};
use photomontage::site::material_pick::MaterialPicker;
use photomontage::site::render::site_scene;

use crate::viewport::ViewTransform;

impl crate::Studio {
    /// Materials tab interaction on the photo: in pick mode, a click picks the material under
    /// it.
    pub(crate) fn material_pick_interaction(
        &mut self,
        response: &egui::Response,
        t: &ViewTransform,
        photo: &str,
    ) {
        if !self.materials.pick_mode() || !response.clicked_by(PointerButton::Primary) {
            return;
        }
        if let Some(p) = response.interact_pointer_pos() {
            self.pick_material_at(photo, t.photo_from_screen(p));
        }
    }

    /// Selects in the Materials tab the material shown at `pixel_px` of `photo`, or says why
    /// there is none.
    pub fn pick_material_at(&mut self, photo: &str, pixel_px: [f64; 2]) {
        let Some(doc) = self.doc.as_ref() else {
            return;
        };
        let hit = site_scene(doc)
            .map_err(|e| e.to_string())
            .and_then(|scene| MaterialPicker::new(&scene).map_err(|e| e.to_string()))
            .and_then(|picker| {
                picker
                    .pick(&doc.site, photo, pixel_px)
                    .map_err(|e| e.to_string())
            });
        match hit {
            Ok(Some(hit)) => {
                let text = format!(
                    "picked {} on {} at {:.1} m",
                    hit.material, hit.object, hit.distance_m
                );
                self.materials
                    .picked(Some(hit.material.as_str()), text.clone());
                self.say(text, false);
            }
            Ok(None) => {
                let text = format!(
                    "no surface here ({:.1}, {:.1}) px: the ray meets no scene surface",
                    pixel_px[0], pixel_px[1]
                );
                self.materials.picked(None, text.clone());
                self.say(text, false);
            }
            Err(e) => {
                self.materials.picked(None, format!("cannot pick: {e}"));
                self.say(format!("cannot pick a material: {e}"), true);
            }
        }
    }
}
