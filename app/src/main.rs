//! `photomontage-studio [SITE] [--screenshot FILE [--frames N]] [--script FILE] [--headless] [--solve]`
//! (arguments parsed by clap; `--help` lists them)
//!
//! Opens SITE (default: the bundled courtyard sample) in the studio window.
//! `--screenshot FILE --frames N`: run at least N frames (and until the photo is shown), save
//! egui's screenshot of the window as PNG, exit. `--script FILE`: apply the edit commands in
//! FILE (one per line: `place PHOTO POINT X Y`, `remove PHOTO POINT`, `control ID X Y Z`,
//! `enable|disable PHOTO POINT`) through the studio's command path at start. `--headless`: run
//! the studio's frames without a window (no display needed; autosave and workers run as usual)
//! until killed — the crash-safety test uses it. `--solve`: start a solve on the first frame.
//! `--tab LABEL` shows that side tab; `--study-dates D --study-times T [--study-shadow-maps
//! [--study-no-montages]] [--study-frame N]` runs the Study tab's sun study on the first frame (the screenshot waits
//! for it; `docs/screenshots.sh` uses these). `--light-render-settings` scrolls the Site & light
//! tab to its exposure and radiosity switches.

use anyhow::{Context as _, bail};
use clap::Parser as _;
use eframe::egui;
use photomontage_studio::{Studio, StudioOptions, commands, default_site_path, state, window};
use std::path::PathBuf;
use std::sync::{Arc, Mutex};

/// The photomontage studio: opens SITE in the studio window.
#[derive(Debug, clap::Parser)]
#[command(
    name = "photomontage-studio",
    version,
    about = "The photomontage studio: opens SITE (default: the bundled courtyard sample) in a window"
)]
struct Args {
    /// Site file to open (default: the bundled courtyard sample).
    site: Option<PathBuf>,
    /// Run at least --frames frames (and until the photo is shown), save egui's screenshot of
    /// the window as PNG to FILE, exit.
    #[arg(long, value_name = "FILE")]
    screenshot: Option<PathBuf>,
    /// Frames to run before the screenshot.
    #[arg(long, value_name = "N", default_value_t = 10, requires = "screenshot")]
    frames: u32,
    /// Apply the edit commands in FILE through the studio's command path at start (one per
    /// line: `place PHOTO POINT X Y`, `remove PHOTO POINT`, `control ID X Y Z`,
    /// `enable|disable PHOTO POINT`).
    #[arg(long, value_name = "FILE")]
    script: Option<PathBuf>,
    /// Run the studio's frames without a window (no display needed; autosave and workers run
    /// as usual) until killed.
    #[arg(long, conflicts_with = "screenshot")]
    headless: bool,
    /// Start a solve on the first frame.
    #[arg(long)]
    solve: bool,
    /// Show the side tab with this label at start ("Study", "Render", …).
    #[arg(long, value_name = "LABEL")]
    tab: Option<String>,
    /// Render every design variant of the first photo on the first frame (the Variants tab's
    /// "Render all variants"; the screenshot waits for it).
    #[arg(long)]
    render_variants: bool,
    /// Run a sun study of the first photo on the first frame, at these dates (as the Study
    /// tab's and `photomontage study`'s --dates).
    #[arg(long, value_name = "LIST", requires = "study_times")]
    study_dates: Option<String>,
    /// The study's local clock times (as --times of `photomontage study`).
    #[arg(long, value_name = "LIST", requires = "study_dates")]
    study_times: Option<String>,
    /// With --study-dates: also map the shadows in plan view (and show the maps).
    #[arg(long, requires = "study_dates")]
    study_shadow_maps: bool,
    /// With --study-shadow-maps: no montages, only the maps (quick).
    #[arg(long, requires = "study_shadow_maps")]
    study_no_montages: bool,
    /// With --study-dates: the preview frame shown (0 = first).
    #[arg(long, value_name = "N", requires = "study_dates")]
    study_frame: Option<usize>,
    /// Open the Materials tab's "Unfolded elevation" and draw the first visible model there on
    /// the first frame (with --tab Materials; the screenshot waits for it).
    #[arg(long)]
    elevation: bool,
    /// With --elevation: colour the façades by their irradiance from a radiosity solve.
    #[arg(long, requires = "elevation")]
    elevation_irradiance: bool,
    /// Scroll the Site & light tab to its render settings: the exposure and the radiosity
    /// switches (with --tab "Site & light").
    #[arg(long)]
    light_render_settings: bool,
    /// Largest photo the studio decodes, in megapixels (as the CLI's option).
    #[arg(long, value_name = "MP", default_value_t = 250.0)]
    max_photo_megapixels: f64,
    /// Most memory decoding one photo may take, in MiB (as the CLI's option).
    #[arg(long, value_name = "MIB", default_value_t = 8192)]
    max_decode_memory_mib: u64,
}

