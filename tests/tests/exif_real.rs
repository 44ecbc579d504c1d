//! EXIF and orientation on real camera JPEGs none of us wrote (`../shared/data/real/exif/`,
//! expected values read with exiftool, see SOURCES.md there).
#![allow(clippy::unwrap_used)] // test helpers outside #[test] functions

use photomontage::photo::{self, FocalSource};
use photomontage_tests::shared_file;

/// DMS values in SOURCES.md are given to 0.01″ ≈ 3e-6°.
const GPS_TOLERANCE_DEG: f64 = 1e-5;

#[test]
fn nikon_d70_focal_lengths() {
    let Some(path) = shared_file("data/real/exif/Nikon_D70.jpg") else {
        return;
    };
    let exif = photo::read_exif(&path).unwrap();
    assert_eq!(exif.focal_length_mm, Some(100.0));
    assert_eq!(exif.focal_length_35mm, Some(150.0));
}

#[test]
fn southern_hemisphere_gps_is_negative() {
    let Some(path) = shared_file("data/real/exif/Kodak_CX7530.jpg") else {
        return;
    };
    let gps = photo::read_exif(&path).unwrap().gps.unwrap();
    let lat = -(22.0 / 60.0 + 16.68 / 3600.0);
    let lon = 36.0 + 3.0 / 60.0 + 23.10 / 3600.0;
    assert!(
        (gps.latitude_deg - lat).abs() < GPS_TOLERANCE_DEG,
        "{gps:?}"
    );
    assert!(
        (gps.longitude_deg - lon).abs() < GPS_TOLERANCE_DEG,
        "{gps:?}"
    );
}

#[test]
fn coolpix_gps_north_east() {
    let Some(path) = shared_file("data/real/exif/DSCN0010.jpg") else {
        return;
    };
    let exif = photo::read_exif(&path).unwrap();
    let gps = exif.gps.unwrap();
    assert!((gps.latitude_deg - (43.0 + 28.0 / 60.0 + 2.81 / 3600.0)).abs() < GPS_TOLERANCE_DEG);
    assert!((gps.longitude_deg - (11.0 + 53.0 / 60.0 + 6.46 / 3600.0)).abs() < GPS_TOLERANCE_DEG);
    assert_eq!(exif.focal_length_35mm, Some(112.0));
}

#[test]
fn orientation_6_swaps_width_and_height() {
    let Some(path) = shared_file("data/real/exif/canon_hdr_NO.jpg") else {
        return;
    };
    assert_eq!(photo::read_exif(&path).unwrap().orientation, 6);
    // Stored 2048 × 1536, displayed rotated 90° clockwise.
    assert_eq!(photo::size_px(&path).unwrap(), [1536, 2048]);
    let img = photo::load(&path).unwrap();
    assert_eq!(img.size_px(), [1536, 2048]);
}

#[test]
fn orientation_test_images() {
    // portrait_6 is stored 600 × 450 and displays as 450 × 600; landscape_6 the reverse.
    let Some(p) = shared_file("data/real/exif/portrait_6.jpg") else {
        return;
    };
    assert_eq!(photo::size_px(&p).unwrap(), [450, 600]);
    let Some(l) = shared_file("data/real/exif/landscape_6.jpg") else {
        return;
    };
    assert_eq!(photo::size_px(&l).unwrap(), [600, 450]);
}

#[test]
fn focal_plane_resolution_in_centimetres() {
    // Fujifilm E500: FocalPlaneResolutionUnit = cm, 4000 px/cm = 400 px/mm.
    let Some(path) = shared_file("data/real/exif/Fujifilm_FinePix_E500.jpg") else {
        return;
    };
    let exif = photo::read_exif(&path).unwrap();
    let res = exif.focal_plane_px_per_mm.unwrap();
    assert!((res[0] - 400.0).abs() < 1e-9, "{res:?}");
}

