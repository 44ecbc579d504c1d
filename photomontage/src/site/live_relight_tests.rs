#![allow(clippy::unwrap_used, clippy::float_cmp)] // a change copies values: compared bit for bit

use std::sync::atomic::AtomicBool;

use nalgebra::Point3;

use super::*;
use crate::radiosity::{NamedLuminaire, PointSource, RELIGHT_L1_REL_TOL, RELIGHT_MEAN_REL_TOL};
use crate::site::render::site_scene;
use crate::site::render::tests::{fixture, fixture_with_photo_from_above};
use crate::site::render_radiosity::site_radiosity_light;
use crate::site::{SiteMaterial, SkyModelName, SunManual};

fn lamp(intensity: f64, x_m: f64) -> NamedLuminaire {
    NamedLuminaire {
        name: "luminaire:lamp".into(),
        source: PointSource {
            position_in_world_m: Point3::new(x_m, 0.0, 4.0),
            luminaire: None,
            intensity_rgb: [intensity, intensity * 0.9, intensity * 0.8],
        },
        dimming: 1.0,
    }
}

fn lighting_of(doc: &SiteDocument) -> (TransferLighting, Vec<(String, Rgb, Option<Rgb>)>) {
    let scene = site_scene(doc).unwrap().scene;
    let (lighting, _) = site_transfer_lighting(doc, &scene, "p1").unwrap();
    (lighting, material_state(&scene))
}

#[test]
fn site_edits_map_to_the_lighting_change_that_makes_them() {
    let dir = tempfile::tempdir().unwrap();
    let doc = fixture(dir.path());
    let (l0, m0) = lighting_of(&doc);
    assert!(is_empty(&lighting_change(&l0, &l0, &m0, &m0).unwrap()));

    // A sun slider step: only the sun changes, to the site's new sun.
    let mut moved = doc.clone();
    moved.site.lighting.sun_manual = Some(SunManual {
        azimuth_deg: 150.0,
        elevation_deg: 35.0,
    });
    let (l1, m1) = lighting_of(&moved);
    let change = lighting_change(&l0, &l1, &m0, &m1).unwrap();
    assert_eq!(change.sun, Some(l1.sun));
    assert!(change.sky.is_none() && change.material_reflectance.is_empty());

    // A sky type: only the sky.
    let mut sky = doc.clone();
    sky.site.lighting.sky_model = SkyModelName::CieOvercast;
    let (l2, m2) = lighting_of(&sky);
    let change = lighting_change(&l0, &l2, &m0, &m2).unwrap();
    assert_eq!(change.sky, Some(l2.sky.clone()));
    assert!(change.sun.is_none() && change.material_reflectance.is_empty());

    // A material colour: that material's diffuse reflectance, nothing else.
    let mut colour = doc.clone();
    colour.site.materials.push(SiteMaterial {
        material: crate::scene::Material::diffuse("brick", [0.6, 0.3, 0.2]),
        colour: None,
    });
    let (l3, m3) = lighting_of(&colour);
    let change = lighting_change(&l0, &l3, &m0, &m3).unwrap();
    assert_eq!(
        change.material_reflectance,
        vec![("brick".to_owned(), [0.6, 0.3, 0.2])]
    );
    assert!(change.sun.is_none() && change.sky.is_none());

    // An emitting material cannot be relit: a build.
    let mut m4 = m0.clone();
    m4[0].2 = Some([1.0; 3]);
    assert!(lighting_change(&l0, &l0, &m0, &m4).is_none());
}

