//! Tests of the hierarchical solver's pieces: link dropping, the refinement bound, the
//! refinement's merge and the push–pull runs.

use super::*;

/// The merge gives the order (and estimates) of a stable sort by receiver of the kept links
/// followed by the new ones, as `refine_bf` did before it merged.
#[test]
fn the_merge_is_the_stable_sort_of_the_kept_then_the_new_links() {
    use rand::{Rng, SeedableRng};
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(7);
    for case in 0..200 {
        let receivers = 1 + case % 40;
        let link = |rng: &mut rand_chacha::ChaCha8Rng, i: u32| Link {
            receiver: rng.random_range(0..receivers),
            source: i,
            form_factor: f64::from(i),
        };
        let mut keep: Vec<Link> = (0..rng.random_range(0..60))
            .map(|i| link(&mut rng, i))
            .collect();
        keep.sort_by_key(|l| l.receiver);
        let kept_estimates: Vec<f64> = (0..keep.len()).map(|i| i as f64 + 0.5).collect();
        let new: Vec<Link> = (0..rng.random_range(0..60))
            .map(|i| link(&mut rng, 1000 + i))
            .collect();
        let mut expected: Vec<(Link, f64)> = keep
            .iter()
            .copied()
            .zip(kept_estimates.iter().copied())
            .chain(new.iter().map(|l| (*l, UNKNOWN)))
            .collect();
        expected.sort_by_key(|(l, _)| l.receiver);
        let mut sorted_new = new.clone();
        sorted_new.sort_by_key(|l| l.receiver);
        let (links, estimates) = merge_by_receiver(keep, kept_estimates, sorted_new);
        let got: Vec<(u32, u32, u64)> = links
            .iter()
            .zip(&estimates)
            .map(|(l, e)| (l.receiver, l.source, e.to_bits()))
            .collect();
        let want: Vec<(u32, u32, u64)> = expected
            .iter()
            .map(|(l, e)| (l.receiver, l.source, e.to_bits()))
            .collect();
        assert_eq!(got, want, "case {case}");
    }
}

/// Each patch's run starts at its node and ends where the next patch starts; the nodes
/// before the first patch are in no run.
#[test]
fn patch_runs_cover_each_patch_to_the_next() {
    let mut b: Vec<Rgb> = (0..20).map(|i| [f64::from(i); 3]).collect();
    let runs = patch_runs(&[2, 5, 6, 15], &mut b);
    let got: Vec<(u32, f64, usize)> = runs
        .iter()
        .map(|(p, run)| (*p, run[0][0], run.len()))
        .collect();
    assert_eq!(got, [(2, 2.0, 3), (5, 5.0, 1), (6, 6.0, 9), (15, 15.0, 5)]);
    assert!(patch_runs(&[], &mut b).is_empty());
}

/// Dropping the occluded links keeps every other link, in order.
#[test]
fn only_links_of_factor_zero_are_dropped() {
    let links: Vec<Link> = (0..40u32)
        .map(|i| Link {
            receiver: i / 8,
            source: i,
            form_factor: match i % 5 {
                0 => 0.0,
                1 => 1e-300,
                _ => f64::from(i) * 1e-3,
            },
        })
        .collect();
    let mut h = Hierarchy {
        links: links.clone(),
        refinement: Vec::new(),
    };
    h.drop_occluded();
    let expected: Vec<Link> = links.into_iter().filter(|l| l.source % 5 != 0).collect();
    assert_eq!(h.links, expected);
}

/// The refinement test skips the estimate when even a factor of [`ESTIMATE_BOUND`] could
/// not pass it: every computed point factor stays under that bound, here for seeded random
/// triangles seen from points near and far, at grazing angles and next to a contact
/// (the point on an edge's extension, a hemisphere nearly filled).
#[test]
fn point_factors_stay_under_the_refinement_bound() {
    use rand::{Rng, SeedableRng};
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(17);
    let mut largest = 0.0_f64;
    for i in 0..200_000 {
        let scale = [1e-3, 1.0, 1e3][i % 3];
        let mut p = || Point3::new(rng.random::<f64>(), rng.random(), rng.random()) * scale;
        let tri = [p(), p(), p()];
        let tri_normal = (tri[1] - tri[0]).cross(&(tri[2] - tri[0]));
        if tri_normal.norm() < 1e-12 * scale * scale {
            continue;
        }
        let tri_normal = tri_normal.normalize();
        // A point just in front of the triangle (a nearly filled hemisphere) or anywhere.
        let x = if i % 2 == 0 {
            let w = [rng.random::<f64>(), rng.random::<f64>()];
            let (u, v) = if w[0] + w[1] > 1.0 {
                (1.0 - w[0], 1.0 - w[1])
            } else {
                (w[0], w[1])
            };
            tri[0]
                + (tri[1] - tri[0]) * u
                + (tri[2] - tri[0]) * v
                + tri_normal * (scale * 10f64.powf(-6.0 * rng.random::<f64>()))
        } else {
            Point3::new(rng.random::<f64>(), rng.random(), rng.random()) * (2.0 * scale)
        };
        let n = Vector3::new(
            rng.random::<f64>() - 0.5,
            rng.random::<f64>() - 0.5,
            rng.random::<f64>() - 0.5,
        );
        let n = if i % 4 == 0 {
            -tri_normal
        } else {
            n.normalize()
        };
        let f = super::super::form_factor::point_to_triangle(&x, &n, &tri, &tri_normal);
        largest = largest.max(f);
    }
    assert!(largest <= ESTIMATE_BOUND, "largest point factor {largest}");
    // The configurations do reach factors near 1 (the bound is tested where it matters).
    assert!(largest > 0.99, "largest point factor {largest}");
}
