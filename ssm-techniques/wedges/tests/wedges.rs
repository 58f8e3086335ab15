//! Penumbra wedges (`wedges`) against the exact answer and against the
//! claims of Forest et al. 2006: the integration is exact for one silhouette,
//! a point light gives the hard shadow of the volumes, the blending removes
//! the over-darkening where penumbrae overlap, and the stated rule for meshes
//! that are not closed (two-sided components) never leaks light.

// Test helpers unwrap too: a failure should stop the test where it happens.
#![allow(clippy::unwrap_used, clippy::expect_used)]

use glam::{Mat4, Quat, Vec2, Vec3};
use ssm_core::metrics::{ShadowClass, classify, compare};
use ssm_scene::{Instance, Mesh, Role, Scene, builtin, primitives};
use ssm_testing::{Rendered, at, gpu, parallel_square_exact, penumbra_mask, pixel_of, reference, render, scene_from_manifest};

const SIZE: (u32, u32) = (160, 120);

fn wedges(scene: &Scene, settings: &[(&str, &str)]) -> Rendered {
    render(&gpu(), scene, &ssm_wedges::INFO, settings, SIZE.0, SIZE.1).unwrap()
}

/// Penumbra MAE against the exact visibility of parallel-square at the same points.
fn parallel_square_error(rendered: &Rendered) -> f64 {
    let exact = rendered.parallel_square_exact();
    compare(&exact, &rendered.visibility, &rendered.coverage(), SIZE.0 as usize, SIZE.1 as usize).mae_penumbra
}

/// A scene's diagnostic by name.
fn diagnostic(scene: &Scene, settings: &[(&str, &str)], name: &str) -> f64 {
    let gpu = gpu();
    let params = ssm_wedges::INFO.params_from(settings.iter().copied()).unwrap();
    let needs = (ssm_wedges::INFO.requirements)(&params).unwrap();
    let mut renderer = ssm_core::Renderer::new(&gpu, scene, SIZE.0, SIZE.1, &needs).unwrap();
    let mut technique = renderer.create_technique(&ssm_wedges::INFO, &params).unwrap();
    renderer.render(technique.as_mut(), "wedges").unwrap();
    technique.diagnostics(&gpu).into_iter().find(|(n, _)| n == name).map(|(_, v)| v).unwrap_or_else(|| panic!("no diagnostic {name}"))
}

/// Mean signed error (negative: too dark) over the pixels in penumbra in the reference, and the
/// penumbra MAE (umbra and penumbra), against a 16×16-ray ground truth.
fn errors_against_reference(truth: &Rendered, rendered: &Rendered) -> (f64, f64) {
    let covered = rendered.coverage();
    let classes = classify(&truth.visibility, &covered);
    let signed: Vec<f64> = classes
        .iter()
        .zip(&rendered.visibility)
        .zip(&truth.visibility)
        .filter(|((class, _), _)| **class == ShadowClass::Penumbra)
        .map(|((_, v), r)| f64::from(v - r))
        .collect();
    let mae = compare(&truth.visibility, &rendered.visibility, &covered, SIZE.0 as usize, SIZE.1 as usize).mae_penumbra;
    (signed.iter().sum::<f64>() / signed.len().max(1) as f64, mae)
}

/// Share of covered pixels where two visibilities disagree by more than 0.5 (for hard shadows).
fn disagreement(a: &Rendered, b: &[f32]) -> f64 {
    let covered = a.coverage();
    let wrong = a.visibility.iter().zip(b).zip(&covered).filter(|((x, y), c)| **c && (*x - *y).abs() > 0.5).count();
    wrong as f64 / covered.iter().filter(|c| **c).count() as f64
}

