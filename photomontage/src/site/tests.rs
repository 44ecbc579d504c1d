use super::*;

const EXAMPLE: &str = r#"schema_version = 1
name = "Test court"

[location]
latitude_deg = 47.37
longitude_deg = 8.54
elevation_m = 410.0
crs = "EPSG:2056"

[[photos]]
id = "P1"
file = "photos/p1.jpg"
taken_at = "2024-06-21T14:00:00+02:00"

[photos.interior]
focal_px = 3000.0
image_size_px = [4000, 3000]

[[photos]]
id = "P2"
file = "photos/p2.jpg"

[[control_points]]
id = "C1"
xyz = [2683000.125, 1247000.5, 410.25]
sigma_m = [0.005, 0.005, 0.01]

[[control_points]]
id = "C2"
xyz = [2683010.0, 1247000.5, 410.25]

[[observations]]
photo = "P1"
point = "C1"
x_px = 1234.5
y_px = 987.25

[[observations]]
photo = "P2"
point = "C2"
x_px = 10.0
y_px = 20.0
sigma_px = 1.0
enabled = false

[[polygons]]
id = "ground"
vertices = ["C1", "C2", "T1"]
material = "asphalt"
image = "P1"

[[observations]]
photo = "P2"
point = "T1"
x_px = 11.0
y_px = 21.0
"#;

fn parse(text: &str) -> Result<Site, SiteError> {
    Site::from_toml(text, Path::new("test.toml"))
}

#[test]
#[allow(clippy::float_cmp)] // the default is this exact literal
fn example_parses_with_defaults() {
    let site = parse(EXAMPLE).unwrap();
    assert_eq!(site.photos.len(), 2);
    assert_eq!(site.control_points[1].sigma_m, [0.01, 0.01, 0.01]);
    assert!(site.observations[0].enabled);
    assert!((site.observations[0].sigma_px - 0.5).abs() < f64::EPSILON);
    assert!(!site.observations[1].enabled);
    assert_eq!(site.solve, SolveSettings::default());
}

#[test]
fn round_trip_is_lossless_and_stable() {
    let site = parse(EXAMPLE).unwrap();
    let text = site.to_toml().unwrap();
    let again = parse(&text).unwrap();
    assert_eq!(site, again);
    // A second save writes exactly the same bytes.
    assert_eq!(text, again.to_toml().unwrap());
}

#[test]
fn round_trip_keeps_every_float_bit() {
    let mut site = parse(EXAMPLE).unwrap();
    site.control_points[0].xyz = [0.1 + 0.2, 1.0 / 3.0, 612_345.678_901_234_5];
    site.observations[0].x_px = std::f64::consts::PI * 1000.0;
    let again = parse(&site.to_toml().unwrap()).unwrap();
    for (a, b) in site.control_points[0]
        .xyz
        .iter()
        .zip(again.control_points[0].xyz)
    {
        assert_eq!(a.to_bits(), b.to_bits());
    }
    assert_eq!(
        site.observations[0].x_px.to_bits(),
        again.observations[0].x_px.to_bits()
    );
}

#[test]
fn syntax_error_names_line_and_column() {
    let text = EXAMPLE.replace("x_px = 1234.5", "x_px = 12 34.5");
    let err = parse(&text).unwrap_err();
    let SiteError::Syntax { line, .. } = err else {
        panic!("expected a syntax error, got {err}");
    };
    let expected = EXAMPLE.lines().position(|l| l == "x_px = 1234.5").unwrap() + 1;
    assert_eq!(line, expected);
}

#[test]
fn type_error_names_line_and_field() {
    let text = EXAMPLE.replace("focal_px = 3000.0", "focal_px = \"long\"");
    let err = parse(&text).unwrap_err();
    let msg = err.to_string();
    let expected = EXAMPLE
        .lines()
        .position(|l| l == "focal_px = 3000.0")
        .unwrap()
        + 1;
    assert!(msg.contains(&format!("test.toml:{expected}:")), "{msg}");
}

