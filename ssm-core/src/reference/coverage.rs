//! The exact share of a rectangle of the light that a few triangles hide from a point: each
//! triangle's central projection from the point onto the light's plane is a convex polygon (the
//! triangle first cut to the slab between the point's plane and the light's, parallel to the
//! light, where a segment from the point to the light can meet it), and the share is the area of
//! their union inside the rectangle, by inclusion–exclusion over the triangles' subsets. In
//! f64, so that a corner near the point's plane, which projects far away, keeps its precision.
//!
//! The ground truth calls this for most refined strata, so nothing here allocates once a
//! thread's buffers have grown ([`Scratch`]), and inclusion–exclusion walks the subsets depth
//! first: a subset's intersection is its parent's clipped once more, and a subset whose
//! intersection is empty (or whose bounding boxes are apart) drops every superset with it.

use std::cell::RefCell;

use glam::{DVec2, DVec3, Vec2, Vec3};
use ssm_scene::RectLight;

/// A corner of a triangle being cut to the slab, and its fraction t of the way from the origin
/// to the light's plane.
type SlabPoint = (DVec3, f64);

/// Buffers reused by every call on a thread.
#[derive(Default)]
struct Scratch {
    slab: [Vec<SlabPoint>; 2],
    /// The triangles' clipped projections (the first `count` of them are this call's).
    polygons: Vec<Vec<DVec2>>,
    /// The intersection of a subset of `polygons` at each depth of the walk.
    levels: Vec<Vec<DVec2>>,
    /// Each polygon's bounding box.
    boxes: Vec<[DVec2; 2]>,
    spare: Vec<DVec2>,
}

thread_local! {
    static SCRATCH: RefCell<Scratch> = RefCell::new(Scratch::default());
}

/// Share of `rect` (light coordinates: [-1, 1]² is the whole light, `[min, max]`) hidden from
/// `origin` by the union of `triangles` (a few: inclusion–exclusion visits every subset whose
/// intersection is not empty), in [0, 1]. `origin` must be in front of the light (positive
/// distance along its normal).
pub(super) fn covered_share(light: &RectLight, origin: Vec3, triangles: &[[Vec3; 3]], [min, max]: [Vec2; 2]) -> f64 {
    let rect = [min.as_dvec2(), max.as_dvec2()];
    SCRATCH.with_borrow_mut(|scratch| {
        scratch.reserve(triangles.len());
        let mut count = 0;
        for triangle in triangles {
            let polygon = &mut scratch.polygons[count];
            project(light, origin, triangle, &mut scratch.slab, polygon);
            clip_to_rect(polygon, &mut scratch.spare, rect);
            if polygon.len() >= 3 {
                count += 1;
            }
        }
        scratch.union_share(count, rect)
    })
}

/// [`covered_share`] of convex polygons already projected onto the light's plane (light
/// coordinates, either winding): a convex piece's hull, a triangle's projection.
pub(super) fn covered_share_of_projected(projected: &[&[DVec2]], rect: [DVec2; 2]) -> f64 {
    SCRATCH.with_borrow_mut(|scratch| {
        scratch.reserve(projected.len());
        let mut count = 0;
        for hull in projected {
            let polygon = &mut scratch.polygons[count];
            polygon.clear();
            polygon.extend_from_slice(hull);
            clip_to_rect(polygon, &mut scratch.spare, rect);
            if polygon.len() >= 3 {
                count += 1;
            }
        }
        scratch.union_share(count, rect)
    })
}

impl Scratch {
    /// Room for `count` polygons.
    fn reserve(&mut self, count: usize) {
        if self.polygons.len() < count {
            self.polygons.resize_with(count, Vec::new);
        }
        if self.levels.len() < count {
            self.levels.resize_with(count, Vec::new);
        }
    }

