//! Small scenes with known answers for the radiosity tests and benches (geometry of
//! `../shared/reference/lighting.md` §5.1 and a closed box for the enclosure identity).
#![allow(clippy::unwrap_used)]

use nalgebra::Point3;

use crate::scene::{ImportedModel, Material, ObjectKind, Scene};

type Tri = [Point3<f64>; 3];

fn p(x: f64, y: f64, z: f64) -> Point3<f64> {
    Point3::new(x, y, z)
}

/// A quad `a b c d` (counter-clockwise from the front) as two triangles.
pub fn quad(a: Point3<f64>, b: Point3<f64>, c: Point3<f64>, d: Point3<f64>) -> Vec<Tri> {
    vec![[a, b, c], [a, c, d]]
}

/// Adds `triangles` as one object with one material.
pub fn add(scene: &mut Scene, name: &str, triangles: Vec<Tri>, material: Material) {
    let n = triangles.len();
    let model = ImportedModel {
        triangles_in_world_m: triangles,
        triangle_materials: vec![0; n],
        materials: vec![material],
        warnings: Vec::new(),
    };
    scene
        .add_model(&model, name, ObjectKind::Artificial)
        .unwrap();
}

/// Grey Lambertian material.
pub fn grey(name: &str, reflectance: f64) -> Material {
    Material::diffuse(name, [reflectance; 3])
}

/// A site's proportions: a 1 km "ground" square (ρ 0.2) with a 20 × 20 × 8 m "house" (ρ 0.6)
/// in its middle.
pub fn kilometre_site() -> Scene {
    let g = |x: f64, y: f64| p(x, y, 0.0);
    let mut scene = Scene::new();
    let (n, f) = (10.0, 500.0);
    add(
        &mut scene,
        "ground",
        quad(g(-f, -f), g(f, -f), g(f, f), g(-f, f)),
        grey("grey", 0.2),
    );
    add(
        &mut scene,
        "house",
        block(p(-n, -n, 0.0), p(n, n, 8.0)),
        grey("white", 0.6),
    );
    scene
}

/// Two directly opposed squares of side `side_m`, `gap_m` apart: "emitter" in z = 0 facing +z,
/// "receiver" in z = gap facing −z.
pub fn squares_parallel(side_m: f64, gap_m: f64) -> Scene {
    let s = side_m;
    let mut scene = Scene::new();
    let emitter = quad(p(0., 0., 0.), p(s, 0., 0.), p(s, s, 0.), p(0., s, 0.));
    let receiver = quad(
        p(0., 0., gap_m),
        p(0., s, gap_m),
        p(s, s, gap_m),
        p(s, 0., gap_m),
    );
    add(&mut scene, "emitter", emitter, grey("white", 0.5));
    add(&mut scene, "receiver", receiver, grey("white", 0.5));
    scene
}

/// Unit squares at right angles with a common edge (the y axis): "emitter" in z = 0 facing +z,
/// "receiver" in x = 0 facing +x.
pub fn squares_perpendicular() -> Scene {
    let mut scene = Scene::new();
    let emitter = quad(p(0., 0., 0.), p(1., 0., 0.), p(1., 1., 0.), p(0., 1., 0.));
    let receiver = quad(p(0., 0., 0.), p(0., 1., 0.), p(0., 1., 1.), p(0., 0., 1.));
    add(&mut scene, "emitter", emitter, grey("white", 0.5));
    add(&mut scene, "receiver", receiver, grey("white", 0.5));
    scene
}

/// Coaxial discs (regular `segments`-gons of radius `radius_m`, fans from the centre), `gap_m`
/// apart: "emitter" in z = 0 facing +z, "receiver" in z = gap facing −z.
pub fn discs(radius_m: f64, gap_m: f64, segments: usize) -> Scene {
    let mut scene = Scene::new();
    let rim = |k: usize, z: f64| {
        #[allow(clippy::cast_precision_loss)]
        let a = std::f64::consts::TAU * k as f64 / segments as f64;
        p(radius_m * a.cos(), radius_m * a.sin(), z)
    };
    let emitter = (0..segments)
        .map(|k| [p(0., 0., 0.), rim(k, 0.), rim(k + 1, 0.)])
        .collect();
    let receiver = (0..segments)
        .map(|k| [p(0., 0., gap_m), rim(k + 1, gap_m), rim(k, gap_m)])
        .collect();
    add(&mut scene, "emitter", emitter, grey("white", 0.5));
    add(&mut scene, "receiver", receiver, grey("white", 0.5));
    scene
}

/// [`squares_parallel`] (1 m, 1 m apart) with a "plate" in z = 0.5 covering x < 0.5: by the
/// symmetry x → 1 − x it blocks exactly half of the exchange.
pub fn squares_half_blocked() -> Scene {
    let mut scene = squares_parallel(1.0, 1.0);
    let plate = quad(
        p(-10., -10., 0.5),
        p(-10., 11., 0.5),
        p(0.5, 11., 0.5),
        p(0.5, -10., 0.5),
    );
    add(&mut scene, "plate", plate, grey("black", 0.0));
    scene
}