#[test]
fn a_dimmed_luminaire_is_a_dimming_and_a_moved_one_a_build() {
    let with = |l: NamedLuminaire| TransferLighting {
        sun: None,
        sky: None,
        luminaires: vec![l],
        emitters: false,
    };
    let built = with(lamp(500.0, 0.0));
    // The site scales the intensity; the transfer knows it as a dimming of the built source.
    let change = lighting_change(&built, &with(lamp(125.0, 0.0)), &[], &[]).unwrap();
    assert_eq!(
        change.luminaire_dimming,
        vec![("luminaire:lamp".to_owned(), 0.25)]
    );
    // After that relight the transfer's lamp is the built source dimmed to 0.25: going back to
    // full output is a dimming of 1.
    let mut dimmed = built.clone();
    dimmed.luminaires[0].dimming = 0.25;
    let change = lighting_change(&dimmed, &with(lamp(500.0, 0.0)), &[], &[]).unwrap();
    assert_eq!(
        change.luminaire_dimming,
        vec![("luminaire:lamp".to_owned(), 1.0)]
    );
    assert!(lighting_change(&built, &with(lamp(500.0, 1.0)), &[], &[]).is_none());
    let mut recoloured = lamp(500.0, 0.0);
    recoloured.source.intensity_rgb[2] = 100.0;
    assert!(lighting_change(&built, &with(recoloured), &[], &[]).is_none());
}

fn assert_matches_fresh_solve(label: &str, relit: &Solution, fresh: &Solution) {
    // The transfer's documented relight tolerances (`radiosity::RELIGHT_*_REL_TOL`).
    let d = relit
        .relative_difference(fresh)
        .unwrap_or_else(|| panic!("{label}: same mesh and a lit scene"));
    assert!(d.l1_rel < RELIGHT_L1_REL_TOL, "{label}: L1 {}", d.l1_rel);
    assert!(
        d.mean_rel.abs() < RELIGHT_MEAN_REL_TOL,
        "{label}: mean {}",
        d.mean_rel
    );
}

#[test]
fn update_builds_once_relights_sky_and_colour_and_matches_a_fresh_solve() {
    let dir = tempfile::tempdir().unwrap();
    let mut doc = fixture(dir.path());
    doc.site.render.radiosity = true;
    let cancel = AtomicBool::new(false);
    let mut slot = None;
    let scene = site_scene(&doc).unwrap().scene;
    let (light, report) =
        SiteTransfers::update(&mut slot, &doc, &scene, "p1", None, &cancel).unwrap();
    assert_eq!(report.update, TransferUpdate::Built);
    // The build's solutions are the render's own solves, bit for bit.
    let (fresh, _) = site_radiosity_light(&doc, &scene, "p1", None, &cancel).unwrap();
    assert_eq!(light.with_artificial.groups, fresh.with_artificial.groups);
    assert_eq!(
        light.without_artificial.groups,
        fresh.without_artificial.groups
    );
    let built = light;
    let (_, report) = SiteTransfers::update(&mut slot, &doc, &scene, "p1", None, &cancel).unwrap();
    assert_eq!(report.update, TransferUpdate::Unchanged);
    assert!(report.build.is_none());

    // The sky type (Site & light tab) and a material colour (Materials tab).
    doc.site.lighting.sky_model = SkyModelName::CieGeneral(12);
    doc.site.materials.push(SiteMaterial {
        material: crate::scene::Material::diffuse("brick", [0.7, 0.35, 0.2]),
        colour: None,
    });
    let scene = site_scene(&doc).unwrap().scene;
    let (light, report) =
        SiteTransfers::update(&mut slot, &doc, &scene, "p1", None, &cancel).unwrap();
    assert_eq!(report.update, TransferUpdate::Relit);
    let (fresh, _) = site_radiosity_light(&doc, &scene, "p1", None, &cancel).unwrap();
    assert_matches_fresh_solve("with", &light.with_artificial, &fresh.with_artificial);
    assert_matches_fresh_solve(
        "without",
        &light.without_artificial,
        &fresh.without_artificial,
    );
    let kept = slot.as_ref().unwrap();
    assert_eq!(
        kept.light_groups()[0].len(),
        fresh.with_artificial.groups.len()
    );
    // A relight keeps the vertex gathers (the rays they traced): the geometry is the same.
    for k in 0..2 {
        assert!(
            Arc::ptr_eq(built.gathers()[k], light.gathers()[k]),
            "gather {k}"
        );
    }

    // Moving the model changes the geometry: a build, with new gathers.
    doc.site.models[0].placement.translation[0] += 2.0;
    let scene = site_scene(&doc).unwrap().scene;
    let (moved, report) =
        SiteTransfers::update(&mut slot, &doc, &scene, "p1", None, &cancel).unwrap();
    assert_eq!(report.update, TransferUpdate::Built);
    assert!(!Arc::ptr_eq(built.gathers()[0], moved.gathers()[0]));
}

