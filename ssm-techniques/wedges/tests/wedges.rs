//! Penumbra wedges (`wedges`) against the exact answer and against the
//! claims of Forest et al. 2006: the integration is exact for one silhouette,
//! a point light gives the hard shadow of the volumes, the blending removes
//! the over-darkening where penumbrae overlap, and the stated rule for meshes
//! that are not closed (two-sided components) never leaks light.

// Test helpers unwrap too: a failure should stop the test where it happens.
#![allow(clippy::unwrap_used, clippy::expect_used)]

use glam::{DVec3, Mat4, Quat, Vec2, Vec3};
use ssm_core::metrics::{ShadowClass, classify, compare};
use ssm_scene::{Instance, Mesh, Role, Scene, builtin, primitives};
use ssm_testing::{Rendered, at, gpu, parallel_square_exact, penumbra_mask, pixel_of, reference, render, scene_from_manifest};

const SIZE: (u32, u32) = (160, 120);

fn wedges(scene: &Scene, settings: &[(&str, &str)]) -> Rendered {
    render(&gpu(), scene, &ssm_wedges::INFO, settings, SIZE.0, SIZE.1).unwrap()
}

/// The point the stencil test and the wedges judge at a pixel showing surface point `p` (its
/// normal towards the camera `normal`): `p` moved along the view ray until its NDC depth has moved
/// by the depth copy's bias, towards the side of the surface facing the light's centre. Found
/// here by bisection on the camera's own projection (in f64), not by the shader's closed form.
fn judged_point(scene: &Scene, (width, height): (u32, u32), p: Vec3, normal: Vec3) -> DVec3 {
    let view_proj = (scene.camera.projection(width as f32 / height as f32) * scene.camera.view()).as_dmat4();
    let eye = scene.camera.position.as_dvec3();
    let towards_camera = normal.dot(scene.lights[0].centre - p) >= 0.0;
    let offset = f64::from(if towards_camera { -ssm_wedges::DEPTH_BIAS } else { ssm_wedges::DEPTH_BIAS });
    let p = p.as_dvec3();
    let target = view_proj.project_point3(p).z + offset;
    let along = |s: f64| eye + (p - eye) * s;
    // NDC depth grows with s along the ray (a perspective projection, depth in [0, 1]).
    let (mut low, mut high) = (0.5, 2.0);
    for _ in 0..200 {
        let middle = 0.5 * (low + high);
        if view_proj.project_point3(along(middle)).z < target { low = middle } else { high = middle }
    }
    along(0.5 * (low + high))
}

/// The exact visibility of `parallel-square` at any point below the occluder (y < 2): the
/// occluder [-0.5, 0.5]² at y = 2 seen from (x, y, z) projects onto the light plane y = 4 with
/// the scale k = (4 - y) / (2 - y) about (x, z), that is onto x (1 - k) ± 0.5 k (and the same in
/// z); the hidden fraction of the unit light [-0.5, 0.5]² is the product of the two 1-D
/// overlaps ([`parallel_square_exact`] at y = 0, where k = 2).
fn parallel_square_exact_at(p: DVec3) -> f64 {
    let k = (4.0 - p.y) / (2.0 - p.y);
    let overlap = |c: f64| ((c * (1.0 - k) + 0.5 * k).min(0.5) - (c * (1.0 - k) - 0.5 * k).max(-0.5)).max(0.0);
    1.0 - overlap(p.x) * overlap(p.z)
}

/// Penumbra MAEs over the ground's penumbra of `parallel-square`: against the exact visibility at
/// the point the stencil and the wedges judged (the integration's own error), and against the
/// exact visibility of the surface point itself (what the depth bias adds).
fn parallel_square_errors(scene: &Scene, rendered: &Rendered) -> (f64, f64) {
    let size = (rendered.renderer.width(), rendered.renderer.height());
    let positions = rendered.renderer.read_positions().unwrap();
    let normals = rendered.renderer.read_normals().unwrap();
    let exact_at_surface = rendered.parallel_square_exact();
    let exact_at_judged: Vec<f32> = positions
        .iter()
        .zip(&normals)
        .map(|(p, n)| {
            if p[3] > 0.5 && p[1].abs() < 1e-3 {
                let judged = judged_point(scene, size, Vec3::new(p[0], p[1], p[2]), Vec3::new(n[0], n[1], n[2]));
                parallel_square_exact_at(judged) as f32
            } else {
                1.0
            }
        })
        .collect();
    let covered = rendered.coverage();
    let mae = |exact: &[f32]| compare(exact, &rendered.visibility, &covered, size.0 as usize, size.1 as usize).mae_penumbra;
    (mae(&exact_at_judged), mae(&exact_at_surface))
}

/// A scene's diagnostics after one frame.
fn diagnostics(scene: &Scene, settings: &[(&str, &str)]) -> std::collections::HashMap<String, f64> {
    let gpu = gpu();
    let params = ssm_wedges::INFO.params_from(settings.iter().copied()).unwrap();
    let needs = (ssm_wedges::INFO.requirements)(&params).unwrap();
    let mut renderer = ssm_core::Renderer::new(&gpu, scene, SIZE.0, SIZE.1, &needs).unwrap();
    let mut technique = renderer.create_technique(&ssm_wedges::INFO, &params).unwrap();
    renderer.render(technique.as_mut(), "wedges").unwrap();
    technique.diagnostics(&gpu).into_iter().collect()
}

