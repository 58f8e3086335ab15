//! The pyramid shortcuts: a pixel's rays share their origin (one on each side of its tangent
//! plane), so the triangles in the pyramid from that origin to the light, or to a part of it,
//! are gathered from the BVH once and decide the part's rays together, with the same answer ray
//! for ray as each ray through the BVH: none, lit; one that covers the pyramid, dark; a few, each
//! ray tested against them (or, for the estimate, the share of the part they hide, exactly:
//! `coverage`); too many, the part cut into quarters. Where the occluders are convex pieces
//! (`pieces`), a part is decided from their projections onto the light's plane instead.

use glam::{DVec2, Vec2, Vec3};
use ssm_scene::RectLight;

use super::traversal::RecentBlockers;
use super::{GroundTruth, SplitMix64, SurfacePoint, coverage, pieces};

/// Most triangles gathered from the BVH for the pyramid from a point to (part of) the light; with
/// more, the part is cut further or its rays traverse the BVH one by one.
const GATHER_LIMIT: usize = 12;

/// With at most this many triangles in a part's pyramid, its rays are tested against them one by
/// one rather than the part being cut into quarters.
const DIRECT_CANDIDATES: usize = 12;

/// The pyramid from a ray origin to a rectangle of the light: every segment from the apex to a
/// point of the rectangle lies inside it.
pub(super) struct Pyramid {
    apex: Vec3,
    /// The rectangle's corners, in order around it.
    base: [Vec3; 4],
    /// Outward normals and offsets of the four sides and the base.
    pub(super) planes: [(Vec3, f32); 5],
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
    pub(super) fn new(apex: Vec3, base: [Vec3; 4], light: &RectLight) -> Option<Self> {
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

/// One pixel's rays, all from one origin: the light, the strata and their jitter.
pub(super) struct PixelRays<'a> {
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
    pub(super) jitter: Vec<Vec<Vec2>>,
    /// The generators the jitter is drawn from, one per set, until it is drawn.
    jitter_rngs: Vec<SplitMix64>,
    recent: RecentBlockers,
    /// Per set, each stratum's visible fraction at j·n + i: its ray's answer (0 or 1), or the
    /// exact fraction where a shortcut decided the stratum's whole part of the light.
    pub(super) strata: Vec<Vec<f32>>,
    /// Per stratum, whether a shortcut decided it exactly (the same value in every set).
    pub(super) exact: Vec<bool>,
    /// The triangles each stratum's rays were tested against (an index into `lists`: every
    /// triangle a ray into that part of the light can cross), or [`NO_LIST`] where they went
    /// through the BVH or a shortcut decided them.
    pub(super) stratum_list: Vec<u32>,
    pub(super) lists: Vec<Vec<u32>>,
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
pub(super) struct Window {
    pub(super) min: Vec2,
    pub(super) size: f32,
}

impl Window {
    /// The whole light.
    pub(super) const LIGHT: Self = Self { min: Vec2::NEG_ONE, size: 2.0 };

    /// The point at `cell` (stratum coordinates: (i, j) plus the jitter) of an N×N grid over this
    /// window. For the whole light, `cell / n · 2 − 1`, the per-ray traversal's formula, bit for bit.
    fn at(self, cell: Vec2, n: u32) -> Vec2 {
        cell / n as f32 * self.size + self.min
    }

    /// Stratum `index` (in the j·n + i order) of an N×N grid over this window, as a window of its own.
    pub(super) fn stratum(self, index: u32, n: u32) -> Self {
        let step = self.size / n as f32;
        Self { min: Vec2::new((index % n) as f32, (index / n) as f32) * step + self.min, size: step }
    }

    /// Its corners, in order around it.
    fn corners(self, light: &RectLight) -> [Vec3; 4] {
        let (min, max) = (self.min, self.min + Vec2::splat(self.size));
        [light.point(min.x, min.y), light.point(max.x, min.y), light.point(max.x, max.y), light.point(min.x, max.y)]
    }

    /// The points of an M×M grid over it, cell (a, b) moved by `jitter[b·m + a]` (in cell units).
    pub(super) fn jittered(self, jitter: &[Vec2], m: u32) -> impl Iterator<Item = Vec2> + '_ {
        (0..m * m).map(move |cell| self.at(Vec2::new((cell % m) as f32, (cell / m) as f32) + jitter[cell as usize], m))
    }
}

/// Most triangles in a stratum's pyramid whose covered area [`coverage`] computes exactly.
pub(super) const EXACT_CANDIDATES: usize = 4;
/// An exactly computed visible fraction this close to 0 or 1 is rounding: it is snapped.
const COVERAGE_SNAP: f64 = 1e-5;
/// No candidate list: [`PixelRays::stratum_list`] of a stratum whose rays go through the BVH.
pub(super) const NO_LIST: u32 = u32::MAX;

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
    pub(super) fn draw_jitter(&mut self) {
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

impl GroundTruth {
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

    /// The shortcut of [`GroundTruth::visibility`] for a point without a footprint: the pyramid
    /// from the point to the light, then to its quarters where it holds too many triangles or the
    /// point's tangent plane cuts it (each part on one side of the plane has one ray origin;
    /// [`GroundTruth::count_visible`]). A point light casts one ray for all N². One set of rays
    /// per generator of `rngs`, each drawing its jitter as visibility_per_ray does; the sets share
    /// the gathers.
    pub(super) fn pyramid_visibility<'a>(
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

    /// The triangles of `list` (every triangle a ray into an enclosing part of the light can
    /// cross) that can cross a ray from `origin` into the part `stratum`: `list` itself when it
    /// holds at most [`EXACT_CANDIDATES`], else those that meet the stratum's pyramid, in `found`.
    pub(super) fn stratum_candidates<'l>(
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

    /// The exact visible fraction of the part `stratum` of the light seen from `origin`, hidden
    /// only by `triangles` (at most [`EXACT_CANDIDATES`], BVH slots): 1 less the share of the
    /// stratum their central projection onto the light's plane covers ([`coverage::covered_share`]).
    pub(super) fn exact_coverage(&self, light: &RectLight, origin: Vec3, stratum: Window, triangles: &[u32]) -> f32 {
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

    /// [`GroundTruth::count_visible`] of the four quarters of `region`.
    fn count_quarters(&self, rays: &mut PixelRays<'_>, region: [u32; 4], parent: Option<&[u32]>, depth: u32, may_gather: bool) {
        let [i0, i1, j0, j1] = region;
        let (im, jm) = ((i0 + i1).div_ceil(2), (j0 + j1).div_ceil(2));
        for quarter in [[i0, im, j0, jm], [im, i1, j0, jm], [i0, im, jm, j1], [im, i1, jm, j1]] {
            self.count_visible(rays, quarter, parent, depth + 1, may_gather);
        }
    }
}
