//! Meshing the scene into patches and elements (Tonn & Donath, seed 000, "Generation of
//! patches": "through the definition of a single global size and different local geometric sizes
//! for patches, the entire geometry of the model is subdivided into … triangles"; Cohen & Wallace
//! ch. 8 for the patch/element distinction of hierarchical radiosity).
//!
//! Every scene triangle is the root of a quadtree of triangles made by midpoint 1→4 splits (each
//! child keeps the parent's orientation; the four children tile the parent exactly, so areas add
//! up exactly and every edge halves per level). The node level where the longest edge first falls
//! to [`MeshParams::max_patch_edge_m`] or below holds the **patches** (roots of the hierarchical
//! solver); the level where it falls to the element size (global, or the object's own) holds the
//! **elements** (leaves, the unknowns of the progressive and the direct solver). The subdivision
//! is deterministic (no randomness): the same scene and parameters give the same mesh.
//!
//! **Grading** ([`MeshParams::grading`], [`super::mesh_grading`]): every size is multiplied by a
//! factor g ≥ 1 that grows with the node's distance from the places a montage looks at, so the
//! levels are decided node by node: a node is a patch where its edge first falls to the patch
//! size times its g, an element where it falls to the element size times its g. Sizes are
//! compared on the scene triangle's longest edge halved once per level, as without grading, so
//! g = 1 gives the ungraded mesh exactly.
//!
//! [`Mesh::ply`] writes the elements as binary-free ASCII PLY with their radiosity as vertex-free
//! face colours, for inspection in MeshLab or Blender.
//!
//! **Refinement** ([`Mesh::build_refined`]): below the element level a node is split further,
//! down to [`Refinement::min_element_edge_m`], where a predicate asks for it. With
//! [`MeshParams::shadow_edge_element_m`] set, [`Mesh::build_lit`] (used by the solve and the
//! transfer, so both mesh alike) splits where a sun shadow edge crosses the node
//! ([`super::shadow_refinement`]), so that a shadow narrower than the element size (a garden
//! wall's) is not averaged into the light around it. Splits stay depth-first, so a patch's
//! elements keep their order; elements of different sizes meet in T-junctions.
//!
//! # Known limitations
//! Refinement only by the predicate given (no a-posteriori refinement on the solution's
//! gradients); a long thin triangle keeps its aspect ratio in its children. Surfaces are
//! one-sided.

use std::collections::BTreeMap;
use std::sync::Arc;

use nalgebra::{Point3, Vector3};

use super::mesh_grading::Grading;
use super::{RadiosityError, Rgb, check_positive};
use crate::bvh::BuildQuality;
use crate::scene::{ObjectId, Scene, SceneTracer};

/// Triangles with area below this fraction of their longest edge squared are degenerate
/// (a sliver whose normal is not defined to better than ~1e-9 rad in `f64`).
const DEGENERATE_AREA_RATIO: f64 = 1e-12;

/// Meshing tunables.
#[derive(Debug, Clone, PartialEq)]
pub struct MeshParams {
    /// Longest patch edge, metres (Tonn's global size; the hierarchy roots).
    pub max_patch_edge_m: f64,
    /// Longest element edge, metres (the finest level), unless the object has its own.
    pub max_element_edge_m: f64,
    /// Per-object element sizes by object name (Tonn's local sizes), metres.
    pub object_element_edge_m: BTreeMap<String, f64>,
    /// Per-object patch sizes by object name, metres (else [`MeshParams::max_patch_edge_m`]):
    /// an object with a coarse element size of its own keeps patches a few elements across
    /// ([`MeshParams::sized_for`]) instead of one patch per element.
    pub object_patch_edge_m: BTreeMap<String, f64>,
    /// Refuse to mesh beyond this many elements.
    pub max_elements: usize,
    /// Split elements that a sun shadow edge crosses down to this edge, metres, when the mesh
    /// is built for a lighting with a sun ([`Mesh::build_lit`]); `None` meshes uniformly.
    pub shadow_edge_element_m: Option<f64>,
    /// Split elements that face another surface closer than their own size (concave corners,
    /// overhangs; [`super::corner_refinement`]) down to this edge, metres; `None` leaves corners
    /// at the element size.
    pub corner_element_m: Option<f64>,
    /// Sizes that grow away from the cameras and the planned objects
    /// ([`super::mesh_grading`]); `None` meshes at the sizes above everywhere.
    pub grading: Option<Grading>,
}