#[test]
fn a_build_with_the_photo_takes_its_reflectances_as_the_render_does() {
    let dir = tempfile::tempdir().unwrap();
    let mut doc = fixture(dir.path());
    doc.site.render.radiosity = true;
    let cancel = AtomicBool::new(false);
    let job = crate::site::render::prepare_view(&doc, "p1").unwrap();
    let photo = crate::site::photo_reflectance::PhotoView {
        camera: &job.camera,
        photo_linear: &job.photo_linear,
        lighting: &job.lighting,
    };
    let scene = &job.scene.scene;
    let mut slot = None;
    let (light, built) =
        SiteTransfers::update(&mut slot, &doc, scene, "p1", Some(&photo), &cancel).unwrap();
    let report = &slot.as_ref().unwrap().report;
    // The update hands the build's report on (the studio shows it).
    assert_eq!(built.build.as_ref(), Some(report));
    let count = report.photo_reflectance.unwrap();
    assert!(count.from_photo > 10, "{count:?}");
    // The fixture's second photo is not solved: named in the notes, as the render's.
    assert!(
        report
            .notes
            .iter()
            .any(|n| n == "photo reflectance: photo p2 not read: it is not solved"),
        "{:?}",
        report.notes
    );
    let (fresh, fresh_report) =
        site_radiosity_light(&doc, scene, "p1", Some(&photo), &cancel).unwrap();
    assert_eq!(
        fresh_report.photo_reflectance.unwrap().from_photo,
        count.from_photo
    );
    // The transfers refit by relights (warm starts), the render's solve by cold solves on the
    // same links: the same fixed points within the relight tolerances.
    assert_matches_fresh_solve("with", &light.with_artificial, &fresh.with_artificial);
    assert_matches_fresh_solve(
        "without",
        &light.without_artificial,
        &fresh.without_artificial,
    );
    // The photographed state's values reach the same natural elements with the objects.
    for solution in [&light.with_artificial, &fresh.with_artificial] {
        let carried = solution
            .mesh
            .element_reflectance_overrides()
            .iter()
            .filter(|r| r.is_some())
            .count();
        assert!(carried > 0 && carried <= count.from_photo, "{carried}");
    }
    // Without the photo the library's values stay.
    let (plain, plain_report) = site_radiosity_light(&doc, scene, "p1", None, &cancel).unwrap();
    assert!(plain_report.photo_reflectance.is_none());
    assert!(plain.without_artificial.mesh.node_reflectance_rgb.is_none());
    // The kept transfers follow a switch of the photo's reflectances (a build each way), and
    // the same photo again is no change.
    let update = |slot: &mut Option<SiteTransfers>, photo| {
        SiteTransfers::update(slot, &doc, scene, "p1", photo, &cancel)
            .unwrap()
            .1
            .update
    };
    assert_eq!(update(&mut slot, Some(&photo)), TransferUpdate::Unchanged);
    assert_eq!(update(&mut slot, None), TransferUpdate::Built);
    let kept = slot.as_ref().unwrap();
    assert!(kept.report.photo_reflectance.is_none());
    assert!(
        kept.without_artificial()
            .mesh
            .node_reflectance_rgb
            .is_none()
    );
    assert_eq!(update(&mut slot, None), TransferUpdate::Unchanged);
    assert_eq!(update(&mut slot, Some(&photo)), TransferUpdate::Built);
    assert!(slot.as_ref().unwrap().report.photo_reflectance.is_some());
}

