//! A new site from real camera JPEGs none of us wrote (`../shared/data/real/exif/`, values read
//! with exiftool, see SOURCES.md there): the focal length in pixels from the focal-plane
//! resolution rescaled to the stored size, the size as displayed (EXIF orientation applied),
//! the capture time of a 2008 camera that records no UTC offset (so no `taken_at`, a warning),
//! and paths relative to a site file in another folder that resolve to the same files.

use photomontage::photo::FocalSource;
use photomontage::site::SiteDocument;
use photomontage::site::new::{FocalOrigin, NewSiteWarning, create_site};
use photomontage_tests::shared_file;

/// SOURCES.md rounds the S40's focal length (21.3125 mm in the file) to 21.3 mm: 6e-4 relative;
/// 1e-3 covers that and the px/inch given to 0.01.
const FOCAL_REL_TOL: f64 = 1e-3;

#[test]
fn a_new_site_from_real_camera_jpegs() {
    let (Some(s40), Some(rotated), Some(eos40d)) = (
        shared_file("data/real/exif/Canon_PowerShot_S40.jpg"),
        shared_file("data/real/exif/canon_hdr_NO.jpg"),
        shared_file("data/real/exif/Canon_40D.jpg"),
    ) else {
        return;
    };
    let dir = tempfile::tempdir().expect("tempdir");
    let site_path = dir.path().join("real.toml");
    let new = create_site(&site_path, &[s40.clone(), rotated.clone(), eos40d.clone()])
        .expect("site from real photos");
    let doc = SiteDocument::load(&site_path).expect("saved site loads");
    assert_eq!(doc.site, new.document.site);
    let ids: Vec<&str> = doc.site.photos.iter().map(|p| p.id.as_str()).collect();
    assert_eq!(ids, ["Canon_PowerShot_S40", "canon_hdr_NO", "Canon_40D"]);
    for (p, file) in doc.site.photos.iter().zip([&s40, &rotated, &eos40d]) {
        assert!(
            p.file.starts_with(".."),
            "{} relative from the temp folder",
            p.file
        );
        assert_eq!(
            std::fs::canonicalize(doc.resolve(&p.file)).expect("resolves"),
            std::fs::canonicalize(file).expect("exists")
        );
    }

    // S40: EXIF says 2272 × 1704 at 8114.29 px/inch, the file is 480 × 360.
    let s40_interior = doc.site.photos[0].interior.as_ref().expect("interior");
    assert_eq!(s40_interior.image_size_px, Some([480, 360]));
    let expected = 21.3 * 8114.29 / 25.4 * 480.0 / 2272.0;
    assert!(
        (s40_interior.focal_px - expected).abs() / expected < FOCAL_REL_TOL,
        "{} vs {expected}",
        s40_interior.focal_px
    );
    assert_eq!(
        new.focal_origins[0],
        FocalOrigin::Exif(FocalSource::FocalPlaneResolution)
    );
    assert!(!doc.site.photos[0].self_calibration.focal);

    // Orientation 6: stored 2048 × 1536, displayed (and measured) 1536 × 2048.
    let hdr = doc.site.photos[1].interior.as_ref().expect("interior");
    assert_eq!(hdr.image_size_px, Some([1536, 2048]));

    // EOS 40D (2008): DateTimeOriginal 2008:05:30 15:56:01 without an offset tag.
    assert_eq!(doc.site.photos[2].taken_at, None);
    assert!(new.warnings.iter().any(|w| matches!(w,
        NewSiteWarning::TimeWithoutOffset { photo, date_time }
        if photo == "Canon_40D" && date_time == "2008:05:30 15:56:01")));
}