impl Default for MeshParams {
    /// 4 m patches, 1 m elements, at most 200 000 elements, no shadow-edge or corner refinement.
    fn default() -> Self {
        Self {
            max_patch_edge_m: 4.0,
            max_element_edge_m: 1.0,
            object_element_edge_m: BTreeMap::new(),
            object_patch_edge_m: BTreeMap::new(),
            max_elements: 200_000,
            shadow_edge_element_m: None,
            corner_element_m: None,
            grading: None,
        }
    }
}

/// A problem that did not stop the meshing.
#[derive(Debug, Clone, PartialEq)]
pub enum MeshWarning {
    /// A triangle with (near) zero area or a non-finite vertex was skipped.
    DegenerateTriangle {
        /// Object name.
        object: String,
        /// Index of the triangle in the scene.
        triangle: usize,
    },
    /// An object reflects nothing (ρ = 0 in every channel): it absorbs all light and takes no
    /// part in the interreflection.
    ZeroReflectance {
        /// Object name.
        object: String,
        /// Material name.
        material: String,
    },
}

impl std::fmt::Display for MeshWarning {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Self::DegenerateTriangle { object, triangle } => write!(
                f,
                "object `{object}`: triangle {triangle} is degenerate (zero area or non-finite) \
                 and was left out of the radiosity mesh"
            ),
            Self::ZeroReflectance { object, material } => write!(
                f,
                "object `{object}`: material `{material}` has zero diffuse reflectance; the \
                 object absorbs all light in the radiosity solve"
            ),
        }
    }
}

/// The surface properties shared by all nodes of one scene triangle.
#[derive(Debug, Clone, PartialEq)]
pub struct Surface {
    /// The scene triangle.
    pub scene_triangle: usize,
    /// Its object.
    pub object: ObjectId,
    /// Diffuse reflectance ρ_d per channel, in [0, 1].
    pub reflectance_rgb: Rgb,
    /// Emitted exitance π·L_e per channel (0 for non-emitters).
    pub emission_rgb: Rgb,
}

/// One triangle of the hierarchy.
#[derive(Debug, Clone, PartialEq)]
pub struct MeshNode {
    /// Vertices, world metres, counter-clockwise seen from the front.
    pub vertices_in_world_m: [Point3<f64>; 3],
    /// Unit front normal.
    pub normal_in_world: Vector3<f64>,
    /// Area, m².
    pub area_m2: f64,
    /// Index into [`Mesh::surfaces`].
    pub surface: u32,
    /// The four children, or `None` for an element.
    pub children: Option<[u32; 4]>,
    /// For an element: its index in [`Mesh::elements`].
    pub element: Option<u32>,
    /// Fraction of the node's area outside closed solids (not under a wall or block standing
    /// on it), [`super::covered`]; 1 until [`super::covered::mark_covered`] runs.
    pub open_fraction: f64,
}

impl MeshNode {
    /// Centroid, world metres.
    #[must_use]
    pub fn centroid_in_world_m(&self) -> Point3<f64> {
        let [a, b, c] = self.vertices_in_world_m;
        Point3::from((a.coords + b.coords + c.coords) / 3.0)
    }

    /// The point of the triangle at unit-square coordinates (u, v), area-uniform
    /// (Cohen & Wallace §4.9 / Shirley's square-to-triangle warp).
    #[must_use]
    pub fn point_at(&self, u: f64, v: f64) -> Point3<f64> {
        let [a, b, c] = self.vertices_in_world_m;
        let s = u.sqrt();
        Point3::from(a.coords * (1.0 - s) + b.coords * (s * (1.0 - v)) + c.coords * (s * v))
    }
}

