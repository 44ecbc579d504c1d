//! The twin rays of [`super::twin`] against the brute force: every ray traced in the whole
//! scene.
#![allow(clippy::unwrap_used)]

use std::collections::BTreeMap;

use super::MeshParams;
use super::city_block::{city_block, city_block_sun};
use super::form_factor::{FormFactorEngine, FormFactorParams};
use super::mesh::Mesh;
use super::sky_transfer::LANES;
use super::sky_transfer::{SkyRays, SkyTransfer};
use super::sources::{DirectSamples, DistantSource, direct_irradiance_at};
use super::sun_rays::sun_counts;
use super::twin::{Twin, twin_elements};
use crate::bvh::BuildQuality;
use crate::scene::ObjectKind;
use crate::scene::SceneTracer;
use crate::sky_dome::icosahedral::{IcosahedralDome, IcosahedralParams};

/// The city block with its planned building and without it, meshed alike, their tracers in one
/// frame, and the twins.
pub(super) struct Pair {
    pub(super) natural_mesh: Mesh,
    pub(super) mesh: Mesh,
    pub(super) natural_tracer: SceneTracer,
    pub(super) tracer: SceneTracer,
    pub(super) twin: Twin,
    pub(super) ff: FormFactorParams,
}

pub(super) fn block_pair() -> Pair {
    let scene = city_block(1, [0.5; 3]).unwrap();
    let natural = scene.part_of_kind(ObjectKind::Natural).unwrap();
    let artificial = scene.part_of_kind(ObjectKind::Artificial).unwrap();
    let tracer = SceneTracer::new(&scene, BuildQuality::Medium).unwrap();
    let natural_tracer =
        SceneTracer::new_in_frame_of(&natural, BuildQuality::Medium, &tracer).unwrap();
    let mut object_element_edge_m = BTreeMap::new();
    object_element_edge_m.insert("ground".to_owned(), 16.0);
    let params = MeshParams {
        max_patch_edge_m: 16.0,
        max_element_edge_m: 4.0,
        object_element_edge_m,
        shadow_edge_element_m: Some(2.0),
        ..MeshParams::default()
    };
    let sun = [city_block_sun(0.7, 2.6).dir_in_world];
    let occluders = [&tracer, &natural_tracer];
    let natural_mesh = Mesh::build_lit(&natural, &params, &sun, &occluders).unwrap();
    let mesh = Mesh::build_lit(&scene, &params, &sun, &occluders).unwrap();
    let ff = FormFactorParams {
        samples_per_axis: 2,
        seed: 3,
        visibility: true,
    };
    let twin = Twin::new(
        twin_elements(&natural_mesh, &mesh),
        natural_mesh.elements.len(),
        &natural_tracer,
        &tracer,
        &artificial,
        &mesh,
    )
    .unwrap()
    .unwrap();
    Pair {
        natural_mesh,
        mesh,
        natural_tracer,
        tracer,
        twin,
        ff,
    }
}

/// The sky transfer of the block with its planned building, read from the natural block's
/// transfer where elements have twins, equals the one traced through the whole scene ray by
/// ray (the brute force), and the building does take sky from some natural elements.
#[test]
fn the_twins_sky_transfer_equals_tracing_every_ray_in_the_whole_scene() {
    let Pair {
        natural_mesh,
        mesh,
        natural_tracer,
        tracer,
        twin,
        ff,
    } = block_pair();
    let dome = IcosahedralDome::new(&IcosahedralParams::tonn_donath()).unwrap();
    let natural_engine = FormFactorEngine::new(&natural_mesh, &natural_tracer, ff).unwrap();
    let natural_samples = DirectSamples::new(&natural_engine, 1);
    let natural_sky = SkyRays {
        group: 1,
        transfer: SkyTransfer::new(&natural_engine, &natural_samples, &dome),
        factors: None,
    };
    // Every natural element has its twin; the building's elements have none.
    assert_eq!(twin.twins(), natural_mesh.elements.len());
    assert!(twin.twins() < mesh.elements.len());
    let engine = FormFactorEngine::new(&mesh, &tracer, ff)
        .unwrap()
        .with_direct_streams(Some(&twin.streams));
    let samples = DirectSamples::new(&engine, 1);
    for (e, t) in twin.twin_of.iter().enumerate() {
        if let Some(w) = t {
            assert_eq!(
                samples.of_element(e),
                natural_samples.of_element(*w as usize)
            );
        }
    }
    let shared = SkyTransfer::beside(&engine, &samples, &dome, Some((&twin, &natural_sky, 1)));
    let brute = SkyTransfer::beside(&engine, &samples, &dome, None);
    assert_eq!(shared.escaped, brute.escaped);
    // Natural elements whose sky the building blocks in part (so the test can fail).
    let f_count = shared.facets();
    let stride = f_count.next_multiple_of(LANES);
    let blocked = twin
        .twin_of
        .iter()
        .enumerate()
        .filter_map(|(e, t)| t.map(|w| (e, w as usize)))
        .filter(|&(e, w)| {
            shared.escaped[e * stride..e * stride + f_count]
                != natural_sky.transfer.escaped[w * stride..w * stride + f_count]
        })
        .count();
    assert!(
        blocked > 100,
        "{blocked} natural elements lose sky to the building"
    );
    // A twin traced for another group is not used (the brute force again).
    let other = SkyTransfer::beside(&engine, &samples, &dome, Some((&twin, &natural_sky, 0)));
    assert_eq!(other.escaped, brute.escaped);
}