/// One silhouette, no overlap: the wedges' integration from the light's centre is exact
/// (Assarsson and Akenine-Möller 2003; Fig. 4), so both blendings match the exact visibility.
#[test]
fn parallel_square_matches_the_exact_visibility_with_both_blendings() {
    let scene = builtin("parallel-square").unwrap().build();
    for blending in ["none", "forest"] {
        let rendered = wedges(&scene, &[("blending", blending)]);
        let error = parallel_square_error(&rendered);
        let exact = rendered.parallel_square_exact();
        let penumbra = penumbra_mask(&exact).iter().filter(|p| **p).count();
        println!("parallel-square, blending={blending}: penumbra MAE {error:.6} over {penumbra} penumbra pixels");
        assert!(penumbra > 500, "the test needs a penumbra: {penumbra}");
        assert!(error <= 0.005, "blending={blending}: penumbra MAE {error}");
    }
    assert_eq!((parallel_square_exact(0.0, 0.0), parallel_square_exact(1.0, 0.0)), (0.0, 0.5));
}

/// The rule for open meshes: the square is two-sided, so it casts the same shadow whichever way
/// its faces are wound (here turned upside down, its faces away from the light).
#[test]
fn an_open_mesh_casts_the_same_shadow_whichever_side_faces_the_light() {
    let mut scene = builtin("parallel-square").unwrap().build();
    let occluder = scene.instances.iter_mut().find(|i| i.role == Role::Occluder).unwrap();
    occluder.transform = Mat4::from_translation(Vec3::new(0.0, 2.0, 0.0)) * Mat4::from_rotation_x(std::f32::consts::PI);
    let error = parallel_square_error(&wedges(&scene, &[]));
    println!("parallel-square, occluder facing away from the light: penumbra MAE {error:.6}");
    assert!(error <= 0.005, "{error}");
}

/// A point light: the wedges have no width, and the result is the hard shadow of the z-fail
/// volumes, which is the exact shadow from the light's centre (a one-ray ground truth) up to
/// rasterisation at the shadow's edge. Contact has objects with role `both`: self-shadowing included.
#[test]
fn a_point_light_gives_the_hard_shadow_of_the_volumes() {
    let gpu = gpu();
    for name in ["contact", "sphere-cube", "leaves"] {
        let mut scene = builtin(name).unwrap().build();
        scene.lights[0].half_size = Vec2::ZERO;
        let rendered = wedges(&scene, &[]);
        let exact = reference(&gpu, &scene, 1, SIZE);
        let wrong = disagreement(&rendered, &exact.visibility);
        let penumbra = rendered.covered_visibility().iter().filter(|v| **v > 0.0 && **v < 1.0).count();
        let hard = render(&gpu, &scene, &ssm_hard::INFO, &[], SIZE.0, SIZE.1).unwrap();
        let hard_wrong = disagreement(&hard, &exact.visibility);
        println!(
            "{name}, point light: {:.3}% of pixels differ from the exact hard shadow (shadow map: {:.3}%)",
            wrong * 100.0,
            hard_wrong * 100.0
        );
        assert_eq!(penumbra, 0, "{name}: a point light casts no penumbra");
        assert!(wrong < 0.003, "{name}: {wrong}");
        assert!(wrong <= hard_wrong + 0.001, "{name}: volumes {wrong} against a shadow map's {hard_wrong}");
    }
}

/// Forest et al., Figs. 1 and 2: where the penumbrae of many silhouettes overlap, summing their
/// occlusions over-darkens; the blending removes most of it. Measured against the ground truth
/// as the mean signed error over the penumbra (negative: too dark).
#[test]
fn forest_blending_halves_the_over_darkening_of_overlapping_penumbrae() {
    let scene = builtin("sphere-cube").unwrap().build();
    let truth = reference(&gpu(), &scene, 16, SIZE);
    let (none_signed, none_mae) = errors_against_reference(&truth, &wedges(&scene, &[("blending", "none")]));
    let (forest_signed, forest_mae) = errors_against_reference(&truth, &wedges(&scene, &[("blending", "forest")]));
    println!(
        "sphere-cube: mean signed penumbra error none {none_signed:.4}, forest {forest_signed:.4}; penumbra MAE none {none_mae:.4}, forest {forest_mae:.4}"
    );
    assert!(none_signed < -0.05, "penumbra wedges over-darken overlaps: {none_signed}");
    assert!(forest_signed.abs() < 0.5 * none_signed.abs(), "forest {forest_signed} against none {none_signed}");
    assert!(forest_mae < 0.5 * none_mae, "forest {forest_mae} against none {none_mae}");
}