/// Patches and elements of a scene.
#[derive(Debug, Clone, PartialEq)]
pub struct Mesh {
    /// All nodes: for every scene triangle its subtree, patches and elements included. Shared
    /// by the mesh's clones, so that a reflectance edit (a relight clones the mesh the renderer
    /// still reads) copies surfaces, not nodes.
    pub nodes: Arc<Vec<MeshNode>>,
    /// Node ids of the patches (hierarchy roots of the hierarchical solver).
    pub patches: Vec<u32>,
    /// Node ids of the elements (leaves), in depth-first order per patch.
    pub elements: Vec<u32>,
    /// Surface properties per meshed scene triangle.
    pub surfaces: Vec<Surface>,
    /// Object names by [`ObjectId`] index.
    pub object_names: Vec<String>,
    /// Problems found while meshing.
    pub warnings: Vec<MeshWarning>,
    /// A hash of the geometry (node vertices, the tree, the elements), set when the mesh is
    /// built. A reflectance edit keeps it, so that what depends on geometry only (the
    /// renderer's vertex gathers) can tell a relit mesh from a new one without comparing nodes.
    pub geometry_hash: u64,
    /// Whether elements were split at corners ([`MeshParams::corner_element_m`]): the
    /// hierarchical solver then judges links by their largest point factor
    /// ([`super::form_factor::FormFactorEngine::largest_estimate`]).
    pub corner_refined: bool,
    /// Diffuse reflectance per node where it is not its surface's (ρ_d recovered from a photo,
    /// [`super::element_reflectance`]), indexed by node; `None` when no node has one.
    pub node_reflectance_rgb: Option<Arc<Vec<Option<Rgb>>>>,
}

/// Longest edge of the triangle `v`, metres.
pub(crate) fn longest_edge_m(v: &[Point3<f64>; 3]) -> f64 {
    (v[1] - v[0])
        .norm()
        .max((v[2] - v[1]).norm())
        .max((v[0] - v[2]).norm())
}

/// Midpoint splits needed to bring `longest_m` to `max_edge_m` or below.
fn levels_for(longest_m: f64, max_edge_m: f64) -> u32 {
    let mut levels = 0;
    let mut edge = longest_m;
    while edge > max_edge_m && levels < 30 {
        edge *= 0.5;
        levels += 1;
    }
    levels
}

/// Whether the node with these vertices (world metres) and unit normal is to be split.
pub type SplitTest<'a> = dyn Fn(&[Point3<f64>; 3], &Vector3<f64>) -> bool + Sync + 'a;

/// Splits elements further where [`Refinement::split`] asks (module doc).
pub struct Refinement<'a> {
    /// No element is split below this edge, metres.
    pub min_element_edge_m: f64,
    /// Whether the node with these vertices and unit normal is to be split.
    pub split: &'a SplitTest<'a>,
}

impl std::fmt::Debug for Refinement<'_> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Refinement")
            .field("min_element_edge_m", &self.min_element_edge_m)
            .finish_non_exhaustive()
    }
}

/// Deepest level a refinement may reach (edges 2⁻²⁴ of the scene triangle's).
const MAX_LEVEL: u32 = 24;

/// How one scene triangle is subdivided (module doc).
struct Subdivision<'a> {
    /// Element and patch edges of the triangle's object, metres.
    element_edge_m: f64,
    patch_edge_m: f64,
    /// The global element edge the grading factor is measured against, metres.
    global_edge_m: f64,
    grading: Option<&'a Grading>,
    refinement: Option<&'a Refinement<'a>>,
    /// Past this many elements no node is split (the build then fails on the budget).
    max_elements: usize,
}

