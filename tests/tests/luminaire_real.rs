//! Luminaire photometry against real third-party files in `../shared/data/real/{ies,ldt}` and
//! their published answers: Photometric Toolbox lumens (echowuzangye `ies_summary.md`), Relux
//! luminance tables (`relux_reference.json`), the Radiance examp1 flux (lighting.md §3.2), and
//! the three `Testlamp_*` IES/LDT pairs of the same luminaires.

use photomontage::luminaire::{EulumdatFile, IesFile, PhotometricFile, PhotometricWeb};
use photomontage_tests::shared_file;
use std::path::{Path, PathBuf};

/// Brief/issue 3 acceptance: total flux within 0.5 % of the Photometric Toolbox lumens.
const TOOLBOX_FLUX_REL: f64 = 0.005;
/// relux_reference.json "tolerance": 3 % relative, or 10 cd/m² absolute for small values.
const RELUX_REL: f64 = 0.03;
/// See [`RELUX_REL`].
const RELUX_ABS_CD_M2: f64 = 10.0;
/// IES and LDT of one luminaire, each normalised to its own total flux, compared at common
/// angles relative to the peak: the files print 4–5 significant digits and were converted by
/// different tools (one pair stores γ to 180° in one format only), so 1 % of the peak.
const PAIR_REL_OF_PEAK: f64 = 0.01;
/// Radiance examp1: lighting.md §3.2 integrated 5294.3 lm with a plain trapezoid; ours
/// integrates the linear interpolant exactly, which differs by O(h²) on the 2.5° grid.
const EXAMP1_REL: f64 = 0.005;
/// LDT: integrated flux / lamp flux is the light output ratio of line 23 (given to 0.1 %–1 %
/// in the files; writers integrate with their own rules): 1.5 %.
const LOR_ABS_PERCENT: f64 = 1.5;

fn files_in(dir: &Path, exts: &[&str]) -> Vec<PathBuf> {
    let mut out = Vec::new();
    let Ok(entries) = std::fs::read_dir(dir) else {
        return out;
    };
    for entry in entries.flatten() {
        let path = entry.path();
        if path.is_dir() {
            out.extend(files_in(&path, exts));
        } else if path
            .extension()
            .and_then(|e| e.to_str())
            .is_some_and(|e| exts.contains(&e.to_ascii_lowercase().as_str()))
        {
            out.push(path);
        }
    }
    out.sort();
    out
}

