//! The ground truth: for each pixel, the fraction of the rectangular light
//! visible from the surface point seen there, by casting stratified, jittered
//! rays to the light against every triangle of the scene (roles do not
//! matter: everything blocks light), on the CPU, with a CWBVH (`obvhs`) and
//! all cores (`rayon`).
//!
//! Each pixel is estimated twice, by two independent sets of N×N strata,
//! each refined where the visibility varies across the light (M×M rays in a
//! stratum whose result in the other set differs from a neighbour's); the
//! estimate is their mean and its noise half their difference, so every
//! error measured against the truth can carry the truth's own error over the
//! same pixels ([`GroundTruth::estimate`], [`ReferenceImage::noise`]).
//!
//! Deterministic: each pixel's jitter comes from a fixed seed and the pixel's
//! index, so the result does not depend on thread scheduling, and it is cached
//! on disk under a hash of everything that changes it.
//!
//! A pixel's rays share their origin (one on each side of its tangent plane),
//! so they are not traced one by one where that can be avoided, with the same
//! answer ray for ray: the triangles in the pyramid from the point to the light
//! (or to the part of it on one side of the plane) are gathered from the BVH once (none:
//! lit; one that covers the pyramid: dark; a few: each ray tested against
//! them; too many: the light cut into quarters, each with its own pyramid),
//! and rays that still traverse the BVH first try the triangles that blocked
//! the pixel's last rays. Those tests use each triangle's edges and normal
//! computed once (obvhs's arithmetic, so the same answers bit for bit), and
//! the BVH's nodes are read with their quantised bounds already converted to
//! floats (`traversal`: obvhs's traversal, node for node): a gather tests a
//! node's eight children against the pyramid at once, a ray its eight boxes.
//! `GroundTruth::visibility_per_ray` is the plain definition, which a test
//! compares it with.
//!
//! The estimate goes further where the occluders are convex pieces (a
//! connected part of a mesh that is a convex solid or a flat convex polygon:
//! a box, a sphere, a leaf card; `pieces`): from a ray origin, each hides one
//! convex polygon of the light, so the share of a part of the light that a
//! few of them hide is computed exactly, in the light's plane, for the whole
//! light or its quarters, with no ray and no noise (`coverage`).

use std::path::{Path, PathBuf};
use std::time::{Duration, Instant};

use glam::{DVec2, UVec2, Vec2, Vec3, Vec3A};
use obvhs::cwbvh::CwBvh;
use obvhs::cwbvh::builder::{build_cwbvh, build_cwbvh_from_tris};
use obvhs::ray::Ray;
use obvhs::triangle::Triangle;
use rayon::prelude::*;
use ssm_scene::{RectLight, Scene};

mod coverage;
mod pieces;
mod traversal;

/// Version of the reference algorithm, part of every cache key: bump it when
/// the results of the same inputs change.
pub const REFERENCE_VERSION: u32 = 7;

/// Most triangles gathered from the BVH for the pyramid from a point to (part of) the light; with
/// more, the part is cut further or its rays traverse the BVH one by one.
const GATHER_LIMIT: usize = 12;

/// With at most this many triangles in a part's pyramid, its rays are tested against them one by
/// one rather than the part being cut into quarters.
const DIRECT_CANDIDATES: usize = 12;

/// The pyramid from a ray origin to a rectangle of the light: every segment from the apex to a
/// point of the rectangle lies inside it.
struct Pyramid {
    apex: Vec3,
    /// The rectangle's corners, in order around it.
    base: [Vec3; 4],
    /// Outward normals and offsets of the four sides and the base.
    planes: [(Vec3, f32); 5],
}

impl Pyramid {
    /// Where the pyramid lies against a plane (`height`: a point's signed distance from it): `None`
    /// when the apex is within `clearance` of it; `Some(true)` when the apex and every corner of
    /// the base lie on one side, clear of it by more than `clearance` (no segment from the apex to
    /// the base crosses it); `Some(false)` otherwise.
    fn beside_plane(&self, height: impl Fn(Vec3) -> f32, clearance: f32) -> Option<bool> {
        let first = height(self.apex);
        if first.abs() <= clearance {
            return None;
        }
        Some(self.base.iter().all(|corner| {
            let distance = height(*corner);
            distance.abs() > clearance && (distance > 0.0) == (first > 0.0)
        }))
    }

    /// `None` when it is degenerate (a side of no area: the apex in the light's plane).
    fn new(apex: Vec3, base: [Vec3; 4], light: &RectLight) -> Option<Self> {
        let inside = (apex + (base[0] + base[2]) * 0.5) * 0.5;
        let mut planes = [(Vec3::ZERO, 0.0f32); 5];
        for (k, plane) in planes.iter_mut().take(4).enumerate() {
            let normal = (base[k] - apex).cross(base[(k + 1) % 4] - apex).try_normalize()?;
            let normal = if normal.dot(inside - apex) > 0.0 { -normal } else { normal };
            *plane = (normal, normal.dot(apex));
        }
        let normal = light.normal();
        let normal = if normal.dot(base[0] - apex) < 0.0 { -normal } else { normal };
        planes[4] = (normal, normal.dot(base[0]));
        Some(Self { apex, base, planes })
    }
}

/// A triangle as the shortcuts test it: its first corner, two edges and (unnormalised) normal
/// computed once, so that each test does what `Triangle::intersect` does without computing them
/// again. The same operations on the same values, in the same order: the same answer, bit for bit
/// (the tests compare the shortcuts, which use it, with the per-ray traversal, which does not).
#[derive(Clone, Copy)]
struct PreparedTriangle {
    v0: Vec3A,
    /// `v0 - v1`.
    e1: Vec3A,
    /// `v2 - v0`.
    e2: Vec3A,
    /// `e1 × e2`.
    normal: Vec3A,
}

impl PreparedTriangle {
    fn new(triangle: &Triangle) -> Self {
        let e1 = triangle.v0 - triangle.v1;
        let e2 = triangle.v2 - triangle.v0;
        Self { v0: triangle.v0, e1, e2, normal: e1.cross(e2) }
    }

    /// The distance along `ray` to the triangle, `f32::INFINITY` for none in [tmin, tmax]:
    /// obvhs 0.4's `Triangle::intersect` (Möller and Trumbore), step for step.
    #[inline(always)]
    fn intersect(&self, ray: &Ray) -> f32 {
        let c = self.v0 - ray.origin;
        let r = ray.direction.cross(c);
        let inv_det = 1.0 / self.normal.dot(ray.direction);
        let u = r.dot(self.e2) * inv_det;
        let v = r.dot(self.e1) * inv_det;
        let w = 1.0 - u - v;
        // Every barycentric's sign bit clear (as obvhs: -0.0 counts as outside).
        let hit = u.to_bits() | v.to_bits() | w.to_bits();
        if inv_det != 0.0 && hit & 0x8000_0000 == 0 {
            let t = self.normal.dot(c) * inv_det;
            if t >= ray.tmin && t <= ray.tmax {
                return t;
            }
        }
        f32::INFINITY
    }
}

/// One pixel's rays, all from one origin: the light, the strata and their jitter.
struct PixelRays<'a> {
    light: &'a RectLight,
    /// The ray origin for samples on the front of the point's tangent plane (offset along its
    /// normal), and for those behind (offset against it).
    origins: [Vec3; 2],
    /// The point's tangent plane: position and normal.
    plane: (Vec3, Vec3),
    /// The point is on a closed mesh: samples behind its tangent plane are blocked.
    closed: bool,
    n: u32,
    /// Per set of rays, the jitter of stratum (i, j) at j·n + i. The sets share the pyramids and
    /// their triangles, which do not depend on the jitter. Empty until a ray needs it
    /// ([`PixelRays::draw_jitter`]: a pixel decided exactly casts none).
    jitter: Vec<Vec<Vec2>>,
    /// The generators the jitter is drawn from, one per set, until it is drawn.
    jitter_rngs: Vec<SplitMix64>,
    recent: RecentBlockers,
    /// Per set, each stratum's visible fraction at j·n + i: its ray's answer (0 or 1), or the
    /// exact fraction where a shortcut decided the stratum's whole part of the light.
    strata: Vec<Vec<f32>>,
    /// Per stratum, whether a shortcut decided it exactly (the same value in every set).
    exact: Vec<bool>,
    /// The triangles each stratum's rays were tested against (an index into `lists`: every
    /// triangle a ray into that part of the light can cross), or [`NO_LIST`] where they went
    /// through the BVH or a shortcut decided them.
    stratum_list: Vec<u32>,
    lists: Vec<Vec<u32>>,
    /// A part of the light with at most [`EXACT_CANDIDATES`] triangles gets the share they hide,
    /// exactly, instead of its rays (the estimate's sets); off, every stratum keeps its ray's
    /// answer, as [`GroundTruth::visibility`] defines it.
    exact_parts: bool,
    /// Per ray origin (`origins`), what the occluders in its pyramid to the whole light hide
    /// ([`GroundTruth::project_occluders`]): `None` until a part of the light needs it.
    projected: [Option<Option<ProjectedOccluders>>; 2],
    /// The polygons of `projected` that may meet the part being decided (scratch).
    picked: Vec<usize>,
}

/// What the occluders in the pyramid from one ray origin to the whole light hide: per occluder
/// (a convex piece or a triangle), its central projection onto the light's plane, a convex
/// polygon in light coordinates, and its bounding box.
#[derive(Default)]
struct ProjectedOccluders {
    polygons: Vec<Vec<DVec2>>,
    boxes: Vec<[DVec2; 2]>,
}

/// With at most this many occluder polygons meeting a part of the light, its visible share is
/// computed exactly (inclusion–exclusion over them: `coverage`).
const EXACT_POLYGONS: usize = 6;
/// Most triangles outside the convex pieces, and most pieces, in the pyramid from a point to the
/// whole light for its occluders to be projected once ([`GroundTruth::project_occluders`]); with
/// more, the shortcuts go on with triangles.
const LOOSE_LIMIT: usize = 16;
const PIECE_LIMIT: usize = 64;

/// What the projected occluders say of a part of the light.
enum PolygonAnswer {
    /// Its exact visible fraction.
    Exact(f32),
    /// More than [`EXACT_POLYGONS`] occluders meet it.
    TooMany,
}

/// A square part of the light in its coordinates ([-1, 1]² is the whole light): the light, or one
/// of its strata being refined.
#[derive(Clone, Copy)]
struct Window {
    min: Vec2,
    size: f32,
}

impl Window {
    /// The whole light.
    const LIGHT: Self = Self { min: Vec2::NEG_ONE, size: 2.0 };

    /// The point at `cell` (stratum coordinates: (i, j) plus the jitter) of an N×N grid over this
    /// window. For the whole light, `cell / n · 2 − 1`, the per-ray traversal's formula, bit for bit.
    fn at(self, cell: Vec2, n: u32) -> Vec2 {
        cell / n as f32 * self.size + self.min
    }

    /// Stratum `index` (in the j·n + i order) of an N×N grid over this window, as a window of its own.
    fn stratum(self, index: u32, n: u32) -> Self {
        let step = self.size / n as f32;
        Self { min: Vec2::new((index % n) as f32, (index / n) as f32) * step + self.min, size: step }
    }

    /// Its corners, in order around it.
    fn corners(self, light: &RectLight) -> [Vec3; 4] {
        let (min, max) = (self.min, self.min + Vec2::splat(self.size));
        [light.point(min.x, min.y), light.point(max.x, min.y), light.point(max.x, max.y), light.point(min.x, max.y)]
    }