/// A sun move in the studio (the natural transfer's rays first, the other reading them through
/// its twins, then both solves side by side) gives both transfers' own relights bit for bit.
#[test]
fn a_studio_sun_move_is_each_transfers_own_relight_bit_for_bit() {
    let dir = tempfile::tempdir().unwrap();
    let mut doc = fixture(dir.path());
    doc.site.render.radiosity = true;
    let cancel = AtomicBool::new(false);
    let mut slot = None;
    let scene = site_scene(&doc).unwrap().scene;
    SiteTransfers::update(&mut slot, &doc, &scene, "p1", None, &cancel).unwrap();
    let kept = slot.as_ref().unwrap();
    assert!(
        kept.with_artificial.transfer.twins().is_some_and(|n| n > 0),
        "the transfer with the model has twins"
    );
    let mut own = [
        kept.with_artificial.transfer.clone(),
        kept.without_artificial.transfer.clone(),
    ];
    for (azimuth_deg, elevation_deg) in [(150.0, 35.0), (151.0, 35.0), (230.0, 20.0)] {
        doc.site.lighting.sun_manual = Some(SunManual {
            azimuth_deg,
            elevation_deg,
        });
        let inputs = inputs(&doc, &scene, "p1").unwrap();
        for (k, t) in own.iter_mut().enumerate() {
            let materials = material_state(&inputs.scenes[k]);
            let change =
                lighting_change(t.lighting(), &inputs.lighting[k], &materials, &materials).unwrap();
            assert!(change.sun.is_some());
            t.relight_in_place(&change).unwrap();
        }
        let (_, report) =
            SiteTransfers::update(&mut slot, &doc, &scene, "p1", None, &cancel).unwrap();
        assert_eq!(report.update, TransferUpdate::Relit);
        let studio = slot.as_ref().unwrap();
        // Per group, the elements whose direct term or radiosity differ in any bit.
        let differing = |a: &Solution, b: &Solution| -> Vec<(usize, usize)> {
            a.groups
                .iter()
                .zip(&b.groups)
                .map(|(x, y)| {
                    let differ = |u: &[Rgb], v: &[Rgb]| {
                        u.iter()
                            .zip(v)
                            .filter(|(p, q)| p.map(f64::to_bits) != q.map(f64::to_bits))
                            .count()
                    };
                    (
                        differ(&x.direct_irradiance_rgb, &y.direct_irradiance_rgb),
                        differ(&x.radiosity_rgb, &y.radiosity_rgb),
                    )
                })
                .collect()
        };
        for (label, studio, alone) in [
            ("with", studio.with_artificial(), own[0].solution()),
            ("without", studio.without_artificial(), own[1].solution()),
        ] {
            let d = differing(studio, alone);
            assert!(
                d.iter().all(|&(a, b)| a == 0 && b == 0),
                "{label} at {azimuth_deg}°: (direct, radiosity) elements differing per group {d:?}"
            );
        }
    }
}

