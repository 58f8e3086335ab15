//! Convex pieces: placed meshes whose triangles together are a convex set (a closed convex solid,
//! such as a box or a tessellated sphere, or a flat convex polygon, such as a quad), so that what
//! they hide of the light from a point is one convex polygon: the convex hull of their corners'
//! central projections onto the light's plane (the piece first cut to the slab between the
//! point's plane and the light's, as `coverage` cuts a triangle). A sphere of hundreds of
//! triangles then counts as one polygon when the ground truth computes the share of a part of the
//! light that a few occluders hide exactly, instead of hundreds of triangles its rays must test.
//!
//! Exact, not an approximation: a segment from the point to the light crosses one of the
//! piece's triangles exactly when it passes through the piece (its solid or its polygon), save
//! for segments that only graze it, a set of no area on the light. Which meshes qualify is
//! decided once per mesh, by tests that prove it (`convex_shape`).

use std::collections::HashSet;

use glam::{DVec2, DVec3, Mat4, Vec3};
use ssm_scene::{Adjacency, Mesh, RectLight, normal_matrix};

use super::coverage;

/// Meshes with more corners than this are not tested (the proof costs corners × faces, and the
/// projection corners per pixel): their triangles stay triangles.
const MOST_CORNERS: usize = 4096;

/// What a mesh's triangles are together, when they are a convex set.
#[derive(Clone, Debug, PartialEq)]
pub(super) struct ConvexShape {
    /// Its corners (welded), the hull's and possibly some inside it.
    pub corners: Vec<Vec3>,
    /// Its edges, as pairs of `corners`: the slab's planes cut the solid's hull along them.
    pub edges: Vec<[u32; 2]>,
    /// Each edge's two faces (indices into `faces`), for a solid: where one faces a point and
    /// the other does not, the edge is on the solid's silhouette from it.
    pub edge_faces: Vec<[u32; 2]>,
    /// A solid's faces, as corner triples; empty when flat.
    pub faces: Vec<[u32; 3]>,
    /// Flat: the plane's unit normal; `None` for a solid.
    pub flat_normal: Option<Vec3>,
}

/// `mesh`'s triangles as one convex set, when they are: a closed two-manifold all of whose corners
/// lie on or behind every face's plane (a convex solid's boundary), or a flat mesh whose
/// triangles on one side cover the convex hull of its corners exactly once (a winding argument:
/// consistently turned triangles whose open edges all lie on the hull's boundary, turning around
/// it, and whose areas add up to the hull's). Tolerances are a hundred-thousandth of the mesh's
/// size.
pub(super) fn convex_shape(mesh: &Mesh) -> Option<ConvexShape> {
    if mesh.positions.is_empty() || mesh.indices.len() < 3 {
        return None;
    }
    let adjacency = Adjacency::of(mesh);
    let corners = &adjacency.welded_positions;
    if corners.len() > MOST_CORNERS || !corners.iter().all(|c| c.is_finite()) {
        return None;
    }
    let (min, max) = corners.iter().fold((Vec3::INFINITY, Vec3::NEG_INFINITY), |(lo, hi), c| (lo.min(*c), hi.max(*c)));
    let size = f64::from((max - min).length());
    if size <= 0.0 {
        return None;
    }
    let tolerance = size * 1e-5;
    let points: Vec<DVec3> = corners.iter().map(|c| c.as_dvec3()).collect();
    let face_normal = |[a, b, c]: [u32; 3]| {
        let (a, b, c) = (points[a as usize], points[b as usize], points[c as usize]);
        (b - a).cross(c - a)
    };
    let edges: Vec<[u32; 2]> = adjacency.edges.iter().map(|e| e.vertices).collect();
    // The largest face's plane: flat when every corner lies on it.
    let largest =
        adjacency.triangles.iter().copied().max_by(|a, b| face_normal(*a).length_squared().total_cmp(&face_normal(*b).length_squared()))?;
    let normal = face_normal(largest).try_normalize()?;
    let anchor = points[largest[0] as usize];
    if points.iter().all(|p| (p - anchor).dot(normal).abs() <= tolerance) {
        return flat_covers_hull(&points, &adjacency.triangles, normal, tolerance).then(|| ConvexShape {
            corners: corners.clone(),
            edges,
            edge_faces: Vec::new(),
            faces: Vec::new(),
            flat_normal: Some(normal.as_vec3()),
        });
    }
    if !adjacency.is_closed_manifold() {
        return None;
    }
    // Every corner on or behind every face's plane, the faces all turned out (or all in).
    for sign in [1.0, -1.0] {
        let convex = adjacency.triangles.iter().all(|t| {
            let Some(normal) = face_normal(*t).try_normalize() else { return true };
            let anchor = points[t[0] as usize];
            points.iter().all(|p| sign * (p - anchor).dot(normal) <= tolerance)
        });
        if convex {
            let edge_faces = adjacency.edges.iter().map(|e| e.faces).collect();
            return Some(ConvexShape {
                corners: corners.clone(),
                edges,
                edge_faces,
                faces: adjacency.triangles.clone(),
                flat_normal: None,
            });
        }
    }
    None
}