    /// The points of an M×M grid over it, cell (a, b) moved by `jitter[b·m + a]` (in cell units).
    fn jittered(self, jitter: &[Vec2], m: u32) -> impl Iterator<Item = Vec2> + '_ {
        (0..m * m).map(move |cell| self.at(Vec2::new((cell % m) as f32, (cell / m) as f32) + jitter[cell as usize], m))
    }
}

/// Most triangles in a stratum's pyramid whose covered area [`coverage`] computes exactly.
const EXACT_CANDIDATES: usize = 4;
/// An exactly computed visible fraction this close to 0 or 1 is rounding: it is snapped.
const COVERAGE_SNAP: f64 = 1e-5;
/// No candidate list: [`PixelRays::stratum_list`] of a stratum whose rays go through the BVH.
const NO_LIST: u32 = u32::MAX;

/// The visible fraction of the part `window` of the light ([min, max], light coordinates), from
/// the occluders `projected` from the part's ray origin: lit when none meets it, dark when one
/// holds it, else the share that their union leaves, when at most [`EXACT_POLYGONS`] meet it.
/// `extra`: one more polygon hiding part of it (the part behind a solid's tangent plane).
/// `picked`: scratch.
fn decide_by_polygons(
    projected: &ProjectedOccluders,
    window: [DVec2; 2],
    picked: &mut Vec<usize>,
    extra: Option<&[DVec2]>,
) -> PolygonAnswer {
    picked.clear();
    for (index, bounds) in projected.boxes.iter().enumerate() {
        if bounds[0].cmpge(window[1]).any() || window[0].cmpge(bounds[1]).any() {
            continue;
        }
        if coverage::holds_rectangle(&projected.polygons[index], window) {
            return PolygonAnswer::Exact(0.0);
        }
        picked.push(index);
    }
    let count = picked.len() + usize::from(extra.is_some());
    if count > EXACT_POLYGONS {
        return PolygonAnswer::TooMany;
    }
    let mut polygons: [&[DVec2]; EXACT_POLYGONS] = [&[]; EXACT_POLYGONS];
    for (slot, index) in polygons.iter_mut().zip(picked.iter()) {
        *slot = &projected.polygons[*index];
    }
    if let Some(extra) = extra {
        polygons[picked.len()] = extra;
    }
    let covered = coverage::covered_share_of_projected(&polygons[..count], window);
    PolygonAnswer::Exact(snap_visible(1.0 - covered))
}

/// An exactly computed visible fraction, snapped to 0 or 1 within [`COVERAGE_SNAP`]: within
/// rounding of all or nothing (two triangles sharing an edge, each clipped on its own, sum to the
/// whole rectangle within about 1e-6 when seen at grazing angles), umbra and lit stay exact, at a
/// cost of at most 1e-5 of a stratum.
fn snap_visible(visible: f64) -> f32 {
    if visible < COVERAGE_SNAP {
        0.0
    } else if visible > 1.0 - COVERAGE_SNAP {
        1.0
    } else {
        visible as f32
    }
}

/// Whether the box `[min, max]` lies wholly beyond the plane `normal · p = offset` (on the side
/// the normal points to).
fn box_beyond([min, max]: [Vec3; 2], normal: Vec3, offset: f32) -> bool {
    // The box's corner least far along the normal.
    let nearest = Vec3::select(normal.cmpge(Vec3::ZERO), min, max);
    normal.dot(nearest) > offset
}

impl PixelRays<'_> {
    /// Draws every stratum's jitter, per set in the order visibility_per_ray draws it, if not yet
    /// drawn.
    fn draw_jitter(&mut self) {
        if self.jitter.is_empty() {
            let count = self.n * self.n;
            self.jitter =
                self.jitter_rngs.iter_mut().map(|rng| (0..count).map(|_| Vec2::new(rng.next_f32(), rng.next_f32())).collect()).collect();
        }
    }

    /// Whether `sample` lies on the front side of the tangent plane (rays to it leave from `origins[0]`).
    fn in_front(&self, sample: Vec3) -> bool {
        self.plane.1.dot(sample - self.plane.0) >= 0.0
    }

    /// The light sample of stratum (i, j) of set `set`, as visibility_per_ray places it.
    fn sample(&self, set: usize, i: u32, j: u32) -> Vec3 {
        let at = Window::LIGHT.at(Vec2::new(i as f32, j as f32) + self.jitter[set][(j * self.n + i) as usize], self.n);
        self.light.point(at.x, at.y)
    }

    /// Records the exact visible fraction `value` for every stratum of `region` ([i0, i1) × [j0, j1)) in every set.
    fn mark(&mut self, region: [u32; 4], value: f32) {
        for (_, _, index) in Self::indices(region, self.n) {
            self.set_exact(index, value);
        }
    }

    /// Records the exact visible fraction `value` of stratum `index` in every set.
    fn set_exact(&mut self, index: usize, value: f32) {
        for strata in &mut self.strata {
            strata[index] = value;
        }
        self.exact[index] = true;
    }

    /// The strata of `region`, as indices j·n + i.
    fn indices([i0, i1, j0, j1]: [u32; 4], n: u32) -> impl Iterator<Item = (u32, u32, usize)> {
        (j0..j1).flat_map(move |j| (i0..i1).map(move |i| (i, j, (j * n + i) as usize)))
    }
}

/// The last few triangles that blocked a pixel's rays (their BVH slots), newest first, and the
/// stack its rays traverse the BVH with (kept, so that a traversal allocates nothing).
#[derive(Default)]
struct RecentBlockers {
    slots: [u32; 4],
    count: usize,
    traversal_stack: Vec<UVec2>,
}

impl RecentBlockers {
    fn triangles(&self) -> &[u32] {
        &self.slots[..self.count]
    }

    fn push(&mut self, triangle: u32) {
        let len = self.slots.len();
        self.slots.copy_within(0..len - 1, 1);
        self.slots[0] = triangle;
        self.count = (self.count + 1).min(len);
    }
}

/// The ray along the segment from `origin` to `target`, stopping just short of `target` so that
/// geometry lying in the light's plane does not count; `None` for a segment of no length.
fn segment_ray(origin: Vec3, target: Vec3) -> Option<Ray> {
    let offset = target - origin;
    let distance = offset.length();
    (distance > 0.0).then(|| Ray::new(Vec3A::from(origin), Vec3A::from(offset / distance), 0.0, distance * (1.0 - 1e-6)))
}

/// The scene's triangles in a BVH, ready for shadow rays.
pub struct GroundTruth {
    triangles: Vec<Triangle>,
    /// The same triangles prepared for the shortcuts' tests, in the BVH's primitive order (slot
    /// k holds triangle `bvh.primitive_indices[k]`), so that a traversal reads a leaf's triangles
    /// side by side without looking their indices up. The shortcuts name triangles by slot.
    prepared: Vec<PreparedTriangle>,
    /// Each triangle's unit normal (zero where it has none), for [`GroundTruth::may_cross`].
    normals: Vec<Vec3>,
    bvh: CwBvh,
    /// The same BVH with its nodes decoded for the shortcuts' traversals (obvhs's, faster).
    decoded: traversal::DecodedBvh,
    /// Offset of ray origins off the surface, world units (scaled to the scene).
    surface_offset: f32,
    /// What the cache is keyed by beyond each image's own inputs: the triangles.
    cache: ReferenceCache,
    /// How [`GroundTruth::trace`] traces each pixel.
    traversal: Traversal,
    /// The scene's convex pieces and its other triangles, each in a BVH of its own, for the exact
    /// share of the light a few occluders hide; `None` when no placed mesh is a convex piece.
    occluders: Option<OccluderLayer>,
}

/// The scene's occluders as the estimate's exact parts read them: every connected part of a placed
/// mesh that is a convex piece (`pieces`), one polygon from a point, and every other triangle.
struct OccluderLayer {
    pieces: Vec<pieces::ConvexPiece>,
    /// The pieces' bounds (slot k holds piece `piece_bvh.primitive_indices[k]`).
    piece_bvh: CwBvh,
    piece_nodes: traversal::DecodedBvh,
    /// The triangles not in a piece (indices into `GroundTruth::triangles`), and their BVH
    /// (slot k holds `loose[loose_bvh.primitive_indices[k]]`); `None` when there are none.
    loose: Vec<u32>,
    loose_bvh: Option<(CwBvh, traversal::DecodedBvh)>,
}

impl OccluderLayer {
    /// The layer of `scene`'s triangles (`keys`: each traced triangle's instance and its index in
    /// the instance's mesh), or `None` when no part of a placed mesh is a convex piece.
    fn of(scene: &Scene, triangles: &[Triangle], keys: &[(u32, u32)]) -> Option<Self> {
        let mut parts: Vec<Option<pieces::MeshParts>> = (0..scene.meshes.len()).map(|_| None).collect();
        // Each convex part of each instance with a triangle traced becomes a piece (a transform
        // that flattens every triangle of a part leaves none, and nothing to hide the light).
        let mut pieces = Vec::new();
        let mut piece_of_part: std::collections::HashMap<(u32, u32), u32> = std::collections::HashMap::new();
        let mut loose = Vec::new();
        for (slot, (instance, triangle)) in keys.iter().enumerate() {
            let placed = &scene.instances[*instance as usize];
            let mesh_parts = parts[placed.mesh].get_or_insert_with(|| pieces::MeshParts::of(&scene.meshes[placed.mesh]));
            let part = mesh_parts.part_of_triangle[*triangle as usize];
            match &mesh_parts.shapes[part as usize] {
                Some(shape) => {
                    piece_of_part.entry((*instance, part)).or_insert_with(|| {
                        pieces.push(pieces::ConvexPiece::placed(shape, placed.transform));
                        pieces.len() as u32 - 1
                    });
                }
                None => loose.push(slot as u32),
            }
        }
        if pieces.is_empty() {
            return None;
        }
        let loose_bvh = (!loose.is_empty()).then(|| {
            let loose_triangles: Vec<Triangle> = loose.iter().map(|t| triangles[*t as usize]).collect();
            let bvh = build_cwbvh_from_tris(&loose_triangles, obvhs::BvhBuildParams::medium_build(), &mut Duration::default());
            let nodes = traversal::DecodedBvh::new(&bvh);
            (bvh, nodes)
        });
        let boxes: Vec<obvhs::aabb::Aabb> =
            pieces.iter().map(|piece| obvhs::aabb::Aabb::new(Vec3A::from(piece.bounds[0]), Vec3A::from(piece.bounds[1]))).collect();
        let piece_bvh = build_cwbvh(&boxes, obvhs::BvhBuildParams::medium_build(), &mut Duration::default());
        let piece_nodes = traversal::DecodedBvh::new(&piece_bvh);
        Some(Self { pieces, piece_bvh, piece_nodes, loose, loose_bvh })
    }
}

/// How [`GroundTruth::trace`] traces a pixel's rays. Both give the same visibility, ray for ray
/// (a test compares every pixel), so the cache does not tell them apart.
#[derive(Clone, Copy, Debug, PartialEq, Eq, crate::Choice)]
pub enum Traversal {
    /// [`GroundTruth::visibility`]: the pyramid from the point to the light (or its quarters)
    /// gathered from the BVH once, its few triangles tested by each ray.
    Shortcuts,
    /// [`GroundTruth::visibility_per_ray`]: every ray through the BVH, the definition.
    PerRay,
}