#[test]
fn every_real_ies_and_ldt_file_parses() {
    let Some(ies_dir) = shared_file("data/real/ies") else {
        return;
    };
    let Some(ldt_dir) = shared_file("data/real/ldt") else {
        return;
    };
    let mut files = files_in(&ies_dir, &["ies"]);
    files.extend(files_in(&ldt_dir, &["ldt"]));
    assert_eq!(
        files.len(),
        26 + 15,
        "SOURCES.md lists 26 IES and 15 LDT files"
    );
    for path in files {
        let file =
            PhotometricFile::read(&path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
        let web = file
            .distribution()
            .unwrap_or_else(|e| panic!("{}: {e}", path.display()));
        let flux = web.total_flux_lm();
        assert!(
            flux.is_finite() && flux > 0.0,
            "{}: flux {flux}",
            path.display()
        );
        assert!(web.max_intensity_cd() > 0.0);
        eprintln!(
            "{:<60} {:<16} {:>10.2} lm  max {:>10.2} cd  {:<9} warnings {:?}",
            path.file_name().and_then(|n| n.to_str()).unwrap_or("?"),
            file.format_label(),
            flux,
            web.max_intensity_cd(),
            web.symmetry().label(),
            file.warnings()
        );
    }
}

#[test]
fn echowuzangye_flux_matches_photometric_toolbox() {
    // ies_summary.md, column "Photometric Toolbox lumen" (4.ies and 6.ies are not in the set).
    let table = [
        ("1.IES", 9217.18),
        ("2.IES", 5834.2),
        ("3.IES", 13359.57),
        ("5.IES", 753.8),
        ("7.IES", 531.98),
        ("8.IES", 828.32),
    ];
    for (name, reference_lm) in table {
        let Some(path) = shared_file(&format!("data/real/ies/echowuzangye/{name}")) else {
            return;
        };
        let f = IesFile::read(&path).unwrap();
        assert!(f.is_absolute());
        let flux = f.distribution().unwrap().total_flux_lm();
        let rel = flux / reference_lm - 1.0;
        eprintln!(
            "{name}: {flux:.2} lm vs {reference_lm} lm ({:+.4} %)",
            rel * 100.0
        );
        assert!(
            rel.abs() < TOOLBOX_FLUX_REL,
            "{name}: {flux} vs {reference_lm}"
        );
    }
}

#[test]
fn type_b_floodlights_are_read_in_their_own_frame() {
    for name in ["2.1.IES", "2.2.ies"] {
        let Some(path) = shared_file(&format!("data/real/ies/echowuzangye/{name}")) else {
            return;
        };
        let f = IesFile::read(&path).unwrap();
        assert_eq!(
            f.photometric_type,
            photomontage::luminaire::PhotometricType::B
        );
        let web = f.distribution().unwrap();
        // A floodlight aimed at nadir sends all its light into the front hemisphere: the flux
        // equals the integral over the C-γ lower hemisphere sampled independently here.
        let flux = web.total_flux_lm();
        let sampled = sampled_lower_hemisphere_flux(&web);
        eprintln!("{name}: {flux:.1} lm exact-interpolant, {sampled:.1} lm resampled");
        assert!(
            (sampled / flux - 1.0).abs() < 0.01,
            "{name}: {flux} vs {sampled}"
        );
    }
}

/// Midpoint rule over C (0.5°) and γ (0.25°) in 0…90°, reading the web through C–γ directions:
/// an independent check of the Type B frame and quadrature (1 % covers the resampling error
/// near the beam edge).
fn sampled_lower_hemisphere_flux(web: &PhotometricWeb) -> f64 {
    let (dc, dg) = (0.5f64, 0.25f64);
    let mut sum = 0.0;
    for i in 0..720 {
        let c = (f64::from(i) + 0.5) * dc;
        for j in 0..360 {
            let g = (f64::from(j) + 0.5) * dg;
            sum += web.intensity_c_gamma_cd(c, g) * g.to_radians().sin();
        }
    }
    sum * dc.to_radians() * dg.to_radians()
}

#[test]
fn radiance_examp1_flux() {
    let Some(path) = shared_file("data/real/ies/examp1.ies") else {
        return;
    };
    let f = IesFile::read(&path).unwrap();
    assert_eq!(f.rated_lumens(), Some(5800.0));
    let flux = f.distribution().unwrap().total_flux_lm();
    eprintln!("examp1: {flux:.2} lm vs 5294.3 lm");
    assert!((flux / 5294.3 - 1.0).abs() < EXAMP1_REL);
}

#[test]
fn ldt_light_output_ratio_matches_integrated_flux() {
    let Some(dir) = shared_file("data/real/ldt") else {
        return;
    };
    for path in files_in(&dir, &["ldt"]) {
        let f = EulumdatFile::read(&path).unwrap();
        let lamp_flux = f.lamp_sets[0].total_flux_lm;
        let lor = 100.0 * f.distribution().unwrap().total_flux_lm() / lamp_flux;
        eprintln!(
            "{}: LOR integrated {lor:.2} %, stated {} %",
            path.display(),
            f.light_output_ratio_percent
        );
        assert!(
            (lor - f.light_output_ratio_percent).abs() < LOR_ABS_PERCENT,
            "{}: {lor} vs {}",
            path.display(),
            f.light_output_ratio_percent
        );
    }
}

#[test]
fn ldt_luminance_matches_relux() {
    let Some(json_path) = shared_file("data/real/ldt/relux_reference.json") else {
        return;
    };
    let json: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(json_path).unwrap()).unwrap();
    let c_planes: Vec<f64> = json["grid"]["c_planes_deg"]
        .as_array()
        .unwrap()
        .iter()
        .map(|v| v.as_f64().unwrap())
        .collect();
    let gammas: Vec<f64> = json["grid"]["g_angles_deg"]
        .as_array()
        .unwrap()
        .iter()
        .map(|v| v.as_f64().unwrap())
        .collect();
    let samples = json["samples"].as_object().unwrap();
    assert_eq!(samples.len(), 10);
    for (name, sample) in samples {
        let Some(path) = shared_file(&format!("data/real/ldt/{name}.ldt")) else {
            return;
        };
        let f = EulumdatFile::read(&path).unwrap();
        let mut worst_rel: f64 = 0.0;
        for &g in &gammas {
            let row = sample["table"][format!("{g}")].as_array().unwrap();
            for (k, &c) in c_planes.iter().enumerate() {
                let reference = row[k].as_f64().unwrap();
                let ours = f.luminance_cd_per_m2(c, g).unwrap();
                let err = (ours - reference).abs();
                if reference > RELUX_ABS_CD_M2 {
                    worst_rel = worst_rel.max(err / reference);
                }
                assert!(
                    err <= RELUX_ABS_CD_M2 || err <= RELUX_REL * reference,
                    "{name} C{c} γ{g}: {ours:.1} vs Relux {reference}"
                );
            }
        }
        eprintln!(
            "{name}: worst relative luminance error {:.3} %",
            worst_rel * 100.0
        );
    }
}