/// The sun's counts of the block with its planned building, read from the natural block's
/// counts where elements have twins, equal those traced through the whole scene ray by ray,
/// and so does the direct irradiance made from them; the building shades some natural
/// elements; counts for another sun direction are not read.
#[test]
fn sun_twin_counts_equal_tracing_every_ray() {
    let pair = block_pair();
    // The cones kept per element are those of their nodes.
    for e in 0..pair.mesh.elements.len() {
        let node = pair.mesh.element_node(e);
        assert_eq!(
            pair.twin.element_cone(e),
            pair.twin.cone_from_node(node),
            "element {e}"
        );
    }
    let natural_engine =
        FormFactorEngine::new(&pair.natural_mesh, &pair.natural_tracer, pair.ff).unwrap();
    let natural_samples = DirectSamples::new(&natural_engine, 0);
    let engine = FormFactorEngine::new(&pair.mesh, &pair.tracer, pair.ff)
        .unwrap()
        .with_direct_streams(Some(&pair.twin.streams));
    let samples = DirectSamples::new(&engine, 0);
    for azimuth in [2.6, 2.62, 4.0] {
        let sun = city_block_sun(0.5, azimuth);
        let source = DistantSource {
            dir_in_world: sun.dir_in_world,
            normal_irradiance_rgb: sun.normal_irradiance_rgb,
        };
        let (natural, _) = sun_counts(&natural_engine, &natural_samples, &source, None);
        let (shared, direct) = sun_counts(&engine, &samples, &source, Some((&pair.twin, &natural)));
        let (brute, _) = sun_counts(&engine, &samples, &source, None);
        assert_eq!(shared.escaped, brute.escaped, "azimuth {azimuth}");
        let traced = direct_irradiance_at(&engine, &samples, std::slice::from_ref(&source));
        let bits =
            |v: &[[f64; 3]]| -> Vec<u64> { v.iter().flat_map(|x| x.map(f64::to_bits)).collect() };
        assert_eq!(bits(&direct), bits(&traced), "azimuth {azimuth}: direct");
        // Natural elements the building shades (so the test can fail), and natural elements
        // in full sun (so the twins' shortcut is taken).
        let shaded = pair
            .twin
            .twin_of
            .iter()
            .enumerate()
            .filter_map(|(e, t)| t.map(|w| (e, w as usize)))
            .filter(|&(e, w)| shared.escaped[e] < natural.escaped[w])
            .count();
        assert!(
            shaded > 20,
            "azimuth {azimuth}: {shaded} shaded by the building"
        );
        assert!(natural.escaped.iter().filter(|&&n| n == 4).count() > 1000);
        // Counts traced for another direction are not read: the brute force again.
        let (other, _) = sun_counts(
            &natural_engine,
            &natural_samples,
            &DistantSource {
                dir_in_world: city_block_sun(0.5, azimuth + 0.3).dir_in_world,
                ..source
            },
            None,
        );
        let (guarded, _) = sun_counts(&engine, &samples, &source, Some((&pair.twin, &other)));
        assert_eq!(
            guarded.escaped, brute.escaped,
            "azimuth {azimuth}: other direction"
        );
    }
}