/// The blending happens between silhouette buffers: with one buffer every silhouette is summed in
/// it, and the umbra is a single stencil test for all of them (Akenine-Möller and Assarsson's
/// single visibility buffer), so forest and none agree there; with more buffers they do not.
#[test]
fn with_one_silhouette_buffer_forest_equals_none() {
    let scene = builtin("sphere-cube").unwrap().build();
    let none = wedges(&scene, &[("blending", "none"), ("silhouette_buffers", "1")]);
    let forest = wedges(&scene, &[("blending", "forest"), ("silhouette_buffers", "1")]);
    let worst = none.visibility.iter().zip(&forest.visibility).map(|(a, b)| (a - b).abs()).fold(0.0f32, f32::max);
    let many = wedges(&scene, &[("blending", "forest"), ("silhouette_buffers", "16")]);
    let differs = none.visibility.iter().zip(&many.visibility).filter(|(a, b)| (*a - *b).abs() > 0.05).count();
    println!("one buffer: forest and none differ by up to {worst}; sixteen buffers: {differs} pixels differ by more than 0.05");
    assert!(worst < 1e-5, "{worst}");
    assert!(differs > 200, "{differs}");
}

/// Silhouettes found on the GPU: one region and one loop of four edges for the square; one
/// region and one loop per sphere of sphere-cube (closed, convex: its lit half).
#[test]
fn silhouettes_regions_and_loops_are_counted_on_the_gpu() {
    let square = builtin("parallel-square").unwrap().build();
    assert_eq!(diagnostic(&square, &[], "silhouette_edges"), 4.0);
    assert_eq!(diagnostic(&square, &[], "silhouette_regions"), 1.0);
    assert_eq!(diagnostic(&square, &[], "silhouette_loops"), 1.0);
    let cube = builtin("sphere-cube").unwrap().build();
    assert_eq!(diagnostic(&cube, &[], "silhouette_regions"), 125.0);
    assert_eq!(diagnostic(&cube, &[], "silhouette_loops"), 125.0);
    assert_eq!(diagnostic(&cube, &[("silhouette_buffers", "8")], "silhouette_buffers_used"), 8.0);
    assert!(diagnostic(&cube, &[], "wedge_fragments") > 1000.0);
    // The passes: silhouettes, depth copy, four per buffer, resolve.
    assert_eq!(diagnostic(&cube, &[("silhouette_buffers", "8")], "passes"), 3.0 + 4.0 * 8.0);
}

/// A long strip of quads, numbered from both ends inwards, so that its faces' labels meet in the
/// middle after several rounds: still one region and one loop.
#[test]
fn label_propagation_joins_a_long_strip_into_one_region() {
    let count = 400usize;
    let mut positions = Vec::new();
    for i in 0..=count {
        let x = i as f32 / count as f32 * 2.0 - 1.0;
        positions.push(Vec3::new(x, 0.0, -0.1));
        positions.push(Vec3::new(x, 0.0, 0.1));
    }
    // Quads in the order 0, count-1, 1, count-2, ...: neighbours in the strip are far apart in index.
    let mut indices = Vec::new();
    for k in 0..count {
        let i = if k % 2 == 0 { k / 2 } else { count - 1 - k / 2 } as u32;
        let (a, b, c, d) = (2 * i, 2 * i + 1, 2 * i + 2, 2 * i + 3);
        indices.extend_from_slice(&[a, b, d, a, d, c]);
    }
    let strip = Mesh::with_generated_normals("strip", positions, indices);
    let mut scene = builtin("parallel-square").unwrap().build();
    scene.meshes.push(strip);
    let occluder = scene.instances.iter_mut().find(|i| i.role == Role::Occluder).unwrap();
    occluder.mesh = scene.meshes.len() - 1;
    let regions = diagnostic(&scene, &[], "silhouette_regions");
    let rounds = diagnostic(&scene, &[], "label_rounds");
    println!("strip of {count} quads: {regions} region(s) after {rounds} rounds");
    assert_eq!(regions, 1.0);
    assert!(rounds >= 2.0, "the order must need more than one round: {rounds}");
}

