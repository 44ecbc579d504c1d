//! The Render panel's Sheet button: the verified-view PDF (`photomontage::verified::sheet`) of
//! the finished view, at the AVR level it was made with, on A3 (the library's default paper).

use std::path::Path;

use photomontage::colour::ToneMap;
use photomontage::colour::tonemap::encode_srgb8;
use photomontage::site::SiteDocument;
use photomontage::verified::ViewGeometryOptions;
use photomontage::verified::sheet::{sheet_for_view, write_sheet};

use crate::render_panel::{RenderPanel, RenderPanelError, site_tone_map};

impl RenderPanel {
    /// Writes the sheet of the finished view to `path` (through a temporary file and a rename).
    ///
    /// # Errors
    /// `NothingToExport` or the sheet's error (unsolved view, write failure, …).
    pub fn export_sheet(
        &self,
        doc: &SiteDocument,
        path: &Path,
        tone_map: &ToneMap,
    ) -> Result<(), RenderPanelError> {
        let m = self.montage().ok_or(RenderPanelError::NothingToExport)?;
        let [w, h] = m.image.size_px;
        let rgb = image::RgbImage::from_fn(w, h, |x, y| {
            let p = m.image.rgba[(y * w + x) as usize];
            image::Rgb(encode_srgb8([p[0], p[1], p[2]], tone_map))
        });
        let pdf = sheet_for_view(
            doc,
            &m.photo_id,
            &rgb,
            m.avr,
            &ViewGeometryOptions::default(),
        )
        .map_err(Box::new)?;
        write_sheet(path, &pdf).map_err(Box::new)?;
        Ok(())
    }
}

impl crate::Studio {
    /// Writes the verified-view sheet of the finished view to the path typed in the panel.
    pub fn export_sheet(&mut self) {
        let Some(doc) = self.doc.as_ref() else {
            return;
        };
        let path = std::path::PathBuf::from(self.render.sheet_path.trim());
        if path.extension().and_then(|e| e.to_str()) != Some("pdf") {
            self.say("type a sheet path ending in .pdf first", true);
            return;
        }
        match self.render.export_sheet(doc, &path, &site_tone_map(doc)) {
            Ok(()) => self.say(format!("wrote the sheet {}", path.display()), false),
            Err(e) => self.say(e.to_string(), true),
        }
    }
}
