//! Forest et al.'s test scene with its size as parameters: the built-in
//! `sphere-cube` (`sphere-cube:spheres=N,segments=S,rings=R`), a cube of
//! spheres 0.3 apart above the ground (Sec. 5, Figs. 1 and 12: "a collection
//! of spheres", 762 triangles each, their number increased to measure how the
//! cost grows with the geometry), and the scene names of the `wedges-fig12`
//! and `wedges-atty-fig25` presets.

use ssm_scene::Scene;

/// Sphere tessellation of the figures: 20 segments and 20 rings make 2·20·19 = 760 triangles,
/// the nearest the UV-sphere generator (2·segments·(rings − 1) triangles) comes to the
/// paper's 762 (= 2·3·127, which no pair of sensible sizes gives).
pub const PAPER_SEGMENTS: u32 = 20;
/// See [`PAPER_SEGMENTS`].
pub const PAPER_RINGS: u32 = 20;
/// Spheres per side of the Fig. 12 scenes (1, 8, 27, ... 343 spheres).
pub const FIG12_SIDES: [u32; 7] = [1, 2, 3, 4, 5, 6, 7];

/// The built-in scene name of a cube of `side`³ spheres of `segments` × `rings`.
#[must_use]
pub fn sphere_cube_name(side: u32, segments: u32, rings: u32) -> String {
    format!("sphere-cube:spheres={side},segments={segments},rings={rings}")
}

/// A cube of `side`³ spheres of `segments` × `rings` (the built-in `sphere-cube` with those
/// parameters): spheres are occluders, the ground receives.
///
/// # Panics
/// If the parameters are outside the built-in scene's ranges (1 to 40 spheres a side, 3 to 256
/// segments, 2 to 256 rings).
#[must_use]
pub fn sphere_cube(side: u32, segments: u32, rings: u32) -> Scene {
    let name = sphere_cube_name(side, segments, rings);
    match ssm_scene::parse_builtin(&name) {
        Some(Ok((_, scene))) => scene,
        Some(Err(error)) => panic!("{error}"),
        None => panic!("`sphere-cube` is not a built-in scene"),
    }
}

/// Fig. 12's scenes: cubes of 1 to 7 spheres a side (1 to 343 spheres) of the paper's 760
/// triangles, the built-in `sphere-cube` with parameters ([`scenes::sphere_cube_name`](crate::scenes::sphere_cube_name)).
pub const FIG12_SCENES: &[&str] = &[
    "sphere-cube:spheres=1,segments=20,rings=20",
    "sphere-cube:spheres=2,segments=20,rings=20",
    "sphere-cube:spheres=3,segments=20,rings=20",
    "sphere-cube:spheres=4,segments=20,rings=20",
    "sphere-cube:spheres=5,segments=20,rings=20",
    "sphere-cube:spheres=6,segments=20,rings=20",
    "sphere-cube:spheres=7,segments=20,rings=20",
];

/// Atty et al.'s Fig. 25: the same cubes from 8 spheres (2 a side).
pub const FIG25_SCENES: &[&str] = FIG12_SCENES.split_at(1).1;

#[cfg(test)]
mod tests {
    #![allow(clippy::unwrap_used)]

    use super::*;

    #[test]
    fn the_paper_sphere_has_760_triangles_and_the_cube_side_cubed_spheres() {
        let scene = sphere_cube(3, PAPER_SEGMENTS, PAPER_RINGS);
        let ball = scene.meshes.iter().find(|m| m.name == "small-sphere").unwrap();
        assert_eq!(ball.indices.len() / 3, 760);
        assert_eq!(scene.instances.iter().filter(|i| i.role == ssm_scene::Role::Occluder).count(), 27);
        scene.validate().unwrap();
        assert!(ssm_scene::Adjacency::of(ball).is_closed_manifold());
    }

    /// The preset's scene names are the built-in scene with the paper's spheres.
    #[test]
    fn the_fig12_preset_names_the_paper_spheres() {
        for (side, name) in FIG12_SIDES.iter().zip(super::super::FIG12_SCENES) {
            assert_eq!(*name, sphere_cube_name(*side, PAPER_SEGMENTS, PAPER_RINGS));
        }
    }
}