impl Mesh {
    /// Meshes every triangle of `scene` (see the module doc), refined at corners when
    /// [`MeshParams::corner_element_m`] is set.
    ///
    /// # Errors
    /// [`RadiosityError::InvalidParameter`] for a non-positive size,
    /// [`RadiosityError::UnknownObject`] for a per-object size naming no object,
    /// [`RadiosityError::TooManyElements`] past the budget, [`RadiosityError::NoPatches`] when
    /// nothing (non-degenerate) remains.
    pub fn build(scene: &Scene, params: &MeshParams) -> Result<Self, RadiosityError> {
        Self::build_lit(scene, params, &[], &[])
    }

    /// [`Mesh::build`] for a lighting whose suns shine from `dirs_to_sun` (unit vectors toward
    /// them): with [`MeshParams::shadow_edge_element_m`] set, elements that a shadow edge of
    /// theirs crosses are split down to that size
    /// ([`super::shadow_refinement::crosses_shadow_edge`]); with
    /// [`MeshParams::corner_element_m`] set, elements facing another surface closer than their
    /// size are split down to that size ([`super::corner_refinement::faces_a_surface_nearby`]).
    /// The shadows and the surfaces are those of each of `occluders` (one that asks splits), or
    /// `scene`'s own when it is empty.
    ///
    /// # Errors
    /// As [`Mesh::build_refined`]; a tracer error for the scene.
    pub fn build_lit(
        scene: &Scene,
        params: &MeshParams,
        dirs_to_sun: &[Vector3<f64>],
        occluders: &[&SceneTracer],
    ) -> Result<Self, RadiosityError> {
        let shadow_m = params
            .shadow_edge_element_m
            .filter(|_| !dirs_to_sun.is_empty());
        let corner_m = params.corner_element_m;
        if let Some(m) = corner_m {
            check_positive("corner_element_m", m)?;
        }
        let min_element_edge_m = match (shadow_m, corner_m) {
            (None, None) => return Self::build_refined(scene, params, None),
            (Some(a), Some(b)) => a.min(b),
            (Some(a), None) | (None, Some(a)) => a,
        };
        let own;
        let tracers: &[&SceneTracer] = if occluders.is_empty() {
            own = [SceneTracer::new(scene, BuildQuality::Medium)?];
            &[&own[0]]
        } else {
            occluders
        };
        let split = |v: &[Point3<f64>; 3], n: &Vector3<f64>| {
            let edge_m = longest_edge_m(v);
            let shadow = shadow_m.is_some_and(|m| edge_m > m)
                && tracers
                    .iter()
                    .any(|t| super::shadow_refinement::crosses_shadow_edge(t, dirs_to_sun, v, n));
            shadow
                || corner_m.is_some_and(|m| edge_m > m)
                    && tracers
                        .iter()
                        .any(|t| super::corner_refinement::faces_a_surface_nearby(t, v, n, edge_m))
        };
        let refinement = Refinement {
            min_element_edge_m,
            split: &split,
        };
        let mut mesh = Self::build_refined(scene, params, Some(&refinement))?;
        mesh.corner_refined = corner_m.is_some();
        Ok(mesh)
    }

