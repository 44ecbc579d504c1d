//! Real kite photos with ground control: OpenDroneMap `odm_data_copr` (Coal Oil Point Reserve,
//! CC BY-SA 4.0; see `data/real/SOURCES.md` and `data/real/gcp/textbook_examples.md` §4).
//!
//! What the data allow: IMG_0031 has three control observations, IMG_0046 and IMG_0052 two
//! each (every image in `gcp_list.txt` has at most three). A unique resection needs four, so
//! the honest answers are typed errors — except that in IMG_0031 two observations (gcp00 and
//! gcp04) sit on the same pixel although the points lie 20 m apart on the (planar, h = 0)
//! ground, which no camera above the ground can see: the resection names that pair.

use photomontage::camera::Intrinsics;
use photomontage::photogrammetry::control_io::parse_odm_gcp_list;
use photomontage::photogrammetry::{PhotogrammetryError, ResectionOptions, resect};

/// Canon EOS 450D with the EF 28-80 at 30 mm: EXIF FocalPlaneXResolution 4865.6 px/inch gives
/// f ≈ 5747 px (textbook_examples.md §4); the EXIF reader must agree to 0.1 %.
const EXPECTED_FOCAL_PX: f64 = 30.0 * 4865.6 / 25.4;
const FOCAL_TOLERANCE: f64 = 1e-3;
/// Hand-picked GCP centres in ODM lists are good to a few pixels.
const SIGMA_PX: f64 = 2.0;
/// Averaged handheld-GPS targets: decimetre class.
const CONTROL_SIGMA_M: f64 = 0.1;

#[test]
fn copr_gcp_list_parses_and_the_mislabelled_point_is_named() {
    let Some(path) = photomontage_tests::shared_file("data/real/gcp/odm_data_copr/gcp_list.txt")
    else {
        return;
    };
    let text = std::fs::read_to_string(&path).expect("readable");
    let list = parse_odm_gcp_list(&text).expect("valid ODM list");
    assert!(list.crs.starts_with("+proj=utm +zone=11"));
    assert_eq!(list.rows.len(), 27);
    assert_eq!(list.images().len(), 22);
    let control = list
        .control_points([CONTROL_SIGMA_M; 3])
        .expect("consistent");
    assert_eq!(control.len(), 10);
    assert!(control.iter().all(|c| c.point_in_world.z == 0.0));

    // The initial focal length comes from the photo's own EXIF, as `solve` does it.
    let photo_path = path.with_file_name("IMG_0031.jpg");
    let size = photomontage::photo::size_px(&photo_path).expect("photo readable");
    assert_eq!(size, [4272, 2848]);
    let exif = photomontage::photo::read_exif(&photo_path).expect("EXIF readable");
    let focal_px = photomontage::photo::initial_focal_px(&exif, size)
        .expect("EXIF focal length")
        .focal_px;
    assert!(
        (focal_px / EXPECTED_FOCAL_PX - 1.0).abs() < FOCAL_TOLERANCE,
        "{focal_px}"
    );
    let options = ResectionOptions::new(Intrinsics::centred(focal_px, size));

    let obs31 = list.observations("IMG_0031.jpg", SIGMA_PX);
    assert_eq!(obs31.len(), 3);
    match resect(&control, &obs31, &options) {
        Err(PhotogrammetryError::CoincidentObservations {
            first,
            second,
            pixel_distance_px,
            world_distance_m,
        }) => {
            println!(
                "IMG_0031: {first} and {second}: {pixel_distance_px:.2} px apart, {world_distance_m:.2} m apart"
            );
            let mut pair = [first, second];
            pair.sort();
            assert_eq!(pair, ["gcp00".to_owned(), "gcp04".to_owned()]);
            assert!(pixel_distance_px < 2.0 && world_distance_m > 19.0);
        }
        other => panic!("IMG_0031 must name the mislabelled pair, got {other:?}"),
    }
    for image in ["IMG_0046.jpg", "IMG_0052.jpg"] {
        let obs = list.observations(image, SIGMA_PX);
        assert_eq!(
            resect(&control, &obs, &options).err(),
            Some(PhotogrammetryError::NotEnoughPoints {
                required: 4,
                found: 2
            }),
            "{image}"
        );
    }
}