/// The six faces of an axis-aligned cube of side `side_m` with normals pointing inwards, each
/// face its own object (`-x`, `+x`, `-y`, `+y`, `-z`, `+z`), all with `material`.
pub fn closed_box(side_m: f64, material: &Material) -> Scene {
    let s = side_m;
    let mut scene = Scene::new();
    let faces = [
        (
            "-x",
            quad(p(0., 0., 0.), p(0., s, 0.), p(0., s, s), p(0., 0., s)),
        ),
        (
            "+x",
            quad(p(s, 0., 0.), p(s, 0., s), p(s, s, s), p(s, s, 0.)),
        ),
        (
            "-y",
            quad(p(0., 0., 0.), p(0., 0., s), p(s, 0., s), p(s, 0., 0.)),
        ),
        (
            "+y",
            quad(p(0., s, 0.), p(s, s, 0.), p(s, s, s), p(0., s, s)),
        ),
        (
            "-z",
            quad(p(0., 0., 0.), p(s, 0., 0.), p(s, s, 0.), p(0., s, 0.)),
        ),
        (
            "+z",
            quad(p(0., 0., s), p(0., s, s), p(s, s, s), p(s, 0., s)),
        ),
    ];
    for (name, tris) in faces {
        add(&mut scene, name, tris, material.clone());
    }
    scene
}

/// The outward faces of a box from `lo` to `hi`.
pub fn block(lo: Point3<f64>, hi: Point3<f64>) -> Vec<Tri> {
    let (a, b) = (lo, hi);
    let mut t = Vec::new();
    t.extend(quad(
        p(a.x, a.y, a.z),
        p(a.x, a.y, b.z),
        p(a.x, b.y, b.z),
        p(a.x, b.y, a.z),
    ));
    t.extend(quad(
        p(b.x, a.y, a.z),
        p(b.x, b.y, a.z),
        p(b.x, b.y, b.z),
        p(b.x, a.y, b.z),
    ));
    t.extend(quad(
        p(a.x, a.y, a.z),
        p(b.x, a.y, a.z),
        p(b.x, a.y, b.z),
        p(a.x, a.y, b.z),
    ));
    t.extend(quad(
        p(a.x, b.y, a.z),
        p(a.x, b.y, b.z),
        p(b.x, b.y, b.z),
        p(b.x, b.y, a.z),
    ));
    t.extend(quad(
        p(a.x, a.y, a.z),
        p(a.x, b.y, a.z),
        p(b.x, b.y, a.z),
        p(b.x, a.y, a.z),
    ));
    t.extend(quad(
        p(a.x, a.y, b.z),
        p(b.x, a.y, b.z),
        p(b.x, b.y, b.z),
        p(a.x, b.y, b.z),
    ));
    t
}

/// A small Cornell-like room (1 m cube, open at y = 0, inward faces): red `-x` wall, green
/// `+x` wall, white floor, back and ceiling, an emitting ceiling panel just below the ceiling
/// and a white block standing on the floor (occlusion).
pub fn small_room() -> Scene {
    let mut scene = closed_box_open_front();
    let panel = quad(
        p(0.35, 0.35, 0.99),
        p(0.35, 0.65, 0.99),
        p(0.65, 0.65, 0.99),
        p(0.65, 0.35, 0.99),
    );
    let mut lamp = grey("lamp", 0.0);
    lamp.emission_rgb_w_m2_sr = Some([1.0, 0.9, 0.7]);
    add(&mut scene, "lamp", panel, lamp);
    add(
        &mut scene,
        "block",
        block(p(0.55, 0.45, 0.0), p(0.8, 0.7, 0.45)),
        grey("white", 0.7),
    );
    scene
}

fn closed_box_open_front() -> Scene {
    let mut scene = Scene::new();
    let red = Material::diffuse("red", [0.63, 0.065, 0.05]);
    let green = Material::diffuse("green", [0.14, 0.45, 0.091]);
    let white = Material::diffuse("white", [0.725, 0.71, 0.68]);
    let faces = [
        (
            "left",
            quad(p(0., 0., 0.), p(0., 1., 0.), p(0., 1., 1.), p(0., 0., 1.)),
            &red,
        ),
        (
            "right",
            quad(p(1., 0., 0.), p(1., 0., 1.), p(1., 1., 1.), p(1., 1., 0.)),
            &green,
        ),
        (
            "back",
            quad(p(0., 1., 0.), p(1., 1., 0.), p(1., 1., 1.), p(0., 1., 1.)),
            &white,
        ),
        (
            "floor",
            quad(p(0., 0., 0.), p(1., 0., 0.), p(1., 1., 0.), p(0., 1., 0.)),
            &white,
        ),
        (
            "ceiling",
            quad(p(0., 0., 1.), p(0., 1., 1.), p(1., 1., 1.), p(1., 0., 1.)),
            &white,
        ),
    ];
    for (name, tris, m) in faces {
        add(&mut scene, name, tris, m.clone());
    }
    scene
}

/// An object "sliver" with one zero-area triangle next to a good one, and an object "soot"
/// whose material reflects nothing.
pub fn degenerate_and_black() -> Scene {
    let mut scene = Scene::new();
    let sliver = vec![
        [p(0., 0., 0.), p(1., 0., 0.), p(2., 0., 0.)],
        [p(0., 0., 0.), p(1., 0., 0.), p(1., 1., 0.)],
    ];
    add(&mut scene, "sliver", sliver, grey("white", 0.5));
    let soot = quad(p(0., 0., 1.), p(0., 1., 1.), p(1., 1., 1.), p(1., 0., 1.));
    add(&mut scene, "soot", soot, grey("soot", 0.0));
    scene
}