#[test]
fn ies_and_ldt_of_the_same_luminaire_agree() {
    for stem in [
        "Testlamp_Isym1_007cfb11e343e2f42e3b476be4ab684e",
        "Testlamp_Isym2_theta180+_erco_33499000_1xqt32_230w",
        "Testlamp_Isym4_43cef5d76a391dd85c41d4d09d68600d",
    ] {
        let ies_name = if stem.contains("erco") {
            format!("data/real/ies/{stem}.IES")
        } else {
            format!("data/real/ies/{stem}.ies")
        };
        let (Some(ies_path), Some(ldt_path)) = (
            shared_file(&ies_name),
            shared_file(&format!("data/real/ldt/{stem}.ldt")),
        ) else {
            return;
        };
        let ies = IesFile::read(&ies_path).unwrap().distribution().unwrap();
        let ldt = EulumdatFile::read(&ldt_path)
            .unwrap()
            .distribution()
            .unwrap();
        let (fi, fl) = (ies.total_flux_lm(), ldt.total_flux_lm());
        let peak = ies.max_intensity_cd() / fi;
        // Common angles: γ over the range both files store, C every 15°.
        let g_max = ies
            .vertical_deg()
            .last()
            .copied()
            .unwrap()
            .min(ldt.vertical_deg().last().copied().unwrap());
        let mut worst: f64 = 0.0;
        for ci in 0..24 {
            let c = f64::from(ci) * 15.0;
            let mut g = 0.0;
            while g <= g_max + 1e-9 {
                let a = ies.intensity_cd(c, g) / fi;
                let b = ldt.intensity_cd(c, g) / fl;
                worst = worst.max((a - b).abs() / peak);
                g += 5.0;
            }
        }
        eprintln!(
            "{stem}: IES {fi:.2} lm, LDT {fl:.2} lm, worst normalised difference {:.3} % of peak",
            worst * 100.0
        );
        assert!(worst < PAIR_REL_OF_PEAK, "{stem}: {worst}");
    }
}

/// A tiny deterministic generator (SplitMix64) for the mutation fuzzing below.
struct SplitMix(u64);
impl SplitMix {
    fn next(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^ (z >> 31)
    }
}

#[test]
fn parsers_never_panic_on_mutated_real_files() {
    let (Some(ies_dir), Some(ldt_dir)) =
        (shared_file("data/real/ies"), shared_file("data/real/ldt"))
    else {
        return;
    };
    let mut files = files_in(&ies_dir, &["ies"]);
    files.extend(files_in(&ldt_dir, &["ldt"]));
    let mut rng = SplitMix(0x1e5_1d7);
    let interesting: &[&[u8]] = &[
        b"999999999",
        b"-1",
        b"\n",
        b" ",
        b",",
        b"1e308",
        b"nan",
        b"TILT=INCLUDE\n",
    ];
    for path in files {
        let original = std::fs::read(&path).unwrap();
        for _ in 0..40 {
            let mut bytes = original.clone();
            for _ in 0..(1 + rng.next() % 6) {
                let at = (rng.next() as usize) % bytes.len().max(1);
                match rng.next() % 4 {
                    0 => bytes[at] = rng.next() as u8,
                    1 => {
                        let piece = interesting[(rng.next() as usize) % interesting.len()];
                        let end = (at + piece.len()).min(bytes.len());
                        bytes.splice(at..end, piece.iter().copied());
                    }
                    2 => {
                        let end = (at + (rng.next() % 64) as usize).min(bytes.len());
                        bytes.drain(at..end);
                    }
                    _ => bytes.truncate(at),
                }
                if bytes.is_empty() {
                    break;
                }
            }
            // Any result is fine; a panic fails the test.
            if let Ok(file) = PhotometricFile::parse(&bytes)
                && let Ok(web) = file.distribution()
            {
                let _ = web.total_flux_lm();
                let _ = web.intensity_c_gamma_cd(12.0, 34.0);
            }
        }
    }
}

#[test]
fn polynomial_fit_of_a_real_curve_improves_with_degree() {
    use photomontage::luminaire::curve_fit::PolynomialFit;
    // Üncü & Kayakuş §2.1 on the BEGA LED downlight (axial, 73 γ angles to 180°). Least squares
    // over nested polynomial spaces: the residual can never grow with the degree.
    let Some(path) =
        shared_file("data/real/ies/Testlamp_Isym1_007cfb11e343e2f42e3b476be4ab684e.ies")
    else {
        return;
    };
    let web = IesFile::read(&path).unwrap().distribution().unwrap();
    let gammas = web.vertical_deg().to_vec();
    let values: Vec<f64> = gammas.iter().map(|&g| web.intensity_cd(0.0, g)).collect();
    let mut previous = f64::INFINITY;
    for degree in 0..=12 {
        let fit = PolynomialFit::fit(&gammas, &values, degree).unwrap();
        eprintln!(
            "degree {degree:2}: rms residual {:.2} cd ({:.2} % of peak)",
            fit.rms_residual,
            100.0 * fit.rms_residual / web.max_intensity_cd()
        );
        assert!(
            fit.rms_residual <= previous * (1.0 + 1e-9),
            "degree {degree}"
        );
        previous = fit.rms_residual;
    }
}