/// A scene's diagnostic by name.
fn diagnostic(scene: &Scene, settings: &[(&str, &str)], name: &str) -> f64 {
    *diagnostics(scene, settings).get(name).unwrap_or_else(|| panic!("no diagnostic {name}"))
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

/// Asserts that a hard shadow differs from the exact one (a one-ray ground truth at the same
/// points) only at pixels on the exact shadow's boundary (a pixel with one of its eight
/// neighbours on the other side): there the volumes' rasterisation and the ray's test judge
/// points a rounding apart, anywhere else a difference is a wrong volume. Returns the share of
/// covered pixels that differ.
fn assert_exact_hard_shadow(name: &str, rendered: &Rendered, exact: &[f32]) -> f64 {
    let (width, height) = (rendered.renderer.width() as i64, rendered.renderer.height() as i64);
    let covered = rendered.coverage();
    let lit = |x: i64, y: i64| exact[(y * width + x) as usize] > 0.5;
    let mut off_boundary = Vec::new();
    for y in 0..height {
        for x in 0..width {
            let i = (y * width + x) as usize;
            if !covered[i] || (rendered.visibility[i] - exact[i]).abs() <= 0.5 {
                continue;
            }
            let boundary = (-1..=1)
                .flat_map(|dy| (-1..=1).map(move |dx| (x + dx, y + dy)))
                .any(|(nx, ny)| (0..width).contains(&nx) && (0..height).contains(&ny) && lit(nx, ny) != lit(x, y));
            if !boundary {
                off_boundary.push((x, y));
            }
        }
    }
    assert!(off_boundary.is_empty(), "{name}: pixels off the shadow's boundary differ from the exact hard shadow: {off_boundary:?}");
    disagreement(rendered, exact)
}

/// One silhouette, no overlap: the wedges' integration from the light's centre is exact
/// (Assarsson and Akenine-Möller 2003; Fig. 4), so both blendings match the exact visibility at
/// the point they judge (the surface point moved by the depth copy's bias along the view ray).
#[test]
fn parallel_square_matches_the_exact_visibility_with_both_blendings() {
    let scene = builtin("parallel-square").unwrap().build();
    for blending in ["none", "forest"] {
        let rendered = wedges(&scene, &[("blending", blending)]);
        let (error, at_surface) = parallel_square_errors(&scene, &rendered);
        let exact = rendered.parallel_square_exact();
        let penumbra = penumbra_mask(&exact).iter().filter(|p| **p).count();
        println!(
            "parallel-square, blending={blending}: penumbra MAE {error:.2e} at the judged points, {at_surface:.2e} at the surface points, over {penumbra} penumbra pixels"
        );
        assert!(penumbra > 500, "the test needs a penumbra: {penumbra}");
        // f32 rounding: coordinates of order 1 (2^-24 relative) through a few dozen operations.
        assert!(error < 1e-6, "blending={blending}: penumbra MAE {error}");
    }
    assert_eq!((parallel_square_exact(0.0, 0.0), parallel_square_exact(1.0, 0.0)), (0.0, 0.5));
    assert_eq!(parallel_square_exact_at(DVec3::new(0.3, 0.0, -0.2)), f64::from(parallel_square_exact(0.3, -0.2)));
}

/// The rule for open meshes: the square is two-sided, so it casts the same shadow whichever way
/// its faces are wound (here turned upside down, its faces away from the light).
#[test]
fn an_open_mesh_casts_the_same_shadow_whichever_side_faces_the_light() {
    let mut scene = builtin("parallel-square").unwrap().build();
    let occluder = scene.instances.iter_mut().find(|i| i.role == Role::Occluder).unwrap();
    occluder.transform = Mat4::from_translation(Vec3::new(0.0, 2.0, 0.0)) * Mat4::from_rotation_x(std::f32::consts::PI);
    let (error, _) = parallel_square_errors(&scene, &wedges(&scene, &[]));
    println!("parallel-square, occluder facing away from the light: penumbra MAE {error:.2e}");
    // As above.
    assert!(error < 1e-6, "{error}");
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
        let wrong = assert_exact_hard_shadow(name, &rendered, &exact.visibility);
        let penumbra = rendered.covered_visibility().iter().filter(|v| **v > 0.0 && **v < 1.0).count();
        let hard = render(&gpu, &scene, &ssm_hard::INFO, &[], SIZE.0, SIZE.1).unwrap();
        let hard_wrong = disagreement(&hard, &exact.visibility);
        println!(
            "{name}, point light: {:.3}% of pixels differ from the exact hard shadow (shadow map: {:.3}%)",
            wrong * 100.0,
            hard_wrong * 100.0
        );
        assert_eq!(penumbra, 0, "{name}: a point light casts no penumbra");
        // Exact volumes against a 2048² map's texels: never more wrong pixels.
        assert!(wrong <= hard_wrong, "{name}: volumes {wrong} against a shadow map's {hard_wrong}");
    }
}

/// Mean signed error over the ground truth's penumbra split into its parts: the sum of the
/// positive errors (too light) and of the negative ones (too dark), each divided by the
/// penumbra's pixels, so that the two add up to the mean signed error.
fn light_and_dark_parts(truth: &Rendered, rendered: &Rendered) -> (f64, f64) {
    let classes = classify(&truth.visibility, &rendered.coverage());
    let errors: Vec<f64> = classes
        .iter()
        .zip(&rendered.visibility)
        .zip(&truth.visibility)
        .filter(|((class, _), _)| **class == ShadowClass::Penumbra)
        .map(|((_, v), r)| f64::from(v - r))
        .collect();
    let count = errors.len().max(1) as f64;
    (errors.iter().filter(|e| **e > 0.0).sum::<f64>() / count, errors.iter().filter(|e| **e < 0.0).sum::<f64>() / count)
}