/// Whether the flat mesh's triangles on one of its sides cover the convex hull of its corners
/// exactly once (see [`convex_shape`]).
fn flat_covers_hull(points: &[DVec3], triangles: &[[u32; 3]], normal: DVec3, tolerance: f64) -> bool {
    let u = normal.any_orthonormal_vector();
    let v = normal.cross(u);
    let flat: Vec<DVec2> = points.iter().map(|p| DVec2::new(p.dot(u), p.dot(v))).collect();
    let mut hull = Vec::new();
    coverage::convex_hull(&mut flat.clone(), &mut hull);
    let hull_area = coverage::polygon_area(&hull);
    if hull_area <= 0.0 {
        return false;
    }
    let signed = |[a, b, c]: [u32; 3]| 0.5 * (flat[b as usize] - flat[a as usize]).perp_dot(flat[c as usize] - flat[a as usize]);
    for sign in [1.0, -1.0] {
        let side: Vec<[u32; 3]> = triangles.iter().copied().filter(|t| sign * signed(*t) > 0.0).collect();
        let area: f64 = side.iter().map(|t| sign * signed(*t)).sum();
        if (area - hull_area).abs() > 1e-4 * hull_area {
            continue;
        }
        let mut directed = HashSet::new();
        let mut repeated = false;
        for t in &side {
            for k in 0..3 {
                repeated |= !directed.insert((t[k], t[(k + 1) % 3]));
            }
        }
        if repeated {
            continue;
        }
        // Every open edge has all corners on its inner side (sign: the side's turn): it runs along
        // the hull's boundary, turning around it as the triangles do.
        let on_hull = directed.iter().filter(|(a, b)| !directed.contains(&(*b, *a))).all(|&(a, b)| {
            let (a, b) = (flat[a as usize], flat[b as usize]);
            let length = (b - a).length();
            flat.iter().all(|p| sign * (b - a).perp_dot(*p - a) >= -tolerance * length)
        });
        if on_hull {
            return true;
        }
    }
    false
}

/// A mesh's connected parts (triangles sharing a corner, on welded positions: a tree's trunk and
/// each of its leaf cards), each with its convex shape where it has one.
pub(super) struct MeshParts {
    /// Each triangle's part.
    pub part_of_triangle: Vec<u32>,
    /// Each part's shape, `None` where it is not convex.
    pub shapes: Vec<Option<ConvexShape>>,
}

impl MeshParts {
    /// The parts of `mesh` (its indices valid).
    pub fn of(mesh: &Mesh) -> Self {
        let adjacency = Adjacency::of(mesh);
        // Union–find over welded corners: a triangle joins its three corners.
        let mut parent: Vec<u32> = (0..adjacency.welded_positions.len() as u32).collect();
        fn root(parent: &mut [u32], mut corner: u32) -> u32 {
            while parent[corner as usize] != corner {
                parent[corner as usize] = parent[parent[corner as usize] as usize];
                corner = parent[corner as usize];
            }
            corner
        }
        for [a, b, c] in &adjacency.triangles {
            for other in [*b, *c] {
                let (x, y) = (root(&mut parent, *a), root(&mut parent, other));
                if x != y {
                    parent[x.max(y) as usize] = x.min(y);
                }
            }
        }
        let mut part_of_root = std::collections::HashMap::new();
        let mut part_triangles: Vec<Vec<[u32; 3]>> = Vec::new();
        let part_of_triangle = adjacency
            .triangles
            .iter()
            .map(|triangle| {
                let part = *part_of_root.entry(root(&mut parent, triangle[0])).or_insert_with(|| {
                    part_triangles.push(Vec::new());
                    part_triangles.len() as u32 - 1
                });
                part_triangles[part as usize].push(*triangle);
                part
            })
            .collect();
        let shapes = if part_triangles.len() == 1 {
            vec![convex_shape(mesh)]
        } else {
            part_triangles
                .iter()
                .map(|triangles| {
                    // The part as a mesh of its own: its corners, renumbered.
                    let mut corner_of = std::collections::HashMap::new();
                    let mut positions = Vec::new();
                    let indices = triangles
                        .iter()
                        .flatten()
                        .map(|corner| {
                            *corner_of.entry(*corner).or_insert_with(|| {
                                positions.push(adjacency.welded_positions[*corner as usize]);
                                positions.len() as u32 - 1
                            })
                        })
                        .collect();
                    let normals = vec![Vec3::Y; positions.len()];
                    convex_shape(&Mesh { name: mesh.name.clone(), positions, normals, indices })
                })
                .collect()
        };
        Self { part_of_triangle, shapes }
    }
}

