//! The Study tab driven by its labels on a small hand-made site (a uniform photo of a ground
//! plane with a black 1 m box, the CLI tests' site, placed in Zurich with
//! `time_zone = "Europe/Zurich"`): a 3-frame study's frames are bit for bit single renders of
//! their times through `RenderPlan` (and its exported PNGs byte for byte the same renders written
//! by the library), each frame's sun is the SPA's, the preview scrubs and plays through the
//! frames with their captions; a cancelled study keeps and writes nothing; a study with no
//! daylight frame shows the library's message and writes nothing.

#![allow(clippy::unwrap_used, clippy::expect_used)]

mod common;

use std::path::{Path, PathBuf};
use std::sync::atomic::AtomicBool;

use common::step_until;
use egui_kittest::Harness;
use egui_kittest::kittest::Queryable;
use photomontage::render::OutputLayers;
use photomontage::site::SiteDocument;
use photomontage::site::render_photo::{RenderPlan, RenderRequest};
use photomontage::site::site_time::site_solar_position;
use photomontage::study::StudyError;
use photomontage::verified::image_metadata::{view_metadata, write_render};
use photomontage_studio::Studio;

const SIZE_PX: [u32; 2] = [96, 64];
const WINDOW: [f32; 2] = [1400.0, 900.0];

/// The CLI tests' site (`photomontage/tests/common`) in Zurich, `size_px` wide and high.
fn make_site(dir: &Path, size_px: [u32; 2]) -> PathBuf {
    image::RgbImage::from_pixel(size_px[0], size_px[1], image::Rgb([150, 140, 130]))
        .save(dir.join("p1.png"))
        .unwrap();
    std::fs::write(
        dir.join("box.obj"),
        "mtllib box.mtl\nusemtl black\nv 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 0 0 1\nv 1 0 1\n\
         v 1 1 1\nv 0 1 1\nf 1 4 3 2\nf 5 6 7 8\nf 1 2 6 5\nf 2 3 7 6\nf 3 4 8 7\nf 4 1 5 8\n",
    )
    .unwrap();
    std::fs::write(dir.join("box.mtl"), "newmtl black\nKd 0 0 0\n").unwrap();
    let site = dir.join("site.toml");
    let [w, h] = size_px;
    std::fs::write(
        &site,
        format!(
            r#"schema_version = 1
name = "study test"

[location]
latitude_deg = 47.3769
longitude_deg = 8.5417
time_zone = "Europe/Zurich"

[lighting]
sky_model = "uniform"
sun_weight = [2.0, 2.0, 2.0]
ambient_weight = [0.1, 0.1, 0.1]
sky_weight = [0.0, 0.0, 0.0]
sun_manual = {{ azimuth_deg = 135.0, elevation_deg = 40.0 }}

[render]
spp_min = 4
spp_max = 8
seed = 7

[[photos]]
id = "p1"
file = "p1.png"

[photos.interior]
focal_px = 160.0
image_size_px = [{w}, {h}]

[photos.exterior]
camera_center = [0.5, -10.0, 1.5]
rotation_world_from_camera = [[1.0, 0.0, 0.0], [0.0, 0.0, 1.0], [0.0, -1.0, 0.0]]

[[control_points]]
id = "a"
xyz = [-10.0, -10.0, 0.0]

[[control_points]]
id = "b"
xyz = [10.0, -10.0, 0.0]

[[control_points]]
id = "c"
xyz = [10.0, 10.0, 0.0]

[[control_points]]
id = "d"
xyz = [-10.0, 10.0, 0.0]

[[polygons]]
id = "ground"
vertices = ["a", "b", "c", "d"]
material = "asphalt"
image = "p1"

[[models]]
id = "box"
file = "box.obj"

[models.placement]
scale = 1.0
"#
        ),
    )
    .unwrap();
    site
}

fn bits(im: &photomontage::render::RenderedImage) -> Vec<u32> {
    im.rgba.iter().flatten().map(|v| v.to_bits()).collect()
}