/// The closed sets of the schema (model units and up axis, sky model) are read as enums: a value
/// outside them is refused at its line, naming the allowed values; every member round-trips.
#[test]
fn closed_sets_are_refused_at_their_line_and_round_trip() {
    let model =
        "\n[[models]]\nid = \"m\"\nfile = \"m.obj\"\nunits = \"UNITS\"\nup_axis = \"AXIS\"\n";
    let with = |units: &str, axis: &str, sky: &str| {
        let text = format!(
            "{EXAMPLE}{}\n[lighting]\nsky_model = \"{sky}\"\n",
            model.replace("UNITS", units).replace("AXIS", axis)
        );
        let line_of = |needle: &str| text.lines().position(|l| l.starts_with(needle)).unwrap() + 1;
        (
            parse(&text),
            line_of("units"),
            line_of("up_axis"),
            line_of("sky_model"),
        )
    };
    for units in ModelUnits::ALL {
        for (axis, expected) in [("z", ModelUpAxis::Z), ("Y", ModelUpAxis::Y)] {
            let (site, ..) = with(units.as_str(), axis, "cie_general:7");
            let site = site.unwrap();
            assert_eq!(site.models[0].units, units);
            assert_eq!(site.models[0].up_axis, expected);
            assert_eq!(site.lighting.sky_model, SkyModelName::CieGeneral(7));
            let again = parse(&site.to_toml().unwrap()).unwrap();
            assert_eq!(again, site);
        }
    }
    let (err, units_line, axis_line, sky_line) = with("furlong", "z", "uniform");
    let msg = err.unwrap_err().to_string();
    assert!(msg.contains(&format!("test.toml:{units_line}:")), "{msg}");
    assert!(msg.contains("furlong") && msg.contains("`ft`"), "{msg}");
    let (err, ..) = with("m", "x", "uniform");
    let msg = err.unwrap_err().to_string();
    assert!(msg.contains(&format!("test.toml:{axis_line}:")), "{msg}");
    let (err, ..) = with("m", "z", "cie_general:16");
    let msg = err.unwrap_err().to_string();
    assert!(msg.contains(&format!("test.toml:{sky_line}:")), "{msg}");
    assert!(msg.contains("cie_general:N"), "{msg}");
    for name in [
        "uniform",
        "cie_overcast",
        "cie_general:1",
        "cie_general:15",
        "perez",
    ] {
        assert_eq!(name.parse::<SkyModelName>().unwrap().to_string(), name);
    }
    assert!("cie_general:0".parse::<SkyModelName>().is_err());
    assert!("perez:1".parse::<SkyModelName>().is_err());
}

#[test]
fn unknown_field_is_refused() {
    let text = EXAMPLE.replace("enabled = false", "enabld = false");
    let msg = parse(&text).unwrap_err().to_string();
    assert!(msg.contains("enabld"), "{msg}");
}

#[test]
fn unknown_photo_reference_gives_field_and_line() {
    let text = EXAMPLE.replace(
        "photo = \"P2\"\npoint = \"C2\"",
        "photo = \"P9\"\npoint = \"C2\"",
    );
    let err = parse(&text).unwrap_err();
    let SiteError::Invalid {
        line,
        field,
        message,
        ..
    } = err
    else {
        panic!("expected a validation error, got {err}");
    };
    assert_eq!(field, "observations[1].photo");
    assert!(message.contains("P9"));
    let expected = text.lines().position(|l| l == "photo = \"P9\"").unwrap() + 1;
    assert_eq!(line, expected);
}

#[test]
fn duplicate_point_id_is_refused() {
    let text = EXAMPLE.replace("id = \"C2\"", "id = \"C1\"");
    let err = parse(&text).unwrap_err();
    assert!(
        matches!(&err, SiteError::Invalid { field, .. } if field == "control_points[1].id"),
        "{err}"
    );
}

#[test]
fn nan_coordinate_is_refused() {
    let text = EXAMPLE.replace(
        "xyz = [2683010.0, 1247000.5, 410.25]",
        "xyz = [nan, 1247000.5, 410.25]",
    );
    let err = parse(&text).unwrap_err();
    assert!(
        matches!(&err, SiteError::Invalid { field, .. } if field == "control_points[1].xyz"),
        "{err}"
    );
}

