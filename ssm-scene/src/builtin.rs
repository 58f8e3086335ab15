//! Procedural scenes that need no files: the analytic case and the classic stress cases.

use std::path::PathBuf;

use glam::{Mat4, Quat, Vec2, Vec3};

use crate::camera::Camera;
use crate::error::{Result, SceneError};
use crate::light::RectLight;
use crate::mesh::Mesh;
use crate::primitives::{cuboid, plane, sphere};
use crate::scene::{Instance, Role, Scene};

/// A built-in scene's name and what it exercises.
#[derive(Clone, Copy, Debug)]
pub struct BuiltinScene {
    /// Name used on the command line and in manifests.
    pub name: &'static str,
    /// One line saying what it is and what it tests.
    pub summary: &'static str,
    build: fn() -> Scene,
}

impl BuiltinScene {
    /// Builds the scene.
    #[must_use]
    pub fn build(&self) -> Scene {
        (self.build)()
    }
}

/// Every built-in scene, in a stable order.
pub const BUILTIN_SCENES: &[BuiltinScene] = &[
    BuiltinScene {
        name: "parallel-square",
        summary: "1x1 square light at y=4, 1x1 occluder square at y=2, 8x8 receiver at y=0: the analytic case of Atty et al. (Sec. 5.2)",
        build: parallel_square,
    },
    BuiltinScene { name: "floating-sphere", summary: "a closed sphere floating above a receiver plane", build: floating_sphere },
    BuiltinScene {
        name: "contact",
        summary: "a box and a sphere resting on the plane: contact hardening, occluder touching receiver",
        build: contact,
    },
    BuiltinScene {
        name: "sphere-cube",
        summary: "a 5x5x5 cube of small spheres above a plane: overlapping penumbrae (Forest et al., Fig. 1)",
        build: sphere_cube,
    },
    BuiltinScene {
        name: "leaves",
        summary: "300 thin quads at varied heights over the ground: occluder fusion and depth discontinuities (Buades et al.'s plant)",
        build: leaves,
    },
    BuiltinScene {
        name: "bar-grid",
        summary: "70 thin bars 0.1 apart, parallel to a large floor under a small light, the camera low and looking along it: high-frequency hard shadows that alias in the distance (Shen et al., Fig. 11)",
        build: bar_grid,
    },
];

/// Looks up a built-in scene by name.
///
/// # Errors
/// [`SceneError::UnknownBuiltin`] listing the names that exist.
pub fn builtin(name: &str) -> Result<&'static BuiltinScene> {
    BUILTIN_SCENES.iter().find(|s| s.name == name).ok_or_else(|| SceneError::UnknownBuiltin {
        name: name.into(),
        known: BUILTIN_SCENES.iter().map(|s| s.name).collect::<Vec<_>>().join(", "),
    })
}

/// The camera every built-in scene shares: at (0, 5, 6) looking at the origin, 45° vertical field of view.
fn standard_camera() -> Camera {
    Camera { position: Vec3::new(0.0, 5.0, 6.0), target: Vec3::ZERO, up: Vec3::Y, fov_y: 45f32.to_radians(), near: 0.1, far: 50.0 }
}

/// A square light of side `size` centred at `centre`, facing down, first side along +X.
fn downward_light(centre: Vec3, size: f32) -> RectLight {
    RectLight { centre, u_axis: Vec3::X, v_axis: Vec3::Z, half_size: Vec2::splat(size * 0.5), intensity: 1.0 }
}

struct SceneBuilder {
    scene: Scene,
}

impl SceneBuilder {
    fn new(name: &str, light: RectLight) -> Self {
        let origin = PathBuf::from(format!("builtin:{name}"));
        Self { scene: Scene { origin, meshes: Vec::new(), instances: Vec::new(), lights: vec![light], camera: standard_camera() } }
    }

    fn mesh(&mut self, mesh: Mesh) -> usize {
        self.scene.meshes.push(mesh);
        self.scene.meshes.len() - 1
    }

    fn place(&mut self, name: impl Into<String>, mesh: usize, transform: Mat4, role: Role) {
        self.scene.instances.push(Instance { name: name.into(), mesh, transform, role });
    }

    fn ground(mut self, size: f32) -> Self {
        let ground = self.mesh(plane("ground", Vec2::splat(size)));
        self.place("ground", ground, Mat4::IDENTITY, Role::Receiver);
        self
    }
}

fn parallel_square() -> Scene {
    let mut b = SceneBuilder::new("parallel-square", downward_light(Vec3::new(0.0, 4.0, 0.0), 1.0)).ground(8.0);
    let occluder = b.mesh(plane("occluder", Vec2::ONE));
    b.place("occluder", occluder, Mat4::from_translation(Vec3::new(0.0, 2.0, 0.0)), Role::Occluder);
    b.scene
}

fn floating_sphere() -> Scene {
    let mut b = SceneBuilder::new("floating-sphere", downward_light(Vec3::new(0.0, 4.0, 0.0), 1.0)).ground(8.0);
    let ball = b.mesh(sphere("sphere", 0.6, 48, 24));
    b.place("sphere", ball, Mat4::from_translation(Vec3::new(0.0, 1.4, 0.0)), Role::Occluder);
    b.scene
}

