//! Parts written, read back and merged on synthetic images (the renderer's own band test is in
//! `render/tests.rs`): the merge is exact, and every bad set of parts is refused by name.

use super::*;
use crate::colour::ToneMap;
use crate::render::output::{write_exr, write_output};

const SIZE_PX: [u32; 2] = [13, 10];
const TILE_PX: u32 = 2;

/// A whole image with every layer, values all distinct (so a misplaced pixel shows).
fn whole() -> (RenderedImage, OutputLayers) {
    let n = (SIZE_PX[0] * SIZE_PX[1]) as usize;
    #[allow(clippy::cast_precision_loss)]
    let v = |i: usize, k: usize| (i * 4 + k) as f32 * 0.013 - 0.2;
    let image = RenderedImage {
        size_px: SIZE_PX,
        rgba: (0..n)
            .map(|i| [v(i, 0), v(i, 1), v(i, 2), v(i, 3)])
            .collect(),
        changed_pixels: 17,
        primary_rays: 4 * n as u64,
    };
    #[allow(clippy::cast_precision_loss)]
    let layers = OutputLayers {
        depth_m: Some(
            (0..n)
                .map(|i| if i % 7 == 0 { f32::INFINITY } else { i as f32 })
                .collect(),
        ),
        object_id: Some((0..n).map(|i| (i % 3) as f32 - 1.0).collect()),
        shadow_change_rgb: Some(
            (0..n)
                .map(|i| [-(i as f32), 0.5, i as f32 * 1e-3])
                .collect(),
        ),
    };
    (image, layers)
}

fn identity(seed: &str) -> BTreeMap<String, String> {
    [("site_sha256", "ab12"), ("view", "V1"), ("seed", seed)]
        .into_iter()
        .map(|(k, v)| (k.to_owned(), v.to_owned()))
        .collect()
}

/// Cuts `whole()` into `count` bands and writes them into `dir`; returns the paths in order.
fn write_bands(dir: &Path, count: u32, seed: &str) -> Vec<PathBuf> {
    let (image, layers) = whole();
    let w = SIZE_PX[0] as usize;
    (1..=count)
        .map(|i| {
            let band = Band::new(i, count).unwrap();
            let rows = band.pixel_rows(SIZE_PX[1], TILE_PX).unwrap();
            let range = rows.start as usize * w..rows.end as usize * w;
            let cut = |v: &Option<Vec<f32>>| v.as_ref().map(|v| v[range.clone()].to_vec());
            let part_image = RenderedImage {
                size_px: [SIZE_PX[0], rows.end - rows.start],
                rgba: image.rgba[range.clone()].to_vec(),
                changed_pixels: 1,
                primary_rays: 2,
            };
            let part_layers = OutputLayers {
                depth_m: cut(&layers.depth_m),
                object_id: cut(&layers.object_id),
                shadow_change_rgb: layers
                    .shadow_change_rgb
                    .as_ref()
                    .map(|v| v[range.clone()].to_vec()),
            };
            let info = PartInfo {
                format: PART_FORMAT.into(),
                tile: band.to_string(),
                full_size_px: SIZE_PX,
                rows_px: [rows.start, rows.end],
                identity: identity(seed),
                exposure: 1.5,
                object_names: Some(vec!["polygon:ground".into(), "model:Ü".into()]),
                changed_pixels: 1,
                primary_rays: 2,
                view_json: None,
            };
            let path = dir.join(format!("{seed}-{i}-of-{count}.exr"));
            write_part(&path, &part_image, &part_layers, &info).unwrap();
            path
        })
        .collect()
}

#[test]
fn merged_parts_are_the_whole_image_bit_for_bit_in_any_order() {
    let dir = tempfile::tempdir().unwrap();
    let (image, layers) = whole();
    let whole_exr = dir.path().join("whole.exr");
    write_exr(&whole_exr, &image, &layers).unwrap();
    for count in [1, 2, 4] {
        let mut paths = write_bands(dir.path(), count, "0");
        paths.reverse();
        let merged = merge_parts(&paths).unwrap();
        assert_eq!(merged.image.rgba, image.rgba, "{count} bands");
        assert_eq!(merged.image.changed_pixels, count as usize);
        let bits = |v: &Option<Vec<f32>>| {
            v.as_ref()
                .unwrap()
                .iter()
                .map(|x| x.to_bits())
                .collect::<Vec<_>>()
        };
        assert_eq!(bits(&merged.layers.depth_m), bits(&layers.depth_m));
        assert_eq!(merged.layers.object_id, layers.object_id);
        assert_eq!(merged.layers.shadow_change_rgb, layers.shadow_change_rgb);
        assert_eq!(merged.info.object_names.as_ref().unwrap()[1], "model:Ü");
        assert!((merged.info.exposure - 1.5).abs() < f64::EPSILON);
        let out = dir.path().join(format!("merged-{count}.exr"));
        write_output(&out, &merged.image, &merged.layers, &ToneMap::clamp()).unwrap();
        assert_eq!(
            std::fs::read(&out).unwrap(),
            std::fs::read(&whole_exr).unwrap()
        );
    }
}

