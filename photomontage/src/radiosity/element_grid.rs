//! Which elements may hold a point: a hierarchical hash grid of the elements' bounding boxes
//! (one uniform grid per power-of-two size class, as in Teschner et al. 2003, "Optimized spatial
//! hashing for collision detection of deformable objects", and the multi-level grids of ray
//! tracing). An element sits in the grid of the smallest cell size 2^L m not below its padded
//! bounding box's largest side, so it enters at most 2 × 2 × 2 cells; a point looks up its cell
//! in every level that holds elements. A query thus sees a handful of candidates whatever the
//! mix of element sizes: one grid of the longest element's size put thousands of 1 m elements in
//! each 35 m cell of a mesh with 25 m elements beside them.
//!
//! The grid answers "whose padded box may contain the point"; [`super::query`] then checks the
//! candidates' planes and barycentric coordinates.

use nalgebra::{Point3, Vector3};

use rustc_hash::FxHashMap;

use super::mesh::Mesh;

/// Elements by cell: key (level L, cell x, y, z) with cells of 2^L metres.
#[derive(Debug, Clone, Default)]
pub(crate) struct ElementGrid {
    /// The levels that hold elements, ascending, each with 2^−L (exact).
    levels: Vec<(i32, f64)>,
    /// Integer keys hash with Fx (the renderer looks up every level at every shading point);
    /// each cell's elements are `members[start..end]`, in ascending order.
    cells: FxHashMap<[i64; 4], (u32, u32)>,
    /// The cells' elements, cell after cell.
    members: Vec<u32>,
    /// Per element, its padded box (low and high corner).
    boxes: Vec<[Point3<f64>; 2]>,
}

/// Levels are clamped to 2^±40 m (sizes beyond that are not geometry).
const LEVEL_LIMIT: i32 = 40;

fn level_of(size_m: f64) -> i32 {
    #[allow(clippy::cast_possible_truncation)]
    let level = size_m.max(f64::MIN_POSITIVE).log2().ceil() as i32;
    level.clamp(-LEVEL_LIMIT, LEVEL_LIMIT)
}

/// 2^−L, exactly (a power of two within the levels' range).
fn inverse_size(level: i32) -> f64 {
    2.0_f64.powi(-level)
}

/// The cell of level `level` (with `inv` = [`inverse_size`]) that holds `p`.
fn cell_of(p: &Point3<f64>, level: i32, inv: f64) -> [i64; 4] {
    [
        i64::from(level),
        floor_to_int(p.x * inv),
        floor_to_int(p.y * inv),
        floor_to_int(p.z * inv),
    ]
}

/// `x.floor() as i64` without a call to `floor` (a library call on the baseline x86-64 this is
/// built for; the renderer asks it three times per level at every shading point): truncate,
/// then step down where that rounded up. The same value for every `x`, NaN and infinities
/// included (both saturate).
#[allow(clippy::cast_possible_truncation, clippy::cast_precision_loss)]
fn floor_to_int(x: f64) -> i64 {
    let t = x as i64;
    if (t as f64) > x {
        t.saturating_sub(1)
    } else {
        t
    }
}

/// The bounding box of element `e`, padded by `pad_m` on every side (low and high corner).
fn padded_box(mesh: &Mesh, e: usize, pad_m: f64) -> [Point3<f64>; 2] {
    let v = &mesh.element_node(e).vertices_in_world_m;
    let pad = Vector3::repeat(pad_m);
    let lo = v.iter().fold(Point3::from([f64::MAX; 3]), |a, p| a.inf(p)) - pad;
    let hi = v.iter().fold(Point3::from([f64::MIN; 3]), |a, p| a.sup(p)) + pad;
    [lo, hi]
}

impl ElementGrid {
    /// The grid of `mesh`'s elements, each box padded by `pad_m` on every side.
    pub(crate) fn new(mesh: &Mesh, pad_m: f64) -> Self {
        let mut entries: Vec<([i64; 4], u32)> = Vec::new();
        let mut levels: Vec<i32> = Vec::new();
        let boxes: Vec<[Point3<f64>; 2]> = (0..mesh.elements.len())
            .map(|e| padded_box(mesh, e, pad_m))
            .collect();
        for (e, [lo, hi]) in boxes.iter().enumerate() {
            let level = level_of((hi - lo).max());
            if let Err(at) = levels.binary_search(&level) {
                levels.insert(at, level);
            }
            let inv = inverse_size(level);
            let (a, b) = (cell_of(lo, level, inv), cell_of(hi, level, inv));
            for x in a[1]..=b[1] {
                for y in a[2]..=b[2] {
                    for z in a[3]..=b[3] {
                        #[allow(clippy::cast_possible_truncation)]
                        entries.push(([a[0], x, y, z], e as u32));
                    }
                }
            }
        }
        // By cell, each cell's elements in ascending order (every entry is another pair).
        entries.sort_unstable();
        let mut cells: FxHashMap<[i64; 4], (u32, u32)> = FxHashMap::default();
        let members: Vec<u32> = entries.iter().map(|&(_, e)| e).collect();
        for (i, (key, _)) in (0u32..).zip(&entries) {
            cells
                .entry(*key)
                .and_modify(|r| r.1 = i + 1)
                .or_insert((i, i + 1));
        }
        Self {
            levels: levels.into_iter().map(|l| (l, inverse_size(l))).collect(),
            cells,
            members,
            boxes,
        }
    }