fn contact() -> Scene {
    let mut b = SceneBuilder::new("contact", downward_light(Vec3::new(1.0, 4.0, -0.5), 1.2)).ground(8.0);
    let block = b.mesh(cuboid("box", Vec3::new(1.0, 1.2, 0.6)));
    let transform = Mat4::from_rotation_translation(Quat::from_rotation_y(0.5), Vec3::new(-0.6, 0.6, 0.0));
    b.place("box", block, transform, Role::Both);
    let ball = b.mesh(sphere("ball", 0.45, 40, 20));
    b.place("ball", ball, Mat4::from_translation(Vec3::new(0.9, 0.45, 0.6)), Role::Both);
    b.scene
}

fn sphere_cube() -> Scene {
    let mut b = SceneBuilder::new("sphere-cube", downward_light(Vec3::new(0.0, 4.5, 0.0), 1.0)).ground(8.0);
    let ball = b.mesh(sphere("small-sphere", 0.11, 16, 8));
    for i in 0..5 {
        for j in 0..5 {
            for k in 0..5 {
                let offset = Vec3::new(i as f32 - 2.0, j as f32 - 2.0, k as f32 - 2.0) * 0.3;
                b.place(format!("sphere-{i}-{j}-{k}"), ball, Mat4::from_translation(Vec3::new(0.0, 1.6, 0.0) + offset), Role::Occluder);
            }
        }
    }
    b.scene
}

fn leaves() -> Scene {
    let mut b = SceneBuilder::new("leaves", downward_light(Vec3::new(0.0, 4.5, 0.0), 1.0)).ground(8.0);
    let leaf = b.mesh(plane("leaf", Vec2::new(0.3, 0.12)));
    // A fixed xorshift sequence: the scene is the same on every machine and every run.
    let mut state = 0x9E37_79B9_u32;
    let mut next = move || {
        state ^= state << 13;
        state ^= state >> 17;
        state ^= state << 5;
        state as f32 / u32::MAX as f32
    };
    for index in 0..300 {
        let position = Vec3::new(next() * 3.0 - 1.5, 0.4 + next() * 2.2, next() * 3.0 - 1.5);
        let rotation = Quat::from_rotation_y(next() * std::f32::consts::TAU) * Quat::from_rotation_x((next() - 0.5) * 1.2);
        b.place(format!("leaf-{index}"), leaf, Mat4::from_rotation_translation(rotation, position), Role::Occluder);
    }
    b.scene
}

fn bar_grid() -> Scene {
    let mut b = SceneBuilder::new("bar-grid", downward_light(Vec3::new(0.0, 6.0, 0.0), 0.05)).ground(16.0);
    let bar = b.mesh(cuboid("bar", Vec3::new(6.0, 0.02, 0.03)));
    for index in 0..70 {
        let z = -3.5 + index as f32 * 0.1;
        b.place(format!("bar-{index}"), bar, Mat4::from_translation(Vec3::new(0.0, 3.0, z)), Role::Occluder);
    }
    // Low and narrow, so that the bars stay above the view and the floor recedes to a grazing angle.
    b.scene.camera =
        Camera { position: Vec3::new(0.0, 1.0, 6.0), target: Vec3::new(0.0, 0.0, -1.0), fov_y: 30f32.to_radians(), ..standard_camera() };
    b.scene
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_builtin_validates() {
        for s in BUILTIN_SCENES {
            let scene = s.build();
            scene.validate().unwrap_or_else(|e| panic!("{}: {e}", s.name));
            assert_eq!(scene.origin.to_str(), Some(format!("builtin:{}", s.name).as_str()));
        }
    }

    #[test]
    fn parallel_square_has_the_documented_geometry() {
        let scene = builtin("parallel-square").unwrap().build();
        let light = scene.lights[0];
        assert_eq!(light.centre, Vec3::new(0.0, 4.0, 0.0));
        assert_eq!(light.half_size, Vec2::splat(0.5));
        assert!((light.normal() + Vec3::Y).length() < 1e-6);
        let occluder = scene.bounds_where(|r| r == Role::Occluder);
        assert_eq!((occluder.min, occluder.max), (Vec3::new(-0.5, 2.0, -0.5), Vec3::new(0.5, 2.0, 0.5)));
        let receiver = scene.bounds_where(|r| r == Role::Receiver);
        assert_eq!((receiver.min, receiver.max), (Vec3::new(-4.0, 0.0, -4.0), Vec3::new(4.0, 0.0, 4.0)));
        assert_eq!(scene.camera.position, Vec3::new(0.0, 5.0, 6.0));
        assert!((scene.camera.fov_y.to_degrees() - 45.0).abs() < 1e-4);
    }

    #[test]
    fn unknown_builtin_lists_the_known_ones() {
        let err = builtin("nope").unwrap_err().to_string();
        assert!(err.contains("parallel-square") && err.contains("leaves"), "{err}");
    }
}
