//! Scenes: meshes placed by instances with roles, lit by rectangular lights.

use std::path::{Path, PathBuf};

use glam::{Mat3, Mat4, Vec3};
use serde::{Deserialize, Serialize};

use crate::adjacency::Adjacency;
use crate::camera::Camera;
use crate::error::{Result, SceneError};
use crate::light::RectLight;
use crate::mesh::Mesh;

/// What an instance does for shadows.
///
/// Techniques that split the scene (Atty et al. render separate occluder and
/// receiver maps) read this; the others and the ground truth treat every
/// triangle as both.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Role {
    /// Casts shadows but is not shaded by techniques that split roles.
    Occluder,
    /// Receives shadows but casts none in techniques that split roles.
    Receiver,
    /// Casts and receives.
    #[default]
    Both,
}

impl Role {
    /// True for `Occluder` and `Both`.
    #[must_use]
    pub fn casts(self) -> bool {
        matches!(self, Self::Occluder | Self::Both)
    }

    /// True for `Receiver` and `Both`.
    #[must_use]
    pub fn receives(self) -> bool {
        matches!(self, Self::Receiver | Self::Both)
    }
}

/// One placement of a mesh.
#[derive(Clone, Debug, PartialEq)]
pub struct Instance {
    /// A name for messages and role overrides (the glTF node name, or the mesh name).
    pub name: String,
    /// Index into [`Scene::meshes`].
    pub mesh: usize,
    /// Object-to-world transform; finite and invertible.
    pub transform: Mat4,
    /// Shadow role.
    pub role: Role,
}

/// An axis-aligned bounding box.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Aabb {
    /// Smallest corner.
    pub min: Vec3,
    /// Largest corner.
    pub max: Vec3,
}

impl Aabb {
    /// The empty box: extending it by a point gives that point.
    pub const EMPTY: Self = Self { min: Vec3::splat(f32::INFINITY), max: Vec3::splat(f32::NEG_INFINITY) };

    /// Grows the box to contain `p`.
    pub fn extend(&mut self, p: Vec3) {
        self.min = self.min.min(p);
        self.max = self.max.max(p);
    }

    /// True when no point was ever added.
    #[must_use]
    pub fn is_empty(&self) -> bool {
        self.min.x > self.max.x
    }

    /// Centre of the box.
    #[must_use]
    pub fn centre(&self) -> Vec3 {
        (self.min + self.max) * 0.5
    }

    /// Edge lengths.
    #[must_use]
    pub fn size(&self) -> Vec3 {
        self.max - self.min
    }

    /// The eight corners.
    #[must_use]
    pub fn corners(&self) -> [Vec3; 8] {
        std::array::from_fn(|i| {
            Vec3::new(
                if i & 1 == 0 { self.min.x } else { self.max.x },
                if i & 2 == 0 { self.min.y } else { self.max.y },
                if i & 4 == 0 { self.min.z } else { self.max.z },
            )
        })
    }
}

/// A complete, validated scene.
///
/// Build one with [`builtin`](crate::builtin), [`Scene::load`] or by hand followed by
/// [`Scene::validate`]; the GPU side assumes the invariants `validate` checks.
#[derive(Clone, Debug, PartialEq)]
pub struct Scene {
    /// Where the scene came from, for messages: a file, or `builtin:<name>`.
    pub origin: PathBuf,
    /// Meshes in object space.
    pub meshes: Vec<Mesh>,
    /// Placements of the meshes.
    pub instances: Vec<Instance>,
    /// Area lights; at least one.
    pub lights: Vec<RectLight>,
    /// The viewing camera.
    pub camera: Camera,
}

/// One world-space triangle with the role of the instance it came from.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct WorldTriangle {
    /// Corners, counter-clockwise seen from the front.
    pub corners: [Vec3; 3],
    /// Corner normals, world space, unit length.
    pub normals: [Vec3; 3],
    /// Role of the source instance.
    pub role: Role,
    /// Index of the source instance's mesh in [`Scene::meshes`].
    pub mesh: usize,
}