#[test]
fn a_photo_taken_at_another_time_is_read_under_its_sun_by_the_render_and_the_studio_alike() {
    let dir = tempfile::tempdir().unwrap();
    let cancel = AtomicBool::new(false);
    let read = |doc: &SiteDocument| {
        let job = crate::site::render::prepare_view(doc, "p1").unwrap();
        let photo = crate::site::photo_reflectance::PhotoView {
            camera: &job.camera,
            photo_linear: &job.photo_linear,
            lighting: &job.lighting,
        };
        let scene = &job.scene.scene;
        let (render, report) =
            site_radiosity_light(doc, scene, "p1", Some(&photo), &cancel).unwrap();
        let mut slot = None;
        let (studio, _) =
            SiteTransfers::update(&mut slot, doc, scene, "p1", Some(&photo), &cancel).unwrap();
        let studio_report = slot.unwrap().report;
        (render, report, studio, studio_report)
    };
    // Low in the west (≈ 20° up) where p1 has it ≈ 40° up in the south-east.
    let afternoon = fixture_with_photo_from_above(dir.path(), "18:14");
    let (render, report, studio, studio_report) = read(&afternoon);
    let count = report.photo_reflectance.unwrap();
    println!("{count:?}; {:?}", report.notes);
    assert!(count.from_other_photos > 5, "{count:?}");
    let note = "photo reflectance: photo p2 read on ";
    let p2_note = report.notes.iter().find(|n| n.starts_with(note)).unwrap();
    assert!(
        p2_note.contains("(read under the sun of its own capture time); exposure not checked"),
        "{p2_note}"
    );
    // The studio reads p2 against its transfer relit to p2's sun: the same elements, the same
    // values within the relight tolerances.
    assert_eq!(
        studio_report.photo_reflectance.unwrap().from_other_photos,
        count.from_other_photos
    );
    assert!(
        studio_report.notes.contains(p2_note),
        "{:?}",
        studio_report.notes
    );
    let rho = |s: &Solution| s.mesh.element_reflectance_overrides();
    let (render_rho, studio_rho) = (
        rho(&render.without_artificial),
        rho(&studio.without_artificial),
    );
    let mut largest = 0.0_f64;
    for (a, b) in render_rho.iter().zip(&studio_rho) {
        assert_eq!(a.is_some(), b.is_some());
        if let (Some(a), Some(b)) = (a, b) {
            for c in 0..3 {
                largest = largest.max((a[c] / b[c] - 1.0).abs());
            }
        }
    }
    println!("largest relative difference of ρ_d, render against studio: {largest:.2e}");
    assert!(largest < STUDIO_RHO_REL_TOL, "{largest}");
    assert_matches_fresh_solve(
        "without",
        &studio.without_artificial,
        &render.without_artificial,
    );
    // The photographed state carries the rendered photo's light only.
    assert_eq!(
        render.without_artificial.groups.len(),
        studio.without_artificial.groups.len()
    );

    // Read as if taken at p1's time, the elements only p2 sees take other values: p2's sun
    // lights them otherwise (the test can fail).
    let (same, same_report, _, _) = read(&fixture_with_photo_from_above(dir.path(), "10:44"));
    let note = same_report
        .notes
        .iter()
        .find(|n| n.starts_with("photo reflectance: photo p2 read on "))
        .unwrap();
    assert!(!note.contains("its own capture time"), "{note}");
    let same_rho = rho(&same.without_artificial);
    let moved = render_rho
        .iter()
        .zip(&same_rho)
        .filter(|(a, b)| match (a, b) {
            (Some(a), Some(b)) => (a[0] / b[0] - 1.0).abs() > 0.05,
            _ => false,
        })
        .count();
    assert!(
        moved * 2 > count.from_other_photos,
        "{moved} of {}",
        count.from_other_photos
    );
}

/// ρ_d read against the studio's relit transfer and the render's solve: both solves' fixed
/// points agree within the relight tolerances (≈ 1 %), which reach ρ_d through E_rad.
const STUDIO_RHO_REL_TOL: f64 = 0.02;