    /// [`Mesh::build`], splitting elements further where `refinement` asks (module doc).
    ///
    /// # Errors
    /// As [`Mesh::build`]; [`RadiosityError::InvalidParameter`] for a non-positive
    /// `min_element_edge_m`; [`RadiosityError::TooManyElements`] when the refined mesh passes
    /// the budget.
    pub fn build_refined(
        scene: &Scene,
        params: &MeshParams,
        refinement: Option<&Refinement<'_>>,
    ) -> Result<Self, RadiosityError> {
        if let Some(r) = refinement {
            check_positive("min_element_edge_m", r.min_element_edge_m)?;
        }
        check_positive("max_patch_edge_m", params.max_patch_edge_m)?;
        check_positive("max_element_edge_m", params.max_element_edge_m)?;
        if let Some(g) = &params.grading {
            g.validate()?;
        }
        let object_names: Vec<String> = scene.objects().iter().map(|o| o.name.clone()).collect();
        for (name, &size) in params
            .object_element_edge_m
            .iter()
            .chain(&params.object_patch_edge_m)
        {
            check_positive("object_element_edge_m", size)?;
            if !object_names.contains(name) {
                return Err(RadiosityError::UnknownObject {
                    object: name.clone(),
                });
            }
        }
        let mut mesh = Self {
            nodes: Arc::new(Vec::new()),
            patches: Vec::new(),
            elements: Vec::new(),
            surfaces: Vec::new(),
            object_names,
            warnings: Vec::new(),
            geometry_hash: 0,
            corner_refined: false,
            node_reflectance_rgb: None,
        };
        let name_of = |id: ObjectId| {
            scene
                .objects()
                .get(id.0 as usize)
                .map_or_else(|| format!("#{}", id.0), |o| o.name.clone())
        };
        let mut zero_reflectance_warned: Vec<(ObjectId, u32)> = Vec::new();
        for (index, tri) in scene.triangles().iter().enumerate() {
            let v = tri.vertices_in_world_m;
            let cross = (v[1] - v[0]).cross(&(v[2] - v[0]));
            let area_m2 = 0.5 * cross.norm();
            let longest = longest_edge_m(&v);
            let finite = v.iter().all(|p| p.coords.iter().all(|c| c.is_finite()));
            if !finite
                || area_m2.partial_cmp(&(DEGENERATE_AREA_RATIO * longest * longest))
                    != Some(std::cmp::Ordering::Greater)
            {
                mesh.warnings.push(MeshWarning::DegenerateTriangle {
                    object: name_of(tri.object),
                    triangle: index,
                });
                continue;
            }
            let material = scene.materials().get(tri.material.0 as usize);
            let reflectance_rgb = material
                .map_or([0.0; 3], |m| m.diffuse_reflectance_rgb())
                .map(|r| {
                    if r.is_finite() {
                        r.clamp(0.0, 1.0)
                    } else {
                        0.0
                    }
                });
            let emission_rgb = material
                .and_then(|m| m.emission_rgb_w_m2_sr)
                .unwrap_or([0.0; 3])
                .map(|l| std::f64::consts::PI * l.max(0.0));
            if reflectance_rgb.iter().all(|&r| r <= 0.0)
                && !zero_reflectance_warned.contains(&(tri.object, tri.material.0))
            {
                zero_reflectance_warned.push((tri.object, tri.material.0));
                mesh.warnings.push(MeshWarning::ZeroReflectance {
                    object: name_of(tri.object),
                    material: material.map_or_else(String::new, |m| m.name.clone()),
                });
            }
            let object_name = name_of(tri.object);
            let element_edge_m = params
                .object_element_edge_m
                .get(&object_name)
                .copied()
                .unwrap_or(params.max_element_edge_m);
            let element_levels = levels_for(longest, element_edge_m);
            let patch_edge_m = params
                .object_patch_edge_m
                .get(&object_name)
                .copied()
                .unwrap_or(params.max_patch_edge_m);
            let new_elements = 1usize << (2 * element_levels.min(31));
            // Graded, the count is known only after the subdivision, which stops at the budget.
            let ungraded_over = params.grading.is_none()
                && mesh.elements.len() + new_elements > params.max_elements;
            if element_levels > 15 || ungraded_over {
                return Err(RadiosityError::TooManyElements {
                    limit: params.max_elements,
                    object: object_name,
                });
            }
            let surface = u32::try_from(mesh.surfaces.len()).map_err(|_| {
                RadiosityError::TooManyElements {
                    limit: params.max_elements,
                    object: object_name.clone(),
                }
            })?;
            mesh.surfaces.push(Surface {
                scene_triangle: index,
                object: tri.object,
                reflectance_rgb,
                emission_rgb,
            });
            let subdivision = Subdivision {
                element_edge_m,
                patch_edge_m,
                global_edge_m: params.max_element_edge_m,
                grading: params.grading.as_ref(),
                refinement,
                max_elements: params.max_elements,
            };
            mesh.add_subtree(
                v,
                cross / (2.0 * area_m2),
                surface,
                (0, longest),
                false,
                &subdivision,
            );
            if mesh.elements.len() > params.max_elements {
                return Err(RadiosityError::TooManyElements {
                    limit: params.max_elements,
                    object: name_of(tri.object),
                });
            }
        }
        if mesh.elements.is_empty() {
            let reason = if scene.triangles().is_empty() {
                String::new()
            } else {
                format!(": all {} triangles are degenerate", scene.triangles().len())
            };
            return Err(RadiosityError::NoPatches { reason });
        }
        mesh.geometry_hash = mesh.hash_geometry();
        Ok(mesh)
    }