/// Forest et al., Figs. 1 and 2: where the penumbrae of many silhouettes overlap, the plain
/// penumbra wedges (Akenine-Möller and Assarsson: one visibility buffer, `blending=none
/// silhouette_buffers=1`) count overlapping occlusion twice, too dark where outer wedges add
/// over each other, and too light where inner wedges subtract twice from one umbra (a single
/// stencil test covers every silhouette). The paper claims that the blending significantly
/// reduces the error; the test asserts that it halves the penumbra error and the too-light part,
/// and lessens the too-dark part (part of which is the blending's own estimate, Sec. 6).
#[test]
fn forest_blending_halves_the_error_of_the_plain_wedges_where_penumbrae_overlap() {
    let scene = builtin("sphere-cube").unwrap().build();
    let truth = reference(&gpu(), &scene, 16, SIZE);
    let plain = wedges(&scene, &[("blending", "none"), ("silhouette_buffers", "1")]);
    let forest = wedges(&scene, &[("blending", "forest")]);
    let (plain_signed, plain_mae) = errors_against_reference(&truth, &plain);
    let (forest_signed, forest_mae) = errors_against_reference(&truth, &forest);
    let (plain_light, plain_dark) = light_and_dark_parts(&truth, &plain);
    let (forest_light, forest_dark) = light_and_dark_parts(&truth, &forest);
    println!(
        "sphere-cube: penumbra MAE plain {plain_mae:.4}, forest {forest_mae:.4}; mean signed penumbra error plain {plain_signed:+.4} \
         ({plain_light:+.4} too light, {plain_dark:+.4} too dark), forest {forest_signed:+.4} ({forest_light:+.4}, {forest_dark:+.4})"
    );
    // The plain wedges' two errors are there to remove: each is beyond what the ground truth's
    // noise could make (its mean over the penumbra is far smaller than one pixel's noise).
    let noise = penumbra_pixel_noise();
    assert!(plain_light > noise && plain_dark < -noise, "plain wedges: {plain_light} too light, {plain_dark} too dark");
    assert!(forest_mae < 0.5 * plain_mae, "forest {forest_mae} against plain {plain_mae}");
    assert!(forest_light < 0.5 * plain_light, "too light: forest {forest_light} against plain {plain_light}");
    assert!(forest_dark > plain_dark, "too dark: forest {forest_dark} against plain {plain_dark}");
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
    println!("one buffer: forest and none differ by up to {worst}");
    // The same arithmetic but for the order in which the blending units add a pixel's wedge
    // fragments (a few dozen here, a rounding of 2^-24 each).
    assert!(worst < 1e-5, "{worst}");
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
    // Each sphere is convex: one stencil level per sphere, ⌈125 / 16⌉ = 8 in the fullest of 16
    // buffers (counting its cap faces would say 870), 125 in one.
    let found = diagnostics(&cube, &[]);
    assert_eq!((found["stencil_levels_bound"], found["stencil_may_wrap"]), (8.0, 0.0));
    assert_eq!(diagnostic(&cube, &[("silhouette_buffers", "1")], "stencil_levels_bound"), 125.0);
    // Without a wedge fragment a pixel reads 0 or 1: every penumbra pixel ran at least one.
    let penumbra = wedges(&cube, &[]).covered_visibility().iter().filter(|v| **v > 0.0 && **v < 1.0).count();
    let fragments = diagnostic(&cube, &[], "wedge_fragments");
    println!("sphere-cube: {fragments} wedge fragments, {penumbra} penumbra pixels");
    assert!(penumbra > 0 && fragments >= penumbra as f64, "{fragments} fragments for {penumbra} penumbra pixels");
    // The passes: silhouettes, depth copy, four per buffer, resolve.
    assert_eq!(diagnostic(&cube, &[("silhouette_buffers", "8")], "passes"), 3.0 + 4.0 * 8.0);
}

/// A strip of quads along x whose faces, in path order along the strip (each quad's two
/// triangles, then the next quad's), get the face indices `label(position)` (a permutation).
fn strip_with_face_order(quads: usize, label: impl Fn(usize) -> usize) -> Mesh {
    let mut positions = Vec::new();
    for i in 0..=quads {
        let x = i as f32 / quads as f32 * 2.0 - 1.0;
        positions.push(Vec3::new(x, 0.0, -0.1));
        positions.push(Vec3::new(x, 0.0, 0.1));
    }
    let mut by_label = vec![[0u32; 3]; 2 * quads];
    for position in 0..2 * quads {
        let i = (position / 2) as u32;
        let (a, b, c, d) = (2 * i, 2 * i + 1, 2 * i + 2, 2 * i + 3);
        // (a, b, d) then (a, d, c): the diagonal a-d joins them, the edge c-d the next quad's first.
        by_label[label(position)] = if position % 2 == 0 { [a, b, d] } else { [a, d, c] };
    }
    Mesh::with_generated_normals("strip", positions, by_label.concat())
}

/// `parallel-square` with `mesh` in place of its occluder.
fn parallel_square_with_occluder(mesh: Mesh) -> Scene {
    let mut scene = builtin("parallel-square").unwrap().build();
    scene.meshes.push(mesh);
    let occluder = scene.instances.iter_mut().find(|i| i.role == Role::Occluder).unwrap();
    occluder.mesh = scene.meshes.len() - 1;
    scene
}

/// A long strip of quads, numbered from both ends inwards, so that its faces' labels meet in the
/// middle after several rounds: still one region and one loop.
#[test]
fn label_propagation_joins_a_long_strip_into_one_region() {
    let count = 400usize;
    // Quads in the order 0, count-1, 1, count-2, ...: neighbours in the strip are far apart in index.
    let quad_rank = |i: usize| if i < count.div_ceil(2) { 2 * i } else { 2 * (count - 1 - i) + 1 };
    let scene = parallel_square_with_occluder(strip_with_face_order(count, |p| 2 * quad_rank(p / 2) + p % 2));
    let found = diagnostics(&scene, &[]);
    let (regions, rounds, capped) = (found["silhouette_regions"], found["label_rounds"], found["label_rounds_capped"]);
    println!("strip of {count} quads: {regions} region(s) after {rounds} rounds (capped: {capped})");
    assert_eq!(regions, 1.0);
    assert!(rounds >= 2.0, "the order must need more than one round: {rounds}");
    assert_eq!(capped, 0.0);
}