/// A closed mesh spoiled every way the rule covers: its top cut away (a bowl: open edges, and
/// light enters it to meet faces turned away from the light, which a volume of the faces
/// turned towards the light alone would let through), a triangle duplicated with the other
/// winding (edges of three faces), collapsed triangles and a sliver, and a duplicate vertex.
/// Its component becomes two-sided; the shadow of a point light still equals the exact one (no
/// light leaks through the stencil), and an area light gives finite visibility in [0, 1].
#[test]
fn open_non_manifold_and_degenerate_meshes_follow_the_two_sided_rule() {
    let ball = primitives::sphere("ball", 0.5, 24, 12);
    let mut indices: Vec<u32> =
        ball.triangles().filter(|t| t.iter().map(|i| ball.positions[*i as usize].y).sum::<f32>() / 3.0 < 0.3).flatten().collect();
    // An edge of three faces: a face again, with the other winding.
    indices.extend_from_slice(&[indices[90], indices[92], indices[91]]);
    // Collapsed triangles (a point, a line) and a sliver, on existing vertices.
    let (p, q) = (indices[100], indices[101]);
    indices.extend_from_slice(&[p, p, p, p, q, q, p, q, p]);
    let mut positions = ball.positions.clone();
    // A duplicate vertex: the same position twice, welded by the adjacency.
    positions.push(ball.positions[indices[30] as usize]);
    indices.extend_from_slice(&[indices[31], indices[32], positions.len() as u32 - 1]);
    let spoiled = Mesh::with_generated_normals("spoiled", positions, indices);
    let adjacency = ssm_scene::Adjacency::of(&spoiled);
    let report = ssm_wedges::CastingMesh::prepare(&adjacency).report;
    assert!(report.open_edges > 0 && report.non_manifold_edges > 0 && report.collapsed_faces > 0, "{report:?}");
    assert_eq!(report.two_sided_components, 1);

    let mut scene = builtin("floating-sphere").unwrap().build();
    scene.meshes.push(spoiled);
    let instance = scene.instances.iter_mut().find(|i| i.role == Role::Occluder).unwrap();
    instance.mesh = scene.meshes.len() - 1;
    instance.transform = Mat4::from_rotation_translation(Quat::from_rotation_z(0.3), Vec3::new(0.0, 1.4, 0.0));
    let area = wedges(&scene, &[]);
    assert!(area.visibility.iter().all(|v| v.is_finite() && (0.0..=1.0).contains(v)));
    let truth = reference(&gpu(), &scene, 16, SIZE);
    let (_, mae) = errors_against_reference(&truth, &area);
    println!("spoiled sphere, area light: penumbra MAE {mae:.4}");
    assert!(mae < 0.1, "{mae}");
    scene.lights[0].half_size = Vec2::ZERO;
    let point = wedges(&scene, &[]);
    let exact = reference(&gpu(), &scene, 1, SIZE);
    let wrong = disagreement(&point, &exact.visibility);
    println!("spoiled sphere, point light: {:.3}% of pixels differ from the exact hard shadow", wrong * 100.0);
    assert!(wrong < 0.003, "{wrong}");
}