/// Opens the Study tab and types `dates` and `times` into its fields by their labels.
fn study_tab(h: &mut Harness<'static, Studio>, dates: &str, times: &str) {
    h.get_by_label("Study tab").click();
    h.run();
    let panel = h.state_mut().study_panel_mut();
    panel.dates.clear();
    panel.times.clear();
    h.run();
    h.get_by_label("study dates").click();
    h.get_by_label("study dates").type_text(dates);
    h.run();
    h.get_by_label("study times").click();
    h.get_by_label("study times").type_text(times);
    h.run();
    assert_eq!(h.state().study_panel().dates, dates);
    assert_eq!(h.state().study_panel().times, times);
}

fn run_study(h: &mut Harness<'static, Studio>, what: &str) {
    let before = h.state().messages().len();
    h.get_by_label("Run study").click();
    step_until(h, what, |s| {
        !s.study_panel().busy() && s.messages().len() > before + 1
    });
}

#[test]
fn a_three_frame_study_is_three_single_renders_and_its_preview_scrubs_and_plays() {
    let dir = tempfile::tempdir().unwrap();
    let site = make_site(dir.path(), SIZE_PX);
    let mut h = common::harness(&site, WINDOW);
    study_tab(&mut h, "2026-06-21", "09:00,12:00,15:00");
    run_study(&mut h, "study");
    let last = h.state().messages().last().unwrap().clone();
    assert!(!last.is_error, "{}", last.text);
    assert!(last.text.contains("3 frame(s) made"), "{}", last.text);

    // Each frame against one render of its time through the library's one entry point.
    let doc = SiteDocument::load(&site).unwrap();
    let times = [
        "2026-06-21T09:00:00+02:00",
        "2026-06-21T12:00:00+02:00",
        "2026-06-21T15:00:00+02:00",
    ];
    let result = h.state().study_panel().result().expect("a finished study");
    assert_eq!(result.outputs.len(), 3);
    let mut singles = Vec::new();
    for (out, time) in result.outputs.iter().zip(times) {
        assert_eq!(out.frame.time_rfc3339(), time);
        let mut single = doc.clone();
        single.site.lighting.time = Some(time.to_owned());
        single.site.lighting.sun_manual = None;
        let plan = RenderPlan::new(&single, &RenderRequest::view("p1")).unwrap();
        let photo = plan
            .render(&single, &|_| {}, &AtomicBool::new(false))
            .unwrap();
        let montage = out.montage.as_ref().expect("a montage");
        assert!(
            bits(&montage.photo.image) == bits(&photo.image),
            "frame {time} differs from the single render"
        );
        let sun = site_solar_position(&single.site, &out.frame.time, "p1").unwrap();
        assert_eq!(
            out.frame.sun_azimuth_deg.to_bits(),
            sun.azimuth_deg.to_bits(),
            "{time}"
        );
        assert_eq!(
            out.frame.sun_elevation_deg.to_bits(),
            sun.elevation_deg.to_bits(),
            "{time}"
        );
        singles.push((single, plan, photo));
    }

    // The preview: three frames, captioned with local time and sun; scrub, then play.
    assert_eq!(h.state().study_panel().frames().len(), 3);
    let caption = h.state().study_panel().caption().unwrap();
    assert!(
        caption.starts_with("2026-06-21 09:00 (UTC+02:00)  sun azimuth"),
        "{caption}"
    );
    h.get_by_label_contains("1/3  2026-06-21 09:00");
    h.state_mut().study_panel_mut().frame = 2;
    h.run();
    h.get_by_label_contains("3/3  2026-06-21 15:00");
    let f = &result_frame(&h, 2);
    assert!(
        h.state()
            .study_panel()
            .caption()
            .unwrap()
            .contains(&format!("azimuth {:.1}°, elevation {:.1}°", f.0, f.1)),
        "{:?}",
        h.state().study_panel().caption()
    );
    h.get_by_label("Play/Pause").click();
    h.run();
    assert!(h.state().study_panel().playing);
    let start = std::time::Instant::now();
    while h.state().study_panel().frame == 2 {
        h.step();
        std::thread::sleep(std::time::Duration::from_millis(20));
        assert!(start.elapsed().as_secs() < 30, "the preview does not play");
    }
    assert_eq!(
        h.state().study_panel().frame,
        0,
        "playing wraps to the first frame"
    );
    h.get_by_label("Play/Pause").click();
    h.run();
    assert!(!h.state().study_panel().playing);

    // Export: a new folder with the frames byte for byte the single renders as written by
    // the library, and the contact sheet.
    let out = dir.path().join("study out");
    h.state_mut().study_panel_mut().export_folder = out.display().to_string();
    h.run();
    h.get_by_label("Export study").click();
    h.run();
    let last = h.state().messages().last().unwrap().clone();
    assert!(!last.is_error, "{}", last.text);
    let reference = dir.path().join("reference.png");
    for ((single, plan, photo), stem) in singles.iter().zip(["0900", "1200", "1500"]) {
        write_render(
            &reference,
            &photo.image,
            &OutputLayers::default(),
            &plan.tone_map(),
            view_metadata(single, "p1").ok().as_ref(),
        )
        .unwrap();
        let exported = std::fs::read(out.join(format!("p1_2026-06-21_{stem}.png"))).unwrap();
        assert!(
            exported == std::fs::read(&reference).unwrap(),
            "exported frame {stem} differs from the single render's PNG"
        );
    }
    let sheet = image::open(out.join("p1_contact_sheet.png")).unwrap();
    assert!(sheet.width() > 3 * photomontage::study::contact_sheet::THUMB_WIDTH_PX);
    let mut names: Vec<String> = std::fs::read_dir(&out)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    names.sort();
    assert_eq!(
        names,
        [
            "p1_2026-06-21_0900.png",
            "p1_2026-06-21_1200.png",
            "p1_2026-06-21_1500.png",
            "p1_contact_sheet.png"
        ]
    );
    // Nothing else beside the folder (the staging folder was renamed into place).
    let beside: Vec<_> = std::fs::read_dir(dir.path())
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .filter(|n| n.contains("partial"))
        .collect();
    assert!(beside.is_empty(), "{beside:?}");
}