    /// Every element whose padded box contains `point` (each level's elements in ascending
    /// order; an element appears once).
    pub(crate) fn candidates<'a>(&'a self, point: &Point3<f64>) -> impl Iterator<Item = u32> + 'a {
        let point = *point;
        self.levels
            .iter()
            .filter_map(move |&(level, inv)| self.cells.get(&cell_of(&point, level, inv)))
            .flat_map(|&(start, end)| &self.members[start as usize..end as usize])
            .copied()
            .filter(move |&e| {
                let [lo, hi] = &self.boxes[e as usize];
                (0..3).all(|k| lo[k] <= point[k] && point[k] <= hi[k])
            })
    }
}

#[cfg(test)]
mod tests {
    use nalgebra::Point3;
    use rand::{Rng, SeedableRng};
    use rand_chacha::ChaCha8Rng;

    use super::*;
    use crate::radiosity::MeshParams;
    use crate::radiosity::test_scenes::{add, grey, quad};
    use crate::scene::Scene;

    const PAD_M: f64 = 0.05;

    /// A 1 m-meshed square beside a 16 m-meshed ring and a 0.25 m-meshed wall: three sizes.
    fn mixed() -> Mesh {
        let p = Point3::new;
        let mut scene = Scene::new();
        add(
            &mut scene,
            "near",
            quad(
                p(-4., -4., 0.),
                p(4., -4., 0.),
                p(4., 4., 0.),
                p(-4., 4., 0.),
            ),
            grey("g", 0.3),
        );
        add(
            &mut scene,
            "far",
            quad(
                p(4., -64., 0.),
                p(68., -64., 0.),
                p(68., 64., 0.),
                p(4., 64., 0.),
            ),
            grey("f", 0.3),
        );
        add(
            &mut scene,
            "wall",
            quad(p(0., -1., 0.), p(0., 1., 0.), p(0., 1., 2.), p(0., -1., 2.)),
            grey("w", 0.5),
        );
        let params = MeshParams {
            max_patch_edge_m: 16.0,
            max_element_edge_m: 16.0,
            object_element_edge_m: [("near".to_owned(), 1.0), ("wall".to_owned(), 0.25)]
                .into_iter()
                .collect(),
            ..MeshParams::default()
        };
        Mesh::build(&scene, &params).expect("mesh")
    }

    /// Against brute force: for random points around the scene, the candidates are exactly the
    /// elements whose padded box contains the point, each once.
    #[test]
    fn candidates_hold_every_box_that_contains_the_point() {
        let mesh = mixed();
        let grid = ElementGrid::new(&mesh, PAD_M);
        let boxes: Vec<[Point3<f64>; 2]> = (0..mesh.elements.len())
            .map(|e| padded_box(&mesh, e, PAD_M))
            .collect();
        let mut rng = ChaCha8Rng::seed_from_u64(7);
        let mut found = 0;
        for i in 0..4000 {
            let point = Point3::new(
                rng.random_range(-6.0..70.0),
                rng.random_range(-66.0..66.0),
                if i % 2 == 0 {
                    0.0
                } else {
                    rng.random_range(-0.1..2.1)
                },
            );
            let mut got: Vec<u32> = grid.candidates(&point).collect();
            let n = got.len();
            got.sort_unstable();
            got.dedup();
            assert_eq!(got.len(), n, "an element listed twice at {point}");
            #[allow(clippy::cast_possible_truncation)]
            let inside: Vec<u32> = boxes
                .iter()
                .enumerate()
                .filter(|(_, [lo, hi])| (0..3).all(|k| lo[k] <= point[k] && point[k] <= hi[k]))
                .map(|(e, _)| e as u32)
                .collect();
            assert_eq!(got, inside, "at {point}");
            found += n;
        }
        // Half the points lie on the ground, on elements of every size (not a vacuous
        // comparison): 3 616 candidates were measured.
        assert!(found > 2000, "{found} candidates in all");
    }

    /// The call-free floor is `floor() as i64` for every value class: random values at every
    /// scale, integers, the values just below them, ±0, the ends of `i64`, infinities and NaN.
    #[test]
    #[allow(clippy::cast_possible_truncation, clippy::cast_precision_loss)]
    fn the_floor_without_a_call_is_floor() {
        let mut rng = ChaCha8Rng::seed_from_u64(3);
        let mut values = vec![
            0.0,
            -0.0,
            0.5,
            -0.5,
            1.0,
            -1.0,
            i64::MAX as f64,
            i64::MIN as f64,
            1e30,
            -1e30,
            f64::INFINITY,
            f64::NEG_INFINITY,
            f64::NAN,
            f64::MIN_POSITIVE,
            -f64::MIN_POSITIVE,
        ];
        for _ in 0..20_000 {
            let scale = 10f64.powi(rng.random_range(-3..19));
            let x: f64 = rng.random_range(-1.0..1.0) * scale;
            values.extend([x, x.round(), x.round().next_down(), x.round().next_up()]);
        }
        for x in values {
            assert_eq!(floor_to_int(x), x.floor() as i64, "at {x:e}");
        }
    }
}