impl Scene {
    /// Checks every invariant: meshes, instances, lights, camera, and that there is something to draw.
    ///
    /// # Errors
    /// The first problem found, naming [`Scene::origin`] and the element.
    pub fn validate(&self) -> Result<()> {
        let file = self.origin.as_path();
        for mesh in &self.meshes {
            mesh.validate(file)?;
        }
        for instance in &self.instances {
            validate_instance(file, instance, self.meshes.len())?;
        }
        if self.triangle_count() == 0 {
            return Err(SceneError::EmptyScene { file: file.into(), what: "no triangles" });
        }
        if self.lights.is_empty() {
            return Err(SceneError::EmptyScene { file: file.into(), what: "no lights" });
        }
        for (index, light) in self.lights.iter().enumerate() {
            light.validate(file, index)?;
        }
        self.camera.validate(file)?;
        if !self.bounds().size().is_finite() {
            return Err(SceneError::EmptyScene { file: file.into(), what: "geometry transforms to non-finite world coordinates" });
        }
        Ok(())
    }

    /// Number of triangles over all instances.
    #[must_use]
    pub fn triangle_count(&self) -> usize {
        self.instances.iter().filter_map(|i| self.meshes.get(i.mesh)).map(Mesh::triangle_count).sum()
    }

    /// World-space bounds of every instance.
    #[must_use]
    pub fn bounds(&self) -> Aabb {
        self.bounds_where(|_| true)
    }

    /// World-space bounds of the instances whose role satisfies `keep`.
    #[must_use]
    pub fn bounds_where(&self, keep: impl Fn(Role) -> bool) -> Aabb {
        let mut bounds = Aabb::EMPTY;
        for instance in self.instances.iter().filter(|i| keep(i.role)) {
            if let Some(mesh) = self.meshes.get(instance.mesh) {
                for &p in &mesh.positions {
                    bounds.extend(instance.transform.transform_point3(p));
                }
            }
        }
        bounds
    }