fn apply_script(studio: &mut Studio, script: &PathBuf) -> anyhow::Result<()> {
    let text = std::fs::read_to_string(script)
        .with_context(|| format!("cannot read script {}", script.display()))?;
    for (n, line) in text.lines().enumerate() {
        let Some(doc) = studio.document() else {
            bail!("no site is open");
        };
        match commands::parse_script_line(&doc.site, line) {
            Ok(Some(c)) => studio.apply(c, None),
            Ok(None) => {}
            Err(e) => bail!("{}:{}: {e}", script.display(), n + 1),
        }
    }
    Ok(())
}

/// The window: the studio plus the screenshot mode.
struct Shell {
    studio: Studio,
    frames: u32,
    screenshot: Option<PathBuf>,
    shot: Arc<Mutex<Option<Arc<egui::ColorImage>>>>,
    requested: bool,
    solve_on_start: bool,
    study_on_start: bool,
    study_frame: Option<usize>,
    variants_on_start: bool,
    /// `--elevation`: `Some(irradiance)` until asked for on the first frame.
    elevation_on_start: Option<bool>,
    /// `--light-render-settings`, applied on every frame (a site opened later resets the tab).
    light_render_settings: bool,
}

impl eframe::App for Shell {
    fn ui(&mut self, ui: &mut egui::Ui, _frame: &mut eframe::Frame) {
        if std::mem::take(&mut self.solve_on_start) {
            let ctx = ui.ctx().clone();
            self.studio.start_solve(&ctx);
        }
        if std::mem::take(&mut self.study_on_start) {
            let ctx = ui.ctx().clone();
            self.studio.start_study(&ctx);
        }
        if let Some(irradiance) = self.elevation_on_start.take() {
            self.studio.start_elevation(irradiance);
        }
        if self.light_render_settings {
            self.studio.scroll_light_to_render_settings();
        }
        if std::mem::take(&mut self.variants_on_start) {
            let ctx = ui.ctx().clone();
            self.studio.start_variant_renders(&ctx);
        }
        if let Some(n) = self.study_frame
            && !self.studio.study_panel().busy()
            && self.studio.study_panel().frames().len() > n
        {
            self.studio.study_panel_mut().frame = n;
            self.study_frame = None;
        }
        self.studio.ui(ui);
        let Some(path) = self.screenshot.clone() else {
            return;
        };
        let ctx = ui.ctx().clone();
        self.frames = self.frames.saturating_sub(1);
        let taken = self.shot.lock().ok().and_then(|mut s| s.take());
        if let Some(img) = taken {
            let [w, h] = img.size;
            let bytes: Vec<u8> = img.pixels.iter().flat_map(|c| c.to_array()).collect();
            let result = image::RgbaImage::from_raw(w as u32, h as u32, bytes)
                .context("screenshot has a wrong size")
                .and_then(|i| {
                    i.save(&path)
                        .with_context(|| format!("cannot write {}", path.display()))
                });
            if let Err(e) = result {
                eprintln!("{e:#}");
            }
            ctx.send_viewport_cmd(egui::ViewportCommand::Close);
        } else if !self.requested && self.frames == 0 && self.studio.is_idle() {
            let shot = Arc::clone(&self.shot);
            let wake = ctx.clone();
            ctx.request_screenshot(move |img| {
                if let Ok(mut s) = shot.lock() {
                    *s = Some(img);
                }
                wake.request_repaint();
            });
            self.requested = true;
        }
        ctx.request_repaint();
    }

    fn clear_color(&self, visuals: &egui::Visuals) -> [f32; 4] {
        window::clear_colour(visuals)
    }

    fn on_exit(&mut self, _gl: Option<&eframe::glow::Context>) {
        self.studio.on_exit();
    }
}