/// Hooking the larger label to the smaller and jumping to the roots leaves, each round, only the
/// labels smaller than all their neighbours' as roots, at most every other one along a strip: a
/// strip of 2^k faces labelled in ruler order (the faces at odd positions largest, then those at
/// positions 2 mod 4, and so on) needs k rounds when every thread of a round reads the labels of
/// the round before. Threads that read a label lowered earlier in the same round go faster: on
/// lavapipe k − 2 rounds (14, 15 and 16 for k = 16, 17, 18). At k = 18 every one of the 16
/// recorded rounds links labels, and the diagnostic says that the cap was reached.
#[test]
fn label_propagation_reports_reaching_its_round_cap() {
    let faces = 1usize << 18;
    // Path positions sorted by how many times 2 divides position + 1, most first: label order.
    let mut order: Vec<usize> = (0..faces).collect();
    order.sort_by_key(|p| (std::cmp::Reverse((p + 1).trailing_zeros()), *p));
    let mut label = vec![0; faces];
    for (l, p) in order.iter().enumerate() {
        label[*p] = l;
    }
    let mut scene = parallel_square_with_occluder(strip_with_face_order(faces / 2, |p| label[p]));
    // A point light: no wedges to draw, the labels are what the test is about.
    scene.lights[0].half_size = Vec2::ZERO;
    let found = diagnostics(&scene, &[]);
    let (regions, rounds, capped) = (found["silhouette_regions"], found["label_rounds"], found["label_rounds_capped"]);
    println!("strip of {faces} faces in ruler order: {regions} region(s) after {rounds} rounds (capped: {capped})");
    assert_eq!(rounds, f64::from(ssm_wedges::MAX_LABEL_ROUNDS));
    assert_eq!(capped, 1.0);
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
    // Values not finite or outside [0, 1] fail the readback (Error::InvalidOutput).
    let area = wedges(&scene, &[]);
    let truth = reference(&gpu(), &scene, 16, SIZE);
    let (_, mae) = errors_against_reference(&truth, &area);
    let error = f64::from(ssm_testing::mean_abs_difference(&truth.visibility, &area.visibility, &area.coverage()));
    println!("spoiled sphere, area light: mean |error| {error:.4}, penumbra MAE {mae:.4}");
    // The extremes matrix's bound: a two-sided bowl is one silhouette region with overlapping
    // inner and outer rims, not a case the wedges are exact for. Over the penumbra and umbra alone
    // too (stricter: a leak under the bowl is a small share of the image).
    assert!(error < 0.1 && mae < 0.1, "mean |error| {error}, penumbra MAE {mae}");
    scene.lights[0].half_size = Vec2::ZERO;
    let point = wedges(&scene, &[]);
    let exact = reference(&gpu(), &scene, 1, SIZE);
    let wrong = assert_exact_hard_shadow("spoiled sphere", &point, &exact.visibility);
    println!("spoiled sphere, point light: {:.3}% of pixels differ from the exact hard shadow", wrong * 100.0);
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
    let wrong = assert_exact_hard_shadow("fin", &rendered, &exact.visibility);
    let shadowed = rendered.covered_visibility().iter().filter(|v| **v < 0.5).count();
    println!("fin: {shadowed} shadowed pixels, {:.3}% differ from the exact hard shadow", wrong * 100.0);
    assert!(shadowed > 100);
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
    let (error, truth, rendered) = mean_error_against_reference(&scene, &[]);
    let (signed, mae) = errors_against_reference(&truth, &rendered);
    let umbra = at(&rendered, pixel_of(&scene, SIZE.0, SIZE.1, Vec3::new(0.1, 0.0, 0.1)));
    println!("camera inside the volume: umbra reads {umbra}, penumbra MAE {mae:.4}, mean signed penumbra error {signed:.4}");
    // The box seen from (0.1, 0, 0.1) covers the whole light: exactly 0.
    assert_eq!(umbra, 0.0);
    // One convex box, one silhouette loop (its top's rim, from every point of the light): exact
    // but for the ground truth's noise.
    assert_within_sampling_noise("camera inside the volume", error, &truth);
    let mut point = scene.clone();
    point.lights[0].half_size = Vec2::ZERO;
    assert_exact_hard_shadow("camera inside the volume", &wedges(&point, &[]), &reference(&gpu(), &point, 1, SIZE).visibility);
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
    let wrong = assert_exact_hard_shadow("41 stacked leaves", &rendered, &exact.visibility);
    let centre = at(&rendered, pixel_of(&scene, SIZE.0, SIZE.1, Vec3::ZERO));
    println!("41 stacked leaves, point light: centre {centre}, {:.3}% of pixels differ from the exact hard shadow", wrong * 100.0);
    assert_eq!(centre, 0.0);
    // The count's bound for two-sided faces is the buffer's cap faces, two per leaf: 82, no wrap possible.
    let found = diagnostics(&scene, &[("silhouette_buffers", "1")]);
    assert_eq!((found["stencil_levels_bound"], found["stencil_may_wrap"]), (82.0, 0.0));
    // 128 leaves (256 faces) could wrap the 8-bit count: reported.
    for k in 40..127 {
        scene.instances.push(Instance {
            name: format!("leaf-{k}"),
            mesh: leaf,
            transform: Mat4::from_translation(Vec3::new(0.0, 1.0 + 0.008 * k as f32, 0.0)),
            role: Role::Occluder,
        });
    }
    let found = diagnostics(&scene, &[("silhouette_buffers", "1")]);
    assert_eq!((found["stencil_levels_bound"], found["stencil_may_wrap"]), (256.0, 1.0));
}

/// The 16×16-ray ground truth's sampling noise on one penumbra pixel, at two standard
/// deviations. A pixel whose light is all seen or all hidden has no noise. In a penumbra pixel,
/// the image of a straight edge on the light crosses at most 31 of the 16 × 16 strata; each
/// holds one jittered ray of weight 1/256, a Bernoulli sample, so the estimate's standard
/// deviation is at most √(31/4)/256 = 0.011.
fn penumbra_pixel_noise() -> f64 {
    2.0 * (31.0f64 / 4.0).sqrt() / 256.0
}

/// The mean |error| over covered pixels that the ground truth's own noise accounts for where the
/// wedges are exact (one silhouette loop, no overlap): [`penumbra_pixel_noise`] times the share
/// of penumbra pixels. An umbra leak or a misplaced volume costs 1 a pixel and exceeds it within
/// a few dozen pixels.
fn sampling_noise(truth: &Rendered) -> f64 {
    let covered = truth.covered_visibility();
    let penumbra = covered.iter().filter(|v| **v > 0.0 && **v < 1.0).count() as f64 / covered.len() as f64;
    penumbra * penumbra_pixel_noise()
}

