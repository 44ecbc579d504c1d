use std::path::PathBuf;

use super::*;
use crate::site::{Location, Site};
use crate::sun::{SpaParams, solar_position};

fn zurich_doc(zone: Option<&str>) -> SiteDocument {
    SiteDocument {
        path: PathBuf::from("site.toml"),
        site: Site {
            location: Some(Location {
                latitude_deg: 47.3769,
                longitude_deg: 8.5417,
                elevation_m: 408.0,
                crs: None,
                grid_convergence_deg: 0.0,
                time_zone: zone.map(str::to_owned),
            }),
            ..Site::default()
        },
    }
}

fn request(dates: &str, times: &str) -> StudyRequest {
    StudyRequest {
        view: "V1".into(),
        dates: parse_dates(dates).unwrap(),
        times: parse_times(times).unwrap(),
        spp_min: None,
        spp_max: None,
        seed: None,
    }
}

#[test]
fn frames_are_local_times_in_the_site_zone_with_the_spa_sun() {
    let doc = zurich_doc(Some("Europe/Zurich"));
    let frames = plan_frames(&doc, &request("2026-03-20,2026-06-21", "09:00,12:00")).unwrap();
    let utc: Vec<String> = frames
        .iter()
        .map(|f| f.time.to_utc().format("%Y-%m-%dT%H:%MZ").to_string())
        .collect();
    // 20 March: CET (+1); 21 June: CEST (+2).
    assert_eq!(
        utc,
        [
            "2026-03-20T08:00Z",
            "2026-03-20T11:00Z",
            "2026-06-21T07:00Z",
            "2026-06-21T10:00Z"
        ]
    );
    assert_eq!(frames[3].time_rfc3339(), "2026-06-21T12:00:00+02:00");
    assert_eq!(frames[3].stem("V1"), "V1_2026-06-21_1200");
    // The same SPA call `photomontage sun` makes (its default pressure, temperature, ΔT).
    let params = SpaParams {
        elevation_m: 408.0,
        ..SpaParams::at(47.3769, 8.5417)
    };
    for f in &frames {
        let pos = solar_position(&f.time, &params).unwrap();
        assert_eq!(f.sun_azimuth_deg.to_bits(), pos.azimuth_deg.to_bits());
        assert_eq!(f.sun_elevation_deg.to_bits(), pos.elevation_deg.to_bits());
        assert!(f.is_daylight());
    }
    // Solar noon in Zurich is near 13:30 CEST / 12:30 CET: at 12:00 local time the sun is still
    // south-east of the site (azimuth between east and south).
    for f in [&frames[1], &frames[3]] {
        assert!((90.0..180.0).contains(&f.sun_azimuth_deg), "{f:?}");
    }
}

#[test]
fn the_frame_document_sets_lighting_time_and_drops_the_manual_sun() {
    let mut doc = zurich_doc(Some("Europe/Zurich"));
    doc.site.lighting.sun_manual = Some(crate::site::SunManual {
        azimuth_deg: 10.0,
        elevation_deg: 10.0,
    });
    let frames = plan_frames(&doc, &request("2026-06-21", "15:00")).unwrap();
    let frame_doc = frames[0].document(&doc);
    assert_eq!(
        frame_doc.site.lighting.time.as_deref(),
        Some("2026-06-21T15:00:00+02:00")
    );
    assert!(frame_doc.site.lighting.sun_manual.is_none());
}

#[test]
fn night_frames_are_kept_but_not_daylight_and_all_night_is_an_error() {
    let doc = zurich_doc(Some("Europe/Zurich"));
    let frames = plan_frames(&doc, &request("2026-12-21", "03:00,12:00")).unwrap();
    assert!(!frames[0].is_daylight());
    assert!(frames[1].is_daylight());
    let e = plan_frames(&doc, &request("2026-12-21,2026-06-21", "00:30,23:30")).unwrap_err();
    assert!(matches!(e, StudyError::NoDaylight { asked: 4 }), "{e}");
}

#[test]
fn times_without_offset_need_the_site_zone() {
    let doc = zurich_doc(None);
    let e = plan_frames(&doc, &request("2026-06-21", "12:00")).unwrap_err();
    assert!(matches!(e, StudyError::NoTimeZone { .. }), "{e}");
    assert!(e.to_string().contains("location.time_zone"), "{e}");
    // With its own offset the time is usable without a zone.
    let frames = plan_frames(&doc, &request("2026-06-21", "12:00+02:00,10:00Z")).unwrap();
    assert_eq!(frames[0].time.to_utc(), frames[1].time.to_utc());
}

#[test]
fn a_skipped_local_time_names_the_date() {
    let doc = zurich_doc(Some("Europe/Zurich"));
    let e = plan_frames(&doc, &request("2026-03-29", "02:30")).unwrap_err();
    let text = e.to_string();
    assert!(matches!(e, StudyError::LocalTime { .. }), "{text}");
    assert!(
        text.contains("2026-03-29") && text.contains("02:30"),
        "{text}"
    );
}

#[test]
fn an_unknown_zone_is_an_error_naming_the_field() {
    let doc = zurich_doc(Some("Europe/Zurch"));
    let e = plan_frames(&doc, &request("2026-06-21", "12:00")).unwrap_err();
    let text = e.to_string();
    assert!(text.contains("location.time_zone"), "{text}");
    assert!(text.contains("Europe/Zurich"), "{text}");
}

#[test]
fn bad_dates_and_times_are_named() {
    for (text, needle) in [
        ("2026-13-01", "2026-13-01"),
        ("2026-06-21,tomorrow", "tomorrow"),
    ] {
        let e = parse_dates(text).unwrap_err();
        assert!(e.to_string().contains(needle), "{e}");
    }
    for text in ["9am", "25:00", "12:00+25:00"] {
        let e = parse_times(text).unwrap_err();
        assert!(matches!(e, StudyError::BadTime { .. }), "{text}: {e}");
        assert!(e.to_string().contains(text), "{e}");
    }
    assert!(matches!(
        parse_times(" , ").unwrap_err(),
        StudyError::Empty { field: "times" }
    ));
    let t = parse_times("09:15:30").unwrap();
    assert_eq!(t[0].clock, NaiveTime::from_hms_opt(9, 15, 30).unwrap());
}

#[test]
fn too_many_frames_are_refused_before_any_work() {
    let doc = zurich_doc(Some("Europe/Zurich"));
    let dates: Vec<String> = (1..=28).map(|d| format!("2026-02-{d:02}")).collect();
    let times: Vec<String> = (0..24).map(|h| format!("{h:02}:00")).collect();
    let e = plan_frames(&doc, &request(&dates.join(","), &times.join(","))).unwrap_err();
    assert!(
        matches!(e, StudyError::TooManyFrames { frames: 672, .. }),
        "{e}"
    );
}