    /// The share of `rect` that the union of the first `count` polygons (already cut to it)
    /// covers, in [0, 1].
    fn union_share(&mut self, count: usize, rect: [DVec2; 2]) -> f64 {
        let area = (rect[1].x - rect[0].x) * (rect[1].y - rect[0].y);
        if area <= 0.0 {
            return 0.0;
        }
        let Self { polygons, levels, boxes, spare, .. } = self;
        let polygons = &polygons[..count];
        boxes.clear();
        boxes.extend(polygons.iter().map(|polygon| bounding_box(polygon)));
        // Inclusion–exclusion: the area of each non-empty subset's intersection, added for an
        // odd count and taken away for an even one.
        let mut covered = 0.0;
        for (first, polygon) in polygons.iter().enumerate() {
            covered += polygon_area(polygon);
            covered += intersections_from(polygons, boxes, first + 1, polygon, boxes[first], 2, levels, spare);
        }
        (covered / area).clamp(0.0, 1.0)
    }
}

/// The central projection of `triangle` from `origin` onto the light's plane, cut to the slab
/// as [`covered_share`] cuts it, into `out` (fewer than three corners when none of it is there).
pub(super) fn project_triangle(light: &RectLight, origin: Vec3, triangle: &[Vec3; 3], out: &mut Vec<DVec2>) {
    SCRATCH.with_borrow_mut(|scratch| project(light, origin, triangle, &mut scratch.slab, out));
}

/// The part of the rectangle `[min, max]` of the light (light coordinates) behind the plane
/// through `plane.0` with normal `plane.1` (where a sample's offset from the point has a
/// negative dot product with the normal: the side a solid's surface at the point hides).
pub(super) fn behind_line(rect: [DVec2; 2], light: &RectLight, (point, normal): (Vec3, Vec3)) -> Vec<DVec2> {
    let normal = normal.as_dvec3();
    let half = light.half_size.as_dvec2();
    // light.point(s, t) = centre + u_axis·half.x·s + v_axis·half.y·t: the offset's dot product
    // with the normal is affine in (s, t).
    let (a, b) = (half.x * normal.dot(light.u_axis.as_dvec3()), half.y * normal.dot(light.v_axis.as_dvec3()));
    let c = normal.dot(light.centre.as_dvec3() - point.as_dvec3());
    let [min, max] = rect;
    let corners = [min, DVec2::new(max.x, min.y), max, DVec2::new(min.x, max.y)];
    let mut out = Vec::with_capacity(5);
    clip_2d(&corners, |p| -(a * p.x + b * p.y + c), &mut out);
    out
}

/// Whether convex `polygon` (either winding) holds the whole rectangle `[min, max]`.
pub(super) fn holds_rectangle(polygon: &[DVec2], [min, max]: [DVec2; 2]) -> bool {
    let orientation = signed_area(polygon).signum();
    if polygon.len() < 3 || orientation == 0.0 {
        return false;
    }
    let corners = [min, DVec2::new(max.x, min.y), max, DVec2::new(min.x, max.y)];
    polygon.iter().enumerate().all(|(k, &a)| {
        let edge = polygon[(k + 1) % polygon.len()] - a;
        corners.iter().all(|c| orientation * edge.perp_dot(*c - a) >= 0.0)
    })
}

/// The convex hull of `points` (sorted in place), counter-clockwise, without collinear corners,
/// into `out` (Andrew's monotone chain); fewer than three corners when the points are collinear.
pub(super) fn convex_hull(points: &mut [DVec2], out: &mut Vec<DVec2>) {
    out.clear();
    points.sort_unstable_by(|a, b| a.x.total_cmp(&b.x).then(a.y.total_cmp(&b.y)));
    if points.len() < 3 {
        out.extend_from_slice(points);
        return;
    }
    let turns_left = |o: DVec2, a: DVec2, b: DVec2| (a - o).perp_dot(b - o) > 0.0;
    // The lower chain left to right, then the upper right to left, each popping corners that do
    // not turn left.
    for &p in points.iter() {
        while out.len() >= 2 && !turns_left(out[out.len() - 2], out[out.len() - 1], p) {
            out.pop();
        }
        out.push(p);
    }
    let lower = out.len() + 1;
    for &p in points.iter().rev().skip(1) {
        while out.len() >= lower && !turns_left(out[out.len() - 2], out[out.len() - 1], p) {
            out.pop();
        }
        out.push(p);
    }
    out.pop();
}