/// The ground truth's on-disk cache for one scene: what an image is keyed
/// by beyond its own inputs (the light, the points, the samples and the
/// seed) is the hash of the scene's triangles, with [`REFERENCE_VERSION`].
/// Made without building the BVH, so a viewer can ask whether a view's
/// ground truth is cached without the cost of a tracer.
#[derive(Clone, Copy, Debug)]
pub struct ReferenceCache {
    geometry_hash: u64,
}

/// The triangles the ground truth traces: every world triangle with a non-zero area.
fn traced_triangles(scene: &Scene) -> impl Iterator<Item = [Vec3; 3]> + '_ {
    traced_triangles_by_instance(scene).map(|(_, corners)| corners)
}

/// [`traced_triangles`], each with the index of the instance it belongs to and its own index in
/// that instance's mesh (the same corners as [`Scene::world_triangles`], in its order).
fn traced_triangles_by_instance(scene: &Scene) -> impl Iterator<Item = ((u32, u32), [Vec3; 3])> + '_ {
    scene
        .instances
        .iter()
        .enumerate()
        .filter_map(|(index, instance)| scene.meshes.get(instance.mesh).map(|mesh| (index as u32, instance, mesh)))
        .flat_map(|(index, instance, mesh)| {
            mesh.triangles()
                .enumerate()
                .map(move |(k, t)| ((index, k as u32), t.map(|i| instance.transform.transform_point3(mesh.positions[i as usize]))))
        })
        .filter(|(_, t)| (t[1] - t[0]).cross(t[2] - t[0]).length_squared() > 0.0)
}

impl ReferenceCache {
    /// The cache of `scene`'s ground truth.
    #[must_use]
    pub fn of(scene: &Scene) -> Self {
        let mut hasher = Fnv64::new();
        for corners in traced_triangles(scene) {
            for corner in corners {
                hasher.write_f32s(&corner.to_array());
            }
        }
        Self { geometry_hash: hasher.finish() }
    }

    /// The image [`GroundTruth::trace_cached`] would return, if `cache_dir`
    /// holds it; `None` without tracing anything otherwise (a live viewer
    /// shows the error against the ground truth only where it is cached).
    #[must_use]
    pub fn cached(
        &self,
        light: &RectLight,
        points: &[Option<SurfacePoint>],
        sampling: Sampling,
        seed: u64,
        cache_dir: &Path,
    ) -> Option<ReferenceImage> {
        let bytes = std::fs::read(self.file(light, points, sampling, seed, cache_dir)).ok()?;
        (bytes.len() == points.len() * 8).then(|| {
            let mut values: Vec<f32> = bytes.chunks_exact(4).map(|b| f32::from_le_bytes([b[0], b[1], b[2], b[3]])).collect();
            let noise = values.split_off(points.len());
            ReferenceImage { visibility: values, noise, rays: 0, elapsed: Duration::ZERO, cached: true }
        })
    }

    fn file(&self, light: &RectLight, points: &[Option<SurfacePoint>], sampling: Sampling, seed: u64, cache_dir: &Path) -> PathBuf {
        cache_dir.join(format!("{:016x}.f32", self.key(light, points, sampling, seed)))
    }

    fn key(&self, light: &RectLight, points: &[Option<SurfacePoint>], sampling: Sampling, seed: u64) -> u64 {
        let mut hasher = Fnv64::new();
        hasher.write(&REFERENCE_VERSION.to_le_bytes());
        hasher.write(&self.geometry_hash.to_le_bytes());
        hasher.write_f32s(&[light.centre.x, light.centre.y, light.centre.z, light.u_axis.x, light.u_axis.y, light.u_axis.z]);
        hasher.write_f32s(&[light.v_axis.x, light.v_axis.y, light.v_axis.z, light.half_size.x, light.half_size.y]);
        hasher.write(&sampling.samples_per_axis.to_le_bytes());
        hasher.write(&sampling.refine.to_le_bytes());
        hasher.write(&seed.to_le_bytes());
        hasher.write(&(points.len() as u64).to_le_bytes());
        for point in points {
            match point {
                Some(p) => {
                    hasher.write_f32s(&[p.position.x, p.position.y, p.position.z, p.normal.x, p.normal.y, p.normal.z]);
                    // One byte of flags per point, so that no two point lists hash the same bytes.
                    hasher.write(&[u8::from(p.closed) | (u8::from(p.footprint.is_some()) << 1)]);
                    if let Some(f) = &p.footprint {
                        for v in [f.eye, f.corner, f.across, f.down] {
                            hasher.write_f32s(&v.to_array());
                        }
                    }
                }
                None => hasher.write(&[0xff]),
            }
        }
        hasher.finish()
    }
}

/// One pixel's surface point as the G-buffer records it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SurfacePoint {
    /// World position.
    pub position: Vec3,
    /// Unit normal (either side; rays leave on the side facing each light sample, except on a
    /// closed surface: see `closed`).
    pub normal: Vec3,
    /// The point lies on a closed mesh ([`ssm_scene::Scene::closed_meshes`]) and `normal` points
    /// to the side the camera sees (as the G-buffer's does). Such a surface is the boundary of an
    /// opaque solid (or of a closed room), so light reaches the seen side only from in front of
    /// its tangent plane: a ray leaving behind it is blocked. Without this, a wall whose far side
    /// faces a light sealed behind it would see that light through itself.
    pub closed: bool,
    /// The camera rays bounding the pixel, when its visibility is averaged over the pixel's
    /// footprint on the surface's tangent plane instead of taken at the point.
    pub footprint: Option<PixelFootprint>,
}

/// The camera rays through one pixel: every ray through it leaves `eye` along
/// `corner + s·across + t·down` for (s, t) in [0, 1]² (directions are affine in
/// pixel coordinates for a pinhole camera).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PixelFootprint {
    /// The camera's centre.
    pub eye: Vec3,
    /// The direction through the pixel's top-left corner.
    pub corner: Vec3,
    /// The change of direction from the left edge to the right one.
    pub across: Vec3,
    /// The change of direction from the top edge to the bottom one.
    pub down: Vec3,
}

impl PixelFootprint {
    /// Where the ray through (s, t) of the pixel meets the plane through `point` with `normal`;
    /// `None` when it runs along the plane or meets it behind the eye.
    #[must_use]
    pub fn on_plane(&self, s: f32, t: f32, point: Vec3, normal: Vec3) -> Option<Vec3> {
        let direction = self.corner + self.across * s + self.down * t;
        let denominator = direction.dot(normal);
        if denominator.abs() < 1e-12 {
            return None;
        }
        let distance = (point - self.eye).dot(normal) / denominator;
        (distance > 0.0 && distance.is_finite()).then(|| self.eye + direction * distance)
    }
}

/// How the ground truth samples each pixel ([`GroundTruth::estimate`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Sampling {
    /// N: each of the two independent sets has N×N strata, one jittered ray each.
    pub samples_per_axis: u32,
    /// M: a stratum where the visibility varies is cut into M×M sub-strata with one jittered ray each,
    /// its own ray standing for the sub-stratum it fell in (1: no refinement).
    pub refine: u32,
}

impl Sampling {
    /// The `reference` technique's defaults: two sets of 12×12 strata, 2×2 rays in a stratum where
    /// the visibility varies.
    pub const DEFAULT: Self = Self { samples_per_axis: 12, refine: 2 };

    /// Two plain stratified sets of `samples_per_axis`² rays, without refinement.
    #[must_use]
    pub const fn uniform(samples_per_axis: u32) -> Self {
        Self { samples_per_axis, refine: 1 }
    }
}

/// One pixel's ground truth: the estimate and its own error.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PixelEstimate {
    /// The visible fraction of the light, (A + B)/2 of the two independent estimates.
    pub visibility: f32,
    /// |A − B|/2: an estimate of the estimate's absolute error (for Gaussian errors its
    /// expectation is E|visibility − exact|, and its square is unbiased for the variance).
    pub noise: f32,
    /// Light samples evaluated.
    pub rays: u64,
}

/// The mean of the strata's visible fractions.
fn visible_fraction(strata: &[f32]) -> f32 {
    strata.iter().sum::<f32>() / strata.len().max(1) as f32
}

/// Whether the visibility of an N×N set (`strata`) varies at stratum `index`: its result differs
/// from one of its four neighbours'. A neighbour given a part of the light's exact share (`exact`,
/// strictly between 0 and 1) says nothing of where its edges run, and is not compared.
fn varies(strata: &[f32], exact: &[bool], n: u32, index: usize) -> bool {
    let n = n as usize;
    let (i, j) = (index % n, index / n);
    let own = strata[index];
    let differs = |neighbour: usize| {
        let value = strata[neighbour];
        value != own && !(exact[neighbour] && value > 0.0 && value < 1.0)
    };
    (i > 0 && differs(index - 1)) || (i + 1 < n && differs(index + 1)) || (j > 0 && differs(index - n)) || (j + 1 < n && differs(index + n))
}

/// The result of tracing one image.
#[derive(Clone, Debug, PartialEq)]
pub struct ReferenceImage {
    /// Visibility per pixel, row-major; 1 for pixels without a surface point.
    pub visibility: Vec<f32>,
    /// The estimate's own error per pixel ([`PixelEstimate::noise`]): the mean over a set of
    /// pixels estimates the ground truth's mean absolute error there, the mean of its squares
    /// its mean squared error.
    pub noise: Vec<f32>,
    /// Light samples evaluated, refinements included (0 when read from the cache). The BVH
    /// shortcuts decide many of them without casting a ray of their own.
    pub rays: u64,
    /// Wall time spent tracing.
    pub elapsed: Duration,
    /// True when the image came from the cache.
    pub cached: bool,
}

impl ReferenceImage {
    /// Shadow rays per second of wall time, when rays were traced.
    #[must_use]
    pub fn rays_per_second(&self) -> Option<f64> {
        (self.rays > 0 && !self.elapsed.is_zero()).then(|| self.rays as f64 / self.elapsed.as_secs_f64())
    }
}

impl GroundTruth {
    /// Builds the BVH over every triangle of `scene` (degenerate ones skipped).
    #[must_use]
    pub fn new(scene: &Scene) -> Self {
        let (keys, triangles): (Vec<(u32, u32)>, Vec<Triangle>) = traced_triangles_by_instance(scene)
            .map(|(key, [v0, v1, v2])| (key, Triangle { v0: Vec3A::from(v0), v1: Vec3A::from(v1), v2: Vec3A::from(v2) }))
            .unzip();
        let occluders = OccluderLayer::of(scene, &triangles, &keys);
        let normals = triangles
            .iter()
            .map(|t| {
                let corners = [Vec3::from(t.v0), Vec3::from(t.v1), Vec3::from(t.v2)];
                (corners[1] - corners[0]).cross(corners[2] - corners[0]).try_normalize().unwrap_or(Vec3::ZERO)
            })
            .collect();
        let bvh = build_cwbvh_from_tris(&triangles, obvhs::BvhBuildParams::medium_build(), &mut Duration::default());
        let prepared = bvh.primitive_indices.iter().map(|index| PreparedTriangle::new(&triangles[*index as usize])).collect();
        let extent = scene.bounds().size().length().max(1e-6);
        Self {
            triangles,
            prepared,
            normals,
            decoded: traversal::DecodedBvh::new(&bvh),
            bvh,
            surface_offset: extent * 1e-5,
            cache: ReferenceCache::of(scene),
            traversal: Traversal::Shortcuts,
            occluders,
        }
    }

    /// This tracer with `traversal` for [`GroundTruth::trace`] (the same visibility either way).
    #[must_use]
    pub fn with_traversal(self, traversal: Traversal) -> Self {
        Self { traversal, ..self }
    }