/// A non-manifold fin (three triangles on one edge) and a lone triangle, as the only occluders:
/// the union of their faces' prisms is the exact hard shadow.
#[test]
fn a_fin_of_three_faces_on_one_edge_casts_its_exact_hard_shadow() {
    let fin = Mesh::with_generated_normals(
        "fin",
        vec![
            Vec3::new(-0.5, 0.0, 0.0),
            Vec3::new(0.5, 0.0, 0.0),
            Vec3::new(0.0, 0.4, 0.3),
            Vec3::new(0.0, -0.3, 0.4),
            Vec3::new(0.0, 0.1, -0.5),
        ],
        vec![0, 1, 2, 1, 0, 3, 0, 1, 4],
    );
    let mut scene = builtin("parallel-square").unwrap().build();
    scene.lights[0].half_size = Vec2::ZERO;
    scene.meshes.push(fin);
    let occluder = scene.instances.iter_mut().find(|i| i.role == Role::Occluder).unwrap();
    occluder.mesh = scene.meshes.len() - 1;
    occluder.transform = Mat4::from_rotation_translation(Quat::from_rotation_y(0.4), Vec3::new(0.2, 2.0, 0.1));
    let rendered = wedges(&scene, &[]);
    let exact = reference(&gpu(), &scene, 1, SIZE);
    let wrong = disagreement(&rendered, &exact.visibility);
    let shadowed = rendered.covered_visibility().iter().filter(|v| **v < 0.5).count();
    println!("fin: {shadowed} shadowed pixels, {:.3}% differ from the exact hard shadow", wrong * 100.0);
    assert!(shadowed > 100);
    assert!(wrong < 0.003, "{wrong}");
}

/// The camera inside a shadow volume (under the occluder, in its umbra, looking down): z-fail
/// counts only what lies behind the surfaces, so the umbra stays dark and the penumbra is right.
#[test]
fn the_camera_inside_a_shadow_volume_sees_the_right_shadow() {
    let text = r#"
[camera]
position = [0.1, 1.0, 0.2]
target = [0.6, 0.0, 0.4]
fov_y_degrees = 80.0
near = 0.01
[[light]]
centre = [0.0, 4.0, 0.0]
normal = [0.0, -1.0, 0.0]
size = [1.0, 1.0]
[[object]]
primitive = "box"
size = [1.2, 0.2, 1.2]
translate = [0.0, 2.0, 0.0]
role = "occluder"
[[object]]
primitive = "plane"
size = [8.0, 8.0]
role = "receiver"
"#;
    let scene = scene_from_manifest(text);
    let truth = reference(&gpu(), &scene, 16, SIZE);
    let rendered = wedges(&scene, &[]);
    let (signed, mae) = errors_against_reference(&truth, &rendered);
    let umbra = at(&rendered, pixel_of(&scene, SIZE.0, SIZE.1, Vec3::new(0.1, 0.0, 0.1)));
    println!("camera inside the volume: umbra reads {umbra}, penumbra MAE {mae:.4}, mean signed penumbra error {signed:.4}");
    assert!(umbra < 0.02, "{umbra}");
    assert!(mae < 0.03, "{mae}");
    let mut point = scene.clone();
    point.lights[0].half_size = Vec2::ZERO;
    let wrong = disagreement(&wedges(&point, &[]), &reference(&gpu(), &point, 1, SIZE).visibility);
    assert!(wrong < 0.003, "{wrong}");
}

/// Occluders that the stencil counts many times over (a stack of 40 leaves in one column, each
/// two-sided, all in one silhouette buffer): the count (8 bits, wrapping at 256) stays exact, and
/// a point light's shadow is the exact hard shadow.
#[test]
fn a_stack_of_overlapping_occluders_keeps_an_exact_stencil_count() {
    let mut scene = builtin("parallel-square").unwrap().build();
    scene.lights[0].half_size = Vec2::ZERO;
    let leaf = scene.instances.iter().find(|i| i.role == Role::Occluder).unwrap().mesh;
    for k in 0..40 {
        scene.instances.push(Instance {
            name: format!("leaf-{k}"),
            mesh: leaf,
            transform: Mat4::from_translation(Vec3::new(0.01 * k as f32, 1.0 + 0.05 * k as f32, 0.02 * k as f32)),
            role: Role::Occluder,
        });
    }
    let rendered = wedges(&scene, &[("silhouette_buffers", "1")]);
    let exact = reference(&gpu(), &scene, 1, SIZE);
    let wrong = disagreement(&rendered, &exact.visibility);
    let centre = at(&rendered, pixel_of(&scene, SIZE.0, SIZE.1, Vec3::ZERO));
    println!("41 stacked leaves, point light: centre {centre}, {:.3}% of pixels differ from the exact hard shadow", wrong * 100.0);
    assert_eq!(centre, 0.0);
    assert!(wrong < 0.003, "{wrong}");
}
