use super::*;

fn fit_sample(id: &str) -> photomontage::site::Sample {
    use photomontage::site::{Sample, SamplePurpose};
    Sample {
        id: id.into(),
        photo: "P1".into(),
        material: "paving".into(),
        purpose: SamplePurpose::Daylight,
        point: None,
        x_px: Some(10.0),
        y_px: Some(20.0),
        window_px: 5,
        enabled: true,
    }
}

#[test]
fn sample_edits_undo_to_the_exact_site() {
    let mut s = Site {
        samples: vec![fit_sample("S1"), fit_sample("S2"), fit_sample("S3")],
        ..Site::default()
    };
    let original = s.clone();
    let mut h = History::default();
    h.apply(
        &mut s,
        Command::Fit(FitCommand::RemoveSample { id: "S2".into() }),
    )
    .expect("remove");
    let mut off = fit_sample("S1");
    off.enabled = false;
    off.purpose = photomontage::site::SamplePurpose::Atmosphere;
    h.apply(
        &mut s,
        Command::Fit(FitCommand::PutSample {
            sample: off,
            at: None,
        }),
    )
    .expect("edit");
    h.apply(
        &mut s,
        Command::Fit(FitCommand::PutHorizonSample {
            sample: photomontage::site::HorizonSample {
                id: "H1".into(),
                photo: "P1".into(),
                origin_px: [1, 2],
                size_px: [30, 10],
                enabled: true,
            },
            at: None,
        }),
    )
    .expect("horizon");
    h.apply(
        &mut s,
        Command::Fit(FitCommand::SetFitSettings(
            photomontage::site::FitSettings {
                interreflection: false,
                ambient: false,
            },
        )),
    )
    .expect("settings");
    let mut lit = s.lighting.clone();
    lit.sun_weight = [2.0, 3.0, 4.0];
    h.apply(
        &mut s,
        Command::Fit(FitCommand::SetLighting {
            lighting: Box::new(lit),
            record: None,
        }),
    )
    .expect("lighting");
    let edited = s.clone();
    assert_eq!(s.samples.len(), 2);
    assert!(!s.samples[0].enabled);
    for _ in 0..5 {
        h.undo(&mut s).expect("undo");
    }
    assert_eq!(s, original, "order and values restored");
    for _ in 0..5 {
        h.redo(&mut s).expect("redo");
    }
    assert_eq!(s, edited);
    assert_eq!(
        h.apply(
            &mut s,
            Command::Fit(FitCommand::RemoveSample { id: "nope".into() })
        ),
        Err(CommandError::NoSuchSample { id: "nope".into() })
    );
}

fn site() -> Site {
    let mut s = Site::default();
    for (i, p) in ["A", "B", "C"].iter().enumerate() {
        s.observations.push(Observation {
            photo: "P1".into(),
            point: (*p).into(),
            x_px: i as f64,
            y_px: 2.0 * i as f64,
            sigma_px: 0.5,
            enabled: true,
        });
    }
    s
}

#[test]
fn undo_restores_the_exact_site_and_redo_reapplies() {
    let original = site();
    let mut s = original.clone();
    let mut h = History::default();
    h.apply(
        &mut s,
        Command::RemoveObservation {
            photo: "P1".into(),
            point: "B".into(),
        },
    )
    .expect("exists");
    let mut moved = original.observations[0].clone();
    moved.x_px = 10.0;
    h.apply(
        &mut s,
        Command::PutObservation {
            observation: moved,
            at: None,
        },
    )
    .expect("put");
    let edited = s.clone();
    assert_eq!(s.observations.len(), 2);
    h.undo(&mut s).expect("undo");
    h.undo(&mut s).expect("undo");
    assert_eq!(s, original, "order and values restored");
    assert_eq!(h.undo(&mut s), Err(CommandError::NothingToUndo));
    h.redo(&mut s).expect("redo");
    h.redo(&mut s).expect("redo");
    assert_eq!(s, edited);
    assert_eq!(h.revision(), 6);
}

#[test]
fn failing_batch_leaves_the_site_unchanged() {
    let original = site();
    let mut s = original.clone();
    let mut h = History::default();
    let batch = Command::Batch(vec![
        Command::RemoveObservation {
            photo: "P1".into(),
            point: "A".into(),
        },
        Command::RemoveObservation {
            photo: "P1".into(),
            point: "Z".into(),
        },
    ]);
    assert!(matches!(
        h.apply(&mut s, batch),
        Err(CommandError::NoSuchObservation { .. })
    ));
    assert_eq!(s, original);
    assert!(!h.can_undo());
}

#[test]
fn adding_a_model_undoes_to_the_exact_site() {
    let original = site();
    let mut s = original.clone();
    let mut h = History::default();
    let model = CadModel {
        id: "box".into(),
        file: "box.obj".into(),
        units: photomontage::site::ModelUnits::Metre,
        up_axis: photomontage::site::ModelUpAxis::Z,
        placement: Placement::default(),
        visible: true,
    };
    h.apply(
        &mut s,
        Command::PutModel {
            model: model.clone(),
            at: None,
        },
    )
    .expect("insert");
    assert_eq!(s.models, vec![model.clone()]);
    h.undo(&mut s).expect("undo");
    assert_eq!(s, original);
    h.redo(&mut s).expect("redo");
    assert_eq!(s.models, vec![model]);
    assert!(matches!(
        apply(&mut s, Command::RemoveModel { id: "nope".into() }),
        Err(CommandError::NoSuchModel { .. })
    ));
}

#[test]
fn self_calibration_flags_undo_to_the_exact_site() {
    let mut original = site();
    original.photos.push(photomontage::site::Photo {
        id: "P1".into(),
        file: "p1.png".into(),
        taken_at: None,
        profile: None,
        interior: None,
        self_calibration: SelfCalibrationFlags::default(),
        exterior: None,
    });
    let mut s = original.clone();
    let mut h = History::default();
    let flags = SelfCalibrationFlags {
        focal: true,
        k1: true,
        ..SelfCalibrationFlags::default()
    };
    h.apply(
        &mut s,
        Command::SetSelfCalibration {
            photo: "P1".into(),
            flags,
        },
    )
    .expect("photo exists");
    assert_eq!(s.photos[0].self_calibration, flags);
    h.undo(&mut s).expect("undo");
    assert_eq!(s, original);
    h.redo(&mut s).expect("redo");
    assert_eq!(s.photos[0].self_calibration, flags);
    assert!(matches!(
        apply(
            &mut s,
            Command::SetSelfCalibration {
                photo: "nope".into(),
                flags
            }
        ),
        Err(CommandError::NoSuchPhoto { .. })
    ));
}

#[test]
fn script_lines_parse_and_reject_garbage() {
    let s = site();
    let c = parse_script_line(&s, "place P1 Q 1.5 2.5").expect("valid");
    assert!(
        matches!(c, Some(Command::PutObservation { ref observation, .. })
        if observation.point == "Q" && (observation.x_px - 1.5).abs() < 1e-12)
    );
    assert_eq!(parse_script_line(&s, "  # note").expect("comment"), None);
    assert!(parse_script_line(&s, "place P1 Q x 2").is_err());
    assert!(parse_script_line(&s, "disable P1 Z").is_err());
    assert!(parse_script_line(&s, "fly away").is_err());
}