#[test]
fn downscaled_copy_rescales_the_focal_plane_resolution() {
    // PowerShot S40: EXIF says 2272 × 1704 at 8114.29 px/inch, the file is 480 × 360.
    let Some(path) = shared_file("data/real/exif/Canon_PowerShot_S40.jpg") else {
        return;
    };
    let exif = photo::read_exif(&path).unwrap();
    let size = photo::size_px(&path).unwrap();
    assert_eq!(size, [480, 360]);
    let est = photo::initial_focal_px(&exif, size).unwrap();
    assert_eq!(est.source, FocalSource::FocalPlaneResolution);
    let expected = 21.3 * 8114.29 / 25.4 * 480.0 / 2272.0;
    // SOURCES.md rounds the focal length (21.3125 mm in the file) to 21.3: 6e-4 relative.
    assert!(
        (est.focal_px - expected).abs() / expected < 1e-3,
        "{est:?} vs {expected}"
    );
}

#[test]
fn copr_canon_450d_focal_in_pixels() {
    // Canon EOS 450D, 30 mm on a 22.2 mm wide sensor, 4272 px wide: 5773 px (±1 % for the
    // rounding of the sensor width in the spec sheet).
    let Some(path) = shared_file("data/real/gcp/odm_data_copr/IMG_0031.jpg") else {
        return;
    };
    let exif = photo::read_exif(&path).unwrap();
    let size = photo::size_px(&path).unwrap();
    let est = photo::initial_focal_px(&exif, size).unwrap();
    let expected = 30.0 * 4272.0 / 22.2;
    assert!((est.focal_px - expected).abs() / expected < 0.01, "{est:?}");
}

#[test]
fn files_without_exif_give_an_error_not_a_panic() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("plain.png");
    image_free_png(&path);
    assert!(photo::read_exif(&path).is_err());
}

/// A valid 1×1 PNG with no EXIF chunk, written without the image crate.
fn image_free_png(path: &std::path::Path) {
    const PNG_1X1: &[u8] = &[
        0x89, 0x50, 0x4E, 0x47, 0x0D, 0x0A, 0x1A, 0x0A, 0x00, 0x00, 0x00, 0x0D, 0x49, 0x48, 0x44,
        0x52, 0x00, 0x00, 0x00, 0x01, 0x00, 0x00, 0x00, 0x01, 0x08, 0x06, 0x00, 0x00, 0x00, 0x1F,
        0x15, 0xC4, 0x89, 0x00, 0x00, 0x00, 0x0D, 0x49, 0x44, 0x41, 0x54, 0x78, 0x9C, 0x63, 0x00,
        0x01, 0x00, 0x00, 0x05, 0x00, 0x01, 0x0D, 0x0A, 0x2D, 0xB4, 0x00, 0x00, 0x00, 0x00, 0x49,
        0x45, 0x4E, 0x44, 0xAE, 0x42, 0x60, 0x82,
    ];
    std::fs::write(path, PNG_1X1).unwrap();
}

