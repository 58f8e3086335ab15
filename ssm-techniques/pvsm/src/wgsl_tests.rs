//! The paper's formulas as the shaders compute them. A few test entry points, appended to the filter
//! pass's own module (`pvsm_filter.wgsl` with `pvsm_common.wgsl`), evaluate its WGSL functions on
//! the GPU for given inputs; the tests compare them with values worked out by hand from the paper
//! (the appendix's convolution, Eqs. 4 and 5, Eq. 2's texels as quads) and with the CPU twins in
//! [`crate::prediction`] (ρ).

// Test helpers unwrap too: a failure should stop the test where it happens.
#![allow(clippy::unwrap_used, clippy::expect_used)]

use ssm_core::passes::{bind_group_layout, storage_entry, texture_entry, uniform_entry};
use ssm_core::{GpuContext, LightFrameUniform, Settings};

use crate::prediction::{self, DYNAMIC_PEAK, Prediction};
use crate::{FILTER_SHADER, LOCAL_SHADERS, PvsmSettings, PvsmSettingsUniform, TileSettingsUniform};

/// The test entry points. Inputs and outputs are `vec4<f32>`s; group 3's bindings 3 and 4 are free in
/// the filter module (0 and 1 hold the tile, 2 the resolve pass's target).
const TEST_ENTRY_POINTS: &str = r"
@group(3) @binding(3) var<storage, read> test_in: array<vec4<f32>>;
@group(3) @binding(4) var<storage, read_write> test_out: array<vec4<f32>>;

// (model, n, x, -) -> (texels_needed(model, n), rho_dynamic(x), rho_static(x), 0)
@compute @workgroup_size(1)
fn test_rho(@builtin(global_invocation_id) id: vec3<u32>) {
    let a = test_in[id.x];
    test_out[id.x] = vec4<f32>(texels_needed(u32(a.x), a.y), rho_dynamic(a.z), rho_static(a.z), 0.0);
}

// (u0, v0), (u1, v1) -> (u.x, u.y, v.y, 0)
@compute @workgroup_size(1)
fn test_convolve(@builtin(global_invocation_id) id: vec3<u32>) {
    let a = test_in[2u * id.x];
    let b = test_in[2u * id.x + 1u];
    test_out[id.x] = vec4<f32>(convolve(a.xy, a.zw, b.xy, b.zw), 0.0);
}

// (model, h), (soft, pixel_uv), (u_phi, v_phi) -> (n0, n1, r0, r1)
@compute @workgroup_size(1)
fn test_predicted(@builtin(global_invocation_id) id: vec3<u32>) {
    let a = test_in[3u * id.x];
    let b = test_in[3u * id.x + 1u];
    let c = test_in[3u * id.x + 2u];
    test_out[id.x] = predicted_texels(u32(a.x), a.yzw, b.xy, c.xy, c.zw, b.zw);
}

// (centre, u), (v_height, depth, -, -) -> (visible, covered, decimated, 0) over the bound tile
@compute @workgroup_size(1)
fn test_integrate(@builtin(global_invocation_id) id: vec3<u32>) {
    let a = test_in[2u * id.x];
    let b = test_in[2u * id.x + 1u];
    let sums = integrate(a.xy, a.zw, b.x, b.y, vec3<f32>(0.0), vec3<f32>(0.0, 1.0, 0.0), vec2<f32>(0.0));
    test_out[id.x] = vec4<f32>(sums, 0.0);
}
";

/// A tile map and the settings [`evaluate`] binds for `integrate` (the other entry points ignore them).
struct Tile {
    settings: PvsmSettingsUniform,
    uniform: TileSettingsUniform,
    /// The map's side and its depths, row-major.
    side: u32,
    depths: Vec<f32>,
}

impl Tile {
    /// An unused 1×1 tile.
    fn none() -> Self {
        Self::new(1, vec![0.0], &[])
    }