    /// This tracer with (`true`, the default) or without the convex pieces: placed meshes whose
    /// triangles are a convex solid or a flat convex polygon, each one polygon when the estimate
    /// computes the share of a part of the light that a few occluders hide exactly. Without, those
    /// parts are sampled by rays, as any other triangles: the same expected visibility, with the
    /// rays' noise (tests of the rays use it).
    #[must_use]
    pub fn with_convex_pieces(self, pieces: bool) -> Self {
        if pieces { self } else { Self { occluders: None, ..self } }
    }

    /// How many placed meshes the estimate treats as convex pieces
    /// ([`GroundTruth::with_convex_pieces`]).
    #[must_use]
    pub fn convex_piece_count(&self) -> usize {
        self.occluders.as_ref().map_or(0, |layer| layer.pieces.len())
    }

    /// True when the segment from `origin` to `target` crosses no triangle.
    fn unoccluded(&self, origin: Vec3, target: Vec3) -> bool {
        segment_ray(origin, target).is_none_or(|ray| {
            self.bvh.ray_traverse_miss(ray, |ray, id| self.triangles[self.bvh.primitive_indices[id] as usize].intersect(ray))
        })
    }

    /// The triangles that can cross a segment inside `pyramid` (their BVH leaf boxes meet it,
    /// no plane of it has all three corners beyond, and their own plane does not pass beside
    /// it), by BVH slot, into `found`; `false` as soon as there are more than `limit`.
    fn pyramid_candidates(&self, pyramid: &Pyramid, limit: usize, found: &mut Vec<u32>) -> bool {
        found.clear();
        self.decoded.gather(&pyramid.planes, self.pyramid_margin(), |first, count| {
            found.extend((first..first + count).filter(|slot| self.may_cross(*slot, pyramid)));
            found.len() <= limit
        })
    }

    /// How far outside a pyramid's planes a box or triangle may lie and still be kept: rays
    /// grazing a triangle's edge must keep it.
    fn pyramid_margin(&self) -> f32 {
        self.surface_offset * 10.0
    }

    /// Whether the triangle in BVH slot `slot` can cross a segment from the pyramid's apex to its base: no
    /// plane of the pyramid has all three of its corners beyond, and its own plane does not
    /// have the apex and the base's corners all on one side, clear of it by half the surface
    /// offset (no segment then crosses it: this drops the surface a point lies on, which its
    /// rays leave by the surface offset, and faces turned away from the light).
    fn may_cross(&self, slot: u32, pyramid: &Pyramid) -> bool {
        self.may_cross_triangle(self.bvh.primitive_indices[slot as usize] as usize, pyramid)
    }

    /// [`GroundTruth::may_cross`] of the triangle at `index` in `triangles`.
    fn may_cross_triangle(&self, index: usize, pyramid: &Pyramid) -> bool {
        let triangle = &self.triangles[index];
        let corners = [Vec3::from(triangle.v0), Vec3::from(triangle.v1), Vec3::from(triangle.v2)];
        let margin = self.pyramid_margin();
        if pyramid.planes.iter().any(|(normal, offset)| corners.iter().all(|c| normal.dot(*c) > offset + margin)) {
            return false;
        }
        let normal = self.normals[index];
        if normal == Vec3::ZERO {
            return true;
        }
        pyramid.beside_plane(|p| normal.dot(p - corners[0]), 0.5 * self.surface_offset) != Some(true)
    }

    /// The BVH slot of the triangle the BVH finds first on `ray` (a [`segment_ray`], with the
    /// test of [`GroundTruth::unoccluded`] and its traversal, node for node), if any.
    fn first_blocker(&self, ray: &Ray, stack: &mut Vec<UVec2>) -> Option<u32> {
        let mut found = None;
        self.decoded.traverse(ray, stack, |slot| {
            let blocks = self.crosses(ray, slot as u32);
            if blocks {
                found = Some(slot as u32);
            }
            blocks
        });
        found
    }

    /// True when `ray` crosses the triangle in BVH slot `slot` before its `tmax`.
    #[inline(always)]
    fn crosses(&self, ray: &Ray, slot: u32) -> bool {
        self.prepared[slot as usize].intersect(ray) < ray.tmax
    }

    /// True when the ray from `origin` to `target` crosses one of `candidates` (BVH slots; the same
    /// segment and intersection test as [`GroundTruth::unoccluded`]).
    fn blocked_by(&self, origin: Vec3, target: Vec3, candidates: &[u32]) -> bool {
        segment_ray(origin, target).is_some_and(|ray| candidates.iter().any(|slot| self.crosses(&ray, *slot)))
    }

    /// True when the ray from `origin` to `target` is blocked: by one of the triangles in
    /// `recent` (tried first: a pixel's neighbouring rays mostly hit the same ones), else by the
    /// triangle the BVH finds, which `recent` then remembers. The same answer as
    /// `!unoccluded`: a ray a remembered triangle blocks is blocked.
    fn blocked_remembering(&self, origin: Vec3, target: Vec3, recent: &mut RecentBlockers) -> bool {
        let Some(ray) = segment_ray(origin, target) else { return false };
        recent.triangles().iter().any(|slot| self.crosses(&ray, *slot))
            || self.first_blocker(&ray, &mut recent.traversal_stack).map(|blocker| recent.push(blocker)).is_some()
    }

    /// Visible fraction of `light` from `point`, with one set of `samples_per_axis`² stratified
    /// samples jittered by `rng`. Points behind the light's plane see none of it.
    /// With a footprint, each sample also starts from its own point of the
    /// pixel's footprint on the tangent plane (stratified too, the pixel's
    /// strata paired with the light's in a random order): the visibility
    /// averaged over the pixel, what a screen-space prefilter aims at.
    /// [`GroundTruth::estimate`] is what the ground truth traces: two such sets, refined where
    /// the visibility varies, with the noise they imply.
    #[must_use]
    pub fn visibility(&self, light: &RectLight, point: &SurfacePoint, samples_per_axis: u32, rng: &mut SplitMix64) -> f32 {
        if point.footprint.is_none() && (point.position - light.centre).dot(light.normal()) <= 0.0 {
            return 0.0;
        }
        visible_fraction(&self.stratified(light, point, samples_per_axis.max(1), rng, true))
    }

    /// [`GroundTruth::visibility`] one ray at a time through the BVH: the definition the
    /// shortcuts must match (tests compare them).
    #[must_use]
    pub fn visibility_per_ray(&self, light: &RectLight, point: &SurfacePoint, n: u32, rng: &mut SplitMix64) -> f32 {
        if point.footprint.is_none() && (point.position - light.centre).dot(light.normal()) <= 0.0 {
            return 0.0;
        }
        visible_fraction(&self.stratified(light, point, n.max(1), rng, false))
    }

    /// The estimate the ground truth traces for one pixel, and its own error.
    ///
    /// Two independent stratified sets of `samples_per_axis`² jittered rays, A and B. Each set is
    /// then refined where the visibility varies across the light: a stratum whose result in the
    /// other set differs from one of its four neighbours' (an edge of the visible region crosses
    /// it or passes near) is decided exactly when at most four triangles can block its rays (the
    /// area their projection covers, `reference/coverage.rs`), and otherwise is cut into `refine`²
    /// sub-strata: its own ray, uniform over the stratum and so over the sub-stratum it fell in,
    /// stands for that one, and each of the others gets a fresh jittered ray.
    /// A part of the light whose pyramid holds at most four triangles, or that at most six convex
    /// pieces' and other triangles' projections meet ([`GroundTruth::with_convex_pieces`]), is
    /// decided exactly for both sets at once, before any ray (in the pyramid shortcuts), and its
    /// strata are neither refined nor compared as neighbours. Each set is unbiased, since which strata it refines
    /// depends only on the other set's rays and on the triangles (not on its own jitter);
    /// the estimate is (A + B)/2 and its noise |A − B|/2, whose mean over pixels estimates the
    /// mean absolute error of the estimate (and its square the variance, pixel by pixel). Lit and
    /// umbra pixels that the BVH shortcuts decide exactly have no noise; a point light casts one
    /// ray. A pixel footprint is sampled without refinement (its strata pair light and pixel
    /// points at random).
    #[must_use]
    pub fn estimate(&self, light: &RectLight, point: &SurfacePoint, sampling: Sampling, rng: &mut SplitMix64) -> PixelEstimate {
        if point.footprint.is_none() && (point.position - light.centre).dot(light.normal()) <= 0.0 {
            return PixelEstimate { visibility: 0.0, noise: 0.0, rays: 0 };
        }
        let n = sampling.samples_per_axis.max(1);
        let shortcuts = self.traversal == Traversal::Shortcuts;
        let mut set_rngs = [rng.fork(), rng.fork()];
        let refine_seeds = [rng.next_u64(), rng.next_u64()];
        // The two sets share the pyramid shortcuts' gathers (the same triangles for any jitter).
        let shared = (shortcuts && point.footprint.is_none()).then(|| self.pyramid_visibility(light, point, n, &mut set_rngs, true));
        let (strata, exact, lists, stratum_list, base_jitter) = match shared {
            Some(mut rays) => {
                // Refinement reads where each stratum's own ray went (drawn already where a ray
                // was cast; the shortcuts decided every other stratum, which is not refined).
                if !rays.exact.iter().all(|e| *e) {
                    rays.draw_jitter();
                }
                (rays.strata, rays.exact, rays.lists, rays.stratum_list, rays.jitter)
            }
            None => {
                // Without a footprint, visibility_of_rays draws each stratum's jitter and nothing
                // else, in this order: the same draws from a copy give where each ray went, which
                // refinement needs. A footprint is not refined.
                let base_jitter = set_rngs
                    .iter()
                    .map(|rng| {
                        let mut rng = rng.clone();
                        let count = if point.footprint.is_none() { n * n } else { 0 };
                        (0..count).map(|_| Vec2::new(rng.next_f32(), rng.next_f32())).collect()
                    })
                    .collect();
                let strata = set_rngs.iter_mut().map(|rng| self.visibility_of_rays(light, point, n, rng, shortcuts)).collect();
                (strata, vec![false; (n * n) as usize], Vec::new(), vec![NO_LIST; (n * n) as usize], base_jitter)
            }
        };
        let refine = if point.footprint.is_some() { 1 } else { sampling.refine.max(1) };
        let sub_rays = refine * refine;
        let mut rays = 2 * u64::from(n * n);
        let mut sets = [0.0f32; 2];
        let mut recent = RecentBlockers::default();
        let (mut jitter, mut candidates) = (Vec::new(), Vec::new());
        let origins = self.origins(point);
        // A pixel every stratum of which a shortcut decided (lit, umbra, or the exact share of a
        // few triangles) has nothing to refine.
        let all_exact = exact.iter().all(|e| *e);
        for (k, set) in sets.iter_mut().enumerate() {
            if refine == 1 || all_exact {
                *set = visible_fraction(&strata[k]);
                continue;
            }
            let other = &strata[1 - k];
            let mut sum = 0.0f32;
            for (index, &value) in strata[k].iter().enumerate() {
                if exact[index] || !varies(other, &exact, n, index) {
                    // Exact: a shortcut decided every ray of this part of the light.
                    sum += value;
                    continue;
                }
                let window = Window::LIGHT.stratum(index as u32, n);
                let list = lists.get(stratum_list[index] as usize);
                // The stratum exactly, from the area its few triangles cover; else M×M rays
                // against the triangles its ray was tested against (those that can cross its own
                // pyramid), or, without a list, through the BVH as its ray went.
                let (exact_value, candidates) = match list {
                    Some(list) => {
                        // A stratum with a list lies on one side of the tangent plane.
                        let origin = origins[usize::from(point.normal.dot(light.point(window.min.x, window.min.y) - point.position) < 0.0)];
                        let candidates = self.stratum_candidates(light, origin, window, list, &mut candidates);
                        let exact_value =
                            (candidates.len() <= EXACT_CANDIDATES).then(|| self.exact_coverage(light, origin, window, candidates));
                        (exact_value, Some((origin, candidates)))
                    }
                    None => (None, None),
                };
                if let Some(value) = exact_value {
                    sum += value;
                    continue;
                }
                rays += u64::from(sub_rays - 1);
                let mut sub_rng = SplitMix64::for_pixel(refine_seeds[k], index as u64);
                jitter.clear();
                jitter.extend((0..sub_rays).map(|_| Vec2::new(sub_rng.next_f32(), sub_rng.next_f32())));
                // The stratum's own ray, uniform over the stratum, is uniform over the sub-stratum
                // it fell in: it stands for that one, and the others get fresh rays.
                let kept_cell = {
                    let cell = (base_jitter[k][index] * refine as f32).floor().clamp(Vec2::ZERO, Vec2::splat((refine - 1) as f32));
                    cell.y as usize * refine as usize + cell.x as usize
                };
                let visible = value as usize
                    + window
                        .jittered(&jitter, refine)
                        .enumerate()
                        .filter(|(cell, _)| *cell != kept_cell)
                        .filter(|(_, at)| match candidates {
                            Some((origin, candidates)) => !self.blocked_by(origin, light.point(at.x, at.y), candidates),
                            None => self.light_sample_visible(light, point, *at, shortcuts.then_some(&mut recent)),
                        })
                        .count();
                sum += visible as f32 / sub_rays as f32;
            }
            *set = sum / (n * n) as f32;
        }
        PixelEstimate { visibility: 0.5 * (sets[0] + sets[1]), noise: 0.5 * (sets[0] - sets[1]).abs(), rays }
    }

