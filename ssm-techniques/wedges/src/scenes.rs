//! Forest et al.'s test scene with its size as parameters: a cube of spheres
//! above a ground plane under sphere-cube's light (Sec. 5, Figs. 1 and 12:
//! "a collection of spheres", 762 triangles each, their number increased to
//! measure how the cost grows with the geometry), and the manifests of the
//! `wedges-fig12` preset, written from it.

use std::fmt::Write as _;

use glam::{Mat4, Vec2, Vec3};
use ssm_scene::primitives::{plane, sphere};
use ssm_scene::{Camera, Instance, RectLight, Role, Scene};

/// Sphere tessellation of the figures: 20 segments and 20 rings make 2·20·19 = 760 triangles,
/// the nearest the UV-sphere generator (2·segments·(rings − 1) triangles) comes to the
/// paper's 762 (= 2·3·127, which no pair of sensible sizes gives).
pub const PAPER_SEGMENTS: u32 = 20;
/// See [`PAPER_SEGMENTS`].
pub const PAPER_RINGS: u32 = 20;
/// Sphere radius and spacing, as in the built-in `sphere-cube`.
pub const SPHERE_RADIUS: f32 = 0.11;
/// Distance between neighbouring spheres' centres.
pub const SPHERE_SPACING: f32 = 0.3;
/// Spheres per side of the Fig. 12 scenes (1, 8, 27, ... 343 spheres).
pub const FIG12_SIDES: [u32; 7] = [1, 2, 3, 4, 5, 6, 7];

/// A cube of `side`³ spheres of `segments` × `rings`, centred 1.6 above an 8 × 8 ground, under sphere-cube's 1 × 1 light at height 4.5, seen from the
/// built-in scenes' camera. Spheres are occluders; the ground receives.
#[must_use]
pub fn sphere_cube(side: u32, segments: u32, rings: u32) -> Scene {
    let ball = sphere("sphere", SPHERE_RADIUS, segments, rings);
    let ground = plane("ground", Vec2::splat(8.0));
    let mut instances = vec![Instance { name: "ground".into(), mesh: 1, transform: Mat4::IDENTITY, role: Role::Receiver }];
    for i in 0..side {
        for j in 0..side {
            for k in 0..side {
                let offset = (Vec3::new(i as f32, j as f32, k as f32) - Vec3::splat(side.saturating_sub(1) as f32 * 0.5)) * SPHERE_SPACING;
                let centre = Vec3::new(0.0, 1.6, 0.0) + offset;
                instances.push(Instance {
                    name: format!("sphere-{i}-{j}-{k}"),
                    mesh: 0,
                    transform: Mat4::from_translation(centre),
                    role: Role::Occluder,
                });
            }
        }
    }
    Scene {
        origin: format!("wedges:sphere-cube-{side}").into(),
        meshes: vec![ball, ground],
        instances,
        lights: vec![RectLight {
            centre: Vec3::new(0.0, 4.5, 0.0),
            u_axis: Vec3::X,
            v_axis: Vec3::Z,
            half_size: Vec2::splat(0.5),
            intensity: 1.0,
        }],
        camera: Camera {
            position: Vec3::new(0.0, 5.0, 6.0),
            target: Vec3::ZERO,
            up: Vec3::Y,
            fov_y: 45f32.to_radians(),
            near: 0.1,
            far: 50.0,
        },
    }
}

/// The sphere of [`sphere_cube`] at the paper's tessellation as a Wavefront OBJ (manifests
/// cannot choose a primitive's tessellation, so the Fig. 12 manifests load this file).
#[must_use]
pub fn paper_sphere_obj() -> String {
    let ball = sphere("sphere", SPHERE_RADIUS, PAPER_SEGMENTS, PAPER_RINGS);
    let mut text = format!(
        "# UV sphere, radius {SPHERE_RADIUS}, {PAPER_SEGMENTS} segments, {PAPER_RINGS} rings: {} triangles\n",
        ball.indices.len() / 3
    );
    for p in &ball.positions {
        let _ = writeln!(text, "v {} {} {}", p.x, p.y, p.z);
    }
    for n in &ball.normals {
        let _ = writeln!(text, "vn {} {} {}", n.x, n.y, n.z);
    }
    for t in ball.triangles() {
        let [a, b, c] = t.map(|i| i + 1);
        let _ = writeln!(text, "f {a}//{a} {b}//{b} {c}//{c}");
    }
    text
}