/// The signed sum, over the subsets made of `common`'s polygons (`size` − 1 of them) and one or
/// more of `polygons[start..]`, of their intersections' areas: + for an odd size, − for even.
#[allow(clippy::too_many_arguments)]
fn intersections_from(
    polygons: &[Vec<DVec2>],
    boxes: &[[DVec2; 2]],
    start: usize,
    common: &[DVec2],
    common_box: [DVec2; 2],
    size: u32,
    levels: &mut [Vec<DVec2>],
    spare: &mut Vec<DVec2>,
) -> f64 {
    let Some((level, deeper)) = levels.split_first_mut() else { return 0.0 };
    let sign = if size % 2 == 1 { 1.0 } else { -1.0 };
    let mut sum = 0.0;
    for next in start..polygons.len() {
        let other = boxes[next];
        if other[0].cmpgt(common_box[1]).any() || common_box[0].cmpgt(other[1]).any() {
            continue;
        }
        clip_convex(common, &polygons[next], level, spare);
        if level.len() < 3 {
            continue;
        }
        sum += sign * polygon_area(level);
        if next + 1 < polygons.len() {
            sum += intersections_from(polygons, boxes, next + 1, level, bounding_box(level), size + 1, deeper, spare);
        }
    }
    sum
}

/// The smallest axis-aligned box around `polygon`: [min, max].
pub(super) fn bounding_box(polygon: &[DVec2]) -> [DVec2; 2] {
    polygon.iter().fold([DVec2::splat(f64::INFINITY), DVec2::splat(f64::NEG_INFINITY)], |[min, max], p| [min.min(*p), max.max(*p)])
}

/// The least fraction of the way from a point to the light's plane kept of an occluder: a corner
/// at t → 0 projects to infinity, so t stays above a bound that leaves the projection in f64's
/// range and far outside any light (the rectangle clip removes it).
pub(super) const T_MIN: f64 = 1e-9;
/// The greatest: rays stop just short of the light (`segment_ray`: at 1 − 10⁻⁶ of the way), so
/// that geometry lying in the light's plane hides none of it; the projection stops there too.
pub(super) const T_MAX: f64 = 1.0 - 1e-6;

/// The central projection from a point onto the light's plane, in light coordinates (u / half
/// width, v / half height), and each point's fraction t of the way from the point's plane
/// (parallel to the light) to the light's.
pub(super) struct CentralProjection {
    origin: DVec3,
    centre: DVec3,
    normal: DVec3,
    /// The origin's distance from the light's plane (positive: in front of it).
    height: f64,
    axes: [DVec3; 2],
    half: DVec2,
}

impl CentralProjection {
    /// The projection from `origin`; `None` when it is not in front of the light.
    pub(super) fn new(light: &RectLight, origin: Vec3) -> Option<Self> {
        let (centre, normal, origin) = (light.centre.as_dvec3(), light.normal().as_dvec3(), origin.as_dvec3());
        let height = (origin - centre).dot(normal);
        (height > 0.0).then(|| Self {
            origin,
            centre,
            normal,
            height,
            axes: [light.u_axis.as_dvec3(), light.v_axis.as_dvec3()],
            half: light.half_size.as_dvec2().max(DVec2::splat(f64::MIN_POSITIVE)),
        })
    }

    /// The fraction t of the way from the origin's plane to the light's (0 at the origin's).
    pub(super) fn t_of(&self, p: DVec3) -> f64 {
        1.0 - (p - self.centre).dot(self.normal) / self.height
    }

    /// Where the ray from the origin through `p` (at fraction `t`) meets the light's plane.
    pub(super) fn onto_light(&self, p: DVec3, t: f64) -> DVec2 {
        let on_light = self.origin + (p - self.origin) / t;
        DVec2::new((on_light - self.centre).dot(self.axes[0]) / self.half.x, (on_light - self.centre).dot(self.axes[1]) / self.half.y)
    }
}

/// The central projection from `origin` onto the light's plane, in light coordinates, of the part
/// of `triangle` strictly between the plane through `origin` parallel to the light and the light's
/// own plane, into `out`; empty when none of it is.
fn project(light: &RectLight, origin: Vec3, triangle: &[Vec3; 3], [slab, cut]: &mut [Vec<SlabPoint>; 2], out: &mut Vec<DVec2>) {
    out.clear();
    let Some(projection) = CentralProjection::new(light, origin) else { return };
    slab.clear();
    slab.extend(triangle.iter().map(|p| (p.as_dvec3(), projection.t_of(p.as_dvec3()))));
    clip_by(slab, |(_, t)| t - T_MIN, cut);
    clip_by(cut, |(_, t)| T_MAX - t, slab);
    out.extend(slab.iter().map(|(p, t)| projection.onto_light(*p, *t)));
}