#[test]
fn newer_schema_version_is_named() {
    let text = EXAMPLE.replace("schema_version = 1", "schema_version = 7");
    let err = parse(&text).unwrap_err();
    assert!(matches!(
        err,
        SiteError::UnsupportedVersion {
            found: 7,
            supported: 1,
            ..
        }
    ));
}

#[test]
fn polygon_needs_known_vertices() {
    let text = EXAMPLE.replace(
        "vertices = [\"C1\", \"C2\", \"T1\"]",
        "vertices = [\"C1\", \"C2\", \"Q7\"]",
    );
    let msg = parse(&text).unwrap_err().to_string();
    assert!(
        msg.contains("Q7") && msg.contains("polygons[0].vertices"),
        "{msg}"
    );
}

#[test]
fn atomic_save_replaces_and_leaves_no_temporary() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("site.toml");
    std::fs::write(&path, "old").unwrap();
    let site = parse(EXAMPLE).unwrap();
    site.save(&path).unwrap();
    let doc = SiteDocument::load(&path).unwrap();
    assert_eq!(doc.site, site);
    let names: Vec<_> = std::fs::read_dir(dir.path())
        .unwrap()
        .map(|e| e.unwrap().file_name())
        .collect();
    assert_eq!(names.len(), 1, "left behind: {names:?}");
}

/// Saving a document keeps the comments and key order of the file it came from (toml_edit
/// merge), with the changed value in place; `save_as` carries them to the new file.
#[test]
fn saving_keeps_the_users_comments_and_order() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("site.toml");
    let commented = format!("# Survey of 3 May, total station TS16\n{EXAMPLE}").replace(
        "x_px = 1234.5",
        "x_px = 1234.5   # clicked twice, centre of the target",
    );
    std::fs::write(&path, &commented).unwrap();
    let mut doc = SiteDocument::load(&path).unwrap();
    doc.site.name = "renamed".into();
    doc.save().unwrap();
    let text = std::fs::read_to_string(&path).unwrap();
    assert!(
        text.starts_with("# Survey of 3 May, total station TS16\n"),
        "{text}"
    );
    assert!(
        text.contains("x_px = 1234.5   # clicked twice, centre of the target"),
        "{text}"
    );
    assert!(text.contains("\"renamed\""), "{text}");
    assert_eq!(SiteDocument::load(&path).unwrap().site, doc.site);
    // Unchanged content: the file is written back exactly as the user left it.
    doc.site.name = parse(&commented).unwrap().name;
    doc.save().unwrap();
    assert_eq!(std::fs::read_to_string(&path).unwrap(), commented);
    std::fs::create_dir(dir.path().join("copy")).unwrap();
    let copy = dir.path().join("copy/site.toml");
    doc.save_as(&copy).unwrap();
    let text = std::fs::read_to_string(&copy).unwrap();
    assert!(text.contains("# clicked twice"), "{text}");
    assert_eq!(SiteDocument::load(&copy).unwrap().site, doc.site);
}

#[test]
fn failed_save_cleans_up_and_reports() {
    let dir = tempfile::tempdir().unwrap();
    // The target is a non-empty folder, so the final rename must fail.
    let path = dir.path().join("site.toml");
    std::fs::create_dir(&path).unwrap();
    std::fs::write(path.join("keep"), "x").unwrap();
    let site = parse(EXAMPLE).unwrap();
    let err = site.save(&path).unwrap_err();
    assert!(matches!(err, SiteError::Write { .. }), "{err}");
    let names: Vec<_> = std::fs::read_dir(dir.path())
        .unwrap()
        .map(|e| e.unwrap().file_name())
        .collect();
    assert_eq!(names, vec![std::ffi::OsString::from("site.toml")]);
    assert_eq!(std::fs::read_to_string(path.join("keep")).unwrap(), "x");
}

