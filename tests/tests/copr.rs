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

/// Canon EOS 450D: 22.2 mm sensor width over 4272 px; EF 28-80 at 30 mm (EXIF). Until the
/// `photo::exif` module lands these constants stand in for the EXIF reader.
const FOCAL_MM: f64 = 30.0;
const SENSOR_WIDTH_MM: f64 = 22.2;
const IMAGE_SIZE_PX: [u32; 2] = [4272, 2848];
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
    let text = std::fs::read_to_string(path).expect("readable");
    let list = parse_odm_gcp_list(&text).expect("valid ODM list");
    assert!(list.crs.starts_with("+proj=utm +zone=11"));
    assert_eq!(list.rows.len(), 27);
    assert_eq!(list.images().len(), 22);
    let control = list
        .control_points([CONTROL_SIGMA_M; 3])
        .expect("consistent");
    assert_eq!(control.len(), 10);
    assert!(control.iter().all(|c| c.point_in_world.z == 0.0));

    let focal_px = FOCAL_MM * f64::from(IMAGE_SIZE_PX[0]) / SENSOR_WIDTH_MM;
    let options = ResectionOptions::new(Intrinsics::centred(focal_px, IMAGE_SIZE_PX));

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