    /// Every triangle in world space, instance by instance.
    pub fn world_triangles(&self) -> impl Iterator<Item = WorldTriangle> + '_ {
        self.instances.iter().filter_map(|i| self.meshes.get(i.mesh).map(|m| (i, m))).flat_map(|(instance, mesh)| {
            let normal_matrix = normal_matrix(instance.transform);
            mesh.triangles().map(move |t| {
                let corner = |k: usize| instance.transform.transform_point3(mesh.positions[t[k] as usize]);
                let normal = |k: usize| (normal_matrix * mesh.normals[t[k] as usize]).normalize_or(Vec3::Y);
                WorldTriangle {
                    corners: [corner(0), corner(1), corner(2)],
                    normals: [normal(0), normal(1), normal(2)],
                    role: instance.role,
                    mesh: instance.mesh,
                }
            })
        })
    }

    /// Per mesh, whether it is closed ([`Adjacency::is_closed`]): every edge, on welded positions,
    /// shared by an even number of triangles. A closed mesh bounds an opaque solid (or a closed
    /// room), so a point on it whose tangent plane (on the side the camera sees) has the whole
    /// light behind it sees none of the light: when the light is on the camera's side of the mesh
    /// (both outside a solid, or both inside a room), a segment from just behind the surface to
    /// the light crosses the mesh an odd number of times; when it is not (a light sealed in a
    /// box, the camera outside), the light lies beyond the surface itself.
    #[must_use]
    pub fn closed_meshes(&self) -> Vec<bool> {
        self.meshes.iter().map(|mesh| Adjacency::of(mesh).is_closed()).collect()
    }

    /// Each placed instance of a closed mesh (`closed`: [`Scene::closed_meshes`]): its triangles in
    /// world space and their bounds.
    fn closed_instances<'a>(&'a self, closed: &'a [bool]) -> impl Iterator<Item = (Vec<[Vec3; 3]>, Aabb)> + 'a {
        self.instances.iter().filter(|i| closed.get(i.mesh).copied().unwrap_or(false)).filter_map(|instance| {
            let mesh = self.meshes.get(instance.mesh)?;
            let triangles: Vec<[Vec3; 3]> =
                mesh.triangles().map(|t| t.map(|k| instance.transform.transform_point3(mesh.positions[k as usize]))).collect();
            let mut bounds = Aabb::EMPTY;
            for corner in triangles.iter().flatten() {
                bounds.extend(*corner);
            }
            Some((triangles, bounds))
        })
    }

    /// True when a placed closed mesh (`closed`: [`Scene::closed_meshes`]) holds the light's
    /// centre, taken a ten-thousandth of the mesh's size off the light along its normal (the side
    /// it emits to): an interior, such as a closed room lit from its wall or ceiling. Surfaces
    /// then surround the light on every side of its hemisphere, and those beside it, which can
    /// hide nothing from a receiver, lie close to its plane in every map it renders. Decided by
    /// the parity of three segments' crossings to points outside the mesh (two must agree).
    #[must_use]
    pub fn encloses_light(&self, closed: &[bool], light: &RectLight) -> bool {
        self.closed_instances(closed).any(|(triangles, bounds)| {
            let size = bounds.size().length().max(f32::MIN_POSITIVE);
            let nudge = size * 1e-4;
            let emitting = light.centre + light.normal() * nudge;
            if !(emitting.cmpge(bounds.min).all() && emitting.cmple(bounds.max).all()) {
                return false;
            }
            // Segments to three points well outside the bounds, in directions no box edge or
            // axis-aligned face runs along: two of three must cross an odd number of times.
            let outside = [Vec3::new(0.63, 0.51, 0.59), Vec3::new(-0.71, 0.37, -0.6), Vec3::new(0.21, -0.86, 0.46)]
                .map(|direction| emitting + direction.normalize() * size * 2.0);
            outside.iter().filter(|&&far| segment_crossings(&triangles, emitting, far).is_some_and(|count| count % 2 == 1)).count() >= 2
        })
    }

    /// True when one placed closed mesh (`closed`: [`Scene::closed_meshes`]) separates the
    /// whole of `light` from `eye`: the light sealed in a box seen from outside, or a camera
    /// inside a closed room whose light is outside it. An opaque closed surface then stands
    /// between the eye's side and every point of the light, so nothing the eye can see receives
    /// any of it, however wide the light's view would have to be to show that (a single
    /// perspective frustum from the light covers less than its hemisphere).
    ///
    /// For each closed instance whose bounds hold the eye or the light: the light's rectangle
    /// must meet none of its triangles (a light crossing or touching the surface is not sealed,
    /// whatever its corners say), and the segments from the eye to the light's centre and
    /// corners, each moved off the light along its normal by a ten-thousandth of the instance's
    /// size (the side it emits to: a light flush on a ceiling lights the room below), must cross
    /// it an odd number of times. A segment through an edge or a vertex may miscount, and one
    /// with a crossing at either end is ambiguous (the camera on the surface), so each is also
    /// taken from two nudged eyes and two of the three must find an odd count. Judged from the
    /// camera's position: a camera whose near plane reaches through a wall sees a side this does
    /// not judge.
    #[must_use]
    pub fn separates_light_from(&self, closed: &[bool], light: &RectLight, eye: Vec3) -> bool {
        let corners = [light.point(-1.0, -1.0), light.point(1.0, -1.0), light.point(1.0, 1.0), light.point(-1.0, 1.0)];
        let light_points: Vec<Vec3> = if light.is_point() { vec![light.centre] } else { [&[light.centre][..], &corners[..]].concat() };
        self.closed_instances(closed).any(|(triangles, bounds)| {
            let nudge = bounds.size().length().max(f32::MIN_POSITIVE) * 1e-4;
            let inside = |p: Vec3| p.cmpge(bounds.min - nudge).all() && p.cmple(bounds.max + nudge).all();
            // An odd count needs one end inside the mesh, so inside its bounds.
            if !inside(eye) && !light_points.iter().any(|p| inside(*p)) {
                return false;
            }
            let eyes = [eye, eye + Vec3::new(0.71, -0.53, 0.47) * nudge, eye + Vec3::new(-0.37, 0.41, -0.83) * nudge];
            let odd = |target: Vec3| {
                eyes.iter().filter(|&&from| segment_crossings(&triangles, from, target).is_some_and(|count| count % 2 == 1)).count() >= 2
            };
            light_points.iter().all(|&p| odd(p + light.normal() * nudge))
                && (light.is_point() || !triangles.iter().any(|triangle| rectangle_meets_triangle(&corners, triangle)))
        })
    }
}