    /// Whether the ray from `point` to the light's point at `at` (in [-1, 1]² along its axes)
    /// reaches it, as [`GroundTruth::visibility_of_rays`] decides one sample of a point without a
    /// footprint; with `recent`, the pixel's last blockers are tried first (the same answer).
    fn light_sample_visible(&self, light: &RectLight, point: &SurfacePoint, at: Vec2, recent: Option<&mut RecentBlockers>) -> bool {
        let sample = light.point(at.x, at.y);
        let front = point.normal.dot(sample - point.position) >= 0.0;
        if point.closed && !front {
            return false;
        }
        let origin = self.origins(point)[usize::from(!front)];
        match recent {
            Some(recent) => !self.blocked_remembering(origin, sample, recent),
            None => self.unoccluded(origin, sample),
        }
    }

    /// One set of N² stratified samples of a point in front of the light: each stratum's result
    /// (0 or 1) at j·n + i. With `shortcuts`, a point without a footprint goes through
    /// the pyramid shortcuts ([`GroundTruth::pyramid_visibility`]); otherwise each ray goes
    /// through the BVH.
    fn stratified(&self, light: &RectLight, point: &SurfacePoint, n: u32, rng: &mut SplitMix64, shortcuts: bool) -> Vec<f32> {
        if shortcuts && point.footprint.is_none() {
            return self.pyramid_visibility(light, point, n, std::slice::from_mut(rng), false).strata.swap_remove(0);
        }
        self.visibility_of_rays(light, point, n, rng, shortcuts)
    }

