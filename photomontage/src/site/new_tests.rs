use super::*;

/// Focal lengths computed here and by the library from the same f64 inputs in the same order
/// agree to rounding; 1e-9 px is ~1e-12 relative for these sizes.
const FOCAL_TOL_PX: f64 = 1e-9;

/// A minimal little-endian EXIF block (TIFF header, IFD0 with the Exif IFD pointer, an Exif IFD
/// with DateTimeOriginal, optionally OffsetTimeOriginal, and FocalLengthIn35mmFilm), laid out
/// by hand after CIPA DC-008 §4.5–4.6.
fn exif_tiff(focal_35mm: u16, date_time: &str, offset: Option<&str>) -> Vec<u8> {
    let n_exif: u16 = if offset.is_some() { 3 } else { 2 };
    let ifd0_at = 8u32;
    let exif_at = ifd0_at + 2 + 12 + 4;
    let data_at = exif_at + 2 + 12 * u32::from(n_exif) + 4;
    let mut dt = date_time.as_bytes().to_vec();
    dt.push(0);
    let offset_bytes = offset.map(|o| {
        let mut b = o.as_bytes().to_vec();
        b.push(0);
        b
    });
    let mut t = Vec::new();
    t.extend_from_slice(b"II*\0");
    t.extend_from_slice(&ifd0_at.to_le_bytes());
    let entry = |t: &mut Vec<u8>, tag: u16, kind: u16, count: u32, value: [u8; 4]| {
        t.extend_from_slice(&tag.to_le_bytes());
        t.extend_from_slice(&kind.to_le_bytes());
        t.extend_from_slice(&count.to_le_bytes());
        t.extend_from_slice(&value);
    };
    // IFD0: ExifIFDPointer (0x8769, LONG).
    t.extend_from_slice(&1u16.to_le_bytes());
    entry(&mut t, 0x8769, 4, 1, exif_at.to_le_bytes());
    t.extend_from_slice(&0u32.to_le_bytes());
    // Exif IFD, tags ascending.
    t.extend_from_slice(&n_exif.to_le_bytes());
    entry(&mut t, 0x9003, 2, dt.len() as u32, data_at.to_le_bytes());
    if let Some(o) = &offset_bytes {
        let at = data_at + dt.len() as u32;
        entry(&mut t, 0x9011, 2, o.len() as u32, at.to_le_bytes());
    }
    let f = focal_35mm.to_le_bytes();
    entry(&mut t, 0xA405, 3, 1, [f[0], f[1], 0, 0]);
    t.extend_from_slice(&0u32.to_le_bytes());
    t.extend_from_slice(&dt);
    if let Some(o) = &offset_bytes {
        t.extend_from_slice(o);
    }
    t
}

/// A `w`×`h` JPEG with `tiff` as its APP1 EXIF segment.
fn jpeg_with_exif(path: &Path, w: u32, h: u32, tiff: &[u8]) {
    let img = image::RgbImage::from_fn(w, h, |x, y| image::Rgb([(x * 3) as u8, (y * 5) as u8, 90]));
    let mut jpeg = Vec::new();
    image::codecs::jpeg::JpegEncoder::new(&mut jpeg)
        .encode_image(&img)
        .unwrap();
    assert_eq!(&jpeg[..2], &[0xFF, 0xD8]);
    let mut out = jpeg[..2].to_vec();
    out.extend_from_slice(&[0xFF, 0xE1]);
    out.extend_from_slice(&((2 + 6 + tiff.len()) as u16).to_be_bytes());
    out.extend_from_slice(b"Exif\0\0");
    out.extend_from_slice(tiff);
    out.extend_from_slice(&jpeg[2..]);
    std::fs::write(path, out).unwrap();
}

fn png(path: &Path, w: u32, h: u32) {
    if let Some(d) = path.parent() {
        std::fs::create_dir_all(d).unwrap();
    }
    image::RgbImage::new(w, h).save(path).unwrap();
}

#[test]
fn exif_focal_time_size_and_relative_paths() {
    let dir = tempfile::tempdir().unwrap();
    let a = dir.path().join("IMG 1.jpg");
    jpeg_with_exif(
        &a,
        60,
        40,
        &exif_tiff(50, "2024:06:21 15:00:00", Some("+02:00")),
    );
    let b = dir.path().join("photos/b.png");
    png(&b, 30, 40);
    let site_path = dir.path().join("new.toml");
    let new = site_from_photos(&site_path, &[a.clone(), b.clone()]).unwrap();
    let site = &new.document.site;
    assert_eq!(site.name, "new");
    assert_eq!(site.photos.len(), 2);

    let pa = &site.photos[0];
    assert_eq!((pa.id.as_str(), pa.file.as_str()), ("IMG 1", "IMG 1.jpg"));
    assert_eq!(pa.taken_at.as_deref(), Some("2024-06-21T15:00:00+02:00"));
    let ia = pa.interior.as_ref().unwrap();
    assert_eq!(ia.image_size_px, Some([60, 40]));
    assert_eq!(ia.principal_point_px, None, "image centre");
    // 35 mm equivalent: f_px = f35 · diagonal_px / 43.2666 mm.
    let expected = 50.0 * 60f64.hypot(40.0) / 43.266_615_305_567_87;
    assert!(
        (ia.focal_px - expected).abs() < FOCAL_TOL_PX,
        "{}",
        ia.focal_px
    );
    assert_eq!(
        new.focal_origins[0],
        FocalOrigin::Exif(FocalSource::Equivalent35mm)
    );
    assert!(!pa.self_calibration.focal, "EXIF focal kept fixed");

    let pb = &site.photos[1];
    assert_eq!((pb.id.as_str(), pb.file.as_str()), ("b", "photos/b.png"));
    assert_eq!(pb.taken_at, None);
    let ib = pb.interior.as_ref().unwrap();
    assert_eq!(ib.image_size_px, Some([30, 40]));
    // Fallback: the diagonal of a 30×40 image is exactly 50 px.
    assert!((ib.focal_px - 50.0).abs() < FOCAL_TOL_PX);
    assert_eq!(new.focal_origins[1], FocalOrigin::Fallback);
    assert!(pb.self_calibration.focal, "fallback focal is estimated");
    assert!(matches!(&new.warnings[..], [
        NewSiteWarning::NoExif { photo: p1, .. },
        NewSiteWarning::NoFocalLength { photo: p2, fallback_focal_px },
    ] if p1 == "b" && p2 == "b" && (fallback_focal_px - 50.0).abs() < FOCAL_TOL_PX));
    assert!(new.warnings[1].to_string().contains("50.0 px"));

    // Saved atomically, it loads back equal and its paths resolve to the photos.
    new.save_new().unwrap();
    let loaded = SiteDocument::load(&site_path).unwrap();
    assert_eq!(&loaded.site, site);
    assert_eq!(
        std::fs::canonicalize(loaded.resolve(&loaded.site.photos[1].file)).unwrap(),
        std::fs::canonicalize(&b).unwrap()
    );
    // Never over an existing file.
    let before = std::fs::read(&site_path).unwrap();
    assert!(matches!(
        create_site(&site_path, std::slice::from_ref(&b)),
        Err(NewSiteError::SiteFileExists { .. })
    ));
    assert!(matches!(
        new.save_new(),
        Err(NewSiteError::SiteFileExists { .. })
    ));
    assert_eq!(std::fs::read(&site_path).unwrap(), before);
}