/// Sutherland–Hodgman against one half-space: the part of `polygon` where `inside` ≥ 0
/// (`inside` affine along edges) into `out`, interpolating position and t.
fn clip_by(polygon: &[SlabPoint], inside: impl Fn(&SlabPoint) -> f64, out: &mut Vec<SlabPoint>) {
    out.clear();
    for (k, current) in polygon.iter().enumerate() {
        let next = &polygon[(k + 1) % polygon.len()];
        let (a, b) = (inside(current), inside(next));
        if a >= 0.0 {
            out.push(*current);
        }
        if (a >= 0.0) != (b >= 0.0) {
            let s = a / (a - b);
            out.push((current.0 + (next.0 - current.0) * s, current.1 + (next.1 - current.1) * s));
        }
    }
}

/// `polygon` cut to the rectangle `[min, max]` in place (`spare`: a buffer).
fn clip_to_rect(polygon: &mut Vec<DVec2>, spare: &mut Vec<DVec2>, [min, max]: [DVec2; 2]) {
    for (axis, bound, keep_above) in [(0, min.x, true), (0, max.x, false), (1, min.y, true), (1, max.y, false)] {
        clip_2d(polygon, |p| if keep_above { p[axis] - bound } else { bound - p[axis] }, spare);
        std::mem::swap(polygon, spare);
    }
}

/// Sutherland–Hodgman in the plane: the part of `polygon` where `inside` ≥ 0, into `out`.
fn clip_2d(polygon: &[DVec2], inside: impl Fn(DVec2) -> f64, out: &mut Vec<DVec2>) {
    out.clear();
    for (k, &current) in polygon.iter().enumerate() {
        let next = polygon[(k + 1) % polygon.len()];
        let (a, b) = (inside(current), inside(next));
        if a >= 0.0 {
            out.push(current);
        }
        if (a >= 0.0) != (b >= 0.0) {
            out.push(current + (next - current) * (a / (a - b)));
        }
    }
}

/// The part of convex `subject` inside convex `clip` (either winding), into `out` (`spare`: a
/// buffer).
fn clip_convex(subject: &[DVec2], clip: &[DVec2], out: &mut Vec<DVec2>, spare: &mut Vec<DVec2>) {
    out.clear();
    if clip.len() < 3 || subject.len() < 3 {
        return;
    }
    let orientation = signed_area(clip).signum();
    if orientation == 0.0 {
        return;
    }
    out.extend_from_slice(subject);
    for (k, &a) in clip.iter().enumerate() {
        let b = clip[(k + 1) % clip.len()];
        let edge = b - a;
        clip_2d(out, |p| orientation * edge.perp_dot(p - a), spare);
        std::mem::swap(out, spare);
        if out.is_empty() {
            break;
        }
    }
}

/// Signed area (positive counter-clockwise).
fn signed_area(polygon: &[DVec2]) -> f64 {
    0.5 * polygon.iter().enumerate().map(|(k, p)| p.perp_dot(polygon[(k + 1) % polygon.len()])).sum::<f64>()
}

pub(super) fn polygon_area(polygon: &[DVec2]) -> f64 {
    if polygon.len() < 3 { 0.0 } else { signed_area(polygon).abs() }
}

#[cfg(test)]
pub(super) mod tests {
    use super::*;

    fn light() -> RectLight {
        RectLight::try_facing(Vec3::new(0.0, 4.0, 0.0), Vec3::NEG_Y, Vec3::X, Vec2::new(2.0, 1.0), 1.0).unwrap()
    }

