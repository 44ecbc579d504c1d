//! Link-refinement study on the city block (not a timing bench): how far the interreflected
//! radiosity of the relight benches' hierarchies lies from a more finely linked reference with the
//! same elements. Prints one row per hierarchy.
//!
//! `cargo bench -p photomontage --bench link_refinement` (release profile; ≈ minutes).
#![allow(clippy::unwrap_used)]

use std::sync::atomic::AtomicBool;
use std::time::Instant;

mod common;
use common::indirect_by_centroid;

use photomontage::radiosity::city_block::{
    RENDER_ALBEDO, city_block, city_block_lighting, city_block_params_with_roots,
};
use photomontage::radiosity::hierarchical::HierarchicalParams;
use photomontage::radiosity::{RelightStrategy, Solver, Sweep, Transfer, TransferParams};

fn params(roots_m: f64, ff_tol: f64, bf_tol: f64, max_links: usize) -> TransferParams {
    let mut p =
        city_block_params_with_roots(RelightStrategy::LinearResponses, Sweep::Shooting, roots_m);
    p.solve.solver = Solver::Hierarchical(HierarchicalParams {
        form_factor_tolerance: ff_tol,
        bf_tolerance: bf_tol,
        max_links,
    });
    p
}

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let ref_tol: f64 = args
        .iter()
        .find_map(|a| a.strip_prefix("--ref-tol=").map(|v| v.parse().unwrap()))
        .unwrap_or(0.01);
    let scene = city_block(0, [RENDER_ALBEDO; 3]).unwrap();
    let build = |p: &TransferParams| {
        let t0 = Instant::now();
        let t = Transfer::build(
            &scene,
            &city_block_lighting(),
            p,
            &AtomicBool::new(false),
            &|_| {},
        )
        .unwrap();
        (t, t0.elapsed().as_secs_f64())
    };
    let (reference, ref_s) = build(&params(8.0, ref_tol, 0.002, 5_000_000));
    let r = indirect_by_centroid(reference.solution());
    println!(
        "reference: 8 m roots, F_eps {ref_tol}: {} links, {ref_s:.1} s",
        reference.solution().interactions
    );
    drop(reference);
    let cases = [
        (
            "8 m roots, F_eps 0.05 (the benches')",
            params(8.0, 0.05, 0.002, 5_000_000),
        ),
        (
            "32 m roots, F_eps 0.05",
            params(32.0, 0.05, 0.002, 5_000_000),
        ),
        (
            "32 m roots, F_eps 0.05, BF 0.0005",
            params(32.0, 0.05, 0.0005, 20_000_000),
        ),
    ];
    for (name, p) in cases {
        let (t, s) = build(&p);
        let o = indirect_by_centroid(t.solution());
        let (mut l1, mut sum_r, mut sum_o, mut worst) = (0.0, 0.0, 0.0, 0.0_f64);
        for (k, &(vr, a)) in &r {
            let vo = o[k].0;
            l1 += a * (vo - vr).abs();
            sum_r += a * vr;
            sum_o += a * vo;
            if vr > 1e-9 {
                worst = worst.max((vo / vr - 1.0).abs());
            }
        }
        println!(
            "{name}: {} patches, {} links, {s:.1} s; interreflected (area-weighted) L1 {:.2} %, \
             mean {:+.2} %, worst element {:.0} %",
            t.solution().mesh.patches.len(),
            t.solution().interactions,
            100.0 * l1 / sum_r,
            100.0 * (sum_o / sum_r - 1.0),
            100.0 * worst
        );
    }
}