/// A convex piece placed in the world.
pub(super) struct ConvexPiece {
    /// Its corners, world space.
    pub corners: Vec<Vec3>,
    /// Its edges, as pairs of `corners`.
    pub edges: Vec<[u32; 2]>,
    /// Its bounds: [min, max].
    pub bounds: [Vec3; 2],
    /// Flat: its plane (unit normal, offset: normal · p for p on it); `None` for a solid.
    pub plane: Option<(Vec3, f32)>,
    /// A solid's faces' planes (unit normal, zero for a face of no area; offset), world space;
    /// empty when flat.
    face_planes: Vec<(DVec3, f64)>,
    /// The same planes as four f32 arrays (normal x, y, z, offset), for the test of which faces a
    /// point sees, a face to a lane.
    face_lanes: [Vec<f32>; 4],
    /// How far from a face's plane, in f32, a point may be called on it (so seeing it edge-on).
    facing_tolerance: f32,
    /// Each edge's two faces (`ConvexShape::edge_faces`); empty when flat.
    edge_faces: Vec<[u32; 2]>,
}

impl ConvexPiece {
    /// `shape` placed by `transform` (any affine transform keeps a convex set convex and a flat
    /// one flat).
    pub fn placed(shape: &ConvexShape, transform: Mat4) -> Self {
        let corners: Vec<Vec3> = shape.corners.iter().map(|c| transform.transform_point3(*c)).collect();
        let bounds = corners.iter().fold([Vec3::INFINITY, Vec3::NEG_INFINITY], |[lo, hi], c| [lo.min(*c), hi.max(*c)]);
        // Normals go through the inverse transpose (a transform may shear them).
        let plane = shape.flat_normal.and_then(|normal| {
            let normal = (normal_matrix(transform) * normal).try_normalize()?;
            Some((normal, normal.dot(*corners.first()?)))
        });
        // Each face's normal turned away from the corners' centroid, which is inside the solid:
        // outwards whichever way the mesh winds and whether the transform mirrors it.
        let centroid = corners.iter().map(|c| c.as_dvec3()).sum::<DVec3>() / corners.len().max(1) as f64;
        let face_planes: Vec<(DVec3, f64)> = shape
            .faces
            .iter()
            .map(|[a, b, c]| {
                let [a, b, c] = [a, b, c].map(|k| corners[*k as usize].as_dvec3());
                let normal = (b - a).cross(c - a).normalize_or_zero();
                let normal = if normal.dot(centroid - a) > 0.0 { -normal } else { normal };
                (normal, normal.dot(a))
            })
            .collect();
        let face_lanes = [0, 1, 2, 3].map(|k| {
            face_planes.iter().map(|(normal, offset): &(DVec3, f64)| if k < 3 { normal[k] as f32 } else { *offset as f32 }).collect()
        });
        // f32 rounding of the plane and the point, relative to the piece's distance from the
        // world's origin and its size, with room to spare.
        let reach = bounds[0].abs().max(bounds[1].abs()).max_element() + (bounds[1] - bounds[0]).max_element();
        let facing_tolerance = reach * 1e-5;
        Self {
            corners,
            edges: shape.edges.clone(),
            bounds,
            plane,
            face_planes,
            face_lanes,
            facing_tolerance,
            edge_faces: shape.edge_faces.clone(),
        }
    }

