//! Polygons to triangles, for the OBJ and PLY loaders.
//!
//! Convex polygons become fans from their first vertex (as every exporter
//! assumes). Concave ones, which Blender, SketchUp and 3ds Max write as
//! n-gons (an L-shaped floor), are ear-clipped in their own plane, so that no
//! triangle covers what the polygon does not.

use glam::{Vec2, Vec3};

use crate::mesh::fan_to_list;

/// Above this many corners a concave polygon is fanned: ear clipping is
/// quadratic to cubic in the corner count, and no exporter writes such polygons
/// with concavities that matter.
const MAX_EAR_CLIPPED: usize = 256;

/// Appends the triangles of `polygon` (indices into `positions`, all in range)
/// to `out`, keeping its winding.
pub(crate) fn triangulate(positions: &[Vec3], polygon: &[u32], out: &mut Vec<u32>) {
    match polygon.len() {
        0..=2 => {}
        3 => out.extend_from_slice(polygon),
        n => {
            let points: Vec<Vec3> = polygon.iter().map(|&i| positions[i as usize]).collect();
            if n > MAX_EAR_CLIPPED || is_convex(&points) {
                out.extend(fan_to_list(polygon));
            } else {
                ear_clip(&points, polygon, out);
            }
        }
    }
}

/// The polygon's normal by Newell's method (robust for non-planar and concave polygons).
fn newell_normal(points: &[Vec3]) -> Vec3 {
    let mut normal = Vec3::ZERO;
    for (k, a) in points.iter().enumerate() {
        let b = points[(k + 1) % points.len()];
        normal += Vec3::new((a.y - b.y) * (a.z + b.z), (a.z - b.z) * (a.x + b.x), (a.x - b.x) * (a.y + b.y));
    }
    normal
}

/// True when no corner turns against the polygon's normal (degenerate polygons count as convex: they are fanned).
fn is_convex(points: &[Vec3]) -> bool {
    let Some(normal) = newell_normal(points).try_normalize() else {
        return true;
    };
    let n = points.len();
    (0..n).all(|k| {
        let previous = points[(k + n - 1) % n];
        let here = points[k];
        let next = points[(k + 1) % n];
        let turn = (here - previous).cross(next - here);
        // A tolerance relative to the edge lengths keeps nearly straight corners convex.
        turn.dot(normal) >= -1e-6 * (here - previous).length() * (next - here).length()
    })
}

/// Ear clipping in the plane that the normal's dominant axis projects onto.
fn ear_clip(points: &[Vec3], polygon: &[u32], out: &mut Vec<u32>) {
    let Some(normal) = newell_normal(points).try_normalize() else {
        out.extend(fan_to_list(polygon));
        return;
    };
    // Drop the dominant axis, and order the remaining two so that the polygon is counter-clockwise.
    let axis = normal.abs().max_position();
    let flat: Vec<Vec2> = points
        .iter()
        .map(|p| {
            let q = match axis {
                0 => Vec2::new(p.y, p.z),
                1 => Vec2::new(p.z, p.x),
                _ => Vec2::new(p.x, p.y),
            };
            if normal[axis] < 0.0 { Vec2::new(q.y, q.x) } else { q }
        })
        .collect();
    let mut remaining: Vec<usize> = (0..points.len()).collect();
    let cross = |a: Vec2, b: Vec2, c: Vec2| (b - a).perp_dot(c - a);
    // Each search starts where the last ear was cut: the next ear is usually right there.
    let mut from = 0;
    while remaining.len() > 3 {
        let m = remaining.len();
        let ear = (0..m).map(|step| (from + step) % m).find(|&k| {
            let (a, b, c) = (remaining[(k + m - 1) % m], remaining[k], remaining[(k + 1) % m]);
            let (pa, pb, pc) = (flat[a], flat[b], flat[c]);
            if cross(pa, pb, pc) <= 0.0 {
                return false;
            }
            // No other corner may lie inside the candidate triangle or on its edges.
            remaining.iter().all(|&o| {
                let po = flat[o];
                o == a
                    || o == b
                    || o == c
                    || po == pa
                    || po == pb
                    || po == pc
                    || cross(pa, pb, po) < 0.0
                    || cross(pb, pc, po) < 0.0
                    || cross(pc, pa, po) < 0.0
            })
        });
        let Some(k) = ear else {
            // Self-intersecting or degenerate: fan what is left rather than fail.
            let rest: Vec<u32> = remaining.iter().map(|&r| polygon[r]).collect();
            out.extend(fan_to_list(&rest));
            return;
        };
        let (a, b, c) = (remaining[(k + m - 1) % m], remaining[k], remaining[(k + 1) % m]);
        out.extend_from_slice(&[polygon[a], polygon[b], polygon[c]]);
        remaining.remove(k);
        from = k.saturating_sub(1);
    }
    out.extend(remaining.iter().map(|&r| polygon[r]));
}

#[cfg(test)]
mod tests {
    use super::*;

    fn area_normal(positions: &[Vec3], triangles: &[u32]) -> (f32, Vec3) {
        let mut total = Vec3::ZERO;
        let mut area = 0.0;
        for t in triangles.chunks_exact(3) {
            let [a, b, c] = [t[0], t[1], t[2]].map(|i| positions[i as usize]);
            let n = (b - a).cross(c - a);
            total += n;
            area += n.length() * 0.5;
        }
        (area, total)
    }

    #[test]
    fn convex_polygons_are_fanned() {
        let square = [Vec3::ZERO, Vec3::X, Vec3::new(1.0, 0.0, 1.0), Vec3::Z];
        let mut out = Vec::new();
        triangulate(&square, &[0, 1, 2, 3], &mut out);
        assert_eq!(out, vec![0, 1, 2, 0, 2, 3]);
    }

    #[test]
    fn a_concave_l_is_covered_exactly_once_with_its_winding() {
        // An L of area 3 in the XY plane, counter-clockwise seen from +Z, whose reflex corner is vertex 4:
        // a fan from vertex 0 would cover the missing square (area 4) and overlap.
        let l = [
            Vec3::new(0.0, 0.0, 0.0),
            Vec3::new(2.0, 0.0, 0.0),
            Vec3::new(2.0, 1.0, 0.0),
            Vec3::new(1.0, 1.0, 0.0),
            Vec3::new(1.0, 2.0, 0.0),
            Vec3::new(0.0, 2.0, 0.0),
        ];
        let polygon: Vec<u32> = vec![2, 3, 4, 5, 0, 1];
        let mut out = Vec::new();
        triangulate(&l, &polygon, &mut out);
        assert_eq!(out.len(), 12);
        let (area, normal) = area_normal(&l, &out);
        assert!((area - 3.0).abs() < 1e-5, "area {area}");
        assert!(normal.z > 0.0 && normal.x.abs() < 1e-5 && normal.y.abs() < 1e-5, "{normal}");
        // Reversed, it is clockwise: the triangles keep that winding too.
        let reversed: Vec<u32> = polygon.iter().rev().copied().collect();
        let mut out = Vec::new();
        triangulate(&l, &reversed, &mut out);
        let (area, normal) = area_normal(&l, &out);
        assert!((area - 3.0).abs() < 1e-5 && normal.z < 0.0, "area {area}, {normal}");
    }
}
