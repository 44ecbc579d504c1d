//! NREL SPA against pvlib 0.16.1 (`spa_python`, numpy) on the shared reference data
//! (`bench/data/pvlib/`): the paper's test case, every hour of 2025 at Zurich, and the daily
//! sunrise/transit/sunset of 2025 at Zurich (`sun_rise_set_transit_spa`).

use chrono::{DateTime, FixedOffset, NaiveDate, Utc};
use photomontage::sun::{SpaParams, solar_position, sun_rise_transit_set};
use photomontage_tests::shared_file;
use serde_json::Value;

/// The brief's threshold for zenith and azimuth against pvlib. pvlib implements the same
/// algorithm in f64, so the real differences are rounding (~1e-9°).
const PVLIB_ANGLE_TOL_DEG: f64 = 1e-4;
/// The brief's threshold for the paper's test case.
const PAPER_ANGLE_TOL_DEG: f64 = 1e-5;
/// Equation of time: same formula as pvlib; 1e-4 min = 6 ms.
const EOT_TOL_MIN: f64 = 1e-4;
/// Sunrise/transit/sunset against pvlib's: the same Appendix A.2 algorithm in f64, so the
/// differences are rounding (measured < 1e-5 s); 1 ms leaves room for libm differences.
const RISE_SET_TOL_S: f64 = 1e-3;

fn params_json() -> Option<Value> {
    let path = shared_file("bench/data/pvlib/params.json")?;
    let text = std::fs::read_to_string(path).expect("readable params.json");
    Some(serde_json::from_str(&text).expect("valid params.json"))
}

fn num(v: &Value, key: &str) -> f64 {
    v[key]
        .as_f64()
        .unwrap_or_else(|| panic!("params.json: {key} missing"))
}

fn angle_diff_deg(a: f64, b: f64) -> f64 {
    let d = (a - b).rem_euclid(360.0);
    d.min(360.0 - d)
}

fn zurich_params(p: &Value) -> SpaParams {
    let z = &p["zurich"];
    SpaParams {
        latitude_deg: num(z, "latitude"),
        longitude_deg: num(z, "longitude"),
        elevation_m: num(z, "elevation_m"),
        pressure_mbar: num(z, "pressure_pa") / 100.0,
        temperature_c: num(z, "temperature_c"),
        delta_t_s: num(z, "delta_t_s"),
        delta_ut1_s: 0.0,
        atmos_refract_deg: num(z, "atmos_refract_deg"),
    }
}

#[test]
fn spa_paper_test_case() {
    let Some(p) = params_json() else { return };
    let c = &p["spa_testcase"];
    let e = &p["spa_testcase_expected"];
    let params = SpaParams {
        latitude_deg: num(c, "latitude"),
        longitude_deg: num(c, "longitude"),
        elevation_m: num(c, "elevation_m"),
        pressure_mbar: num(c, "pressure_mbar"),
        temperature_c: num(c, "temperature_c"),
        delta_t_s: num(c, "delta_t_s"),
        delta_ut1_s: num(c, "delta_ut1_s"),
        atmos_refract_deg: num(c, "atmos_refract_deg"),
    };
    let time = DateTime::parse_from_rfc3339("2003-10-17T12:30:30-07:00").expect("valid time");
    let pos = solar_position(&time, &params).expect("valid inputs");
    assert!((pos.zenith_deg - num(e, "zenith_deg")).abs() < PAPER_ANGLE_TOL_DEG);
    assert!((pos.azimuth_deg - num(e, "azimuth_deg")).abs() < PAPER_ANGLE_TOL_DEG);
    assert!((pos.julian_day - num(e, "julian_day")).abs() < 1e-6);
    let incidence = pos.incidence_deg(num(c, "slope_deg"), num(c, "azm_rotation_deg"));
    assert!((incidence - num(e, "incidence_deg")).abs() < PAPER_ANGLE_TOL_DEG);
    let rts = sun_rise_transit_set(time.date_naive(), time.offset(), &params).expect("valid");
    let hms = |t: Option<DateTime<FixedOffset>>| {
        t.map(|t| t.format("%H:%M:%S").to_string())
            .unwrap_or_default()
    };
    assert_eq!(hms(rts.sunrise), e["sunrise_local"].as_str().unwrap_or("?"));
    assert_eq!(hms(rts.sunset), e["sunset_local"].as_str().unwrap_or("?"));
}