/// What one file of `data/real/exif` must give.
enum Expect {
    /// A focal length in pixels, from this source, `focal_mm × long side px / width`.
    Px(FocalSource, f64),
    /// An error naming this tag.
    Missing(&'static str),
}

/// Diagonal of the 36 × 24 mm frame.
const DIAGONAL_35MM_MM: f64 = 43.266_615_305_567_87;

/// Same arithmetic on the same inputs; only the rounding of the spec values below (their
/// stated digits) separates them.
const FOCAL_TABLE_REL_TOL: f64 = 1e-3;

#[test]
fn every_sample_gives_a_focal_length_or_names_the_missing_tag() {
    use Expect::{Missing, Px};
    use FocalSource::{Equivalent35mm, FocalPlaneResolution, SensorTable};
    // Focal lengths (mm) from SOURCES.md (exiftool); sensor widths (mm) from the spec sheets
    // as in `photo::sensor_table`; long sides as stored. A stated 35 mm equivalent comes before
    // the table (image diagonal over 43.27 mm); the Samsung's model `<Digimax i50 MP3, Samsung
    // #1 MP3>` and `NIKON CORPORATION` also match the table (`photo::sensor_table`'s tests),
    // but their 35 mm tag wins.
    let table: [(&str, Expect); 15] = [
        ("Canon_40D.jpg", Px(SensorTable, 135.0 * 100.0 / 22.2)),
        // 8114.29 px/inch on the 2272-px original, rescaled to 480 px.
        (
            "Canon_PowerShot_S40.jpg",
            Px(
                FocalPlaneResolution,
                21.3125 * 8114.29 / 25.4 * 480.0 / 2272.0,
            ),
        ),
        (
            "DSCN0010.jpg",
            Px(Equivalent35mm, 112.0 * 800.0 / DIAGONAL_35MM_MM),
        ),
        // FocalPlaneResolutionUnit cm, but PixelXDimension was rewritten to the 100-px copy:
        // the implied 0.25 mm sensor is refused and the table used.
        (
            "Fujifilm_FinePix_E500.jpg",
            Px(SensorTable, 4.7 * 100.0 / 5.76),
        ),
        (
            "Kodak_CX7530.jpg",
            Px(
                Equivalent35mm,
                102.0 * 100.0f64.hypot(78.0) / DIAGONAL_35MM_MM,
            ),
        ),
        (
            "Nikon_D70.jpg",
            Px(
                Equivalent35mm,
                150.0 * 100.0f64.hypot(66.0) / DIAGONAL_35MM_MM,
            ),
        ),
        ("Olympus_C8080WZ.jpg", Px(SensorTable, 15.8 * 100.0 / 8.8)),
        (
            "Panasonic_DMC-FZ30.jpg",
            Px(Equivalent35mm, 82.0 * 125.0 / DIAGONAL_35MM_MM),
        ),
        // Make `PENTAX Corporation`, model `PENTAX K10D`: the case of issue 15.
        ("Pentax_K10D.jpg", Px(SensorTable, 90.0 * 100.0 / 23.5)),
        // Model `<Digimax i50 MP3, Samsung #1 MP3>`.
        (
            "Samsung_Digimax_i50_MP3.jpg",
            Px(Equivalent35mm, 39.0 * 125.0 / DIAGONAL_35MM_MM),
        ),
        // 8427.98 px/inch, 57.02 mm, 2048 px.
        (
            "canon_hdr_NO.jpg",
            Px(FocalPlaneResolution, 57.019 * 8427.98 / 25.4),
        ),
        ("landscape_3.jpg", Missing("FocalLength (tag 0x920A)")),
        ("landscape_6.jpg", Missing("FocalLength (tag 0x920A)")),
        ("nikon-e950.jpg", Px(SensorTable, 12.8 * 800.0 / 6.4)),
        ("portrait_6.jpg", Missing("FocalLength (tag 0x920A)")),
    ];
    let Some(dir) = shared_file("data/real/exif") else {
        return;
    };
    let mut on_disk: Vec<String> = std::fs::read_dir(&dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .filter(|n| n.ends_with(".jpg"))
        .collect();
    on_disk.sort();
    let mut listed: Vec<String> = table.iter().map(|(n, _)| (*n).to_owned()).collect();
    listed.sort();
    assert_eq!(on_disk, listed, "the table covers every file");
    for (name, expect) in &table {
        let path = dir.join(name);
        let exif = photo::read_exif(&path).unwrap();
        let got = photo::focal_px_from_exif(&exif, photo::size_px(&path).unwrap());
        match (expect, got) {
            (Px(source, px), Ok(est)) => {
                assert_eq!(est.source, *source, "{name}");
                assert!(
                    (est.focal_px - px).abs() / px < FOCAL_TABLE_REL_TOL,
                    "{name}: {} px vs {px} px",
                    est.focal_px
                );
                assert!(exif.focal_35mm_equiv_mm().is_some(), "{name}");
            }
            (Missing(tag), Err(e)) => {
                assert!(e.to_string().contains(tag), "{name}: {e}");
                assert!(exif.focal_35mm_equiv_mm().is_none(), "{name}");
            }
            (_, got) => panic!("{name}: {got:?}"),
        }
    }
}