    /// The share of `rect` hidden, by rays through a fine grid of the rectangle (the definition).
    pub(crate) fn counted(light: &RectLight, origin: Vec3, triangles: &[[Vec3; 3]], [min, max]: [Vec2; 2]) -> f64 {
        const N: usize = 400;
        let mut hidden = 0usize;
        for j in 0..N {
            for i in 0..N {
                let at = min + (max - min) * Vec2::new((i as f32 + 0.5) / N as f32, (j as f32 + 0.5) / N as f32);
                let target = light.point(at.x, at.y);
                let blocked = triangles.iter().any(|t| segment_crosses(origin, target, t));
                hidden += usize::from(blocked);
            }
        }
        hidden as f64 / (N * N) as f64
    }

    /// Möller–Trumbore on the open segment.
    fn segment_crosses(origin: Vec3, target: Vec3, [a, b, c]: &[Vec3; 3]) -> bool {
        let (origin, direction) = (origin.as_dvec3(), (target - origin).as_dvec3());
        let (e1, e2) = (b.as_dvec3() - a.as_dvec3(), c.as_dvec3() - a.as_dvec3());
        let p = direction.cross(e2);
        let det = e1.dot(p);
        if det.abs() < 1e-15 {
            return false;
        }
        let s = origin - a.as_dvec3();
        let u = s.dot(p) / det;
        let q = s.cross(e1);
        let v = direction.dot(q) / det;
        let t = e2.dot(q) / det;
        u >= 0.0 && v >= 0.0 && u + v <= 1.0 && t > 0.0 && t < 1.0
    }

    fn random(state: &mut u64) -> f32 {
        *state = state.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
        (*state >> 40) as f32 / (1u64 << 24) as f32
    }

    /// On random triangles (one to four, some crossing the light's plane or the point's), seen from
    /// random points through random parts of the light, the exact share matches the share of a
    /// 400² grid of rays within the grid's resolution.
    #[test]
    fn the_exact_share_is_what_rays_through_a_fine_grid_find() {
        let light = light();
        let mut state = 7u64;
        let mut nonzero = 0;
        for case in 0..300 {
            let point = |state: &mut u64| Vec3::new(random(state) * 4.0 - 2.0, random(state) * 5.0 - 0.5, random(state) * 4.0 - 2.0);
            let origin = Vec3::new(point(&mut state).x * 0.3, -1.0 + random(&mut state) * 0.5, point(&mut state).z * 0.3);
            let triangles: Vec<[Vec3; 3]> = (0..1 + case % 4).map(|_| [point(&mut state), point(&mut state), point(&mut state)]).collect();
            let corner = Vec2::new(random(&mut state), random(&mut state)) * 2.0 - Vec2::ONE;
            let size = 0.1 + random(&mut state);
            let rect = [corner, (corner + Vec2::splat(size)).min(Vec2::ONE)];
            let exact = covered_share(&light, origin, &triangles, rect);
            let rays = counted(&light, origin, &triangles, rect);
            nonzero += usize::from(exact > 0.01 && exact < 0.99);
            assert!(
                (exact - rays).abs() < 0.01,
                "case {case}: exact {exact}, rays {rays}, triangles {triangles:?}, origin {origin}, rect {rect:?}"
            );
        }
        assert!(nonzero > 50, "too few partly hidden cases ({nonzero}) to test anything");
    }

    #[test]
    fn a_triangle_covering_the_view_hides_everything_and_one_behind_the_light_nothing() {
        let light = light();
        let origin = Vec3::ZERO;
        let big = [Vec3::new(-50.0, 2.0, -50.0), Vec3::new(50.0, 2.0, -50.0), Vec3::new(0.0, 2.0, 80.0)];
        let rect = [Vec2::NEG_ONE, Vec2::ONE];
        assert!((covered_share(&light, origin, &[big], rect) - 1.0).abs() < 1e-12);
        let beyond = big.map(|p| p + Vec3::Y * 3.0);
        assert_eq!(covered_share(&light, origin, &[beyond], rect), 0.0);
        // Two copies of one triangle hide what one does.
        let half = [Vec3::new(0.0, 2.0, -5.0), Vec3::new(5.0, 2.0, -5.0), Vec3::new(0.0, 2.0, 5.0)];
        let one = covered_share(&light, origin, &[half], rect);
        assert!((covered_share(&light, origin, &[half, half], rect) - one).abs() < 1e-12 && one > 0.1);
    }
}