    /// The shortcut of [`GroundTruth::visibility`] for a point without a footprint: the pyramid
    /// from the point to the light, then to its quarters where it holds too many triangles or the
    /// point's tangent plane cuts it (each part on one side of the plane has one ray origin;
    /// [`GroundTruth::count_visible`]). A point light casts one ray for all N². One set of rays
    /// per generator of `rngs`, each drawing its jitter as visibility_per_ray does; the sets share
    /// the gathers.
    fn pyramid_visibility<'a>(
        &self,
        light: &'a RectLight,
        point: &SurfacePoint,
        n: u32,
        rngs: &mut [SplitMix64],
        exact_parts: bool,
    ) -> PixelRays<'a> {
        let count = (n * n) as usize;
        let mut rays = PixelRays {
            light,
            origins: self.origins(point),
            plane: (point.position, point.normal),
            closed: point.closed,
            n,
            jitter: Vec::new(),
            jitter_rngs: Vec::new(),
            recent: RecentBlockers::default(),
            strata: vec![vec![0.0; count]; rngs.len()],
            exact: vec![false; count],
            stratum_list: vec![NO_LIST; count],
            lists: Vec::new(),
            exact_parts,
            projected: [None, None],
            picked: Vec::new(),
        };
        if light.is_point() {
            let front = rays.in_front(light.centre);
            let open = (front || !point.closed) && self.unoccluded(rays.origins[usize::from(!front)], light.centre);
            rays.mark([0, n, 0, n], if open { 1.0 } else { 0.0 });
            return rays;
        }
        // The jitter of every stratum, drawn in the order visibility_per_ray draws it: with exact
        // parts (the estimate's own generators) only once a ray needs it; otherwise now, so that
        // `rngs` moves on as visibility_per_ray moves it.
        rays.jitter_rngs = rngs.to_vec();
        if !exact_parts {
            rays.draw_jitter();
            rngs.clone_from_slice(&rays.jitter_rngs);
        }
        self.count_visible(&mut rays, [0, n, 0, n], None, 0, true);
        rays
    }

    /// The ray origins off `point`'s surface: for light samples in front of its tangent plane
    /// (offset along the normal) and behind it (against it).
    fn origins(&self, point: &SurfacePoint) -> [Vec3; 2] {
        let offset = point.normal * self.surface_offset;
        [point.position + offset, point.position - offset]
    }

    /// The triangles of `list` (every triangle a ray into an enclosing part of the light can
    /// cross) that can cross a ray from `origin` into the part `stratum`: `list` itself when it
    /// holds at most [`EXACT_CANDIDATES`], else those that meet the stratum's pyramid, in `found`.
    fn stratum_candidates<'l>(
        &self,
        light: &RectLight,
        origin: Vec3,
        stratum: Window,
        list: &'l [u32],
        found: &'l mut Vec<u32>,
    ) -> &'l [u32] {
        if list.len() <= EXACT_CANDIDATES {
            return list;
        }
        match Pyramid::new(origin, stratum.corners(light), light) {
            Some(pyramid) => {
                found.clear();
                found.extend(list.iter().copied().filter(|slot| self.may_cross(*slot, &pyramid)));
                found
            }
            None => list,
        }
    }

    /// The corners of the triangle in BVH slot `slot`.
    fn triangle_of_slot(&self, slot: u32) -> [Vec3; 3] {
        self.triangle_corners(self.bvh.primitive_indices[slot as usize] as usize)
    }

    /// The exact visible fraction of the part `stratum` of the light seen from `origin`, hidden
    /// only by `triangles` (at most [`EXACT_CANDIDATES`], BVH slots): 1 less the share of the
    /// stratum their central projection onto the light's plane covers ([`coverage::covered_share`]).
    fn exact_coverage(&self, light: &RectLight, origin: Vec3, stratum: Window, triangles: &[u32]) -> f32 {
        self.exact_coverage_of(light, origin, [stratum.min, stratum.min + Vec2::splat(stratum.size)], triangles)
    }

    /// [`GroundTruth::exact_coverage`] of the rectangle `[min, max]` of the light (light
    /// coordinates).
    fn exact_coverage_of(&self, light: &RectLight, origin: Vec3, [min, max]: [Vec2; 2], triangles: &[u32]) -> f32 {
        debug_assert!(triangles.len() <= EXACT_CANDIDATES);
        let mut corners = [[Vec3::ZERO; 3]; EXACT_CANDIDATES];
        for (corner, slot) in corners.iter_mut().zip(triangles) {
            *corner = self.triangle_of_slot(*slot);
        }
        let corners = &corners[..triangles.len().min(EXACT_CANDIDATES)];
        snap_visible(1.0 - coverage::covered_share(light, origin, corners, [min, max]))
    }

    /// Which of the rays of every set to the strata [i0, i1) × [j0, j1) reach the light, from the
    /// triangles in the pyramid from the origin to that part of the light (`parent`: those of
    /// the enclosing part, or `None` to gather them from the BVH). None in it: every ray reaches
    /// the light. One triangle that the four corner rays all cross: it covers the pyramid (a
    /// convex triangle, a convex cone), none does. At most [`EXACT_CANDIDATES`], for the
    /// estimate's sets ([`PixelRays::exact_parts`]): every stratum gets the share of the part
    /// they hide, exactly. A few: each ray is tested against them. Otherwise the part is cut into
    /// quarters. Exact: a triangle a ray crosses is always among the candidates, and each ray is
    /// decided by the same test as the BVH's.
    fn count_visible(&self, rays: &mut PixelRays<'_>, region: [u32; 4], parent: Option<&[u32]>, depth: u32, may_gather: bool) {
        let [i0, i1, j0, j1] = region;
        let strata = (i1 - i0) * (j1 - j0);
        if strata == 0 {
            return;
        }
        let scale = 2.0 / rays.n as f32;
        let (s0, s1, t0, t1) = (i0 as f32 * scale - 1.0, i1 as f32 * scale - 1.0, j0 as f32 * scale - 1.0, j1 as f32 * scale - 1.0);
        let corners = [rays.light.point(s0, t0), rays.light.point(s1, t0), rays.light.point(s1, t1), rays.light.point(s0, t1)];
        // The side of the tangent plane is affine in the sample, so the corners decide a part's.
        let front = rays.in_front(corners[0]);
        let window = [DVec2::new(f64::from(s0), f64::from(t0)), DVec2::new(f64::from(s1), f64::from(t1))];
        if corners.iter().any(|c| rays.in_front(*c) != front) {
            // On a solid, the part behind the tangent plane is dark and the rest is seen from
            // the front origin: the part of the light behind the plane is one more polygon
            // hiding it, with the occluders projected from there.
            if rays.closed && rays.exact_parts && self.occluders.is_some() {
                self.ensure_projected(rays, 0);
                if let Some(Some(projected)) = &rays.projected[0] {
                    let behind = coverage::behind_line(window, rays.light, rays.plane);
                    if let PolygonAnswer::Exact(visible) = decide_by_polygons(projected, window, &mut rays.picked, Some(&behind)) {
                        rays.mark(region, visible);
                        return;
                    }
                }
            }
            if strata > 1 {
                // The plane cuts this part: each quarter has a side of its own, or is cut further.
                self.count_quarters(rays, region, None, depth, may_gather);
                return;
            }
            rays.draw_jitter();
            for set in 0..rays.strata.len() {
                for (i, j, index) in PixelRays::indices(region, rays.n) {
                    let sample = rays.sample(set, i, j);
                    let open = (rays.in_front(sample) || !rays.closed)
                        && !self.blocked_remembering(rays.origins[usize::from(!rays.in_front(sample))], sample, &mut rays.recent);
                    rays.strata[set][index] = if open { 1.0 } else { 0.0 };
                }
            }
            return;
        }
        if rays.closed && !front {
            // Behind the seen side of a solid's surface.
            rays.mark(region, 0.0);
            return;
        }
        let side = usize::from(!front);
        let origin = rays.origins[side];
        if rays.exact_parts && self.occluders.is_some() {
            self.ensure_projected(rays, side);
            if let Some(Some(projected)) = &rays.projected[side] {
                match decide_by_polygons(projected, window, &mut rays.picked, None) {
                    PolygonAnswer::Exact(visible) => {
                        rays.mark(region, visible);
                        return;
                    }
                    PolygonAnswer::TooMany if strata > 1 => {
                        self.count_quarters(rays, region, None, depth, may_gather && depth == 0);
                        return;
                    }
                    // One stratum that more occluders meet: its rays, as below.
                    PolygonAnswer::TooMany => {}
                }
            }
        }
        let gathered = Pyramid::new(origin, corners, rays.light).and_then(|pyramid| {
            let mut found = Vec::new();
            let complete = match parent {
                Some(parent) => {
                    found.extend(parent.iter().copied().filter(|slot| self.may_cross(*slot, &pyramid)));
                    true
                }
                // Gathering from the BVH costs a traversal: only for the whole light, its quarters
                // and the parts the tangent plane leaves whole.
                None if may_gather => self.pyramid_candidates(&pyramid, GATHER_LIMIT, &mut found),
                None => false,
            };
            complete.then_some(found)
        });
        match gathered {
            Some(candidates) if candidates.is_empty() => rays.mark(region, 1.0),
            Some(candidates) if candidates.iter().any(|slot| corners.iter().all(|c| self.blocked_by(origin, *c, &[*slot]))) => {
                rays.mark(region, 0.0);
            }
            Some(candidates) if rays.exact_parts && strata > 1 && candidates.len() <= EXACT_CANDIDATES => {
                // So few triangles that the area they hide of this whole part of the light is
                // cheaper than its rays and their refinement: every stratum of it gets that share,
                // exactly, in both sets (no noise), and none is refined.
                let window = [Vec2::new(s0, t0), Vec2::new(s1, t1)];
                let visible = self.exact_coverage_of(rays.light, origin, window, &candidates);
                rays.mark(region, visible);
            }
            Some(candidates) if strata == 1 || candidates.len() <= DIRECT_CANDIDATES => {
                rays.draw_jitter();
                for set in 0..rays.strata.len() {
                    for (i, j, index) in PixelRays::indices(region, rays.n) {
                        let open = !self.blocked_by(origin, rays.sample(set, i, j), &candidates);
                        rays.strata[set][index] = if open { 1.0 } else { 0.0 };
                    }
                }
                let list = rays.lists.len() as u32;
                for (_, _, index) in PixelRays::indices(region, rays.n) {
                    rays.stratum_list[index] = list;
                }
                rays.lists.push(candidates);
            }
            Some(candidates) => self.count_quarters(rays, region, Some(&candidates), depth, false),
            None if strata > 1 && depth == 0 => self.count_quarters(rays, region, None, depth, true),
            None => {
                // Too many triangles even here: each ray through the BVH.
                rays.draw_jitter();
                for set in 0..rays.strata.len() {
                    for (i, j, index) in PixelRays::indices(region, rays.n) {
                        let open = !self.blocked_remembering(origin, rays.sample(set, i, j), &mut rays.recent);
                        rays.strata[set][index] = if open { 1.0 } else { 0.0 };
                    }
                }
            }
        }
    }

    /// Projects the occluders from ray origin `side` of `rays` ([`GroundTruth::project_occluders`]),
    /// once per pixel.
    fn ensure_projected(&self, rays: &mut PixelRays<'_>, side: usize) {
        if rays.projected[side].is_none() {
            rays.projected[side] = Some(self.project_occluders(rays.light, rays.origins[side]));
        }
    }

    /// What the occluders in the pyramid from `origin` to the whole light hide, projected onto the
    /// light's plane: each convex piece as one polygon ([`pieces::ConvexPiece::project`]), each
    /// other triangle as its own. `None` where no piece can hide any of it (the triangles'
    /// shortcuts do as well), or where they cannot all be projected: more than [`LOOSE_LIMIT`]
    /// triangles or [`PIECE_LIMIT`] pieces, or a solid piece that may hold the origin (its
    /// projection has no bound; a point on the piece, its origin off the surface, is outside).
    fn project_occluders(&self, light: &RectLight, origin: Vec3) -> Option<ProjectedOccluders> {
        let layer = self.occluders.as_ref()?;
        let pyramid = Pyramid::new(origin, Window::LIGHT.corners(light), light)?;
        let margin = self.pyramid_margin();
        // The pieces first (a small BVH): a pyramid that none can cross, such as one over the
        // ground alone, is left to the triangles, as if there were no pieces.
        let mut found = Vec::new();
        let complete = layer.piece_nodes.gather(&pyramid.planes, margin, |first, count| {
            found.extend((first..first + count).map(|slot| layer.piece_bvh.primitive_indices[slot as usize] as usize));
            found.len() <= PIECE_LIMIT
        });
        if !complete {
            return None;
        }
        let clearance = 0.5 * self.surface_offset;
        let mut relevant = Vec::with_capacity(found.len());
        for index in found {
            let piece = &layer.pieces[index];
            if pyramid.planes.iter().any(|(normal, offset)| box_beyond(piece.bounds, *normal, *offset + margin)) {
                continue;
            }
            if let Some((normal, offset)) = piece.plane {
                // A flat piece with the origin and the whole light on one side of it, clear of
                // it, hides nothing (as `may_cross` drops a triangle): such as the surface the
                // point lies on. One through the origin has no bounded projection.
                match pyramid.beside_plane(|p| normal.dot(p) - offset, clearance) {
                    Some(true) => continue,
                    None => return None,
                    Some(false) => {}
                }
            } else if piece.may_hold(origin, 0.5 * clearance) {
                // Inside a convex solid that also holds the whole light (a room lit from
                // within), its surface hides nothing; else the projection has no bound.
                if piece.holds_inside(&pyramid.base, margin) && piece.holds_inside(&[origin], 0.0) {
                    continue;
                }
                return None;
            }
            relevant.push(index);
        }
        if relevant.is_empty() {
            return None;
        }
        let mut loose = Vec::new();
        if let Some((bvh, nodes)) = &layer.loose_bvh {
            let complete = nodes.gather(&pyramid.planes, margin, |first, count| {
                for slot in first..first + count {
                    let index = layer.loose[bvh.primitive_indices[slot as usize] as usize] as usize;
                    if self.may_cross_triangle(index, &pyramid) {
                        loose.push(index);
                    }
                }
                loose.len() <= LOOSE_LIMIT
            });
            if !complete {
                return None;
            }
        }
        let mut projected = ProjectedOccluders::default();
        let mut scratch = pieces::ProjectScratch::default();
        for index in relevant {
            let mut polygon = Vec::new();
            layer.pieces[index].project(light, origin, &mut scratch, &mut polygon);
            if polygon.len() >= 3 {
                projected.boxes.push(coverage::bounding_box(&polygon));
                projected.polygons.push(polygon);
            }
        }
        for index in loose {
            let mut polygon = Vec::new();
            coverage::project_triangle(light, origin, &self.triangle_corners(index), &mut polygon);
            if polygon.len() >= 3 {
                projected.boxes.push(coverage::bounding_box(&polygon));
                projected.polygons.push(polygon);
            }
        }
        Some(projected)
    }

    /// The corners of the triangle at `index` in `triangles`.
    fn triangle_corners(&self, index: usize) -> [Vec3; 3] {
        let triangle = &self.triangles[index];
        [triangle.v0, triangle.v1, triangle.v2].map(Vec3::from)
    }

    /// [`GroundTruth::count_visible`] of the four quarters of `region`.
    fn count_quarters(&self, rays: &mut PixelRays<'_>, region: [u32; 4], parent: Option<&[u32]>, depth: u32, may_gather: bool) {
        let [i0, i1, j0, j1] = region;
        let (im, jm) = ((i0 + i1).div_ceil(2), (j0 + j1).div_ceil(2));
        for quarter in [[i0, im, j0, jm], [im, i1, j0, jm], [i0, im, jm, j1], [im, i1, jm, j1]] {
            self.count_visible(rays, quarter, parent, depth + 1, may_gather);
        }
    }

    /// The N² rays of a pixel, each through the BVH, each stratum's result; with `remember`, each ray first tries the
    /// last few triangles that blocked the pixel's rays (neighbouring rays mostly hit the same
    /// ones), which changes no answer: a ray one of them blocks is blocked.
    fn visibility_of_rays(&self, light: &RectLight, point: &SurfacePoint, n: u32, rng: &mut SplitMix64, remember: bool) -> Vec<f32> {
        let n = n.max(1);
        let mut recent = RecentBlockers::default();
        // With a footprint, the pixel's strata in a random order: a fixed pairing with the
        // light's strata (such as (i, j) with (j, i)) correlates them and biases the average.
        let pixel_strata: Vec<u32> = match point.footprint {
            Some(_) => {
                let mut order: Vec<u32> = (0..n * n).collect();
                for k in (1..order.len()).rev() {
                    order.swap(k, (rng.next_u64() % (k as u64 + 1)) as usize);
                }
                order
            }
            None => Vec::new(),
        };
        let mut strata = vec![0.0f32; (n * n) as usize];
        for j in 0..n {
            for i in 0..n {
                let jitter = Vec2::new(rng.next_f32(), rng.next_f32());
                let stratum = (Vec2::new(i as f32, j as f32) + jitter) / n as f32 * 2.0 - Vec2::ONE;
                let sample = light.point(stratum.x, stratum.y);
                let position = match &point.footprint {
                    Some(footprint) => {
                        let cell = pixel_strata[(j * n + i) as usize];
                        let sub_pixel =
                            (Vec2::new((cell % n) as f32, (cell / n) as f32) + Vec2::new(rng.next_f32(), rng.next_f32())) / n as f32;
                        let position = footprint.on_plane(sub_pixel.x, sub_pixel.y, point.position, point.normal).unwrap_or(point.position);
                        if (position - light.centre).dot(light.normal()) <= 0.0 {
                            continue;
                        }
                        position
                    }
                    None => point.position,
                };
                // Leave the surface on the side facing this sample, so that it does not shadow itself;
                // a closed surface passes no light to its seen side from behind.
                let side = if point.normal.dot(sample - position) >= 0.0 { 1.0 } else { -1.0 };
                if point.closed && side < 0.0 {
                    continue;
                }
                let origin = position + point.normal * (side * self.surface_offset);
                let open = if remember { !self.blocked_remembering(origin, sample, &mut recent) } else { self.unoccluded(origin, sample) };
                strata[(j * n + i) as usize] = if open { 1.0 } else { 0.0 };
            }
        }
        strata
    }

    /// Traces every pixel (`None`: no surface, visibility 1, noise 0) on all cores, each as
    /// [`GroundTruth::estimate`] with its own generator seeded from `seed` and its index.
    #[must_use]
    pub fn trace(&self, light: &RectLight, points: &[Option<SurfacePoint>], sampling: Sampling, seed: u64) -> ReferenceImage {
        let start = Instant::now();
        let estimates: Vec<PixelEstimate> = points
            .par_iter()
            .enumerate()
            .map(|(index, point)| match point {
                Some(point) => self.estimate(light, point, sampling, &mut SplitMix64::for_pixel(seed, index as u64)),
                None => PixelEstimate { visibility: 1.0, noise: 0.0, rays: 0 },
            })
            .collect();
        ReferenceImage {
            visibility: estimates.iter().map(|e| e.visibility).collect(),
            noise: estimates.iter().map(|e| e.noise).collect(),
            rays: estimates.iter().map(|e| e.rays).sum(),
            elapsed: start.elapsed(),
            cached: false,
        }
    }

    /// As [`GroundTruth::trace`], through a cache in `cache_dir` keyed by a hash
    /// of the geometry, the light, the points, the sampling, the seed and
    /// [`REFERENCE_VERSION`]. A cache that cannot be read or written is ignored.
    #[must_use]
    pub fn trace_cached(
        &self,
        light: &RectLight,
        points: &[Option<SurfacePoint>],
        sampling: Sampling,
        seed: u64,
        cache_dir: &Path,
    ) -> ReferenceImage {
        if let Some(image) = self.cache.cached(light, points, sampling, seed, cache_dir) {
            return image;
        }
        let file = self.cache.file(light, points, sampling, seed, cache_dir);
        let image = self.trace(light, points, sampling, seed);
        // The visibility, then the noise.
        let bytes: Vec<u8> = image.visibility.iter().chain(&image.noise).flat_map(|v| v.to_le_bytes()).collect();
        // Write then rename, so that a concurrent reader never sees half a file.
        let partial = file.with_extension(format!("partial{}", std::process::id()));
        if std::fs::create_dir_all(cache_dir).is_ok() && std::fs::write(&partial, bytes).is_ok() {
            let _ = std::fs::rename(&partial, &file);
        }
        image
    }

    /// Number of triangles in the BVH.
    #[must_use]
    pub fn triangle_count(&self) -> usize {
        self.triangles.len()
    }
}