/// The instant preview ([`crate::render::preview`]) on the studio's path: recorded once with the
/// kept transfers' light, then replayed after a relight (sky type and a material colour) without
/// a ray: the same values, bit for bit, as a new recording under the edited site; and under the
/// recording's own light, the recorded values.
#[test]
fn the_preview_replays_a_sky_and_colour_edit_as_a_new_recording_would() {
    use crate::render::differential::replay::SampleReplay;
    use crate::render::preview::PreviewRecords;
    const STRIDE_PX: u32 = 1;

    let dir = tempfile::tempdir().unwrap();
    let mut doc = fixture(dir.path());
    doc.site.render.radiosity = true;
    let cancel = AtomicBool::new(false);
    let mut slot = None;
    let view = |doc: &SiteDocument, slot: &mut Option<SiteTransfers>| {
        let mut job = crate::site::render::prepare_view(doc, "p1").unwrap();
        let (light, report) =
            SiteTransfers::update(slot, doc, &job.scene.scene, "p1", None, &cancel).unwrap();
        job.lighting.radiosity = Some(light);
        (job, report.update)
    };
    let (job0, update) = view(&doc, &mut slot);
    assert_eq!(update, TransferUpdate::Built);
    let tracer0 = job0.tracer().unwrap();
    let records = PreviewRecords::record(&tracer0, STRIDE_PX, &cancel).unwrap();
    let count = |f: &dyn Fn(&SampleReplay) -> bool| {
        records.samples().iter().filter(|s| f(&s.replay)).count()
    };
    let artificial = count(&|r| matches!(r, SampleReplay::Artificial { at: Some(_), .. }));
    let natural = count(&|r| matches!(r, SampleReplay::Natural { .. }));
    let total = records.samples().len();
    assert!(
        artificial > 20 && natural > 100,
        "{artificial} {natural} of {total}"
    );
    // Under the recording's light: the recorded values.
    let same = records
        .replay(&job0.scene.scene, &job0.lighting, &job0.camera)
        .unwrap();
    for (s, p) in records.samples().iter().zip(&same.rgba) {
        #[allow(clippy::cast_possible_truncation)]
        let recorded = s.radiance_rgb.map(|x| x as f32);
        assert_eq!([p[0], p[1], p[2]], recorded);
    }

    doc.site.lighting.sky_model = SkyModelName::CieGeneral(12);
    doc.site.materials.push(SiteMaterial {
        material: crate::scene::Material::diffuse("brick", [0.7, 0.35, 0.2]),
        colour: None,
    });
    let (job1, update) = view(&doc, &mut slot);
    assert_eq!(update, TransferUpdate::Relit);
    let (scene1, lighting1, camera1) = (&job1.scene.scene, &job1.lighting, &job1.camera);
    // The replay needs no tracer: the edited site's scene, lighting and camera.
    assert!(records.fits(scene1, lighting1, camera1));
    let replayed = records.replay(scene1, lighting1, camera1).unwrap();
    let tracer1 = job1.tracer().unwrap();
    let fresh = PreviewRecords::record(&tracer1, STRIDE_PX, &cancel)
        .unwrap()
        .replay(scene1, lighting1, camera1)
        .unwrap();
    let bits = |img: &crate::render::preview::PreviewImage| -> Vec<u32> {
        img.rgba.iter().flat_map(|p| p.map(f32::to_bits)).collect()
    };
    let (a, b) = (bits(&replayed), bits(&fresh));
    let differ = a.iter().zip(&b).filter(|(x, y)| x != y).count();
    assert!(
        a.len() == b.len() && differ == 0,
        "{differ} of {} values differ",
        a.len()
    );
    // The edit shows: the planned object's colour and the light around it changed.
    let changed = replayed
        .rgba
        .iter()
        .zip(&same.rgba)
        .filter(|(a, b)| a != b)
        .count();
    assert!(changed > artificial, "{changed} of {}", same.rgba.len());

    // Moving the model: the records no longer fit, and say so.
    doc.site.models[0].placement.translation[0] += 2.0;
    let (job2, update) = view(&doc, &mut slot);
    assert_eq!(update, TransferUpdate::Built);
    let (scene2, lighting2, camera2) = (&job2.scene.scene, &job2.lighting, &job2.camera);
    assert!(!records.fits(scene2, lighting2, camera2));
    let err = records
        .replay(scene2, lighting2, camera2)
        .unwrap_err()
        .to_string();
    assert!(err.contains("geometry changed"), "{err}");
}