    /// A tile of `side`² texels covering the whole frame, with `depths`, under `settings` on top of
    /// the defaults, compared with the receiver's own depth (no tangent plane: no frame needed).
    fn new(side: u32, depths: Vec<f32>, settings: &[(&str, &str)]) -> Self {
        let assignments = [("receiver_plane", "false")].into_iter().chain(settings.iter().copied());
        let params = crate::INFO.params_from(assignments).unwrap();
        let settings = PvsmSettingsUniform::from(&PvsmSettings::from_params(&params).unwrap());
        let uniform = TileSettingsUniform { uv_min: [0.0; 2], uv_max: [1.0; 2], size: [side as f32; 2], _pad0: 0.0, _pad1: 0.0 };
        Self { settings, uniform, side, depths }
    }
}

/// Runs test entry point `entry` once per output on `inputs`, with `tile` bound.
fn evaluate(gpu: &GpuContext, entry: &str, inputs: &[[f32; 4]], outputs: usize, tile: &Tile) -> Vec<[f32; 4]> {
    let device = &gpu.device;
    let source = format!("{FILTER_SHADER}\n{TEST_ENTRY_POINTS}");
    let module = ssm_core::shader::create_shader_with_imports(gpu, "pvsm_test_module", &source, LOCAL_SHADERS).unwrap();
    let frame_layout = bind_group_layout(device, "pvsm_test_frame_layout", &[uniform_entry(0)]);
    let empty_layout = bind_group_layout(device, "pvsm_test_empty_layout", &[]);
    let settings_layout = bind_group_layout(device, "pvsm_test_settings_layout", &[uniform_entry(1)]);
    let tile_layout = bind_group_layout(
        device,
        "pvsm_test_tile_layout",
        &[uniform_entry(0), texture_entry(1), storage_entry(3, true), storage_entry(4, false)],
    );
    let pipeline = ssm_core::passes::compute_pipeline(
        device,
        "pvsm_test_pipeline",
        &module,
        entry,
        &[&frame_layout, &empty_layout, &settings_layout, &tile_layout],
        &[],
    );
    let init = |label: &str, contents: &[u8], usage: wgpu::BufferUsages| {
        wgpu::util::DeviceExt::create_buffer_init(device, &wgpu::util::BufferInitDescriptor { label: Some(label), contents, usage })
    };
    // The frame is read only through the tangent plane, which these tests turn off.
    let frame =
        init("pvsm_test_frame", bytemuck::bytes_of(&<LightFrameUniform as bytemuck::Zeroable>::zeroed()), wgpu::BufferUsages::UNIFORM);
    let settings = init("pvsm_test_settings", bytemuck::bytes_of(&tile.settings), wgpu::BufferUsages::UNIFORM);
    let tile_uniform = init("pvsm_test_tile", bytemuck::bytes_of(&tile.uniform), wgpu::BufferUsages::UNIFORM);
    let input = init("pvsm_test_inputs", bytemuck::cast_slice(inputs), wgpu::BufferUsages::STORAGE);
    let output = ssm_core::passes::storage_buffer(device, "pvsm_test_outputs", (outputs * 16) as u64);
    let texture = wgpu::util::DeviceExt::create_texture_with_data(
        device,
        &gpu.queue,
        &wgpu::TextureDescriptor {
            label: Some("pvsm_test_tile_map"),
            size: wgpu::Extent3d { width: tile.side, height: tile.side, depth_or_array_layers: 1 },
            mip_level_count: 1,
            sample_count: 1,
            dimension: wgpu::TextureDimension::D2,
            format: wgpu::TextureFormat::R32Float,
            usage: wgpu::TextureUsages::TEXTURE_BINDING,
            view_formats: &[],
        },
        wgpu::util::TextureDataOrder::LayerMajor,
        bytemuck::cast_slice(&tile.depths),
    );
    let view = ssm_core::passes::labelled_view(&texture, "pvsm_test_tile_map_view");
    let group = |label: &str, layout: &wgpu::BindGroupLayout, entries: &[(u32, wgpu::BindingResource<'_>)]| {
        let entries: Vec<wgpu::BindGroupEntry<'_>> =
            entries.iter().map(|(binding, resource)| wgpu::BindGroupEntry { binding: *binding, resource: resource.clone() }).collect();
        device.create_bind_group(&wgpu::BindGroupDescriptor { label: Some(label), layout, entries: &entries })
    };
    let groups = [
        group("pvsm_test_frame_group", &frame_layout, &[(0, frame.as_entire_binding())]),
        group("pvsm_test_empty_group", &empty_layout, &[]),
        group("pvsm_test_settings_group", &settings_layout, &[(1, settings.as_entire_binding())]),
        group(
            "pvsm_test_tile_group",
            &tile_layout,
            &[
                (0, tile_uniform.as_entire_binding()),
                (1, wgpu::BindingResource::TextureView(&view)),
                (3, input.as_entire_binding()),
                (4, output.as_entire_binding()),
            ],
        ),
    ];
    let mut encoder = device.create_command_encoder(&wgpu::CommandEncoderDescriptor { label: Some("pvsm_test_encoder") });
    {
        let mut pass = encoder.begin_compute_pass(&wgpu::ComputePassDescriptor { label: Some("pvsm_test_pass"), timestamp_writes: None });
        pass.set_pipeline(&pipeline);
        for (index, group) in groups.iter().enumerate() {
            pass.set_bind_group(index as u32, group, &[]);
        }
        pass.dispatch_workgroups(outputs as u32, 1, 1);
    }
    gpu.queue.submit([encoder.finish()]);
    let bytes = ssm_core::readback::read_buffer(gpu, &output, (outputs * 16) as u64, "PVSM test outputs").unwrap();
    assert_eq!(gpu.take_errors(), Vec::<String>::new());
    bytemuck::pod_collect_to_vec(&bytes)
}

/// |a - b| within `relative` of the larger magnitude (and of 1e-12, for zeros).
fn close(a: f32, b: f32, relative: f32) -> bool {
    (a - b).abs() <= relative * a.abs().max(b.abs()).max(1e-12)
}

/// Float32 arithmetic over a handful of operations: a few units in the last place.
const F32_TOLERANCE: f32 = 1e-5;

/// ρ and its cubics in the shaders are the CPU's (prediction.rs), for every model, below the one-pixel
/// clamp, between, and past each cubic's peak (x up to 12: the clamps are where the CPU's are).
#[test]
fn the_shaders_rho_is_the_cpus() {
    let gpu = ssm_testing::gpu();
    let models = [Prediction::Dynamic, Prediction::Static, Prediction::Linear, Prediction::Fixed];
    let pixels = [0.25f32, 1.0, 1.5, 2.0, 3.0, 4.0, 16.0, 64.0, 200.0, 1_000.0, 2f32.powf(DYNAMIC_PEAK), 5_000.0, 1e6];
    let mut inputs = Vec::new();
    for model in models {
        for (index, n) in pixels.iter().enumerate() {
            // The cubics themselves at x from 0 to past both peaks.
            inputs.push([model.code() as f32, *n, index as f32, 0.0]);
        }
    }
    let outputs = evaluate(&gpu, "test_rho", &inputs, inputs.len(), &Tile::none());
    for (input, output) in inputs.iter().zip(&outputs) {
        let model = models[(input[0] as u32) as usize];
        let x = input[2];
        let expected = [prediction::texels_needed(model, input[1]), prediction::rho_dynamic(x), prediction::rho_static(x)];
        for (got, want) in output.iter().zip(expected) {
            assert!(close(*got, want, F32_TOLERANCE), "{model:?}, n = {}, x = {x}: WGSL {output:?}, Rust {expected:?}", input[1]);
        }
    }
}

/// The appendix: the convolution of two parallelogram filters, seen as Gaussians of variances
/// M Mᵀ, is the parallelogram whose Cholesky factor L = [u v] (v vertical) has L Lᵀ = the sum of
/// the two variances. Checked on filters of every orientation and on a degenerate pair (all zero).
#[test]
fn the_convolution_is_the_cholesky_factor_of_the_summed_variances() {
    let gpu = ssm_testing::gpu();
    let pairs: [[[f32; 4]; 2]; 5] = [
        // s_α (axis-aligned) with a sheared pixel footprint, as step 3 convolves them.
        [[0.01, 0.0, 0.0, 0.02], [0.003, 0.001, -0.0005, 0.002]],
        // Two rotated parallelograms.
        [[0.3, 0.4, -0.2, 0.1], [0.05, -0.07, 0.02, 0.09]],
        // A footprint alone (s_α of zero size: a point light).
        [[0.0, 0.0, 0.0, 0.0], [0.002, 0.0015, 0.0004, -0.003]],
        // A very anisotropic pair.
        [[1e-4, 0.0, 0.0, 3.0], [0.5, 0.5, 0.0, 1e-3]],
        [[0.0; 4], [0.0; 4]],
    ];
    let inputs: Vec<[f32; 4]> = pairs.iter().flatten().copied().collect();
    let outputs = evaluate(&gpu, "test_convolve", &inputs, pairs.len(), &Tile::none());
    for (pair, out) in pairs.iter().zip(&outputs) {
        let [[u0x, u0y, v0x, v0y], [u1x, u1y, v1x, v1y]] = *pair;
        // The summed variance V = Σ M Mᵀ, as f64.
        let v = |a: [f32; 4], b: [f32; 4]| -> f64 {
            [(a[0], b[0]), (a[1], b[1]), (a[2], b[2]), (a[3], b[3])].iter().map(|(x, y)| f64::from(*x) * f64::from(*y)).sum()
        };
        let (xs, ys) = ([u0x, v0x, u1x, v1x], [u0y, v0y, u1y, v1y]);
        let (m00, m10, m11) = (v(xs, xs), v(xs, ys), v(ys, ys));
        // L Lᵀ with L's columns u = (out.x, out.y) and v = (0, out.z).
        let (ux, uy, vy) = (f64::from(out[0]), f64::from(out[1]), f64::from(out[2]));
        let product = [ux * ux, ux * uy, uy * uy + vy * vy];
        let scale = (m00 + m11).max(1e-24);
        for (got, want) in product.iter().zip([m00, m10, m11]) {
            assert!((got - want).abs() <= 1e-5 * scale, "{pair:?}: L Lᵀ {product:?} against V ({m00}, {m10}, {m11})");
        }
        assert!(vy >= 0.0 && out[3] == 0.0);
    }
}

/// Eqs. 4 and 5 on footprints whose answers are worked out by hand:
/// - A, axis-aligned: u_φ = (0.001, 0), v_φ = (0, 0.002), h = (0.004, 0, 0.006): M_φ⁻¹ = diag(1000,
///   500), so n0 = |(4, 0)| = 4 and n1 = |(0, 3)| = 3; ρ_dynamic(log2 4 = 2) = 0.667 + 1.5588 +
///   1.5868 − 0.21728 = 3.59532, r0 = 2 × 0.004 / 3.59532 = 0.00222511; ρ_dynamic(log2 3) =
///   2.790732, r1 = 0.012 / 2.790732 = 0.00429995.
/// - B, sheared: u_φ = (0.002, 0.001), the same v_φ and h: det M_φ = 4e-6, M_φ⁻¹ (0.004, 0) =
///   (0.002, -0.001) × 0.004 / 4e-6 = (2, -1), n0 = √5; ρ_dynamic(log2 √5) = 2.064043, r0 =
///   0.008 / 2.064043 = 0.00387589; M_φ⁻¹ (0, 0.006) = (0, 3): n1 = 3 and r1 as in A.
/// - C, A's point-sampled, a sharp shadow: s_α = (0.0005, 0.0005) spans 0.5 and 0.25 pixels, so ρ is
///   ρ(1) = 0.667 < PENUMBRA_TEXELS = 2 and s_α's texels are 2 × 0.0005 / 2 = 0.0005; the pixel's
///   texel 0.0008 is coarser, so both texels are 0.0008 (finer than Eq. 5's); n is Eq. 4's.
/// - D, A's point-sampled, a soft shadow: s_α = (0.003, 0.0045) spans 3 and 2.25 pixels: ρ(3) =
///   2.790732 and ρ(2.25) = 2.078321, texels 0.006 / 2.790732 = 0.00214997 (finer than Eq. 5's
///   0.00222511: kept) and 0.009 / 2.078321 = 0.00433042 (coarser than Eq. 5's 0.00429995: Eq. 5's).
#[test]
fn eqs_4_and_5_give_the_hand_computed_sizes() {
    let gpu = ssm_testing::gpu();
    let h = [0.004, 0.0, 0.006];
    let axis_aligned = [0.001, 0.0, 0.0, 0.002];
    let sheared = [0.002, 0.001, 0.0, 0.002];
    let case = |h: [f32; 3], soft: [f32; 2], pixel: f32, footprint: [f32; 4]| {
        [[0.0, h[0], h[1], h[2]], [soft[0], soft[1], pixel, pixel], footprint]
    };
    let cases = [
        (case(h, [0.0; 2], 0.0, axis_aligned), [4.0, 3.0, 0.002_225_11, 0.004_299_95]),
        (case(h, [0.0; 2], 0.0, sheared), [5f32.sqrt(), 3.0, 0.003_875_89, 0.004_299_95]),
        (case(h, [0.0005; 2], 0.0008, axis_aligned), [4.0, 3.0, 0.0008, 0.0008]),
        (case(h, [0.003, 0.0045], 0.0008, axis_aligned), [4.0, 3.0, 0.002_149_97, 0.004_299_95]),
    ];
    let inputs: Vec<[f32; 4]> = cases.iter().flat_map(|(input, _)| *input).collect();
    let outputs = evaluate(&gpu, "test_predicted", &inputs, cases.len(), &Tile::none());
    for ((name, (_, expected)), got) in ["A", "B", "C", "D"].iter().zip(&cases).zip(&outputs) {
        // The hand values carry 6 significant digits.
        assert!(
            got.iter().zip(expected).all(|(g, e)| close(*g, *e, 2e-6 + F32_TOLERANCE)),
            "case {name}: (n0, n1, r0, r1) = {got:?}, by hand {expected:?}"
        );
    }
}

/// A step edge in a tile map: 8×8 texels, the left four columns an occluder at depth 0.5, the right
/// four empty, seen from a receiver at depth 1.
fn step_edge(settings: &[(&str, &str)]) -> Tile {
    let depths = (0..64).map(|i| if i % 8 < 4 { 0.5 } else { ssm_core::NO_SURFACE }).collect();
    Tile::new(8, depths, settings)
}

/// Visibility (Σ c·o / Σ c) of box filters over [`step_edge`]'s tile, each given by its centre and
/// half-width in texels along x, three texels tall, on the tile's middle row.
fn box_visibility(gpu: &GpuContext, tile: &Tile, boxes: &[(f32, f32)]) -> Vec<[f32; 4]> {
    let texel = 1.0 / 8.0;
    let inputs: Vec<[f32; 4]> =
        boxes.iter().flat_map(|(centre, half)| [[centre * texel, 4.0 * texel, half * texel, 0.0], [1.5 * texel, 1.0, 0.0, 0.0]]).collect();
    evaluate(gpu, "test_integrate", &inputs, boxes.len(), tile)
}

/// Eq. 2, texels as quads: a texel's weight is the area of its intersection with the filter. Over
/// the step edge at x = 4 texels, a box [3.5, 4.5] has half of an occluding and half of a lit texel
/// (V = 0.5), and [3.5, 5.5] half an occluding texel and one and a half lit ones (V = 0.75); the
/// covered area is the box's own, 1 × 3 and 2 × 3 texels (in shadow-map units, / 64).
#[test]
fn a_half_covered_texel_counts_half() {
    let gpu = ssm_testing::gpu();
    let out = box_visibility(&gpu, &step_edge(&[]), &[(4.0, 0.5), (4.5, 1.0)]);
    for (got, (visibility, covered)) in out.iter().zip([(0.5f32, 3.0f32), (0.75, 6.0)]) {
        assert!(close(got[0] / got[1], visibility, F32_TOLERANCE), "{got:?}: V {} against {visibility}", got[0] / got[1]);
        assert!(close(got[1], covered / 64.0, F32_TOLERANCE), "{got:?}: covered {} against {}", got[1], covered / 64.0);
        assert_eq!(got[2], 0.0, "a filter this small is not decimated");
    }
}

/// Eq. 2 is continuous in the filter's position: a box 1.5 texels wide slid across the step edge in
/// steps of 1/64 texel gives V = clamp((c + 0.75 - 4) / 1.5, 0, 1) at every position (the box's lit
/// fraction), so V moves by at most 1/96 a step. Point-sampled PCF jumps by a third at once when a
/// texel centre enters the box (Fig. 4(a)), which the same check catches.
#[test]
fn quads_are_continuous_under_sub_texel_shifts_and_points_are_not() {
    let gpu = ssm_testing::gpu();
    let centres: Vec<f32> = (0..=128).map(|k| 3.0 + k as f32 / 64.0).collect();
    let boxes: Vec<(f32, f32)> = centres.iter().map(|c| (*c, 0.75)).collect();
    let visibility = |tile: &Tile| -> Vec<f32> { box_visibility(&gpu, tile, &boxes).iter().map(|v| v[0] / v[1]).collect() };
    let quads = visibility(&step_edge(&[]));
    for (c, v) in centres.iter().zip(&quads) {
        let expected = ((c + 0.75 - 4.0) / 1.5).clamp(0.0, 1.0);
        assert!((v - expected).abs() < 1e-5, "centre {c}: V = {v}, the box's lit fraction {expected}");
    }
    let largest_step = |values: &[f32]| values.windows(2).map(|w| (w[1] - w[0]).abs()).fold(0.0f32, f32::max);
    assert!(largest_step(&quads) <= 1.0 / 96.0 + 1e-5, "{}", largest_step(&quads));
    let points = visibility(&step_edge(&[("integration", "points")]));
    assert!(largest_step(&points) > 0.3, "point samples step: {}", largest_step(&points));
}

/// A filter of zero size (a point light, antialiasing off) is the shadow test of the texel under the
/// point, as Eq. 2's weights give in the limit: occluded just left of the edge, lit just right of it
/// (within a hundredth of a texel of it on either side).
#[test]
fn a_filter_of_zero_size_reads_the_texel_under_the_point() {
    let gpu = ssm_testing::gpu();
    let out = box_visibility(&gpu, &step_edge(&[]), &[(3.99, 0.0), (4.01, 0.0), (0.5, 0.0), (7.5, 0.0)]);
    let visibility: Vec<f32> = out.iter().map(|v| v[0] / v[1]).collect();
    assert_eq!(visibility, [0.0, 1.0, 0.0, 1.0], "{out:?}");
}

/// A filter spanning more than MAX_TEXELS_PER_AXIS texels is read at every k-th texel, each sample
/// standing for a k×k block, and says so. A box 200 texels wide over a step edge at 128 is read in
/// blocks of k = ceil(200 / 96) = 3 from column 27; the block [126, 129) reads texel 127, occluding,
/// so 101 of the 200 columns count as occluded: V = 99 / 200. A box 80 texels wide reads every
/// texel: V = 1/2.
#[test]
fn a_filter_wider_than_96_texels_is_decimated_and_reported() {
    let gpu = ssm_testing::gpu();
    // 256 texels, the left half occluding: a box 200 texels wide centred on the edge.
    let depths = (0..256 * 256).map(|i| if i % 256 < 128 { 0.5 } else { ssm_core::NO_SURFACE }).collect();
    let tile = Tile::new(256, depths, &[]);
    let texel = 1.0 / 256.0;
    let inputs = [
        [128.0 * texel, 128.0 * texel, 100.0 * texel, 0.0],
        [1.5 * texel, 1.0, 0.0, 0.0],
        [128.0 * texel, 128.0 * texel, 40.0 * texel, 0.0],
        [1.5 * texel, 1.0, 0.0, 0.0],
    ];
    let out = evaluate(&gpu, "test_integrate", &inputs, 2, &tile);
    assert_eq!((out[0][2], out[1][2]), (1.0, 0.0), "200 texels wide: decimated; 80: not ({out:?})");
    for (sums, visibility) in out.iter().zip([99.0 / 200.0, 0.5]) {
        assert!(close(sums[0] / sums[1], visibility, F32_TOLERANCE), "{sums:?}: V against {visibility}");
    }
}
