//! Every photo format the site accepts decodes to float RGB as displayed.
#![allow(clippy::unwrap_used)] // test helpers outside #[test] functions

use photomontage::photo::{self, Transfer};
use photomontage_tests::shared_file;

#[test]
fn exr_is_read_as_linear_float() {
    let Some(path) = shared_file("bench/data/mitsuba/llvm_ad_rgb_16spp_without_box.exr") else {
        return;
    };
    let img = photo::load(&path).unwrap();
    assert_eq!(img.transfer, Transfer::Linear);
    let meta: serde_json::Value = serde_json::from_str(
        &std::fs::read_to_string(shared_file("bench/data/mitsuba/scene.json").unwrap()).unwrap(),
    )
    .unwrap();
    let camera = &meta["camera"];
    assert_eq!(
        [u64::from(img.size_px()[0]), u64::from(img.size_px()[1])],
        [
            camera["width"].as_u64().unwrap(),
            camera["height"].as_u64().unwrap()
        ]
    );
    // Linear HDR values of a sunlit scene: finite and non-negative.
    assert!(
        img.pixels
            .pixels()
            .all(|p| p.0.iter().all(|v| v.is_finite() && *v >= 0.0))
    );
}

#[test]
fn tiff_and_jpeg_round_trip_through_the_loader() {
    let dir = tempfile::tempdir().unwrap();
    // A flat colour, so that JPEG's chroma subsampling cannot move it.
    let img = image::RgbImage::from_pixel(8, 4, image::Rgb([30, 60, 90]));
    for name in ["p.tif", "p.jpg", "p.png"] {
        let path = dir.path().join(name);
        img.save(&path).unwrap();
        let photo = photo::load(&path).unwrap();
        assert_eq!(photo.size_px(), [8, 4], "{name}");
        assert_eq!(photo.transfer, Transfer::Srgb);
        let p = photo.pixels.get_pixel(0, 0);
        // JPEG is lossy: within 3/255 on a flat colour (YCbCr rounding).
        for (got, want) in p.0.iter().zip([30.0f32, 60.0, 90.0]) {
            assert!((got - want / 255.0).abs() < 3.0 / 255.0, "{name}: {p:?}");
        }
    }
}