/// The default cache folder: `$SSM_CACHE_DIR/reference`, else
/// `$XDG_CACHE_HOME/ssm/reference`, else `~/.cache/ssm/reference`, else
/// `ssm-cache/reference` under the working folder.
#[must_use]
pub fn default_cache_dir() -> PathBuf {
    if let Some(dir) = std::env::var_os("SSM_CACHE_DIR") {
        return PathBuf::from(dir).join("reference");
    }
    if let Some(dir) = std::env::var_os("XDG_CACHE_HOME") {
        return PathBuf::from(dir).join("ssm/reference");
    }
    if let Some(home) = std::env::var_os("HOME") {
        return PathBuf::from(home).join(".cache/ssm/reference");
    }
    PathBuf::from("ssm-cache/reference")
}

/// Exact visibility of a rectangular light from `point` past one rectangular
/// occluder parallel to the light and aligned with its axes: the occluder
/// seen from the point projects onto the light's plane as a rectangle, and
/// the hidden fraction is the product of the two clamped 1-D overlaps with
/// the light (Atty et al., Sec. 4.2). `occluder_centre` is a point of the
/// occluder; `occluder_half_size` its half extents along the light's u and v.
/// Used to test the ray caster on `parallel-square`.
#[must_use]
pub fn parallel_rectangle_visibility(light: &RectLight, occluder_centre: Vec3, occluder_half_size: Vec2, point: Vec3) -> f32 {
    let normal = light.normal();
    let local = |p: Vec3| {
        let offset = p - light.centre;
        (Vec2::new(offset.dot(light.u_axis), offset.dot(light.v_axis)), offset.dot(normal))
    };
    let (point_uv, point_depth) = local(point);
    let (occluder_uv, occluder_depth) = local(occluder_centre);
    if point_depth <= 0.0 {
        return 0.0;
    }
    if !(occluder_depth > 0.0 && occluder_depth < point_depth) {
        return 1.0;
    }
    // From the point, the occluder's plane maps onto the light's plane by this factor.
    let scale = point_depth / (point_depth - occluder_depth);
    if light.is_point() {
        // One ray, to the centre: where does it cross the occluder's plane?
        let crossing = point_uv - point_uv / scale;
        return if (crossing - occluder_uv).abs().cmple(occluder_half_size).all() { 0.0 } else { 1.0 };
    }
    let low = point_uv + (occluder_uv - occluder_half_size - point_uv) * scale;
    let high = point_uv + (occluder_uv + occluder_half_size - point_uv) * scale;
    let overlap = (high.min(light.half_size) - low.max(-light.half_size)).max(Vec2::ZERO);
    1.0 - overlap.x * overlap.y / light.area()
}

/// SplitMix64 (Steele et al. 2014): a tiny, well-distributed generator; one
/// per pixel, seeded from the run's seed and the pixel's index.
#[derive(Clone, Debug)]
pub struct SplitMix64 {
    state: u64,
}

impl SplitMix64 {
    /// A generator for pixel `index` of a run seeded with `seed`.
    #[must_use]
    pub fn for_pixel(seed: u64, index: u64) -> Self {
        let mut mixer = Self { state: seed ^ index.wrapping_mul(0x9E37_79B9_7F4A_7C15) };
        // Decorrelate neighbouring pixels before use.
        mixer.next_u64();
        mixer
    }

    /// The next 64 random bits.
    pub fn next_u64(&mut self) -> u64 {
        self.state = self.state.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.state;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^ (z >> 31)
    }

    /// An independent generator seeded from this one's next output.
    pub fn fork(&mut self) -> Self {
        let state = self.next_u64();
        let mut forked = Self { state };
        forked.next_u64();
        forked
    }

    /// A float uniform in `[0, 1)`.
    pub fn next_f32(&mut self) -> f32 {
        (self.next_u64() >> 40) as f32 / (1u64 << 24) as f32
    }
}

/// FNV-1a, 64-bit: a stable hash (the same on every machine and Rust version) for cache keys.
struct Fnv64(u64);

impl Fnv64 {
    fn new() -> Self {
        Self(0xcbf2_9ce4_8422_2325)
    }

    fn write(&mut self, bytes: &[u8]) {
        for byte in bytes {
            self.0 ^= u64::from(*byte);
            self.0 = self.0.wrapping_mul(0x0100_0000_01b3);
        }
    }

    fn write_f32s(&mut self, values: &[f32]) {
        for value in values {
            self.write(&value.to_le_bytes());
        }
    }

    fn finish(&self) -> u64 {
        self.0
    }
}

#[cfg(test)]
mod tests {
    use ssm_scene::builtin;

    use super::*;

    #[test]
    fn analytic_formula_matches_the_hand_computed_parallel_square() {
        let scene = builtin("parallel-square").unwrap().build();
        let light = &scene.lights[0];
        let exact = |x: f32, z: f32| parallel_rectangle_visibility(light, Vec3::new(0.0, 2.0, 0.0), Vec2::splat(0.5), Vec3::new(x, 0.0, z));
        assert_eq!(exact(0.0, 0.0), 0.0);
        assert_eq!(exact(2.0, 0.0), 1.0);
        // Half-way through the penumbra along x, half the light is hidden.
        assert!((exact(1.0, 0.0) - 0.5).abs() < 1e-6);
        // At (1, 1) a quarter of the light is hidden.
        assert!((exact(1.0, 1.0) - 0.75).abs() < 1e-6);
    }

    #[test]
    fn generator_is_uniform_enough_and_repeatable() {
        let mut a = SplitMix64::for_pixel(7, 3);
        let mut b = SplitMix64::for_pixel(7, 3);
        let samples: Vec<f32> = (0..10_000).map(|_| a.next_f32()).collect();
        assert!(samples.iter().all(|s| (0.0..1.0).contains(s)));
        let mean = samples.iter().sum::<f32>() / samples.len() as f32;
        assert!((mean - 0.5).abs() < 0.01, "{mean}");
        assert_eq!(samples[0], b.next_f32());
        assert_ne!(SplitMix64::for_pixel(7, 4).next_u64(), SplitMix64::for_pixel(7, 3).next_u64());
    }

    /// A point in [-1, 1)^3 from `rng`.
    fn random_point(rng: &mut SplitMix64) -> Vec3 {
        Vec3::new(rng.next_f32(), rng.next_f32(), rng.next_f32()) * 2.0 - Vec3::ONE
    }

    /// The prepared triangle answers as obvhs's `Triangle::intersect`, bit for bit: on random
    /// rays, on rays through a corner or an edge (where rounding decides), inside it, in its
    /// plane, and on segments that end before it.
    #[test]
    fn prepared_triangles_intersect_as_obvhs_bit_for_bit() {
        let mut rng = SplitMix64::for_pixel(11, 0);
        let (mut compared, mut hits) = (0, 0);
        for _ in 0..2_000 {
            let triangle = Triangle {
                v0: Vec3A::from(random_point(&mut rng)),
                v1: Vec3A::from(random_point(&mut rng)),
                v2: Vec3A::from(random_point(&mut rng)),
            };
            let prepared = PreparedTriangle::new(&triangle);
            let [v0, v1, v2] = [triangle.v0, triangle.v1, triangle.v2].map(Vec3::from);
            let origin = random_point(&mut rng) * 3.0;
            let (a, b) = (rng.next_f32(), rng.next_f32());
            let targets = [
                random_point(&mut rng) * 3.0,
                v0,
                v1,
                (v1 + v2) * 0.5,
                v0 + (v1 - v0) * a,
                v0 + (v1 - v0) * a + (v2 - v0) * b,
                // In the triangle's plane: beside it or through it.
                origin + (v1 - v0) * a + (v2 - v0) * b,
            ];
            for aim in targets {
                // Past the point aimed at, so that the segment crosses the triangle's plane.
                let target = origin + (aim - origin) * 2.0;
                let Some(ray) = segment_ray(origin, target) else { continue };
                for ray in [ray, Ray { tmax: ray.tmax * 0.5, ..ray }] {
                    let (expected, actual) = (triangle.intersect(&ray), prepared.intersect(&ray));
                    assert_eq!(expected.to_bits(), actual.to_bits(), "origin {origin}, through {aim}: {expected} against {actual}");
                    compared += 1;
                    hits += usize::from(expected.is_finite());
                }
            }
        }
        assert!(hits > compared / 10 && hits < compared, "{hits} hits of {compared}: both cases must be seen");
    }
}

/// The points the ground truth samples, one per pixel (`None` where nothing
/// was drawn): the G-buffer's positions (`w` = coverage) and normals as read
/// back, with each pixel's footprint on its tangent plane when
/// `pixel_footprint` (the `footprint = pixel` parameter). These points are
/// part of the cache key, so the same view gives the same points.
#[must_use]
pub fn surface_points(
    positions: &[[f32; 4]],
    normals: &[[f32; 4]],
    camera: &crate::CameraUniform,
    pixel_footprint: bool,
) -> Vec<Option<SurfacePoint>> {
    let width = (camera.viewport[0] as usize).max(1);
    positions
        .iter()
        .zip(normals)
        .enumerate()
        .map(|(index, (p, n))| {
            (p[3] > 0.5).then(|| SurfacePoint {
                position: Vec3::new(p[0], p[1], p[2]),
                normal: Vec3::new(n[0], n[1], n[2]).normalize_or(Vec3::Y),
                closed: crate::GBuffer::flags(n[3]) & crate::GBuffer::CLOSED != 0,
                footprint: pixel_footprint.then(|| pixel_rays(camera, (index % width) as f32, (index / width) as f32)),
            })
        })
        .collect()
}