/// Asserts that `error` (a mean |error| over covered pixels) is within [`sampling_noise`].
fn assert_within_sampling_noise(name: &str, error: f64, truth: &Rendered) {
    let bound = sampling_noise(truth);
    println!("{name}: mean |error| {error:.4} against the ground truth's sampling noise {bound:.4}");
    assert!(error < bound, "{name}: mean |error| {error} above the ground truth's sampling noise {bound}");
}

/// Mean |error| over the covered pixels against a 16×16-ray ground truth (the extremes matrix's
/// metric), with the truth and the rendering for further checks.
fn mean_error_against_reference(scene: &Scene, settings: &[(&str, &str)]) -> (f64, Rendered, Rendered) {
    let gpu = gpu();
    let truth = reference(&gpu, scene, 16, SIZE);
    let rendered = wedges(scene, settings);
    let covered = rendered.coverage();
    let error = f64::from(ssm_testing::mean_abs_difference(&truth.visibility, &rendered.visibility, &covered));
    (error, truth, rendered)
}

/// A light inside a container resting on the ground, seen from outside: `container` is the
/// object's manifest lines (primitive, size, transform), `normal` the light's.
fn light_in_a_container(container: &str, normal: [f32; 3]) -> Scene {
    scene_from_manifest(&format!(
        r#"
[camera]
position = [0.0, 5.0, 7.0]
target = [0.0, 0.0, 0.0]
[[light]]
centre = [0.0, 0.8, 0.0]
normal = {normal:?}
size = [0.5, 0.5]
[[object]]
{container}
role = "both"
[[object]]
primitive = "plane"
size = [10.0, 10.0]
role = "receiver"
"#
    ))
}

/// The same scene with the container's mesh wound the other way (its faces turned inwards).
fn inverted_container(mut scene: Scene) -> Scene {
    let container = scene.instances.iter().find(|i| i.role == Role::Both).unwrap().mesh;
    let mesh = &mut scene.meshes[container];
    for triangle in mesh.indices.chunks_exact_mut(3) {
        triangle.swap(1, 2);
    }
    for normal in &mut mesh.normals {
        *normal = -*normal;
    }
    scene
}

/// The light sealed inside closed containers resting on the ground, the camera outside: every
/// face of each container is turned away from the light's centre, so there is no silhouette at
/// all, yet no light leaves it. The volume is closed by the faces turned away from the light
/// (the near cap) and their projections to infinity (the far cap): Sec. 3, 4.1 and z-fail's
/// caps. A box (the extremes matrix's case), a turned box with the light facing sideways, a
/// sphere with the light facing up, and a box wound inwards (its faces all turned towards the
/// light: the classic volume, which needs no inside test).
#[test]
fn a_light_sealed_in_a_closed_mesh_lights_nothing_outside_it() {
    let cases = [
        ("box", light_in_a_container("primitive = \"box\"\nsize = [2.0, 1.0, 2.0]\ntranslate = [0.0, 0.5, 0.0]", [0.0, -1.0, 0.0])),
        (
            "turned box, light facing sideways",
            light_in_a_container(
                "primitive = \"box\"\nsize = [2.0, 1.6, 1.5]\ntranslate = [0.0, 0.8, 0.0]\nrotate_degrees = [0.0, 30.0, 0.0]",
                [1.0, -0.2, 0.3],
            ),
        ),
        (
            "sphere, light facing up",
            light_in_a_container("primitive = \"sphere\"\nsize = [1.2]\ntranslate = [0.0, 1.0, 0.0]", [0.0, 1.0, 0.0]),
        ),
        (
            "box wound inwards",
            inverted_container(light_in_a_container(
                "primitive = \"box\"\nsize = [2.0, 1.0, 2.0]\ntranslate = [0.0, 0.5, 0.0]",
                [0.0, -1.0, 0.0],
            )),
        ),
    ];
    for (name, scene) in &cases {
        for blending in ["forest", "none"] {
            let (error, truth, rendered) = mean_error_against_reference(scene, &[("blending", blending)]);
            let ground = at(&rendered, pixel_of(scene, SIZE.0, SIZE.1, Vec3::new(3.0, 0.0, 2.0)));
            let lit = rendered.covered_visibility().iter().filter(|v| **v > 0.0).count();
            let truth_lit = truth.covered_visibility().iter().filter(|v| **v > 0.0).count();
            println!("{name}, blending={blending}: mean |error| {error:.5}, ground outside {ground}, {lit} lit pixels (truth {truth_lit})");
            assert_eq!(truth_lit, 0, "{name}: the ground truth sees no light outside a sealed container");
            // Exact: every covered pixel is outside the container (or its unlit outside) and the
            // umbra of a closed volume has no approximation in it.
            assert_eq!(lit, 0, "{name}, blending={blending}: light leaves the container (mean |error| {error})");
        }
    }
}

/// A closed mesh with a hole (a box with one wall missing, so an open mesh: two-sided) around
/// the light: the silhouette is only the hole's rim, and light leaves through the hole alone.
#[test]
fn a_light_in_a_box_with_a_hole_lights_the_ground_through_the_hole_only() {
    let mut scene = light_in_a_container("primitive = \"box\"\nsize = [2.0, 1.0, 2.0]\ntranslate = [0.0, 0.5, 0.0]", [0.3, -1.0, 0.0]);
    let container = scene.instances.iter().find(|i| i.role == Role::Both).unwrap().mesh;
    let mesh = &mut scene.meshes[container];
    // The cuboid's faces are two triangles each, in the order -x, +x, -y, +y, -z, +z: drop +x.
    mesh.indices.drain(6..12);
    let (error, truth, rendered) = mean_error_against_reference(&scene, &[]);
    let (_, mae) = errors_against_reference(&truth, &rendered);
    let beyond_hole = at(&rendered, pixel_of(&scene, SIZE.0, SIZE.1, Vec3::new(2.2, 0.0, 0.0)));
    let behind_wall = at(&rendered, pixel_of(&scene, SIZE.0, SIZE.1, Vec3::new(-2.5, 0.0, 0.0)));
    let regions = diagnostic(&scene, &[], "silhouette_regions");
    let loops = diagnostic(&scene, &[], "silhouette_loops");
    println!(
        "box with a hole: mean |error| {error:.4}, penumbra MAE {mae:.4}, ground beyond the hole {beyond_hole}, behind a wall {behind_wall}; {regions} region(s), {loops} loop(s)"
    );
    assert_eq!(behind_wall, 0.0);
    assert!(beyond_hole > 0.99, "{beyond_hole}");
    // The box is one region whose only silhouette is the hole's rim.
    assert_eq!((regions, loops), (1.0, 1.0));
    // One silhouette loop and no overlap: the wedges' integration is exact (the parallel-square
    // case), so what is left is the ground truth's noise.
    assert_within_sampling_noise("box with a hole", error, &truth);
}