#[test]
fn save_as_elsewhere_keeps_every_referenced_file_reachable() {
    let dir = tempfile::tempdir().unwrap();
    let src = dir.path().join("src");
    std::fs::create_dir_all(src.join("photos")).unwrap();
    let path = src.join("site.toml");
    let mut site = parse(EXAMPLE).unwrap();
    site.lighting.material_library = Some("materials.toml".into());
    site.models.push(CadModel {
        id: "M".into(),
        file: "model.obj".into(),
        units: ModelUnits::Metre,
        up_axis: ModelUpAxis::Z,
        placement: Placement::default(),
        visible: true,
    });
    site.luminaires.push(SiteLuminaire {
        id: "L".into(),
        file: "lamp.ies".into(),
        position_m: [0.0; 3],
        rotation_z_deg: 0.0,
        tilt_deg: 0.0,
        colour_rgb: [1.0; 3],
        scale: 1.0,
        enabled: true,
    });
    site.save(&path).unwrap();
    let mut doc = SiteDocument::load(&path).unwrap();
    let before: Vec<PathBuf> = referenced_files(&doc);
    let copy = dir.path().join("elsewhere").join("copy.toml");
    std::fs::create_dir_all(dir.path().join("elsewhere")).unwrap();
    doc.save_as(&copy).unwrap();
    let again = SiteDocument::load(&copy).unwrap();
    let after = referenced_files(&again);
    assert_eq!(before.len(), 5);
    assert_eq!(before, after);
}

/// Every file a site refers to, resolved against the site's folder.
fn referenced_files(doc: &SiteDocument) -> Vec<PathBuf> {
    let s = &doc.site;
    s.photos
        .iter()
        .map(|p| &p.file)
        .chain(s.models.iter().map(|m| &m.file))
        .chain(s.luminaires.iter().map(|l| &l.file))
        .chain(s.lighting.material_library.iter())
        .map(|f| doc.resolve(f))
        .collect()
}

#[test]
fn render_depth_above_the_limit_is_refused() {
    // max_depth 5000 with mirrors once overflowed the stack.
    let err = parse(&format!("{EXAMPLE}\n[render]\nmax_depth = 5000\n")).unwrap_err();
    assert!(
        matches!(&err, SiteError::Invalid { field, .. } if field == "render.max_depth"),
        "{err}"
    );
    assert!(err.to_string().contains("5000"), "{err}");
    let limit = crate::render::MAX_DEPTH_LIMIT;
    assert!(parse(&format!("{EXAMPLE}\n[render]\nmax_depth = {limit}\n")).is_ok());
}

#[test]
fn non_positive_exposure_is_refused() {
    let err = parse(&format!("{EXAMPLE}\n[render]\nexposure = -1.0\n")).unwrap_err();
    assert!(
        matches!(&err, SiteError::Invalid { field, .. } if field == "render.exposure"),
        "{err}"
    );
}

#[test]
fn absurd_focal_length_is_refused_naming_the_photo() {
    // A focal length of 1e-200 px once sent the solver into an endless loop.
    let err = parse(&EXAMPLE.replace("focal_px = 3000.0", "focal_px = 1e-200")).unwrap_err();
    assert!(
        matches!(&err, SiteError::Invalid { field, .. } if field == "photos[0].interior.focal_px"),
        "{err}"
    );
    let text = EXAMPLE.replace(
        "focal_px = 3000.0",
        "focal_px = 3000.0\nprincipal_point_px = [1e300, 1500.0]",
    );
    let err = parse(&text).unwrap_err();
    assert!(
        matches!(&err, SiteError::Invalid { field, .. } if field == "photos[0].interior.principal_point_px[0]"),
        "{err}"
    );
}

#[test]
fn stated_image_size_above_the_photo_limit_is_refused() {
    let err = parse(&EXAMPLE.replace(
        "image_size_px = [4000, 3000]",
        "image_size_px = [100000, 100000]",
    ))
    .unwrap_err();
    assert!(
        matches!(&err, SiteError::Invalid { field, .. } if field == "photos[0].interior.image_size_px"),
        "{err}"
    );
    assert!(err.to_string().contains("100000×100000"), "{err}");
}