    /// Whether `point` may lie inside the solid: in its bounds grown by `margin`, and behind or
    /// within `margin` of every face's plane. Its projection from there is not used (every ray
    /// from inside crosses the surface; the projection has no bound). A flat piece holds nothing.
    pub fn may_hold(&self, point: Vec3, margin: f32) -> bool {
        let in_bounds = point.cmpge(self.bounds[0] - Vec3::splat(margin)).all() && point.cmple(self.bounds[1] + Vec3::splat(margin)).all();
        let point = point.as_dvec3();
        in_bounds
            && !self.face_planes.is_empty()
            && self.face_planes.iter().all(|(normal, offset)| normal.dot(point) - offset <= f64::from(margin))
    }

    /// Whether every one of `points` lies inside the solid, deeper than `margin` behind every
    /// face's plane. A segment between two points inside a convex solid stays inside: its
    /// surface hides nothing from a point inside it of a light inside it (a room lit from
    /// within). A flat piece holds nothing.
    pub fn holds_inside(&self, points: &[Vec3], margin: f32) -> bool {
        !self.face_planes.is_empty()
            && points.iter().all(|point| {
                let point = point.as_dvec3();
                self.face_planes.iter().all(|(normal, offset)| normal.dot(point) - offset < -f64::from(margin))
            })
    }

    /// The central projection from `origin` onto the light's plane, in light coordinates, of the
    /// part of the piece strictly between the plane through `origin` parallel to the light and
    /// the light's own plane (as `coverage` projects a triangle): the convex hull of its corners
    /// in that slab and of its edges' crossings of the slab's two planes, into `out` (empty when
    /// none of it is in the slab).
    pub fn project(&self, light: &RectLight, origin: Vec3, scratch: &mut ProjectScratch, out: &mut Vec<DVec2>) {
        out.clear();
        let ProjectScratch { points, facing, ts, marked } = scratch;
        points.clear();
        let Some(projection) = coverage::CentralProjection::new(light, origin) else { return };
        let normal = light.normal().as_dvec3();
        let origin = origin.as_dvec3();
        let t_of = |p: DVec3| projection.t_of(p);
        let onto_light = |p: DVec3, t: f64| projection.onto_light(p, t);
        // The range of t over the piece's bounds: t is affine, so its extremes are at corners of
        // the box.
        let [min, max] = self.bounds.map(Vec3::as_dvec3);
        let box_t = |pick: [bool; 3]| {
            t_of(DVec3::new(if pick[0] { max.x } else { min.x }, if pick[1] { max.y } else { min.y }, if pick[2] { max.z } else { min.z }))
        };
        let towards = normal.to_array().map(|n| n < 0.0);
        let (box_low, box_high) = (box_t(towards.map(|b| !b)), box_t(towards));
        if box_high <= coverage::T_MIN || box_low >= coverage::T_MAX {
            return;
        }
        if box_low > coverage::T_MIN && box_high < coverage::T_MAX && !self.face_planes.is_empty() {
            // A solid wholly in the slab: its outline is the projection of its silhouette, the
            // edges between a face turned to the origin and one turned away (a face seen edge-on
            // counts as both, so that rounding drops no corner of the outline).
            // In f32, a face to a lane; a face within rounding of edge-on counts as both sides
            // (its corners then join the outline's candidates, which only adds points inside it).
            let [xs, ys, zs, offsets] = &self.face_lanes;
            let point = origin.as_vec3();
            let tolerance = self.facing_tolerance;
            facing.clear();
            facing.extend(xs.iter().zip(ys).zip(zs).zip(offsets).map(|(((x, y), z), offset)| {
                let height = x * point.x + y * point.y + z * point.z - offset;
                i8::from(height > tolerance) - i8::from(height < -tolerance)
            }));
            // Each corner of the silhouette once (it ends two of its edges).
            marked.clear();
            marked.resize(self.corners.len(), false);
            for ([a, b], [f, g]) in self.edges.iter().zip(&self.edge_faces) {
                let (f, g) = (facing[*f as usize], facing.get(*g as usize).copied().unwrap_or(0));
                if f != g || f == 0 {
                    for corner in [*a as usize, *b as usize] {
                        if !marked[corner] {
                            marked[corner] = true;
                            let corner = self.corners[corner].as_dvec3();
                            points.push(onto_light(corner, t_of(corner)));
                        }
                    }
                }
            }
            coverage::convex_hull(points, out);
            return;
        }
        ts.clear();
        ts.extend(self.corners.iter().map(|c| t_of(c.as_dvec3())));
        for (corner, t) in self.corners.iter().zip(ts.iter()) {
            if *t > coverage::T_MIN && *t < coverage::T_MAX {
                points.push(onto_light(corner.as_dvec3(), *t));
            }
        }
        for [a, b] in &self.edges {
            let (ta, tb) = (ts[*a as usize], ts[*b as usize]);
            let (pa, pb) = (self.corners[*a as usize].as_dvec3(), self.corners[*b as usize].as_dvec3());
            for bound in [coverage::T_MIN, coverage::T_MAX] {
                if (ta - bound) * (tb - bound) < 0.0 {
                    let s = (bound - ta) / (tb - ta);
                    points.push(onto_light(pa + (pb - pa) * s, bound));
                }
            }
        }
        coverage::convex_hull(points, out);
    }
}