/// The light and the camera inside a closed room (a box seen from inside), with a box of
/// furniture on its floor (the extremes matrix's case): the room's faces are all turned away
/// from the light, so they bound the volume; it lies outside the room, and the room stays lit
/// but for the furniture's shadow.
#[test]
fn a_light_inside_a_closed_room_lights_the_room_and_casts_the_furniture_shadow() {
    let manifest = |light: &str, furniture: &str| {
        format!(
            r#"
[camera]
position = [-2.5, 1.5, 2.5]
target = [0.5, 0.3, -0.5]
[[light]]
centre = {light}
normal = [0.0, -1.0, 0.0]
size = [0.8, 0.8]
[[object]]
primitive = "box"
size = [8.0, 3.0, 8.0]
translate = [0.0, 1.5, 0.0]
role = "both"
[[object]]
primitive = "box"
size = [1.0, 0.8, 1.0]
translate = {furniture}
role = "both"
"#
        )
    };
    let scene = scene_from_manifest(&manifest("[0.0, 2.7, 0.0]", "[0.5, 0.4, -0.5]"));
    let (error, truth, rendered) = mean_error_against_reference(&scene, &[]);
    let (_, mae) = errors_against_reference(&truth, &rendered);
    let floor = at(&rendered, pixel_of(&scene, SIZE.0, SIZE.1, Vec3::new(-1.5, 0.0, 1.5)));
    let wall = at(&rendered, pixel_of(&scene, SIZE.0, SIZE.1, Vec3::new(2.0, 1.5, -4.0)));
    println!("room: mean |error| {error:.4}, penumbra MAE {mae:.4}, open floor {floor}, back wall {wall}");
    assert!(floor > 0.99 && wall > 0.99, "the room is lit: floor {floor}, wall {wall}");
    // One convex occluder, one silhouette loop: exact but for the ground truth's noise. The furniture's two faces whose planes hold the light's centre (half the
    // light behind each) read 0.5 as they should: the wedges judge the point the stencil judged,
    // off the plane, not a point on it.
    assert_within_sampling_noise("room", error, &truth);
    // The umbra alone, with a point light behind the furniture (its shadow towards the camera):
    // the hard shadow of the volumes is exact up to rasterisation at its edge, as in the
    // point-light test.
    let mut point = scene_from_manifest(&manifest("[1.8, 2.7, -2.2]", "[0.5, 0.4, -0.5]"));
    point.lights[0].half_size = Vec2::ZERO;
    let rendered = wedges(&point, &[]);
    let wrong = assert_exact_hard_shadow("room", &rendered, &reference(&gpu(), &point, 1, SIZE).visibility);
    let shadowed = rendered.covered_visibility().iter().filter(|v| **v < 0.5).count();
    println!("room, point light: {shadowed} shadowed pixels, {:.3}% differ from the exact hard shadow", wrong * 100.0);
    assert!(shadowed > 100, "{shadowed}");
}

/// An L-shaped room, 3 high: the legs [0, 4] × [0, 2] and [0, 2] × [0, 4] in x and z, closed,
/// wound outwards, flat faces (each its own vertices, as the cuboid's), welded by the adjacency.
fn l_shaped_room() -> Mesh {
    let outline =
        [Vec2::new(0.0, 0.0), Vec2::new(4.0, 0.0), Vec2::new(4.0, 2.0), Vec2::new(2.0, 2.0), Vec2::new(2.0, 4.0), Vec2::new(0.0, 4.0)];
    let height = 3.0;
    let mut mesh = Mesh { name: "l-room".into(), ..Mesh::default() };
    // A flat polygon (a fan from its first corner), wound so that its normal is `normal`.
    let mut polygon = |corners: &[Vec3], normal: Vec3| {
        let base = mesh.positions.len() as u32;
        mesh.positions.extend_from_slice(corners);
        mesh.normals.extend(corners.iter().map(|_| normal));
        for k in 1..corners.len() as u32 - 1 {
            let (b, c) = (base + k, base + k + 1);
            let winding = (corners[k as usize] - corners[0]).cross(corners[k as usize + 1] - corners[0]).dot(normal);
            mesh.indices.extend_from_slice(&if winding > 0.0 { [base, b, c] } else { [base, c, b] });
        }
    };
    // Floor and ceiling: the fan from (0, 0) covers the L (every corner is seen from it).
    let at = |p: Vec2, y: f32| Vec3::new(p.x, y, p.y);
    polygon(&outline.map(|p| at(p, 0.0)), Vec3::NEG_Y);
    polygon(&outline.map(|p| at(p, height)), Vec3::Y);
    // Walls: the outline runs counter-clockwise seen from below (+z after +x), so each edge's
    // outward normal is its direction turned by (dx, dz) -> (dz, -dx).
    for k in 0..outline.len() {
        let (p, q) = (outline[k], outline[(k + 1) % outline.len()]);
        let d = q - p;
        polygon(&[at(p, 0.0), at(q, 0.0), at(q, height), at(p, height)], Vec3::new(d.y, 0.0, -d.x).normalize());
    }
    mesh
}