#[test]
fn unique_ids_parent_paths_and_a_time_without_offset() {
    let dir = tempfile::tempdir().unwrap();
    let x1 = dir.path().join("day1/x.png");
    let x2 = dir.path().join("day2/x.png");
    png(&x1, 8, 6);
    png(&x2, 8, 6);
    let t = dir.path().join("day2/t.jpg");
    jpeg_with_exif(&t, 16, 16, &exif_tiff(28, "2020:01:02 03:04:05", None));
    std::fs::create_dir(dir.path().join("sites")).unwrap();
    let site_path = dir.path().join("sites/s.toml");
    let new = create_site(&site_path, &[x1, x2, t]).unwrap();
    let site = SiteDocument::load(&site_path).unwrap().site;
    let ids: Vec<_> = site.photos.iter().map(|p| p.id.as_str()).collect();
    assert_eq!(ids, ["x", "x_2", "t"]);
    let files: Vec<_> = site.photos.iter().map(|p| p.file.as_str()).collect();
    assert_eq!(files, ["../day1/x.png", "../day2/x.png", "../day2/t.jpg"]);
    assert_eq!(site.photos[2].taken_at, None);
    assert!(new.warnings.iter().any(|w| matches!(w,
        NewSiteWarning::TimeWithoutOffset { photo, date_time }
        if photo == "t" && date_time == "2020:01:02 03:04:05")));
    // 28 mm equivalent on a square 16 px image.
    let f = site.photos[2].interior.as_ref().unwrap().focal_px;
    assert!((f - 28.0 * 16f64.hypot(16.0) / 43.266_615_305_567_87).abs() < FOCAL_TOL_PX);
}

#[test]
fn errors_name_what_is_wrong_and_write_nothing() {
    let dir = tempfile::tempdir().unwrap();
    let p = dir.path().join("photos/p.png");
    png(&p, 4, 4);
    let site_path = dir.path().join("s.toml");
    assert!(matches!(
        site_from_photos(&site_path, &[]),
        Err(NewSiteError::NoPhotos)
    ));
    let same = dir.path().join("photos/./p.png");
    let e = site_from_photos(&site_path, &[p.clone(), same]).unwrap_err();
    assert!(matches!(e, NewSiteError::DuplicatePhoto { .. }), "{e}");
    assert!(e.to_string().contains("p.png"));
    let missing = dir.path().join("photos/none.jpg");
    let e = site_from_photos(&site_path, &[missing]).unwrap_err();
    assert!(
        matches!(e, NewSiteError::Photo(PhotoError::Missing { .. })),
        "{e}"
    );
    let bad = dir.path().join("bad.jpg");
    std::fs::write(&bad, b"\xff\xd8\xff\xe0 not a jpeg").unwrap();
    let e = create_site(&site_path, &[p.clone(), bad]).unwrap_err();
    assert!(
        matches!(e, NewSiteError::Photo(PhotoError::Decode { .. })),
        "{e}"
    );
    let e = create_site(
        &dir.path().join("no/such/folder/s.toml"),
        std::slice::from_ref(&p),
    )
    .unwrap_err();
    assert!(matches!(e, NewSiteError::NoSiteFolder { .. }), "{e}");
    assert!(!site_path.exists(), "nothing written on error");
    let too_many = vec![p; MAX_PHOTOS + 1];
    assert!(matches!(
        site_from_photos(&site_path, &too_many),
        Err(NewSiteError::TooManyPhotos { .. })
    ));
}

#[test]
fn relative_paths_climb_with_dot_dot() {
    let r = |b: &str, t: &str| relative_path(Path::new(b), Path::new(t));
    assert_eq!(r("/a/b", "/a/b/c/d.jpg"), PathBuf::from("c/d.jpg"));
    assert_eq!(r("/a/b", "/a/x/d.jpg"), PathBuf::from("../x/d.jpg"));
    assert_eq!(r("/a/b/c", "/d.jpg"), PathBuf::from("../../../d.jpg"));
}