/// Buffers [`ConvexPiece::project`] reuses.
#[derive(Default)]
pub(super) struct ProjectScratch {
    points: Vec<DVec2>,
    facing: Vec<i8>,
    ts: Vec<f64>,
    marked: Vec<bool>,
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::{Quat, Vec2};
    use ssm_scene::{Mesh, primitives};

    #[test]
    fn boxes_spheres_and_quads_are_convex_and_the_rest_is_not() {
        let boxed = convex_shape(&primitives::cuboid("box", Vec3::new(1.0, 2.0, 0.5))).expect("a box is convex");
        assert_eq!((boxed.corners.len(), boxed.flat_normal), (8, None));
        let ball = convex_shape(&primitives::sphere("ball", 0.5, 16, 8)).expect("a sphere is convex");
        assert_eq!(ball.corners.len(), 16 * 7 + 2);
        let quad = convex_shape(&primitives::plane("quad", Vec2::new(2.0, 1.0))).expect("a quad is convex");
        assert!(quad.flat_normal.is_some_and(|n| n.y.abs() > 0.999));
        // Both sides of a quad: either side covers it.
        let mut two_sided = primitives::plane("two-sided", Vec2::ONE);
        two_sided.indices.extend_from_slice(&[0, 1, 2, 0, 2, 3]);
        assert!(convex_shape(&two_sided).is_some());

        // An L of three squares: flat, its open edges not all on its hull.
        let positions = vec![
            Vec3::new(0.0, 0.0, 0.0),
            Vec3::new(1.0, 0.0, 0.0),
            Vec3::new(2.0, 0.0, 0.0),
            Vec3::new(0.0, 0.0, 1.0),
            Vec3::new(1.0, 0.0, 1.0),
            Vec3::new(2.0, 0.0, 1.0),
            Vec3::new(0.0, 0.0, 2.0),
            Vec3::new(1.0, 0.0, 2.0),
        ];
        let indices = vec![0, 3, 4, 0, 4, 1, 1, 4, 5, 1, 5, 2, 3, 6, 7, 3, 7, 4];
        assert!(convex_shape(&Mesh::with_generated_normals("L", positions, indices)).is_none());
        // A quad whose two triangles overlap and leave a gap: the areas add up, the cover does not.
        let positions = vec![Vec3::ZERO, Vec3::X, Vec3::new(1.0, 0.0, 1.0), Vec3::Z];
        let folded = Mesh::with_generated_normals("folded", positions.clone(), vec![0, 2, 1, 0, 2, 1]);
        assert!(convex_shape(&folded).is_none());
        // A box with one face missing is not closed; two boxes apart are not convex.
        let mut open = primitives::cuboid("open", Vec3::ONE);
        open.indices.truncate(30);
        assert!(convex_shape(&open).is_none());
        let mut pair = primitives::cuboid("pair", Vec3::ONE);
        let offset = pair.positions.len() as u32;
        pair.positions.extend(primitives::cuboid("second", Vec3::ONE).positions.iter().map(|p| *p + Vec3::X * 3.0));
        pair.normals.extend_from_within(..);
        pair.indices.extend(primitives::cuboid("second", Vec3::ONE).indices.iter().map(|i| i + offset));
        assert!(convex_shape(&pair).is_none());
        // A dented sphere is closed but not convex.
        let mut dented = primitives::sphere("dented", 1.0, 12, 6);
        dented.positions[20] *= 0.6;
        assert!(convex_shape(&dented).is_none());
    }

