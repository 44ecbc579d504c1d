//! The photomontage studio. This first window opens a site (the argument, or the bundled
//! courtyard sample) and shows its photos, points and solve state; calibration by clicking,
//! scene building and the render preview come with the studio issue.

use eframe::egui;
use photomontage::site::SiteDocument;
use std::path::PathBuf;

struct Studio {
    path: PathBuf,
    site: Result<SiteDocument, String>,
}

impl Studio {
    fn open(path: PathBuf) -> Self {
        let site = SiteDocument::load(&path).map_err(|e| e.to_string());
        Self { path, site }
    }
}

impl eframe::App for Studio {
    fn ui(&mut self, ui: &mut egui::Ui, _frame: &mut eframe::Frame) {
        egui::CentralPanel::default().show(ui, |ui| {
            ui.heading("photomontage studio");
            ui.label(format!("site: {}", self.path.display()));
            match &self.site {
                Err(e) => {
                    ui.colored_label(egui::Color32::RED, e);
                }
                Ok(doc) => {
                    let site = &doc.site;
                    ui.label(format!("name: {}", site.name));
                    ui.separator();
                    ui.strong(format!("photos ({})", site.photos.len()));
                    for p in &site.photos {
                        let state = p.exterior.as_ref().map_or_else(
                            || "not solved".to_string(),
                            |e| format!("solved ({}), RMS {:.2} px", e.solved_by, e.rms_px),
                        );
                        ui.label(format!("{}  {}  {state}", p.id, p.file));
                    }
                    ui.separator();
                    ui.label(format!(
                        "control points: {}   tie points: {}   observations: {}   polygons: {}   models: {}",
                        site.control_points.len(),
                        site.tie_points.len(),
                        site.observations.len(),
                        site.polygons.len(),
                        site.models.len()
                    ));
                }
            }
        });
    }
}

fn default_site() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../sample_sites/courtyard/site.toml")
}

fn main() -> anyhow::Result<()> {
    let path = std::env::args_os()
        .nth(1)
        .map_or_else(default_site, PathBuf::from);
    let options = eframe::NativeOptions {
        viewport: egui::ViewportBuilder::default().with_inner_size([900.0, 600.0]),
        ..Default::default()
    };
    eframe::run_native(
        "photomontage studio",
        options,
        Box::new(move |_cc| Ok(Box::new(Studio::open(path)))),
    )
    .map_err(|e| anyhow::anyhow!("cannot start the studio window: {e}"))
}