/// Where the segment from `from` to `to` meets `triangle` (Möller and Trumbore): `Some(t)` for a
/// point strictly inside the triangle at `t` of the way, in `[0, 1]`; `None` for no such point
/// (or a segment in the triangle's plane).
fn segment_hit(triangle: &[Vec3; 3], from: Vec3, to: Vec3) -> Option<f32> {
    let [a, b, c] = *triangle;
    let direction = to - from;
    let (edge1, edge2) = (b - a, c - a);
    let p = direction.cross(edge2);
    let determinant = edge1.dot(p);
    if determinant.abs() <= f32::EPSILON * edge1.length() * edge2.length() * direction.length() {
        return None;
    }
    let inverse = 1.0 / determinant;
    let offset = from - a;
    let u = offset.dot(p) * inverse;
    let q = offset.cross(edge1);
    let v = direction.dot(q) * inverse;
    let t = edge2.dot(q) * inverse;
    (u > 0.0 && v > 0.0 && u + v < 1.0 && (0.0..=1.0).contains(&t)).then_some(t)
}

/// How many of `triangles` the segment from `from` to `to` crosses; `None` when a crossing lies
/// within a millionth of the segment of either end (an end on the surface: its side is unknown).
fn segment_crossings(triangles: &[[Vec3; 3]], from: Vec3, to: Vec3) -> Option<usize> {
    let mut count = 0;
    for triangle in triangles {
        if let Some(t) = segment_hit(triangle, from, to) {
            if !(1e-6..=1.0 - 1e-6).contains(&t) {
                return None;
            }
            count += 1;
        }
    }
    Some(count)
}

/// True when the rectangle with corners `corners` (in order around it) and `triangle` meet: an
/// edge of either crosses the other (the rectangle as its two triangles). Coplanar overlap is
/// not seen, which a light flush on a surface needs: its side is the one it emits to.
fn rectangle_meets_triangle(corners: &[Vec3; 4], triangle: &[Vec3; 3]) -> bool {
    let halves = [[corners[0], corners[1], corners[2]], [corners[0], corners[2], corners[3]]];
    let triangle_edges = (0..3).any(|k| halves.iter().any(|half| segment_hit(half, triangle[k], triangle[(k + 1) % 3]).is_some()));
    triangle_edges || (0..4).any(|k| segment_hit(triangle, corners[k], corners[(k + 1) % 4]).is_some())
}

/// The matrix that carries normals of an object with this transform (inverse transpose).
#[must_use]
pub fn normal_matrix(transform: Mat4) -> Mat3 {
    Mat3::from_mat4(transform).inverse().transpose()
}