/// A closed, non-convex room around the light (an L, the light in one leg, the camera in the
/// other): the room's faces turned away from the light bound the volume, and its inner corner
/// is a silhouette whose penumbra crosses the other leg's floor. The faces turned away take
/// part turned to face the light, so the corner's wedge has the orientation of the classic
/// volume's (inner half towards the umbra): one silhouette loop, no overlap, so the
/// integration from the light's centre is exact (as on `parallel-square`).
#[test]
fn a_light_inside_a_non_convex_room_casts_the_inner_corner_penumbra() {
    let room = l_shaped_room();
    assert!(ssm_scene::Adjacency::of(&room).is_closed_manifold());
    let mut scene = scene_from_manifest(
        r#"
[camera]
position = [0.3, 2.2, 2.3]
target = [1.5, 0.0, 3.5]
fov_y_degrees = 80.0
near = 0.01
[[light]]
centre = [3.0, 2.7, 1.0]
normal = [0.0, -1.0, 0.0]
size = [0.8, 0.8]
[[object]]
primitive = "box"
size = [0.1, 0.1, 0.1]
role = "both"
"#,
    );
    scene.meshes[0] = room;
    let (error, truth, rendered) = mean_error_against_reference(&scene, &[]);
    let (signed, mae) = errors_against_reference(&truth, &rendered);
    let penumbra = truth.covered_visibility().iter().filter(|v| **v > 0.02 && **v < 0.98).count();
    let regions = diagnostic(&scene, &[], "silhouette_regions");
    println!(
        "L-shaped room: mean |error| {error:.4}, penumbra MAE {mae:.4}, mean signed penumbra error {signed:+.4}, {penumbra} penumbra pixels, {regions} region(s)"
    );
    assert!(penumbra > 500, "the case needs a penumbra: {penumbra}");
    assert_within_sampling_noise("L-shaped room", error, &truth);
}

/// Full HD: the final buffer's 80 bytes per pixel in one binding (165,888,000 bytes) exceeded
/// lavapipe's 128 MiB storage bindings and wgpu stopped with its validation text; split into
/// five bindings of 16 bytes per pixel it renders, and the one silhouette of `parallel-square`
/// is still exact (`plan.rs` checks 3840 × 2160 against the limits without rendering it).
/// At this size rows of pixels fall within the depth bias of the volume's sides: judged at the
/// surface point, the half-wedge there disagreed with the stencil and the sum was off by up to half
/// the light along a row of 370 pixels.
#[test]
fn full_hd_renders_and_stays_exact() {
    let scene = builtin("parallel-square").unwrap().build();
    let (width, height) = (1920, 1080);
    let started = std::time::Instant::now();
    let rendered = render(&gpu(), &scene, &ssm_wedges::INFO, &[], width, height).unwrap();
    let seconds = started.elapsed().as_secs_f64();
    let (error, at_surface) = parallel_square_errors(&scene, &rendered);
    let worst = rendered.visibility.iter().zip(rendered.parallel_square_exact()).map(|(v, e)| (v - e).abs()).fold(0.0f32, f32::max);
    let penumbra = penumbra_mask(&rendered.parallel_square_exact()).iter().filter(|p| **p).count();
    println!(
        "parallel-square at {width}×{height}: penumbra MAE {error:.2e} at the judged points, {at_surface:.2e} at the surface points (largest difference {worst:.2e}) over {penumbra} penumbra pixels, {seconds:.1} s"
    );
    assert!(penumbra > 100_000, "{penumbra}");
    // As at 160×120: f32 rounding.
    assert!(error < 1e-6, "{error}");
}