    /// Adds the node for `v` at `level` and its subtree; returns its id. `nominal_m` is the
    /// scene triangle's longest edge halved once per level (exact in `f64`, so the sizes are
    /// compared as [`levels_for`] does); `under_patch` whether an ancestor is a patch.
    #[allow(clippy::cast_possible_truncation)] // the element budget keeps ids far below 2³²
    fn add_subtree(
        &mut self,
        v: [Point3<f64>; 3],
        normal_in_world: Vector3<f64>,
        surface: u32,
        (level, nominal_m): (u32, f64),
        under_patch: bool,
        sub: &Subdivision<'_>,
    ) -> u32 {
        let id = self.nodes.len() as u32;
        let area_m2 = 0.5 * (v[1] - v[0]).cross(&(v[2] - v[0])).norm();
        Arc::make_mut(&mut self.nodes).push(MeshNode {
            vertices_in_world_m: v,
            normal_in_world,
            area_m2,
            surface,
            children: None,
            element: None,
            open_fraction: 1.0,
        });
        let grow = sub.grading.map_or(1.0, |g| g.factor(&v, sub.global_edge_m));
        let element_size = nominal_m <= sub.element_edge_m * grow;
        let patch = !under_patch && (element_size || nominal_m <= sub.patch_edge_m * grow);
        if patch {
            self.patches.push(id);
        }
        if element_size || self.elements.len() >= sub.max_elements {
            let split = level < MAX_LEVEL
                && self.elements.len() < sub.max_elements
                && sub.refinement.is_some_and(|r| {
                    longest_edge_m(&v) > r.min_element_edge_m * grow
                        && (r.split)(&v, &normal_in_world)
                });
            if !split {
                Arc::make_mut(&mut self.nodes)[id as usize].element =
                    Some(self.elements.len() as u32);
                self.elements.push(id);
                return id;
            }
        }
        let mid = |a: &Point3<f64>, b: &Point3<f64>| Point3::from((a.coords + b.coords) * 0.5);
        let [a, b, c] = v;
        let (ab, bc, ca) = (mid(&a, &b), mid(&b, &c), mid(&c, &a));
        let children = [[a, ab, ca], [ab, b, bc], [ca, bc, c], [ab, bc, ca]].map(|child| {
            self.add_subtree(
                child,
                normal_in_world,
                surface,
                (level + 1, nominal_m * 0.5),
                under_patch || patch,
                sub,
            )
        });
        Arc::make_mut(&mut self.nodes)[id as usize].children = Some(children);
        id
    }

    /// [`Mesh::geometry_hash`] of the mesh as it is.
    #[must_use]
    pub fn hash_geometry(&self) -> u64 {
        use std::hash::{Hash, Hasher};
        let mut h = std::collections::hash_map::DefaultHasher::new();
        for node in self.nodes.iter() {
            for v in &node.vertices_in_world_m {
                for c in v.iter() {
                    c.to_bits().hash(&mut h);
                }
            }
            node.children.hash(&mut h);
            node.element.hash(&mut h);
            node.surface.hash(&mut h);
        }
        self.elements.hash(&mut h);
        h.finish()
    }