/// The camera rays through the pixel whose top-left corner is at (`x`, `y`), in pixels.
fn pixel_rays(camera: &crate::CameraUniform, x: f32, y: f32) -> PixelFootprint {
    let inverse = glam::Mat4::from_cols_array_2d(&camera.inverse_view_proj);
    let eye = Vec3::new(camera.position[0], camera.position[1], camera.position[2]);
    // Points of the far plane are affine in NDC, so the directions are affine in pixels.
    let direction = |x: f32, y: f32| {
        let ndc = glam::Vec4::new(x * camera.viewport[2] * 2.0 - 1.0, 1.0 - y * camera.viewport[3] * 2.0, 1.0, 1.0);
        let far = inverse * ndc;
        far.truncate() / far.w - eye
    };
    let corner = direction(x, y);
    PixelFootprint { eye, corner, across: direction(x + 1.0, y) - corner, down: direction(x, y + 1.0) - corner }
}

/// The registered name of the ground truth.
pub const NAME: &str = "reference";

/// Parameters of the `reference` technique.
pub const PARAMS: &[crate::ParamSpec] = &[
    crate::ParamSpec {
        name: "samples",
        kind: crate::ParamKind::Int { default: 12, min: 1, max: 256 },
        doc: "light samples per axis (N): two independent sets of N×N stratified, jittered shadow rays per pixel, whose difference is the noise reported",
    },
    crate::ParamSpec {
        name: "refine",
        kind: crate::ParamKind::Int { default: 2, min: 1, max: 16 },
        doc: "rays per axis (M) in a stratum where the visibility varies (its result in the other set differs from a neighbour's): M×M instead of one; 1 = plain stratified sampling",
    },
    crate::ParamSpec { name: "seed", kind: crate::ParamKind::Int { default: 1, min: 0, max: i64::MAX }, doc: "seed of the jitter" },
    crate::ParamSpec {
        name: "cache",
        kind: crate::ParamKind::Bool { default: true },
        doc: "read and write the on-disk cache (SSM_CACHE_DIR, else ~/.cache/ssm)",
    },
    crate::ParamSpec {
        name: "traversal",
        kind: crate::ParamKind::Choice { default: "shortcuts", options: <Traversal as crate::Choice>::OPTIONS },
        doc: "how rays are traced, with the same answer ray for ray: shortcuts (each pixel's pyramid to the light gathered from the BVH once, cut into quarters where it holds many triangles) or per_ray (every ray through the BVH, the definition: to time the shortcuts against, with cache = false)",
    },
    crate::ParamSpec {
        name: "footprint",
        kind: crate::ParamKind::Choice { default: "centre", options: &["centre", "pixel"] },
        doc: "where each pixel is sampled: at the G-buffer's point (centre), or over the pixel's footprint on the point's tangent plane (pixel: the prefiltered visibility that anti-aliasing aims at)",
    },
];

/// The ground truth as a technique: traces on the CPU, uploads, copies into the target.
struct ReferenceTechnique {
    truth: GroundTruth,
    sampling: Sampling,
    seed: u64,
    cache_dir: Option<PathBuf>,
    /// The G-buffer's points, read once: the scene and camera are static.
    points: Option<Vec<Option<SurfacePoint>>>,
    /// Whether each point carries its pixel's footprint (`footprint = pixel`).
    pixel_footprint: bool,
    /// One texture and bind group per light: an upload is recorded on the queue
    /// before the frame's commands run, so lights sharing one texture would all
    /// read the last light's upload.
    traced: Vec<(wgpu::Texture, wgpu::BindGroup)>,
    upload: crate::ScreenPass,
    /// Each light's traced image, kept: the scene and camera are static, so later frames only copy it into the target.
    traced_per_light: Vec<Option<ReferenceImage>>,
    /// The view's width and height.
    size: (u32, u32),
}

impl ReferenceTechnique {
    fn points(&mut self, frame: &crate::Frame<'_>) -> crate::Result<&[Option<SurfacePoint>]> {
        if self.points.is_none() {
            let gbuffer = frame.shared.gbuffer(NAME)?;
            let positions = crate::readback::read_texture(frame.gpu, &gbuffer.position, 16, "G-buffer positions")?;
            let normals = crate::readback::read_texture(frame.gpu, &gbuffer.normal, 16, "G-buffer normals")?;
            let positions: Vec<[f32; 4]> = bytemuck::pod_collect_to_vec(&positions);
            let normals: Vec<[f32; 4]> = bytemuck::pod_collect_to_vec(&normals);
            self.points = Some(surface_points(&positions, &normals, &frame.scene.camera, self.pixel_footprint));
        }
        Ok(self.points.as_deref().unwrap_or_default())
    }
}

impl crate::ShadowTechnique for ReferenceTechnique {
    fn render(&mut self, frame: &mut crate::Frame<'_>, light: usize, output: &wgpu::TextureView) -> crate::Result<()> {
        let rect = frame
            .scene
            .light_frames
            .get(light)
            .map(|f| f.light)
            .ok_or_else(|| crate::Error::Technique { technique: NAME.into(), message: format!("no light {light}") })?;
        let (traced, traced_group) = self
            .traced
            .get(light)
            .cloned()
            .ok_or_else(|| crate::Error::Technique { technique: NAME.into(), message: format!("no light {light}") })?;
        if self.traced_per_light.len() <= light {
            self.traced_per_light.resize(light + 1, None);
        }
        if self.traced_per_light[light].is_none() {
            let (samples, seed) = (self.sampling, self.seed);
            let cache_dir = self.cache_dir.clone();
            let points = self.points(frame)?.to_vec();
            let image = match &cache_dir {
                Some(dir) => self.truth.trace_cached(&rect, &points, samples, seed, dir),
                None => self.truth.trace(&rect, &points, samples, seed),
            };
            // Uploaded once, into this light's own texture: the scene and camera are static.
            let (width, height) = (traced.width(), traced.height());
            frame.gpu.queue.write_texture(
                traced.as_image_copy(),
                bytemuck::cast_slice(&image.visibility),
                wgpu::TexelCopyBufferLayout { offset: 0, bytes_per_row: Some(width * 4), rows_per_image: Some(height) },
                wgpu::Extent3d { width, height, depth_or_array_layers: 1 },
            );
            self.traced_per_light[light] = Some(image);
        }
        self.upload.encode(frame, light, output, Some(&traced_group), None);
        Ok(())
    }

    /// The noise of light 0 as `truth_noise`, and of light k as `truth_noise-light<k>`.
    fn debug_outputs(&mut self, _gpu: &crate::GpuContext, requested: &[&str]) -> crate::Result<Vec<crate::ExtraImage>> {
        if !requested.contains(&NOISE_OUTPUT) {
            return Ok(Vec::new());
        }
        let (width, height) = self.size;
        Ok(self
            .traced_per_light
            .iter()
            .enumerate()
            .filter_map(|(light, image)| {
                let image = image.as_ref()?;
                let name = if light == 0 { NOISE_OUTPUT.to_owned() } else { format!("{NOISE_OUTPUT}-light{light}") };
                Some(crate::ExtraImage { name, width, height, values: image.noise.clone(), overlay: false })
            })
            .collect())
    }

    /// Totals over the lights traced so far: rays, trace time, rays per second, and how many came from the cache.
    fn diagnostics(&mut self, _gpu: &crate::GpuContext) -> Vec<(String, f64)> {
        let images: Vec<&ReferenceImage> = self.traced_per_light.iter().flatten().collect();
        if images.is_empty() {
            return Vec::new();
        }
        let rays: u64 = images.iter().map(|i| i.rays).sum();
        let seconds: f64 = images.iter().map(|i| i.elapsed.as_secs_f64()).sum();
        let mut out = vec![
            ("reference_lights_from_cache".to_owned(), images.iter().filter(|i| i.cached).count() as f64),
            ("reference_rays".to_owned(), rays as f64),
            ("reference_trace_ms".to_owned(), seconds * 1e3),
        ];
        if rays > 0 && seconds > 0.0 {
            out.push(("reference_rays_per_second".to_owned(), rays as f64 / seconds));
        }
        out
    }
}

fn create(setup: &crate::TechniqueSetup<'_>) -> crate::Result<Box<dyn crate::ShadowTechnique>> {
    let params = setup.params;
    let device = &setup.gpu.device;
    let (width, height) = (setup.scene.width, setup.scene.height);
    let layout = setup.gpu.texture_layout();
    let traced = (0..setup.scene.light_count())
        .map(|light| {
            let label = format!("reference_traced_light{light}");
            let texture =
                crate::passes::render_texture(device, &label, width, height, crate::VISIBILITY_FORMAT, wgpu::TextureUsages::COPY_DST);
            let view = crate::passes::labelled_view(&texture, &label);
            let group = device.create_bind_group(&wgpu::BindGroupDescriptor {
                label: Some(&format!("{label}_bind_group")),
                layout,
                entries: &[wgpu::BindGroupEntry { binding: 0, resource: wgpu::BindingResource::TextureView(&view) }],
            });
            (texture, group)
        })
        .collect();
    let module = crate::shader::create_shader(setup.gpu, "reference_upload_shader", ssm_shaders::core::REFERENCE_UPLOAD)?;
    let upload = crate::ScreenPass::new(
        setup,
        NAME,
        "reference_upload",
        (&module, "reference_upload"),
        Some(layout),
        crate::VISIBILITY_FORMAT.into(),
        &[],
    )?;
    Ok(Box::new(ReferenceTechnique {
        truth: GroundTruth::new(setup.cpu_scene).with_traversal(
            <Traversal as crate::Choice>::from_name(params.choice("traversal")?).ok_or(crate::ParamError::WrongType {
                technique: NAME.into(),
                name: "traversal".into(),
                wanted: "Traversal",
            })?,
        ),
        sampling: Sampling {
            samples_per_axis: u32::try_from(params.int("samples")?).unwrap_or(Sampling::DEFAULT.samples_per_axis),
            refine: u32::try_from(params.int("refine")?).unwrap_or(Sampling::DEFAULT.refine),
        },
        seed: u64::try_from(params.int("seed")?).unwrap_or(1),
        cache_dir: params.bool("cache")?.then(default_cache_dir),
        points: None,
        pixel_footprint: params.choice("footprint")? == "pixel",
        traced,
        upload,
        traced_per_light: Vec::new(),
        size: (width, height),
    }))
}

/// The registration of the ground truth.
pub const INFO: crate::TechniqueInfo = crate::TechniqueInfo {
    name: NAME,
    summary: "ground truth: two independent sets of N×N stratified jittered shadow rays per pixel, refined where the visibility varies, on the CPU (CWBVH, all cores), cached on disk, with its own noise per pixel",
    paper: "Monte Carlo estimate of the visible fraction of the light (stratified sampling, refined where the visibility varies)",
    kind: crate::TechniqueKind::GroundTruth,
    // Rays to points all over the light, blocked behind a closed surface (SurfacePoint::closed).
    light_sampling: crate::LightSampling::PerSample,
    light_view: crate::LightView::Hemisphere,
    params: PARAMS,
    requirements: |_| Ok(crate::Requirements { gbuffer: true, ..crate::Requirements::NONE }),
    create,
    presets: &[],
    trade: None,
    debug_outputs: &[crate::DebugOutput { name: NOISE_OUTPUT, doc: NOISE_DOC, overlay: false }],
    uniforms: &[],
    limits: &[],
    paper_configuration: crate::PaperConfiguration::DEFAULTS,
};

/// The debug output holding the ground truth's own error per pixel ([`ReferenceImage::noise`]);
/// every command that measures errors asks for it.
pub const NOISE_OUTPUT: &str = "truth_noise";

const NOISE_DOC: &str = "the ground truth's own error per pixel, |A − B|/2 of its two independent estimates (visibility units): its mean over pixels estimates the truth's mean absolute error there";

crate::register_technique!(INFO);