    /// A mesh of several parts splits into them: two boxes apart are two convex parts; a box with
    /// a quad beside it (a trunk and a leaf card) two; a dented sphere beside a box one that is
    /// not and one that is; each triangle names its own part.
    #[test]
    fn a_mesh_splits_into_its_connected_parts_each_convex_or_not() {
        let join = |parts: &[Mesh]| {
            let mut joined = Mesh { name: "joined".into(), positions: Vec::new(), normals: Vec::new(), indices: Vec::new() };
            for part in parts {
                let base = joined.positions.len() as u32;
                joined.positions.extend_from_slice(&part.positions);
                joined.normals.extend_from_slice(&part.normals);
                joined.indices.extend(part.indices.iter().map(|i| i + base));
            }
            joined
        };
        let moved = |mut mesh: Mesh, by: Vec3| {
            mesh.positions.iter_mut().for_each(|p| *p += by);
            mesh
        };
        let boxed = primitives::cuboid("box", Vec3::ONE);
        let pair = MeshParts::of(&join(&[boxed.clone(), moved(boxed.clone(), Vec3::X * 3.0)]));
        assert_eq!(pair.shapes.len(), 2);
        assert!(pair.shapes.iter().all(|s| s.as_ref().is_some_and(|s| s.corners.len() == 8 && s.flat_normal.is_none())));
        assert_eq!(pair.part_of_triangle, [vec![0; 12], vec![1; 12]].concat());
        let tree = MeshParts::of(&join(&[boxed.clone(), moved(primitives::plane("card", Vec2::ONE), Vec3::new(0.0, 2.0, 0.0))]));
        assert_eq!(tree.shapes.iter().map(|s| s.as_ref().map(|s| s.flat_normal.is_some())).collect::<Vec<_>>(), [Some(false), Some(true)]);
        let mut dented = primitives::sphere("dented", 1.0, 12, 6);
        dented.positions[20] *= 0.6;
        let mixed = MeshParts::of(&join(&[dented, moved(boxed, Vec3::X * 4.0)]));
        assert_eq!(mixed.shapes.iter().map(Option::is_some).collect::<Vec<_>>(), [false, true]);
    }

    /// A placed sphere's projection from points around it is the hull of what its triangles
    /// project to, cut to the slab the same way: checked by rays through a grid of the light.
    #[test]
    fn a_placed_piece_projects_to_what_its_triangles_hide() {
        let light = RectLight::try_facing(Vec3::new(0.0, 4.0, 0.0), Vec3::NEG_Y, Vec3::X, Vec2::new(2.0, 1.0), 1.0).unwrap();
        let mesh = primitives::sphere("ball", 0.5, 10, 6);
        let shape = convex_shape(&mesh).unwrap();
        // Some placements cross the light's plane or the point's: the slab cuts them.
        for (k, centre) in [Vec3::new(0.1, 2.0, 0.0), Vec3::new(0.6, 3.8, 0.2), Vec3::new(-0.3, 0.3, 0.1), Vec3::new(0.0, 1.0, 0.9)]
            .into_iter()
            .enumerate()
        {
            let transform = Mat4::from_scale_rotation_translation(Vec3::new(1.0, 0.7, 1.3), Quat::from_rotation_z(0.4), centre);
            let piece = ConvexPiece::placed(&shape, transform);
            let triangles: Vec<[Vec3; 3]> =
                mesh.triangles().map(|t| t.map(|i| transform.transform_point3(mesh.positions[i as usize]))).collect();
            let origin = Vec3::new(0.05, 0.2, -0.05);
            let (mut scratch, mut hull) = (ProjectScratch::default(), Vec::new());
            piece.project(&light, origin, &mut scratch, &mut hull);
            let rect = [Vec2::new(-1.0, -0.8), Vec2::new(0.7, 1.0)];
            let exact = coverage::covered_share_of_projected(&[hull.as_slice()], [rect[0].as_dvec2(), rect[1].as_dvec2()]);
            let counted = coverage::tests::counted(&light, origin, &triangles, rect);
            assert!((exact - counted).abs() < 0.01, "placement {k}: hull {exact}, rays {counted}");
            assert!(k == 3 || exact > 0.01, "placement {k} hides nothing: the test tests nothing");
        }
    }
}