    /// The node of element `e`.
    #[must_use]
    pub fn element_node(&self, e: usize) -> &MeshNode {
        &self.nodes[self.elements[e] as usize]
    }

    /// Reflectance of node `n`: its own where one was set
    /// ([`Mesh::set_element_reflectances`]), else its surface's.
    #[must_use]
    pub fn reflectance_rgb(&self, n: usize) -> Rgb {
        self.node_reflectance_rgb
            .as_ref()
            .and_then(|r| r[n])
            .unwrap_or(self.surfaces[self.nodes[n].surface as usize].reflectance_rgb)
    }

    /// Reflectance of element `e` ([`Mesh::reflectance_rgb`] of its node).
    #[must_use]
    pub fn element_reflectance_rgb(&self, e: usize) -> Rgb {
        self.reflectance_rgb(self.elements[e] as usize)
    }

    /// The name of the object node `n` belongs to.
    #[must_use]
    pub fn object_name(&self, n: usize) -> &str {
        let object = self.surfaces[self.nodes[n].surface as usize].object;
        self.object_names
            .get(object.0 as usize)
            .map_or("", String::as_str)
    }

    /// Total element area, m².
    #[must_use]
    pub fn total_area_m2(&self) -> f64 {
        self.elements
            .iter()
            .map(|&n| self.nodes[n as usize].area_m2)
            .sum()
    }

    /// The elements as ASCII PLY: three vertices per element (unshared, so flat colours stay
    /// flat), faces with `red green blue` 8-bit colours from `radiosity_rgb` scaled so that
    /// `white_rgb_value` maps to 255 (grey 200 without a solution).
    #[must_use]
    pub fn ply(&self, radiosity_rgb: Option<&[Rgb]>, white_value: f64) -> String {
        use std::fmt::Write;
        let n = self.elements.len();
        let mut out = String::with_capacity(96 * n + 256);
        let _ = write!(
            out,
            "ply\nformat ascii 1.0\ncomment photomontage radiosity mesh: {n} elements, \
             {} patches, world metres\nelement vertex {}\nproperty double x\n\
             property double y\nproperty double z\nelement face {n}\n\
             property list uchar int vertex_indices\nproperty uchar red\n\
             property uchar green\nproperty uchar blue\nend_header\n",
            self.patches.len(),
            3 * n
        );
        for &node in &self.elements {
            for p in &self.nodes[node as usize].vertices_in_world_m {
                let _ = writeln!(out, "{} {} {}", p.x, p.y, p.z);
            }
        }
        let scale = if white_value > 0.0 {
            255.0 / white_value
        } else {
            0.0
        };
        for e in 0..n {
            #[allow(clippy::cast_possible_truncation, clippy::cast_sign_loss)]
            let rgb = radiosity_rgb
                .and_then(|b| b.get(e))
                .map_or([200u8; 3], |b| {
                    b.map(|c| (c * scale).clamp(0.0, 255.0).round() as u8)
                });
            let _ = writeln!(
                out,
                "3 {} {} {} {} {} {}",
                3 * e,
                3 * e + 1,
                3 * e + 2,
                rgb[0],
                rgb[1],
                rgb[2]
            );
        }
        out
    }