fn run_headless(mut studio: Studio) -> anyhow::Result<()> {
    let ctx = egui::Context::default();
    let start = std::time::Instant::now();
    loop {
        let input = egui::RawInput {
            screen_rect: Some(egui::Rect::from_min_size(
                egui::Pos2::ZERO,
                egui::vec2(1280.0, 800.0),
            )),
            time: Some(start.elapsed().as_secs_f64()),
            ..Default::default()
        };
        let mut output = ctx.run_ui(input, |ui| studio.ui(ui));
        // No renderer: the texture uploads are dropped on purpose.
        output.textures_delta.clear();
        std::thread::sleep(std::time::Duration::from_millis(16));
    }
}

fn main() -> anyhow::Result<()> {
    let args = Args::parse();
    photomontage::photo::DecodeLimits::set_for_process(
        photomontage::photo::DecodeLimits::from_megapixels_and_mib(
            args.max_photo_megapixels,
            args.max_decode_memory_mib,
        )?,
    )?;
    let site = args.site.clone().unwrap_or_else(default_site_path);
    let options = StudioOptions {
        site_path: site,
        state_path: if args.headless || args.screenshot.is_some() {
            None
        } else {
            state::default_state_path()
        },
    };
    let mut studio = Studio::new(options);
    studio.set_host_clears_to_panel_fill(!args.headless);
    if let Some(script) = &args.script {
        apply_script(&mut studio, script)?;
    }
    if let Some(tab) = &args.tab {
        studio.select_tab(tab).map_err(anyhow::Error::msg)?;
    }
    if let (Some(dates), Some(times)) = (&args.study_dates, &args.study_times) {
        let panel = studio.study_panel_mut();
        panel.dates.clone_from(dates);
        panel.times.clone_from(times);
        panel.shadow_maps = args.study_shadow_maps;
        panel.montages = !args.study_no_montages;
        if args.study_shadow_maps {
            panel.show = photomontage_studio::study_panel::PreviewKind::ShadowMap;
        }
    }
    if args.headless {
        return run_headless(studio);
    }
    let native = window::native_options([1400.0, 860.0], "photomontage studio");
    let shell = Shell {
        studio,
        frames: args.frames.max(1),
        screenshot: args.screenshot,
        shot: Arc::new(Mutex::new(None)),
        requested: false,
        solve_on_start: args.solve,
        study_on_start: args.study_dates.is_some(),
        study_frame: args.study_frame,
        variants_on_start: args.render_variants,
        elevation_on_start: args.elevation.then_some(args.elevation_irradiance),
        light_render_settings: args.light_render_settings,
    };
    eframe::run_native(
        "photomontage studio",
        native,
        Box::new(move |_cc| Ok(Box::new(shell))),
    )
    .map_err(|e| anyhow::anyhow!("cannot start the studio window: {e}"))
}

#[cfg(test)]
mod tests {
    #![allow(clippy::unwrap_used, clippy::expect_used)]

    use super::*;
    use clap::CommandFactory as _;

    #[test]
    fn arguments_parse_as_documented() {
        Args::command().debug_assert();
        let a = Args::try_parse_from(["studio"]).unwrap();
        assert!(a.site.is_none() && a.screenshot.is_none() && !a.headless && !a.solve);
        assert_eq!(a.frames, 10);
        let a = Args::try_parse_from([
            "studio",
            "s.toml",
            "--screenshot",
            "x.png",
            "--frames",
            "3",
            "--solve",
        ])
        .unwrap();
        assert_eq!(a.site, Some(PathBuf::from("s.toml")));
        assert_eq!(a.screenshot, Some(PathBuf::from("x.png")));
        assert_eq!(a.frames, 3);
        assert!(a.solve);
        let a = Args::try_parse_from(["studio", "--headless", "--script", "e.txt"]).unwrap();
        assert!(a.headless && a.script == Some(PathBuf::from("e.txt")));
        // Refused: frames without a screenshot, headless with a screenshot, two sites, a
        // frame count that is not a whole number.
        for bad in [
            &["studio", "--frames", "3"][..],
            &["studio", "--headless", "--screenshot", "x.png"],
            &["studio", "a.toml", "b.toml"],
            &["studio", "--screenshot", "x.png", "--frames", "many"],
        ] {
            assert!(Args::try_parse_from(bad).is_err(), "{bad:?} accepted");
        }
    }
}