fn validate_instance(file: &Path, instance: &Instance, mesh_count: usize) -> Result<()> {
    if instance.mesh >= mesh_count {
        return Err(SceneError::MissingMesh { file: file.into(), instance: instance.name.clone(), mesh: instance.mesh, count: mesh_count });
    }
    if !instance.transform.is_finite() {
        return Err(SceneError::InvalidTransform { file: file.into(), instance: instance.name.clone(), problem: "not finite" });
    }
    // Singular, or too nearly so for normals to be transformed. Judged relative to the axes'
    // lengths, so that a tiny uniform scale (glTF's dequantisation, millimetre units) is fine.
    let linear = Mat3::from_mat4(instance.transform);
    let axes = linear.x_axis.length() * linear.y_axis.length() * linear.z_axis.length();
    if !(axes > 0.0 && (linear.determinant() / axes).abs() > 1e-6 && normal_matrix(instance.transform).is_finite()) {
        return Err(SceneError::InvalidTransform { file: file.into(), instance: instance.name.clone(), problem: "singular" });
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use glam::Vec4;

    use super::*;

    fn instance(transform: Mat4) -> Instance {
        Instance { name: "i".into(), mesh: 0, transform, role: Role::Both }
    }

    #[test]
    fn a_tiny_uniform_scale_is_valid_but_a_flattening_one_is_singular() {
        let file = Path::new("f");
        // gltfpack dequantises 14-bit positions of a 0.1-wide model with a scale of about 6e-6 (determinant 2e-16).
        assert!(validate_instance(file, &instance(Mat4::from_scale(Vec3::splat(6e-6))), 1).is_ok());
        // Axes that are almost parallel flatten the model onto a plane, whatever their length.
        let sheared = Mat4::from_cols(Vec4::X, Vec4::new(1.0, 1e-8, 0.0, 0.0), Vec4::Z, Vec4::W);
        assert!(validate_instance(file, &instance(sheared), 1).is_err());
        assert!(validate_instance(file, &instance(sheared * Mat4::from_scale(Vec3::splat(1e3))), 1).is_err());
        assert!(validate_instance(file, &instance(Mat4::from_scale(Vec3::ZERO)), 1).is_err());
        assert!(
            validate_instance(
                file,
                &instance(Mat4::from_cols_array(&[1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 1.0])),
                1
            )
            .is_err()
        );
    }

    /// A 2-unit box (closed) placed at `centre`, and an open quad, lit by `light`.
    fn boxed(centre: Vec3, light: RectLight) -> Scene {
        let mut scene = crate::builtin("parallel-square").unwrap_or_else(|e| panic!("{e}")).build();
        scene.meshes = vec![crate::primitives::cuboid("box", Vec3::splat(2.0)), crate::primitives::plane("quad", glam::Vec2::splat(2.0))];
        scene.instances = vec![
            Instance { name: "box".into(), mesh: 0, transform: Mat4::from_translation(centre), role: Role::Both },
            Instance { name: "quad".into(), mesh: 1, transform: Mat4::from_translation(Vec3::new(0.0, 5.0, 0.0)), role: Role::Both },
        ];
        scene.lights = vec![light];
        scene
    }

    #[test]
    fn a_closed_mesh_separates_a_light_inside_it_from_an_eye_outside() {
        let light = |centre: Vec3, size: f32| {
            RectLight::try_facing(centre, -Vec3::Y, Vec3::X, glam::Vec2::splat(size), 1.0).unwrap_or_else(|| panic!("light"))
        };
        let inside = light(Vec3::new(0.1, 0.5, -0.2), 0.5);
        let scene = boxed(Vec3::ZERO, inside);
        let closed = scene.closed_meshes();
        assert_eq!(closed, vec![true, false]);
        let outside_eye = Vec3::new(0.0, 3.0, 6.0);
        assert!(scene.separates_light_from(&closed, &inside, outside_eye), "sealed light, eye outside");
        assert!(!scene.separates_light_from(&closed, &inside, Vec3::new(0.5, -0.5, 0.5)), "eye in the same box");
        // The eye looking straight down the box's edge and through a vertex: the nudged eyes decide.
        assert!(scene.separates_light_from(&closed, &light(Vec3::ZERO, 0.0), Vec3::splat(5.0)), "through a vertex");
        let above = light(Vec3::new(0.0, 4.0, 0.0), 0.5);
        assert!(!scene.separates_light_from(&closed, &above, outside_eye), "light and eye outside");
        // An eye inside the box and the light outside it: separated too.
        assert!(scene.separates_light_from(&closed, &above, Vec3::new(0.3, 0.2, 0.1)), "eye sealed in");
        // A light straddling a wall is not sealed: part of it is outside.
        let straddling = light(Vec3::new(1.0, 0.5, 0.0), 0.5);
        assert!(!scene.separates_light_from(&closed, &straddling, outside_eye), "straddling light");
        // An open quad separates nothing.
        assert!(!scene.separates_light_from(&closed, &light(Vec3::new(0.0, 6.0, 0.0), 0.5), Vec3::new(0.0, 4.0, 0.0)), "open quad");
        // A light flush on the box's ceiling, facing down, lights the box's inside; one lying on
        // its top, facing up, lights the outside: neither is sealed from an eye on its side.
        let flush = light(Vec3::new(0.3, 1.0, 0.2), 0.5);
        assert!(!scene.separates_light_from(&closed, &flush, Vec3::new(-0.5, -0.5, 0.5)), "flush on the ceiling");
        let on_top = RectLight::try_facing(Vec3::new(0.3, 1.0, 0.2), Vec3::Y, Vec3::X, glam::Vec2::splat(0.5), 1.0)
            .unwrap_or_else(|| panic!("light"));
        assert!(!scene.separates_light_from(&closed, &on_top, outside_eye), "lying on the top");
        assert!(scene.separates_light_from(&closed, &on_top, Vec3::new(-0.5, -0.5, 0.5)), "lying on the top, eye inside");
    }

    /// A light inside a closed box is enclosed whatever the eye (flush on its ceiling and facing
    /// in, too); one outside it, lying on its top facing out, or under an open quad is not.
    #[test]
    fn a_closed_mesh_encloses_a_light_inside_it() {
        let light = |centre: Vec3, normal: Vec3| {
            let along = if normal.x == 0.0 { Vec3::X } else { Vec3::Z };
            RectLight::try_facing(centre, normal, along, glam::Vec2::splat(0.5), 1.0).unwrap_or_else(|| panic!("light"))
        };
        let inside = light(Vec3::new(0.1, 0.5, -0.2), -Vec3::Y);
        let scene = boxed(Vec3::ZERO, inside);
        let closed = scene.closed_meshes();
        assert!(scene.encloses_light(&closed, &inside), "inside");
        assert!(scene.encloses_light(&closed, &light(Vec3::new(0.3, 1.0, 0.2), -Vec3::Y)), "flush on the ceiling, facing in");
        assert!(scene.encloses_light(&closed, &light(Vec3::new(-1.0, 0.2, 0.0), Vec3::X)), "on a wall, facing in");
        assert!(!scene.encloses_light(&closed, &light(Vec3::new(0.3, 1.0, 0.2), Vec3::Y)), "on the top, facing out");
        assert!(!scene.encloses_light(&closed, &light(Vec3::new(0.0, 4.0, 0.0), -Vec3::Y)), "above the box, under the open quad");
        assert!(!scene.encloses_light(&[false, false], &inside), "the box not closed");
    }

    /// Three closed boxes in a row, one mesh: a light whose centre and corners all lie inside
    /// boxes, but whose edges cross the gaps between them, is not sealed.
    #[test]
    fn a_light_whose_edges_leave_a_closed_mesh_is_not_sealed() {
        let cube = crate::primitives::cuboid("box", Vec3::ONE);
        let mut row = Mesh { name: "row".into(), positions: Vec::new(), normals: Vec::new(), indices: Vec::new() };
        for x in [-2.0f32, 0.0, 2.0] {
            let base = row.positions.len() as u32;
            row.positions.extend(cube.positions.iter().map(|p| *p + Vec3::new(x, 0.0, 0.0)));
            row.normals.extend_from_slice(&cube.normals);
            row.indices.extend(cube.indices.iter().map(|i| base + i));
        }
        let long = RectLight::try_facing(Vec3::ZERO, -Vec3::Y, Vec3::X, glam::Vec2::new(4.4, 0.4), 1.0).unwrap_or_else(|| panic!("light"));
        let mut scene = boxed(Vec3::ZERO, long);
        scene.meshes[0] = row;
        let closed = scene.closed_meshes();
        assert!(closed[0]);
        let eye = Vec3::new(0.0, 4.0, 6.0);
        assert!(!scene.separates_light_from(&closed, &long, eye), "the light's edges cross the gaps");
        let short = RectLight { half_size: glam::Vec2::splat(0.2), ..long };
        assert!(scene.separates_light_from(&closed, &short, eye), "a light inside the middle box");
    }
}