#[test]
fn zurich_2025_hourly_matches_pvlib() {
    let Some(p) = params_json() else { return };
    let Some(csv) = shared_file("bench/data/pvlib/zurich_2025_hourly.csv") else {
        return;
    };
    let params = zurich_params(&p);
    let text = std::fs::read_to_string(csv).expect("readable csv");
    let mut rows = 0;
    let (mut worst_zenith, mut worst_azimuth, mut worst_geometric, mut worst_eot) =
        (0.0_f64, 0.0_f64, 0.0_f64, 0.0_f64);
    for line in text.lines().skip(1).filter(|l| !l.trim().is_empty()) {
        let f: Vec<&str> = line.split(',').collect();
        assert_eq!(f.len(), 7, "bad row {line}");
        let time: DateTime<Utc> = f[0].parse().expect("RFC 3339 time");
        let value = |i: usize| f[i].parse::<f64>().expect("number");
        let pos = solar_position(&time, &params).expect("valid inputs");
        worst_zenith = worst_zenith.max((pos.zenith_deg - value(1)).abs());
        worst_geometric = worst_geometric.max((pos.geometric_zenith_deg - value(2)).abs());
        worst_azimuth = worst_azimuth.max(angle_diff_deg(pos.azimuth_deg, value(5)));
        worst_eot = worst_eot.max((pos.equation_of_time_min - value(6)).abs());
        rows += 1;
    }
    eprintln!(
        "zurich hourly: {rows} rows, max |Δ apparent zenith| {worst_zenith:.3e}°, \
         |Δ zenith| {worst_geometric:.3e}°, |Δ azimuth| {worst_azimuth:.3e}°, |Δ EoT| {worst_eot:.3e} min"
    );
    assert_eq!(rows, 8760);
    assert!(worst_zenith < PVLIB_ANGLE_TOL_DEG);
    assert!(worst_geometric < PVLIB_ANGLE_TOL_DEG);
    assert!(worst_azimuth < PVLIB_ANGLE_TOL_DEG);
    assert!(worst_eot < EOT_TOL_MIN);
}

#[test]
fn zurich_2025_rise_set_matches_pvlib() {
    let Some(p) = params_json() else { return };
    let Some(csv) = shared_file("bench/data/pvlib/zurich_2025_daily_rise_set.csv") else {
        return;
    };
    let params = zurich_params(&p);
    let text = std::fs::read_to_string(csv).expect("readable csv");
    let mut worst = [0.0_f64; 3];
    let mut days = 0;
    for line in text.lines().skip(1).filter(|l| !l.trim().is_empty()) {
        let f: Vec<&str> = line.split(',').collect();
        assert_eq!(f.len(), 4, "bad row {line}");
        let date = NaiveDate::parse_from_str(f[0], "%Y-%m-%d").expect("date");
        let rts = sun_rise_transit_set(date, &Utc, &params).expect("valid");
        let got = [
            rts.sunrise.expect("rises"),
            rts.sunset.expect("sets"),
            rts.transit,
        ];
        for k in 0..3 {
            let want: DateTime<Utc> = f[k + 1].parse().expect("RFC 3339 time");
            let diff_s = (got[k] - want).num_microseconds().unwrap_or(i64::MAX) as f64 * 1e-6;
            worst[k] = worst[k].max(diff_s.abs());
        }
        days += 1;
    }
    eprintln!(
        "zurich daily: {days} days, max |Δ| sunrise {:.4} s, sunset {:.4} s, transit {:.4} s",
        worst[0], worst[1], worst[2]
    );
    assert_eq!(days, 365);
    for w in worst {
        assert!(w < RISE_SET_TOL_S, "{worst:?}");
    }
}