fn result_frame(h: &Harness<'static, Studio>, k: usize) -> (f64, f64) {
    let f = &h.state().study_panel().result().unwrap().outputs[k].frame;
    (f.sun_azimuth_deg, f.sun_elevation_deg)
}

#[test]
fn a_cancelled_study_keeps_and_writes_nothing() {
    let dir = tempfile::tempdir().unwrap();
    // Larger frames and six of them, so that the cancel lands while tiles are still to come.
    let site = make_site(dir.path(), [480, 320]);
    let mut h = common::harness(&site, WINDOW);
    study_tab(&mut h, "2026-06-21,2026-09-22", "09:00,12:00,15:00");
    let out = dir.path().join("cancelled");
    h.state_mut().study_panel_mut().export_folder = out.display().to_string();
    h.get_by_label("Run study").click();
    h.step();
    assert!(h.state().study_panel().busy());
    h.step();
    h.get_by_label("Cancel study").click();
    h.step();
    step_until(&mut h, "cancelled study", |s| !s.study_panel().busy());
    let last = h.state().messages().last().unwrap().clone();
    assert!(last.is_error, "{}", last.text);
    assert_eq!(last.text, StudyError::Cancelled.to_string());
    assert!(h.state().study_panel().result().is_none());
    assert!(h.state().study_panel().frames().is_empty());
    // Export stays disabled; the handler itself refuses too.
    h.get_by_label("Export study").click();
    h.run();
    assert!(!out.exists());
    assert_eq!(
        std::fs::read_dir(dir.path()).unwrap().count(),
        4,
        "only the site, photo, OBJ and MTL"
    );
}

#[test]
fn a_study_without_daylight_shows_the_library_message_and_writes_nothing() {
    let dir = tempfile::tempdir().unwrap();
    let site = make_site(dir.path(), SIZE_PX);
    let mut h = common::harness(&site, WINDOW);
    study_tab(&mut h, "2026-12-21", "00:30,23:30");
    let out = dir.path().join("night");
    h.state_mut().study_panel_mut().export_folder = out.display().to_string();
    h.get_by_label("Run study").click();
    h.step();
    assert!(!h.state().study_panel().busy());
    let last = h.state().messages().last().unwrap().clone();
    assert!(last.is_error);
    assert_eq!(last.text, StudyError::NoDaylight { asked: 2 }.to_string());
    assert!(h.state().study_panel().result().is_none());
    h.get_by_label("Export study").click();
    h.run();
    assert!(!out.exists());
}