    /// Writes [`Mesh::ply`] to `path` atomically.
    ///
    /// # Errors
    /// [`RadiosityError::Io`] naming the file.
    pub fn write_ply(
        &self,
        path: &std::path::Path,
        radiosity_rgb: Option<&[Rgb]>,
        white_value: f64,
    ) -> Result<(), RadiosityError> {
        crate::atomic_file::write_atomically(path, self.ply(radiosity_rgb, white_value).as_bytes())
            .map_err(|source| RadiosityError::Io {
                path: path.display().to_string(),
                source,
            })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::radiosity::test_scenes;

    /// Areas add up in f64 to rounding.
    const AREA_REL_TOL: f64 = 1e-12;

    #[test]
    fn subdivision_sizes_and_areas() {
        // A 4 m square (two triangles, longest edge 4√2 m) at 1 m elements and 3 m patches.
        let scene = test_scenes::squares_parallel(4.0, 1.0);
        let params = MeshParams {
            max_patch_edge_m: 3.0,
            max_element_edge_m: 1.0,
            ..MeshParams::default()
        };
        let mesh = Mesh::build(&scene, &params).unwrap();
        for &e in &mesh.elements {
            assert!(longest_edge_m(&mesh.nodes[e as usize].vertices_in_world_m) <= 1.0 + 1e-12);
        }
        for &p in &mesh.patches {
            assert!(longest_edge_m(&mesh.nodes[p as usize].vertices_in_world_m) <= 3.0 + 1e-12);
        }
        // 4√2 → 0.707 needs 3 levels (64 elements per triangle); patches after 1 level.
        assert_eq!(mesh.elements.len(), 4 * 64);
        assert_eq!(mesh.patches.len(), 4 * 4);
        let total = mesh.total_area_m2();
        assert!((total - 32.0).abs() < AREA_REL_TOL * 32.0, "{total}");
        // Deterministic.
        assert_eq!(mesh, Mesh::build(&scene, &params).unwrap());
    }

    #[test]
    fn per_object_size_and_unknown_object() {
        let scene = test_scenes::squares_parallel(1.0, 1.0);
        let mut params = MeshParams {
            max_element_edge_m: 2.0,
            ..MeshParams::default()
        };
        params.object_element_edge_m.insert("receiver".into(), 0.5);
        let mesh = Mesh::build(&scene, &params).unwrap();
        // Emitter: 2 elements; receiver: √2 → 0.354 is 2 levels, 2·16 elements.
        assert_eq!(mesh.elements.len(), 2 + 32);
        params.object_element_edge_m.insert("nope".into(), 0.5);
        let err = Mesh::build(&scene, &params).unwrap_err();
        assert!(err.to_string().contains("`nope`"), "{err}");
    }

    #[test]
    fn bad_input_is_named() {
        let empty = Scene::new();
        let err = Mesh::build(&empty, &MeshParams::default()).unwrap_err();
        assert!(matches!(err, RadiosityError::NoPatches { .. }), "{err}");
        let degenerate = test_scenes::degenerate_and_black();
        let mesh = Mesh::build(&degenerate, &MeshParams::default()).unwrap();
        let text: Vec<String> = mesh.warnings.iter().map(ToString::to_string).collect();
        assert!(text.iter().any(|t| t.contains("`sliver`")), "{text:?}");
        assert!(text.iter().any(|t| t.contains("`soot`")), "{text:?}");
        let err = Mesh::build(
            &degenerate,
            &MeshParams {
                max_element_edge_m: 1e-6,
                max_elements: 1000,
                ..MeshParams::default()
            },
        )
        .unwrap_err();
        assert!(
            matches!(err, RadiosityError::TooManyElements { .. }),
            "{err}"
        );
        let err = Mesh::build(
            &degenerate,
            &MeshParams {
                max_element_edge_m: f64::NAN,
                ..MeshParams::default()
            },
        )
        .unwrap_err();
        assert!(err.to_string().contains("max_element_edge_m"), "{err}");
    }

    #[test]
    fn ply_header_and_counts() {
        let scene = test_scenes::squares_parallel(1.0, 1.0);
        let mesh = Mesh::build(&scene, &MeshParams::default()).unwrap();
        let text = mesh.ply(None, 1.0);
        assert!(text.starts_with("ply\nformat ascii 1.0\n"));
        // √2 m edges at 1 m elements: one split, 4 elements per triangle, 16 in all.
        assert!(text.contains("element vertex 48\n"));
        assert!(text.contains("element face 16\n"));
        let body = text.split("end_header\n").nth(1).unwrap();
        assert_eq!(body.lines().count(), 48 + 16);
    }
}