#[test]
fn a_part_header_is_read_without_its_pixels_and_knows_its_band() {
    let dir = tempfile::tempdir().unwrap();
    let paths = write_bands(dir.path(), 4, "0");
    let info = read_part_info(&paths[2]).unwrap();
    assert_eq!(info.band().unwrap(), Band::new(3, 4).unwrap());
    assert_eq!(info.full_size_px, SIZE_PX);
    let part = read_part(&paths[2]).unwrap();
    assert_eq!(part.image.size_px[1], info.rows_px[1] - info.rows_px[0]);
}

#[test]
fn missing_duplicate_and_foreign_parts_are_named() {
    let dir = tempfile::tempdir().unwrap();
    let paths = write_bands(dir.path(), 4, "0");
    let err = merge_parts(&[paths[0].clone(), paths[2].clone()]).unwrap_err();
    assert!(
        matches!(&err, PartError::Missing { missing, count: 4 } if missing == &[2, 4]),
        "{err}"
    );
    assert!(err.to_string().contains("missing tiles 2, 4 of 4"), "{err}");

    let err = merge_parts(&[paths[0].clone(), paths[1].clone(), paths[1].clone()]).unwrap_err();
    assert!(err.to_string().contains("tile 2/4 is given twice"), "{err}");

    let other_seed = write_bands(dir.path(), 4, "7");
    let mixed = [
        paths[0].clone(),
        paths[1].clone(),
        other_seed[2].clone(),
        paths[3].clone(),
    ];
    let err = merge_parts(&mixed).unwrap_err();
    let text = err.to_string();
    assert!(matches!(err, PartError::Foreign { .. }), "{text}");
    assert!(
        text.contains("its seed is `7`") && text.contains("has `0`"),
        "{text}"
    );
    assert!(text.contains("7-3-of-4.exr"), "{text}");

    let halves = write_bands(dir.path(), 2, "0");
    let err = merge_parts(&[paths[0].clone(), halves[1].clone()]).unwrap_err();
    assert!(err.to_string().contains("tile count"), "{err}");

    assert!(matches!(merge_parts(&[]), Err(PartError::NoParts)));
}

#[test]
fn files_that_are_not_parts_are_refused_by_name() {
    let dir = tempfile::tempdir().unwrap();
    let (image, layers) = whole();
    let plain = dir.path().join("plain.exr");
    write_exr(&plain, &image, &layers).unwrap();
    let err = merge_parts(&[plain]).unwrap_err();
    assert!(matches!(err, PartError::NotAPart { .. }), "{err}");
    assert!(
        err.to_string()
            .contains("plain.exr is not a photomontage part"),
        "{err}"
    );

    let garbage = dir.path().join("garbage.exr");
    std::fs::write(&garbage, b"not an exr at all").unwrap();
    let err = merge_parts(&[garbage]).unwrap_err();
    assert!(matches!(err, PartError::Read { .. }), "{err}");

    let missing = dir.path().join("nope.exr");
    let err = merge_parts(&[missing]).unwrap_err();
    assert!(err.to_string().contains("nope.exr"), "{err}");
}

#[test]
fn a_band_image_that_does_not_fit_its_rows_is_not_written() {
    let dir = tempfile::tempdir().unwrap();
    let (image, layers) = whole();
    let info = PartInfo {
        format: PART_FORMAT.into(),
        tile: "1/2".into(),
        full_size_px: SIZE_PX,
        rows_px: [0, 4],
        identity: identity("0"),
        exposure: 1.0,
        object_names: None,
        changed_pixels: 0,
        primary_rays: 0,
        view_json: None,
    };
    let path = dir.path().join("bad.exr");
    assert!(write_part(&path, &image, &layers, &info).is_err());
    assert!(!path.exists());
}