/// Forest et al.'s blending formulas (Sec. 3.2), checked against values worked out by hand for
/// one receiver point and three occluders in three silhouette buffers, all projecting into one
/// radial part of the light and none hiding its centre (no umbra).
///
/// Coordinates are the radial part's own (Sec. 4.2-4.3): the light is [-1, 1]², the part is
/// [0, 1]² (area 1, a quarter of the light), the centre at (0, 0). Each occluder lies in the plane
/// y = 2, parallel to the light (y = 4), so seen from the receiver point its image on the light
/// is itself scaled and moved: straight edges stay parallel to themselves.
///
/// - T1, a right triangle with corner a and legs of length L along +x and +y, inside the part:
///   its legs face the centre (outer half-wedges), its hypotenuse does not (inner). Occluded area
///   A1 = L²/2. The rectangle bounds what lies beyond the outer edges up to the light's border, as
///   seen from the centre: the corner a and the exits of the rays through the legs' ends, so
///   B1 = [a.x, 1] × [a.y, 1].
/// - T2, a triangle whose only edge crossing the light is x + y = s (its other edges lie beyond
///   the light's border): the edge clipped to the light runs from (s − 1, 1) to (1, s − 1), and
///   the occluded corner beyond it is a right triangle, A2 = (2 − s)²/2, B2 = [s − 1, 1]².
/// - S, a square with lower-left corner (x0, y0) and side w, y0 > x0 + w: outer edges left and
///   bottom, inner edges right and top. A3 = w². The left edge's rays leave the part through the
///   top border at x0/y0 and x0/(y0 + w), the bottom edge's at x0/y0 and (x0 + w)/y0, so
///   B3 = [x0, (x0 + w)/y0] × [y0, 1] (not the square's own box: only outer edges bound it,
///   inner ones adjust it only in an umbra, Fig. 10).
///
/// The blend, buffer by buffer in order: A_f ← A_f + A_s − ε, ε = (A_f / B_f)(A_s / B_s) β, β the
/// area of B_f ∩ B_s, and B_f ← B_f ∪ B_s (Sec. 3.2); the first buffer is copied. Visibility is
/// one minus the occluded share: the part is a quarter of the light, so V = 1 − A_f / 4. Plain
/// sums (`blending=none`) give V = 1 − (A1 + A2 + A3) / 4.
#[test]
fn forest_blending_follows_its_formulas_for_three_occluders_in_separate_buffers() {
    let mut scene = scene_from_manifest(
        r#"
[camera]
position = [0.3, 1.2, 0.5]
target = [0.0, 0.0, 0.0]
[[light]]
centre = [0.0, 4.0, 0.0]
normal = [0.0, -1.0, 0.0]
size = [1.0, 1.0]
[[object]]
primitive = "plane"
size = [8.0, 8.0]
role = "receiver"
"#,
    );
    let light = scene.lights[0];
    let (u, v, half) = (light.u_axis.as_dvec3(), light.v_axis.as_dvec3(), light.half_size.as_dvec2());
    let centre = light.centre.as_dvec3();
    // The design: radial-part coordinates seen from the origin, where the plane y = 2 is halfway
    // to the light: a point of the part maps to the occluder plane at half its light position.
    let occluder_point = |x: f64, y: f64| ((centre + u * (x * half.x) + v * (y * half.y)) * 0.5).as_vec3();
    let mut add = |name: &str, corners: &[(f64, f64)], indices: Vec<u32>| {
        let positions = corners.iter().map(|&(x, y)| occluder_point(x, y)).collect();
        scene.meshes.push(Mesh::with_generated_normals(name, positions, indices));
        scene.instances.push(Instance { name: name.into(), mesh: scene.meshes.len() - 1, transform: Mat4::IDENTITY, role: Role::Occluder });
    };
    add("t1", &[(0.2, 0.2), (0.9, 0.2), (0.2, 0.9)], vec![0, 1, 2]);
    add("t2", &[(0.3, 1.3), (1.3, 1.3), (1.3, 0.3)], vec![0, 1, 2]);
    add("s", &[(0.1, 0.7), (0.3, 0.7), (0.3, 0.9), (0.1, 0.9)], vec![0, 1, 2, 0, 2, 3]);

    let size = (33, 33);
    let gpu = gpu();
    let forest = render(&gpu, &scene, &ssm_wedges::INFO, &[("blending", "forest"), ("silhouette_buffers", "3")], size.0, size.1).unwrap();
    let none = render(&gpu, &scene, &ssm_wedges::INFO, &[("blending", "none"), ("silhouette_buffers", "3")], size.0, size.1).unwrap();
    // The receiver point: the G-buffer's point at the pixel showing the origin, moved as the
    // stencil and the wedges judge it; the occluders' images are worked out from it exactly.
    let pixel = pixel_of(&scene, size.0, size.1, Vec3::ZERO);
    let index = (pixel.1 * size.0 + pixel.0) as usize;
    let (position, normal) = (forest.renderer.read_positions().unwrap()[index], forest.renderer.read_normals().unwrap()[index]);
    let p = judged_point(&scene, size, Vec3::new(position[0], position[1], position[2]), Vec3::new(normal[0], normal[1], normal[2]));
    let image = |x: f64, y: f64| {
        let q = (centre + u * (x * half.x) + v * (y * half.y)) * 0.5;
        let on_light = p + (q - p) * ((4.0 - p.y) / (2.0 - p.y));
        ((on_light - centre).dot(u) / half.x, (on_light - centre).dot(v) / half.y)
    };
    let area = |r: [f64; 4]| (r[1] - r[0]).max(0.0) * (r[3] - r[2]).max(0.0);
    let intersection = |r: [f64; 4], s: [f64; 4]| [r[0].max(s[0]), r[1].min(s[1]), r[2].max(s[2]), r[3].min(s[3])];
    let union = |r: [f64; 4], s: [f64; 4]| [r[0].min(s[0]), r[1].max(s[1]), r[2].min(s[2]), r[3].max(s[3])];
    // T1: corner a, leg L.
    let a = image(0.2, 0.2);
    let leg = image(0.9, 0.2).0 - a.0;
    let (a1, b1) = (leg * leg / 2.0, [a.0, 1.0, a.1, 1.0]);
    // T2: the edge x + y = s.
    let s = image(0.3, 1.3).0 + image(0.3, 1.3).1;
    let (a2, b2) = ((2.0 - s).powi(2) / 2.0, [s - 1.0, 1.0, s - 1.0, 1.0]);
    // S: corner (x0, y0), side w.
    let (x0, y0) = image(0.1, 0.7);
    let w = image(0.3, 0.7).0 - x0;
    let (a3, b3) = (w * w, [x0, (x0 + w) / y0, y0, 1.0]);
    // The blend, buffers 0, 1, 2.
    let epsilon2 = (a1 / area(b1)) * (a2 / area(b2)) * area(intersection(b1, b2));
    let (final2, bound2) = (a1 + a2 - epsilon2, union(b1, b2));
    let epsilon3 = (final2 / area(bound2)) * (a3 / area(b3)) * area(intersection(bound2, b3));
    let final3 = final2 + a3 - epsilon3;
    let expected_forest = 1.0 - final3 / 4.0;
    let expected_none = 1.0 - (a1 + a2 + a3) / 4.0;
    let (got_forest, got_none) = (f64::from(at(&forest, pixel)), f64::from(at(&none, pixel)));
    println!(
        "A = {a1:.5}, {a2:.5}, {a3:.5}; B = {:.5}, {:.5}, {:.5}; eps = {epsilon2:.5}, {epsilon3:.5}; forest {got_forest:.6} (by hand {expected_forest:.6}, off by {:.1e}), none {got_none:.6} (by hand {expected_none:.6}, off by {:.1e})",
        area(b1),
        area(b2),
        area(b3),
        (got_forest - expected_forest).abs(),
        (got_none - expected_none).abs()
    );
    assert_eq!(diagnostics(&scene, &[("silhouette_buffers", "3")])["silhouette_regions"], 3.0);
    // The design's values, seen from the origin itself: A1 = 0.245, B1 = 0.64; A2 = 0.08, B2 = 0.16;
    // A3 = 0.04, B3 = (3/7 − 0.1) · 0.3; ε2 = 0.3828 · 0.5 · 0.16 = 0.0306.
    assert!((a1 - 0.245).abs() < 1e-3 && (area(b2) - 0.16).abs() < 1e-3 && (epsilon2 - 0.030625).abs() < 1e-3, "{a1} {b2:?} {epsilon2}");
    // f32 arithmetic on values of order 1 through the wedges' integration and the blend.
    assert!((got_forest - expected_forest).abs() < 1e-6, "forest: {got_forest} against {expected_forest}");
    assert!((got_none - expected_none).abs() < 1e-6, "none: {got_none} against {expected_none}");
    // The formula's estimate differs from the plain sum by ε2 + ε3 (a quarter of it in visibility).
    assert!((expected_forest - expected_none - (epsilon2 + epsilon3) / 4.0).abs() < 1e-12);
}
