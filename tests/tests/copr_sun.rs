//! Sun cross-check on the real COPR kite photos (OpenDroneMap `odm_data_copr`, CC BY-SA 4.0;
//! `data/real/SOURCES.md`): the SPA sun for each photo's EXIF capture time at the site's field
//! GPS position (mean of `GPS_average.txt`, Coal Oil Point Reserve, California).
//!
//! The Canon 450D writes DateTimeOriginal without an offset; the camera clock is taken as local
//! time, Pacific Daylight Time (UTC−7) — the photos are from 2009 and US daylight saving time
//! ran from 8 March to 1 November that year; the test checks the date lies in that range. No
//! object/shadow pair is surveyed in this data set (the GCPs are flat ground targets), so the
//! check is the weaker known answer every daylight photo must pass: the sun is above the
//! horizon at the stated time; the SPA position is printed for the report.

use chrono::{DateTime, Datelike, NaiveDateTime};
use photomontage::fit::sun_check::check_sun;
use photomontage::sun::{SpaParams, solar_position};

/// Pacific Daylight Time.
const PDT: &str = "-07:00";

#[test]
fn copr_photos_have_the_sun_above_the_horizon_at_their_exif_time() {
    let Some(gps) = photomontage_tests::shared_file("data/real/gcp/odm_data_copr/GPS_average.txt")
    else {
        return;
    };
    let text = std::fs::read_to_string(&gps).expect("readable");
    let coords: Vec<(f64, f64)> = text
        .lines()
        .skip(1)
        .filter_map(|l| {
            let f: Vec<&str> = l.split(',').collect();
            Some((
                f.get(1)?.trim().parse().ok()?,
                f.get(2)?.trim().parse().ok()?,
            ))
        })
        .collect();
    assert_eq!(coords.len(), 10);
    let n = coords.len() as f64;
    let lat = coords.iter().map(|c| c.0).sum::<f64>() / n;
    let lon = coords.iter().map(|c| c.1).sum::<f64>() / n;
    assert!((lat - 34.41).abs() < 0.01 && (lon + 119.88).abs() < 0.01);
    let params = SpaParams::at(lat, lon);
    for image in ["IMG_0031.jpg", "IMG_0046.jpg", "IMG_0052.jpg"] {
        let exif = photomontage::photo::read_exif(&gps.with_file_name(image)).expect("EXIF");
        let stamp = exif.date_time_original.expect("DateTimeOriginal");
        let naive = NaiveDateTime::parse_from_str(stamp.trim(), "%Y:%m:%d %H:%M:%S").unwrap();
        assert_eq!(naive.year(), 2009, "{image}: {stamp}");
        let offset = exif.offset_time_original.unwrap_or_else(|| PDT.to_owned());
        let time = DateTime::parse_from_rfc3339(&format!(
            "{}{}",
            naive.format("%Y-%m-%dT%H:%M:%S"),
            offset.trim()
        ))
        .unwrap();
        assert!(
            (3..=10).contains(&naive.month()),
            "{image}: {stamp} is outside 2009's daylight saving time"
        );
        let sun = solar_position(&time, &params).unwrap();
        println!(
            "{image}: EXIF {stamp} ({offset}) → SPA sun elevation {:.2}°, azimuth {:.2}°",
            sun.elevation_deg, sun.azimuth_deg
        );
        assert!(
            sun.elevation_deg > 0.0,
            "{image}: the sun is below the horizon at the EXIF time: wrong camera clock"
        );
        // The check itself, with a synthetic pole whose shadow matches the SPA sun: agrees.
        let d = sun.direction_enu();
        let top = nalgebra::Point3::new(0.0, 0.0, 2.0);
        let tip = nalgebra::Point3::new(-2.0 * d[0] / d[2], -2.0 * d[1] / d[2], 0.0);
        let c = check_sun(top, tip, &time, &params, 0.0, 2.0).unwrap();
        assert!(c.agrees());
    }
}
