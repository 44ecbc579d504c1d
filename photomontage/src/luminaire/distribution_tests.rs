use super::*;
use approx::assert_relative_eq;
use std::f64::consts::PI;

/// Exact integration of a constant interpolant: only rounding remains.
const EXACT_REL: f64 = 1e-12;
/// Linear interpolation of cos γ on a 1° grid: the error of the trapezoid-like interpolant
/// is ≈ h²/12 ≈ 2.5e-5 relative; 1e-4 leaves margin and still fails a wrong weight.
const LAMBERT_REL: f64 = 1e-4;

fn grid(step: f64, from: f64, to: f64) -> Vec<f64> {
    let n = ((to - from) / step).round() as usize;
    (0..=n).map(|i| from + step * i as f64).collect()
}

#[test]
fn isotropic_flux_is_four_pi_i() {
    let v = grid(5.0, 0.0, 180.0);
    let web = PhotometricWeb::from_planes(
        PhotometricType::C,
        Symmetry::Axial,
        &[0.0],
        &v,
        &vec![100.0; v.len()],
    )
    .unwrap();
    assert_relative_eq!(web.total_flux_lm(), 400.0 * PI, max_relative = EXACT_REL);
    // Same with a full asymmetric web of 24 planes.
    let c = grid(15.0, 0.0, 345.0);
    let web = PhotometricWeb::from_planes(
        PhotometricType::C,
        Symmetry::None,
        &c,
        &v,
        &vec![100.0; v.len() * c.len()],
    )
    .unwrap();
    assert_relative_eq!(web.total_flux_lm(), 400.0 * PI, max_relative = EXACT_REL);
}

#[test]
fn lambertian_flux_is_pi_i0() {
    let v = grid(1.0, 0.0, 90.0);
    let values: Vec<f64> = v.iter().map(|g| 1000.0 * g.to_radians().cos()).collect();
    let web = PhotometricWeb::from_planes(PhotometricType::C, Symmetry::Axial, &[0.0], &v, &values)
        .unwrap();
    assert_relative_eq!(web.total_flux_lm(), PI * 1000.0, max_relative = LAMBERT_REL);
}

#[test]
fn type_b_isotropic_front_hemisphere_is_two_pi_i() {
    let h = grid(5.0, 0.0, 90.0);
    let v = grid(5.0, -90.0, 90.0);
    let web = PhotometricWeb::from_planes(
        PhotometricType::B,
        Symmetry::Lateral,
        &h,
        &v,
        &vec![10.0; h.len() * v.len()],
    )
    .unwrap();
    assert_relative_eq!(web.total_flux_lm(), 20.0 * PI, max_relative = EXACT_REL);
    // Type A with the same numbers covers the same hemisphere.
    let web = PhotometricWeb::from_planes(
        PhotometricType::A,
        Symmetry::Lateral,
        &h,
        &v,
        &vec![10.0; h.len() * v.len()],
    )
    .unwrap();
    assert_relative_eq!(web.total_flux_lm(), 20.0 * PI, max_relative = EXACT_REL);
    // Nadir is the aiming direction; straight up is behind it.
    assert_relative_eq!(web.intensity_toward_cd(&Vector3::new(0.0, 0.0, -1.0)), 10.0);
    assert_relative_eq!(web.intensity_toward_cd(&Vector3::new(0.0, 0.0, 1.0)), 0.0);
}

#[test]
fn type_b_direction_round_trip() {
    // A Type B web whose intensity is H + 100 + V/1000 identifies the angles it was read at.
    let h = grid(1.0, -90.0, 90.0);
    let v = grid(1.0, -90.0, 90.0);
    let mut values = Vec::new();
    for &hh in &h {
        for &vv in &v {
            values.push(hh + 100.0 + vv / 1000.0);
        }
    }
    let web =
        PhotometricWeb::from_planes(PhotometricType::B, Symmetry::None, &h, &v, &values).unwrap();
    let (hd, vd) = (20.0_f64.to_radians(), 30.0_f64.to_radians());
    let d = Vector3::new(hd.cos() * vd.sin(), hd.sin(), -hd.cos() * vd.cos());
    assert_relative_eq!(web.intensity_toward_cd(&d), 120.03, epsilon = 1e-9);
}

#[test]
fn symmetry_expansion_matches_mirrored_planes() {
    // Quadrant data I = 100 + C (C in 0..90) must read I(180 − C) = I(180 + C) = I(360 − C).
    let c = grid(15.0, 0.0, 90.0);
    let v = grid(45.0, 0.0, 90.0);
    let mut values = Vec::new();
    for &cc in &c {
        values.extend(std::iter::repeat_n(100.0 + cc, v.len()));
    }
    let web = PhotometricWeb::from_planes(PhotometricType::C, Symmetry::Quadrant, &c, &v, &values)
        .unwrap();
    for probe in [0.0, 15.0, 37.5, 90.0] {
        let expected = 100.0 + probe;
        for c_deg in [probe, 180.0 - probe, 180.0 + probe, 360.0 - probe] {
            assert_relative_eq!(web.intensity_cd(c_deg, 45.0), expected, epsilon = 1e-9);
        }
    }
    // C90–C270 data I = C (C in 90..270): I(540 − C) must equal I(C).
    let c = grid(30.0, 90.0, 270.0);
    let mut values = Vec::new();
    for &cc in &c {
        values.extend(std::iter::repeat_n(cc, v.len()));
    }
    let web = PhotometricWeb::from_planes(PhotometricType::C, Symmetry::C90C270, &c, &v, &values)
        .unwrap();
    assert_relative_eq!(web.intensity_cd(60.0, 10.0), 120.0, epsilon = 1e-9);
    assert_relative_eq!(web.intensity_cd(0.0, 10.0), 180.0, epsilon = 1e-9);
    assert_relative_eq!(web.intensity_cd(330.0, 10.0), 210.0, epsilon = 1e-9);
}

#[test]
fn outside_vertical_range_is_dark() {
    let v = grid(10.0, 0.0, 90.0);
    let web = PhotometricWeb::from_planes(
        PhotometricType::C,
        Symmetry::Axial,
        &[0.0],
        &v,
        &vec![5.0; v.len()],
    )
    .unwrap();
    assert_relative_eq!(web.intensity_cd(0.0, 120.0), 0.0);
    assert_relative_eq!(web.total_flux_lm(), 10.0 * PI, max_relative = EXACT_REL);
}

#[test]
fn bad_axes_are_refused() {
    let err = PhotometricWeb::from_planes(
        PhotometricType::C,
        Symmetry::Axial,
        &[0.0],
        &[0.0, 10.0, 5.0],
        &[1.0, 1.0, 1.0],
    );
    assert!(matches!(err, Err(DistributionError::NotIncreasing { .. })));
    let err = PhotometricWeb::from_planes(
        PhotometricType::C,
        Symmetry::Axial,
        &[0.0],
        &[0.0, 10.0],
        &[1.0],
    );
    assert_eq!(
        err,
        Err(DistributionError::WrongCount {
            expected: 2,
            found: 1
        })
    );
}

#[test]
fn tilt_table_interpolates_and_clamps() {
    let t = TiltTable {
        geometry: LampGeometry::Vertical,
        angles_deg: vec![0.0, 45.0, 90.0],
        multipliers: vec![1.0, 0.9, 0.8],
    };
    assert_relative_eq!(t.multiplier_at(22.5), 0.95, epsilon = 1e-12);
    assert_relative_eq!(t.multiplier_at(120.0), 0.8);
    assert_relative_eq!(t.multiplier_at(-5.0), 1.0);
}