/// The manifest of [`sphere_cube`]`(side, 20, 20)`, loading the sphere from `sphere-760.obj` beside it.
#[must_use]
pub fn fig12_manifest(side: u32) -> String {
    let count = side * side * side;
    let mut text = format!(
        "# Forest et al., Fig. 12: {count} spheres of 760 triangles ({} in all), written by\n# `cargo run --release -p ssm-wedges --example fig12 -- --write-scenes`.\n\n[camera]\nposition = [0.0, 5.0, 6.0]\ntarget = [0.0, 0.0, 0.0]\nfov_y_degrees = 45.0\nnear = 0.1\nfar = 50.0\n\n[[light]]\ncentre = [0.0, 4.5, 0.0]\nnormal = [0.0, -1.0, 0.0]\nu_axis = [1.0, 0.0, 0.0]\nsize = [1.0, 1.0]\n\n[[object]]\nprimitive = \"plane\"\nsize = [8.0, 8.0]\nrole = \"receiver\"\n",
        count * 760
    );
    let half = side.saturating_sub(1) as f32 * 0.5;
    for i in 0..side {
        for j in 0..side {
            for k in 0..side {
                let c = Vec3::new(0.0, 1.6, 0.0) + (Vec3::new(i as f32, j as f32, k as f32) - Vec3::splat(half)) * SPHERE_SPACING;
                let _ = write!(
                    text,
                    "\n[[object]]\nmodel = \"sphere-760.obj\"\ntranslate = [{:.4}, {:.4}, {:.4}]\nrole = \"occluder\"\n",
                    c.x, c.y, c.z
                );
            }
        }
    }
    text
}

#[cfg(test)]
mod tests {
    #![allow(clippy::unwrap_used)]

    use super::*;

    #[test]
    fn the_paper_sphere_has_760_triangles_and_the_cube_side_cubed_spheres() {
        let scene = sphere_cube(3, PAPER_SEGMENTS, PAPER_RINGS);
        assert_eq!(scene.meshes[0].indices.len() / 3, 760);
        assert_eq!(scene.instances.iter().filter(|i| i.role == Role::Occluder).count(), 27);
        scene.validate().unwrap();
        assert!(ssm_scene::Adjacency::of(&scene.meshes[0]).is_closed_manifold());
    }

    /// The committed manifests are what this module writes (rerun the example with
    /// `--write-scenes` after changing it), and they load into the scene built in code.
    #[test]
    fn the_fig12_manifests_are_up_to_date_and_match_the_scene() {
        let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes");
        assert_eq!(std::fs::read_to_string(dir.join("sphere-760.obj")).unwrap(), paper_sphere_obj());
        for side in FIG12_SIDES {
            let path = dir.join(format!("spheres-{}.toml", side * side * side));
            assert_eq!(std::fs::read_to_string(&path).unwrap(), fig12_manifest(side), "{}", path.display());
        }
        let (loaded, _) = ssm_scene::Scene::load(&dir.join("spheres-8.toml").to_string_lossy()).unwrap();
        let built = sphere_cube(2, PAPER_SEGMENTS, PAPER_RINGS);
        assert_eq!(loaded.triangle_count(), built.triangle_count());
        let (a, b) = (loaded.bounds(), built.bounds());
        assert!((a.min - b.min).length() < 1e-3 && (a.max - b.max).length() < 1e-3, "{a:?} {b:?}");
    }
}
