//! The paper's formulas as the shaders compute them. A few test entry points, appended to the filter
//! pass's own module (`pvsm_filter.wgsl` with `pvsm_common.wgsl`), evaluate its WGSL functions on
//! the GPU for given inputs; the tests compare them with values worked out by hand from the paper
//! (the appendix's convolution, Eqs. 4 and 5, Eq. 2's texels as quads), with the CPU twins in
//! [`crate::prediction`] (ρ), and the hierarchical walk of Eq. 2 (over the min/max pyramid that the
//! real `pvsm_filter_pyramid.wgsl` builds) with the per-texel sum.

// Test helpers unwrap too: a failure should stop the test where it happens.
#![allow(clippy::unwrap_used, clippy::expect_used)]

use ssm_core::passes::{bind_group_layout, storage_entry, texture_entry, uniform_entry, write_storage_texture_entry};
use ssm_core::{GpuContext, LightFrameUniform, Settings};

use crate::filter::{
    FILTER_PYRAMID_SHADER, FILTER_SHADER, TILE_PYRAMID_COUNTS_FORMAT, TILE_PYRAMID_FORMAT, TilePyramidLevelUniform, TileSettingsUniform,
};
use crate::gpu::{LOCAL_SHADERS, uint_texture_entry};
use crate::prediction::{self, DYNAMIC_PEAK, Prediction};
use crate::{PvsmSettings, PvsmSettingsUniform};

/// The test entry points. Inputs and outputs are `vec4<f32>`s; group 3's bindings 5 and 6 are free in
/// the filter module (0, 1, 3 and 4 hold the tile, its map and its pyramid, 2 the resolve pass's target).
const TEST_ENTRY_POINTS: &str = r"
@group(3) @binding(5) var<storage, read> test_in: array<vec4<f32>>;
@group(3) @binding(6) var<storage, read_write> test_out: array<vec4<f32>>;

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

// (centre, u), (v_height, depth, -, -), (position, -), (normal, -) -> (visible, covered, capped,
// texels read) over the bound tile
@compute @workgroup_size(1)
fn test_integrate(@builtin(global_invocation_id) id: vec3<u32>) {
    let a = test_in[4u * id.x];
    let b = test_in[4u * id.x + 1u];
    let position = test_in[4u * id.x + 2u].xyz;
    let normal = test_in[4u * id.x + 3u].xyz;
    let sums = integrate(a.xy, a.zw, b.x, b.y, position, normal, vec2<f32>(0.0));
    test_out[id.x] = vec4<f32>(sums.visible, sums.covered, select(0.0, 1.0, sums.capped), f32(sums.reads));
}

// test_integrate's inputs -> (texels read, the bytes they fetched, 0, 0)
@compute @workgroup_size(1)
fn test_integrate_bytes(@builtin(global_invocation_id) id: vec3<u32>) {
    let a = test_in[4u * id.x];
    let b = test_in[4u * id.x + 1u];
    let position = test_in[4u * id.x + 2u].xyz;
    let normal = test_in[4u * id.x + 3u].xyz;
    let sums = integrate(a.xy, a.zw, b.x, b.y, position, normal, vec2<f32>(0.0));
    test_out[id.x] = vec4<f32>(f32(sums.reads), f32(sums.bytes), 0.0, 0.0);
}
";

/// A tile map, its region and the settings [`evaluate`] binds for `integrate` (the other entry points
/// ignore them).
struct Tile {
    settings: PvsmSettingsUniform,
    uniform: TileSettingsUniform,
    /// The map's side (a power of two) and its depths, row-major.
    side: u32,
    depths: Vec<f32>,
    /// The light frame the tangent plane is taken in (zero: receiver_plane off).
    frame: LightFrameUniform,
}

impl Tile {
    /// An unused 1×1 tile.
    fn none() -> Self {
        Self::new(1, vec![0.0], &[])
    }

    /// A tile of `side`² texels covering the whole frame, with `depths`, under `settings` on top of
    /// the defaults, compared with the receiver's own depth (no tangent plane: no frame needed).
    fn new(side: u32, depths: Vec<f32>, settings: &[(&str, &str)]) -> Self {
        let uniform = TileSettingsUniform { uv_min: [0.0; 2], uv_max: [1.0; 2], size: [side as f32; 2], _pad0: 0.0, _pad1: 0.0 };
        Self { settings: Self::settings(false, settings), uniform, side, depths, frame: bytemuck::Zeroable::zeroed() }
    }

    fn settings(receiver_plane: bool, settings: &[(&str, &str)]) -> PvsmSettingsUniform {
        let plane = if receiver_plane { "true" } else { "false" };
        let assignments = [("receiver_plane", plane)].into_iter().chain(settings.iter().copied());
        let params = crate::INFO.params_from(assignments).unwrap();
        PvsmSettingsUniform::from(&PvsmSettings::from_params(&params).unwrap())
    }

    /// The same tile with a region of `size` texels (the top-left of the map) spanning `uv_min` to
    /// `uv_max` of the light frame, compared with the receiver's tangent plane in `frame`, under
    /// `settings`.
    fn region(mut self, size: [f32; 2], uv: [[f32; 2]; 2], frame: LightFrameUniform, settings: &[(&str, &str)]) -> Self {
        self.uniform.size = size;
        self.uniform.uv_min = uv[0];
        self.uniform.uv_max = uv[1];
        self.frame = frame;
        self.settings = Self::settings(true, settings);
        self
    }
}

/// Builds `tile`'s two-layer min/max pyramid (depths and near counts) with `pvsm_filter_pyramid.wgsl`,
/// as the technique does before each tile's filter: levels 1 to ceil(log2 of the region's longer side).
fn build_pyramid(gpu: &GpuContext, tile: &Tile, map: &wgpu::TextureView, pyramid: &wgpu::Texture, counts: &wgpu::Texture) {
    let device = &gpu.device;
    let module =
        ssm_core::shader::create_shader_with_imports(gpu, "pvsm_test_pyramid_module", FILTER_PYRAMID_SHADER, LOCAL_SHADERS).unwrap();
    let tile_layout = bind_group_layout(device, "pvsm_test_pyramid_tile_layout", &[uniform_entry(0)]);
    let level_layout = bind_group_layout(
        device,
        "pvsm_test_pyramid_level_layout",
        &[
            uniform_entry(0),
            texture_entry(1),
            write_storage_texture_entry(2, TILE_PYRAMID_FORMAT),
            ssm_core::read_counts::ReadCounts::layout_entry(3),
            uint_texture_entry(4),
            write_storage_texture_entry(5, TILE_PYRAMID_COUNTS_FORMAT),
        ],
    );
    let pipeline =
        ssm_core::passes::compute_pipeline(device, "pvsm_test_pyramid", &module, "pvsm_tile_pyramid", &[&tile_layout, &level_layout], &[]);
    let read_counts = ssm_core::read_counts::ReadCounts::new(device, "pvsm_test_pyramid_counts", &["pyramid"], false);
    let tile_uniform = ssm_core::passes::uniform_buffer(device, "pvsm_test_pyramid_tile", &tile.uniform);
    let tile_group =
        ssm_core::passes::bind_group(device, "pvsm_test_pyramid_tile_group", &tile_layout, &[tile_uniform.as_entire_binding()]);
    let mip = |texture: &wgpu::Texture, level: u32| {
        texture.create_view(&wgpu::TextureViewDescriptor {
            label: Some("pvsm_test_pyramid_mip"),
            base_mip_level: level,
            mip_level_count: Some(1),
            ..Default::default()
        })
    };
    // Level 1 reads the map, not counts.
    let no_counts = device.create_texture(&wgpu::TextureDescriptor {
        label: Some("pvsm_test_pyramid_no_counts"),
        size: wgpu::Extent3d { width: 1, height: 1, depth_or_array_layers: 1 },
        mip_level_count: 1,
        sample_count: 1,
        dimension: wgpu::TextureDimension::D2,
        format: TILE_PYRAMID_COUNTS_FORMAT,
        usage: wgpu::TextureUsages::TEXTURE_BINDING,
        view_formats: &[],
    });
    let longer = tile.uniform.size[0].max(tile.uniform.size[1]) as u32;
    let levels = longer.max(2).next_power_of_two().ilog2();
    let mut encoder = device.create_command_encoder(&wgpu::CommandEncoderDescriptor { label: Some("pvsm_test_pyramid_encoder") });
    for level in 1..=levels {
        let value = TilePyramidLevelUniform { level, from_map: u32::from(level == 1), _pad0: 0, _pad1: 0 };
        let uniform = ssm_core::passes::uniform_buffer(device, "pvsm_test_pyramid_level", &value);
        let finer = if level == 1 { map.clone() } else { mip(pyramid, level - 2) };
        let finer_counts =
            if level == 1 { ssm_core::passes::labelled_view(&no_counts, "pvsm_test_no_counts") } else { mip(counts, level - 2) };
        let group = ssm_core::passes::bind_group(
            device,
            "pvsm_test_pyramid_level_group",
            &level_layout,
            &[
                uniform.as_entire_binding(),
                wgpu::BindingResource::TextureView(&finer),
                wgpu::BindingResource::TextureView(&mip(pyramid, level - 1)),
                read_counts.buffer().as_entire_binding(),
                wgpu::BindingResource::TextureView(&finer_counts),
                wgpu::BindingResource::TextureView(&mip(counts, level - 1)),
            ],
        );
        let texels = (longer + (1 << level) - 1) >> level;
        let mut pass =
            encoder.begin_compute_pass(&wgpu::ComputePassDescriptor { label: Some("pvsm_test_pyramid_pass"), timestamp_writes: None });
        pass.set_pipeline(&pipeline);
        pass.set_bind_group(0, &tile_group, &[]);
        pass.set_bind_group(1, &group, &[]);
        pass.dispatch_workgroups(texels.div_ceil(8), texels.div_ceil(8), 1);
    }
    gpu.queue.submit([encoder.finish()]);
}

/// Runs test entry point `entry` once per output on `inputs`, with `tile` bound (its pyramid built).
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
        &[uniform_entry(0), texture_entry(1), texture_entry(3), uint_texture_entry(4), storage_entry(5, true), storage_entry(6, false)],
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
    let frame = init("pvsm_test_frame", bytemuck::bytes_of(&tile.frame), wgpu::BufferUsages::UNIFORM);
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
    // The pyramid as the technique sizes it: half the map's side, one mip per level.
    let pyramid_side = (tile.side / 2).max(1);
    let pyramid_texture = |label: &str, format: wgpu::TextureFormat| {
        device.create_texture(&wgpu::TextureDescriptor {
            label: Some(label),
            size: wgpu::Extent3d { width: pyramid_side, height: pyramid_side, depth_or_array_layers: 1 },
            mip_level_count: pyramid_side.ilog2() + 1,
            sample_count: 1,
            dimension: wgpu::TextureDimension::D2,
            format,
            usage: wgpu::TextureUsages::TEXTURE_BINDING | wgpu::TextureUsages::STORAGE_BINDING,
            view_formats: &[],
        })
    };
    let pyramid = pyramid_texture("pvsm_test_tile_pyramid", TILE_PYRAMID_FORMAT);
    let counts = pyramid_texture("pvsm_test_tile_pyramid_near_counts", TILE_PYRAMID_COUNTS_FORMAT);
    if tile.side > 1 {
        build_pyramid(gpu, tile, &view, &pyramid, &counts);
    }
    let pyramid_view = ssm_core::passes::labelled_view(&pyramid, "pvsm_test_tile_pyramid");
    let counts_view = ssm_core::passes::labelled_view(&counts, "pvsm_test_tile_pyramid_near_counts");
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
                (3, wgpu::BindingResource::TextureView(&pyramid_view)),
                (4, wgpu::BindingResource::TextureView(&counts_view)),
                (5, input.as_entire_binding()),
                (6, output.as_entire_binding()),
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
    let inputs: Vec<[f32; 4]> = boxes
        .iter()
        .flat_map(|(centre, half)| filter_input(*centre * texel, 4.0 * texel, [*half * texel, 0.0], 1.5 * texel, 1.0))
        .collect();
    evaluate(gpu, "test_integrate", &inputs, boxes.len(), tile)
}

/// `test_integrate`'s input for a filter of half-axis `u` and half-height `v_height` centred on
/// (x, y), shadow-map coordinates, for a receiver at `depth` compared with its own depth.
fn filter_input(x: f32, y: f32, u: [f32; 2], v_height: f32, depth: f32) -> [[f32; 4]; 4] {
    [[x, y, u[0], u[1]], [v_height, depth, 0.0, 0.0], [0.0; 4], [0.0, 1.0, 0.0, 0.0]]
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
        assert_eq!(got[2], 0.0, "a filter this small is not capped");
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

/// A small deterministic generator (xorshift32) for the random cases: uniform in [0, 1).
struct Random(u32);

impl Random {
    fn next(&mut self) -> f32 {
        self.0 ^= self.0 << 13;
        self.0 ^= self.0 >> 17;
        self.0 ^= self.0 << 5;
        (self.0 >> 8) as f32 / (1u32 << 24) as f32
    }

    fn range(&mut self, low: f32, high: f32) -> f32 {
        low + (high - low) * self.next()
    }
}

/// A 64² map of depths with every kind of block: a far background with no surface, rectangles of
/// constant depth in front of every receiver (0.6), behind every receiver (3) and between (1 to 2),
/// a ramp crossing the receivers' depths, and a patch of per-texel noise (mixed at every level).
fn mixed_depths(random: &mut Random) -> Vec<f32> {
    let side = 64usize;
    let mut depths = vec![ssm_core::NO_SURFACE; side * side];
    for index in 0..14 {
        let depth = match index % 3 {
            0 => 0.6,
            1 => 3.0,
            _ => random.range(1.0, 2.0),
        };
        let (x, y) = ((random.next() * 56.0) as usize, (random.next() * 56.0) as usize);
        let (w, h) = (1 + (random.next() * 24.0) as usize, 1 + (random.next() * 24.0) as usize);
        for row in y..(y + h).min(side) {
            for column in x..(x + w).min(side) {
                depths[row * side + column] = depth;
            }
        }
    }
    for row in 40..64 {
        for column in 0..20 {
            depths[row * side + column] = 1.0 + column as f32 / 20.0;
        }
    }
    for row in 4..20 {
        for column in 44..60 {
            depths[row * side + column] = random.range(0.5, 2.5);
        }
    }
    depths
}

/// A light frame looking down -y from the origin with 45° half-angles (tan = 1), as `tap_plane`
/// reads it: a point at shadow-map coordinates (u, v) and depth d is d (2u − 1, −1, 2v − 1).
fn test_frame() -> LightFrameUniform {
    let mut frame: LightFrameUniform = bytemuck::Zeroable::zeroed();
    frame.centre = [0.0, 0.0, 0.0, 1.0];
    frame.u_axis = [1.0, 0.0, 0.0, 0.5];
    frame.v_axis = [0.0, 0.0, 1.0, 0.5];
    frame.normal = [0.0, -1.0, 0.0, 1.0];
    frame.projection = [1.0, 1.0, 0.01, 10.0];
    frame
}

/// Random filters over [`mixed_depths`], for receivers compared with their tangent planes: centres
/// from a tenth of the region outside it to a tenth past it (filters straddling the tile's edges),
/// half-widths from nothing (the texel under the point) to `largest` texels, sheared as antialiasing makes
/// them, receivers at depths 1 to 2 tilted up to about 60° from the light (some nearly edge-on, where
/// the plane's depth is unbounded over a block).
fn random_filters(random: &mut Random, count: usize, texel: [f32; 2], largest: f32) -> Vec<[f32; 4]> {
    let mut inputs = Vec::new();
    for index in 0..count {
        let (u, v) = (random.range(-0.1, 1.1), random.range(-0.1, 1.1));
        let depth = random.range(1.0, 2.0);
        let half = if index % 7 == 0 { 0.0 } else { random.range(0.0, largest) };
        let shear = if index % 2 == 0 { 0.0 } else { random.range(-0.5, 0.5) * half };
        let height = if index % 7 == 0 { 0.0 } else { random.range(0.0, largest) };
        let tilt = if index % 11 == 0 { 1.55 } else { random.range(0.0, 1.0) };
        let turn = random.range(0.0, std::f32::consts::TAU);
        let normal = [tilt.sin() * turn.cos(), tilt.cos(), tilt.sin() * turn.sin()];
        let position = [depth * (2.0 * u - 1.0), -depth, depth * (2.0 * v - 1.0)];
        inputs.extend([
            [u, v, half * texel[0], shear * texel[1]],
            [height * texel[1], depth, 0.0, 0.0],
            [position[0], position[1], position[2], 0.0],
            [normal[0], normal[1], normal[2], 0.0],
        ]);
    }
    inputs
}

/// The hierarchical walk sums what the per-texel walk sums. Both weigh each texel by the same
/// covered area and test it the same way (a block is decided at once only when bounds that hold for
/// every texel's f32 test put all of them on one side); they differ only in the order of the sums
/// and in adding a block's area in closed form. Each walk's sums add N terms of at most one texel's
/// area (N: the texels under the filter, which the per-texel walk reads), so in f32 each is within
/// (N − 1) u Σ c of the exact sum (Higham's bound for recursive summation, u = 2⁻²⁴), and a closed-form
/// block area errs by a few u of itself: the two walks agree within 2 (N + 10) u Σ c; and a sheared
/// filter's column centres, a + b i here and c.y + (x − c.x) b there, are off by a few u of the texel
/// coordinates' magnitude M (under 128) times 1 + |b|, which moves each of at most N columns' clipped
/// heights by twice that: 12 u M (1 + |b|) N more (none with b = 0, where both compute c.y
/// exactly). 300 random
/// filters on two regions: the whole 64² map, and a 50 × 37 region (anisotropic texels, a pyramid
/// whose blocks run past the region's edges) of a smaller rectangle of the frame. The hierarchy
/// reads fewer texels overall.
#[test]
fn the_hierarchy_sums_what_every_texel_sums() {
    let gpu = ssm_testing::gpu();
    let mut random = Random(0x9e37_79b9);
    let depths = mixed_depths(&mut random);
    let regions = [([64.0f32, 64.0], [[0.0f32, 0.0], [1.0, 1.0]]), ([50.0, 37.0], [[0.2, 0.3], [0.7, 0.8]])];
    let (mut hierarchy_reads, mut texel_reads) = (0.0, 0.0);
    for (size, uv) in regions {
        let texel = [(uv[1][0] - uv[0][0]) / size[0], (uv[1][1] - uv[0][1]) / size[1]];
        let inputs = spread_over(random_filters(&mut random, 300, texel, 40.0), uv);
        let tile = |walk: &str| Tile::new(64, depths.clone(), &[]).region(size, uv, test_frame(), &[("filter_walk", walk)]);
        let walked = evaluate(&gpu, "test_integrate", &inputs, 300, &tile("hierarchy"));
        let every = evaluate(&gpu, "test_integrate", &inputs, 300, &tile("texels"));
        let (h, t) = assert_walks_agree(&inputs, &walked, &every, texel, &format!("region {size:?}"));
        hierarchy_reads += h;
        texel_reads += t;
    }
    println!("texels read: hierarchy {hierarchy_reads}, every texel {texel_reads}");
    assert!(hierarchy_reads < texel_reads, "{hierarchy_reads} against {texel_reads}");
}

/// [`random_filters`]' centres, drawn over [0, 1]², moved into the region's rectangle `uv` of the
/// frame, and their receivers' positions with them.
fn spread_over(mut inputs: Vec<[f32; 4]>, uv: [[f32; 2]; 2]) -> Vec<[f32; 4]> {
    for case in inputs.chunks_mut(4) {
        case[0][0] = uv[0][0] + case[0][0] * (uv[1][0] - uv[0][0]);
        case[0][1] = uv[0][1] + case[0][1] * (uv[1][1] - uv[0][1]);
        let depth = case[1][1];
        case[2] = [depth * (2.0 * case[0][0] - 1.0), -depth, depth * (2.0 * case[0][1] - 1.0), 0.0];
    }
    inputs
}

/// Asserts that the hierarchy's sums (`walked`) are the per-texel walk's (`every`) for each filter
/// of `inputs` within the f32 bound of [`the_hierarchy_sums_what_every_texel_sums`], that no walk was
/// capped, and that umbra, penumbra and lit filters are all among them; returns the texels each
/// walk read.
fn assert_walks_agree(inputs: &[[f32; 4]], walked: &[[f32; 4]], every: &[[f32; 4]], texel: [f32; 2], label: &str) -> (f32, f32) {
    let (mut hierarchy_reads, mut texel_reads) = (0.0, 0.0);
    let mut decided = [0usize; 3];
    for (index, (h, t)) in walked.iter().zip(every).enumerate() {
        let texels = t[3];
        let u = f32::EPSILON / 2.0;
        let (half, shear) = (inputs[4 * index][2] / texel[0], inputs[4 * index][3] / texel[1]);
        let slope = shear.abs() / half.abs().max(1e-3);
        let texel_area = texel[0] * texel[1];
        let sheared = if shear == 0.0 { 0.0 } else { 12.0 * u * 128.0 * (1.0 + slope) * texels * texel_area };
        let tolerance = 2.0 * (texels + 10.0) * u * t[1].max(h[1]) + sheared;
        assert!(
            (h[0] - t[0]).abs() <= tolerance && (h[1] - t[1]).abs() <= tolerance,
            "{label}, filter {index} ({:?}): hierarchy (Σ c·o, Σ c) = ({}, {}), every texel ({}, {}); {texels} texels, tolerance {tolerance}",
            &inputs[4 * index..4 * index + 4],
            h[0],
            h[1],
            t[0],
            t[1],
        );
        assert_eq!((h[2], t[2]), (0.0, 0.0), "{label}: no walk this small reaches the cap");
        hierarchy_reads += h[3];
        texel_reads += texels;
        if t[1] > 0.0 {
            decided[usize::from(t[0] > 0.0) + usize::from(t[0] >= t[1])] += 1;
        }
    }
    println!(
        "{label}: {} filters in umbra, {} in penumbra, {} lit; texels read: hierarchy {hierarchy_reads}, every texel {texel_reads}",
        decided[0], decided[1], decided[2]
    );
    assert!(decided.iter().all(|count| *count >= 3), "{label}: every kind of filter is exercised: {decided:?}");
    (hierarchy_reads, texel_reads)
}

/// A 128² map of bars over a floor, as thin geometry under a large light gives the filter: a floor
/// whose depth ramps from 2.5 to 3 across the map (behind every receiver, not parallel to the
/// light's plane) under `bars` bars 1 to 6 texels wide and `lengths` (shortest, extra) long, across
/// or along the map, crossing each other, at depths 0.3 to 0.9 (in front of every receiver); with
/// `middle_layer`, every third bar at 1.2 to 1.8 instead (between the receivers' depths: three
/// layers, where the widest gap need not hold the receiver).
fn bars_over_a_floor(random: &mut Random, bars: usize, lengths: (f32, f32), middle_layer: bool) -> Vec<f32> {
    let side = 128usize;
    let mut depths: Vec<f32> = (0..side * side).map(|i| 2.5 + 0.5 * (i % side) as f32 / side as f32).collect();
    for index in 0..bars {
        let depth = if middle_layer && index % 3 == 2 { random.range(1.2, 1.8) } else { random.range(0.3, 0.9) };
        let (width, length) = (1 + (random.next() * 6.0) as usize, (lengths.0 + random.next() * lengths.1) as usize);
        let (w, h) = if index % 2 == 0 { (length, width) } else { (width, length) };
        let (x, y) = ((random.next() * side as f32) as usize, (random.next() * side as f32) as usize);
        for row in y..(y + h).min(side) {
            for column in x..(x + w).min(side) {
                depths[row * side + column] = depth;
            }
        }
    }
    depths
}

/// Over the 128² map `depths`, 300 random filters (half-axes up to 60 texels, so that blocks of up
/// to 32² lie inside them; sheared; receivers' tangent planes at depths 1 to 2, tilted up to nearly
/// edge-on) on the whole map and on a 100 × 77 region of a smaller rectangle of the frame (blocks
/// past the region's edges, whose near counts hold the region's texels only) give the per-texel
/// sums within the bound of [`the_hierarchy_sums_what_every_texel_sums`], for fewer reads.
fn assert_hierarchy_exact_over(depths: &[f32], random: &mut Random, label: &str) {
    let gpu = ssm_testing::gpu();
    let regions = [([128.0f32, 128.0], [[0.0f32, 0.0], [1.0, 1.0]]), ([100.0, 77.0], [[0.15, 0.1], [0.8, 0.9]])];
    for (size, uv) in regions {
        let texel = [(uv[1][0] - uv[0][0]) / size[0], (uv[1][1] - uv[0][1]) / size[1]];
        let inputs = spread_over(random_filters(random, 300, texel, 60.0), uv);
        let tile = |walk: &str| Tile::new(128, depths.to_vec(), &[]).region(size, uv, test_frame(), &[("filter_walk", walk)]);
        let walked = evaluate(&gpu, "test_integrate", &inputs, 300, &tile("hierarchy"));
        let every = evaluate(&gpu, "test_integrate", &inputs, 300, &tile("texels"));
        let (h, t) = assert_walks_agree(&inputs, &walked, &every, texel, &format!("{label}, region {size:?}"));
        assert!(h < t, "{h} against {t}");
    }
}

/// The two-layer blocks are exact over 24 bars over a floor, a third of them between the
/// receivers' depths ([`assert_hierarchy_exact_over`]).
#[test]
fn the_two_layer_hierarchy_sums_what_every_texel_sums_over_bars() {
    let mut random = Random(0x2545_f491);
    let depths = bars_over_a_floor(&mut random, 24, (10.0, 90.0), true);
    assert_hierarchy_exact_over(&depths, &mut random, "bars");
}

/// Two-layer blocks straddling the filter's edge are exact: over 40 bars in front of a floor (two
/// layers only, so every block holding both is two layers around the receiver), their children
/// inside the filter, their children of one cluster and, at level 1, their texels are settled from
/// the per-child near counts, and only the children holding both clusters on the edge are walked
/// ([`assert_hierarchy_exact_over`]).
#[test]
fn two_layer_blocks_on_the_filters_edge_sum_what_every_texel_sums() {
    let mut random = Random(0x6a09_e667);
    let depths = bars_over_a_floor(&mut random, 40, (4.0, 96.0), false);
    assert_hierarchy_exact_over(&depths, &mut random, "two layers");
}

/// A bar over a floor under a filter covering the whole 64² tile (centre 32, half-axes 33 texels:
/// every texel weighs its whole area), a receiver at depth 1 compared with its own depth. The walk
/// starts at the four 32² blocks (level 5). One bar at 0.5 over columns 8 to 11, the floor at 3: the
/// two left blocks are two layers with the receiver between (one read each, and one for its near
/// count), the right ones all lit (one read): 6 reads, V = 60 / 64. Bars at 0.5 (columns 8 to 11)
/// and 2 (columns 20 to 23) over the floor: the left blocks' widest gap is 0.5 to 2 (1.5 against 1),
/// the receiver in it: 6 reads, V = 60 / 64 again; a receiver at 2.5 is in the far cluster's span
/// (2 to 3), so the left blocks descend: their 16² children hold one bar each over the floor,
/// two layers around 2.5 (2 reads each), and the right blocks are lit: 4 + 2 × 4 × 2 = 20 reads,
/// V = 56 / 64 (both bars occlude).
#[test]
fn a_bar_over_a_floor_inside_the_filter_costs_one_block_and_its_count() {
    let gpu = ssm_testing::gpu();
    let texel = 1.0 / 64.0;
    let floor_with = |bars: &[(usize, f32)]| {
        let depths = (0..64 * 64)
            .map(|i| bars.iter().find(|(first, _)| (*first..first + 4).contains(&(i % 64))).map_or(3.0, |(_, depth)| *depth))
            .collect();
        Tile::new(64, depths, &[])
    };
    let input = |depth: f32| filter_input(32.0 * texel, 32.0 * texel, [33.0 * texel, 0.0], 33.0 * texel, depth);
    let one_bar = evaluate(&gpu, "test_integrate", &input(1.0), 1, &floor_with(&[(8, 0.5)]))[0];
    let two_bars = floor_with(&[(8, 0.5), (20, 2.0)]);
    let between = evaluate(&gpu, "test_integrate", &input(1.0), 1, &two_bars)[0];
    let behind_both = evaluate(&gpu, "test_integrate", &input(2.5), 1, &two_bars)[0];
    println!("one bar: {one_bar:?}; two bars, receiver at 1: {between:?}, at 2.5: {behind_both:?}");
    for (got, visibility, reads) in [(one_bar, 60.0 / 64.0, 6.0), (between, 60.0 / 64.0, 6.0), (behind_both, 56.0 / 64.0, 20.0)] {
        assert!(close(got[0] / got[1], visibility, F32_TOLERANCE), "{got:?}: V against {visibility}");
        assert!(close(got[1], 1.0, F32_TOLERANCE), "{got:?}: the whole tile is covered");
        assert_eq!((got[2], got[3]), (0.0, reads), "{got:?}");
    }
}

/// The hierarchy's cost follows the penumbra's boundary, by hand. A 64² tile, a filter covering
/// texels [2, 62)² (start level 5: the four 32² blocks): with every texel occluding, each of the four
/// blocks is decided at once (4 reads, V = 0). With an edge between columns 32 and 33 (texels x ≤ 32
/// occluding at 0.5; those past it lit, at 1.1 on even rows and 5 on odd ones, so that a block
/// across the edge is not two layers around the receiver at 1: its widest gap, 1.1 to 5, is
/// behind it), the blocks holding both columns are mixed at every level l (one column of blocks, at
/// most ceil(62 / 2^l) + 1 of them), and each mixed block reads its four children: at most
/// 4 + 4 Σ_{l=1..5} (ceil(62 / 2^l) + 1) = 4 + 4 (32 + 17 + 9 + 5 + 3) = 268 reads against the 3,600
/// texels under the filter; V = 29 / 60 exactly (columns 33 to 61 lit).
#[test]
fn a_decided_block_costs_one_read_and_an_edge_its_boundary() {
    let gpu = ssm_testing::gpu();
    let texel = 1.0 / 64.0;
    let input = filter_input(32.0 * texel, 32.0 * texel, [30.0 * texel, 0.0], 30.0 * texel, 1.0);
    let occluding = Tile::new(64, vec![0.5; 64 * 64], &[]);
    let edge = Tile::new(64, (0..64 * 64).map(|i| if i % 64 <= 32 { 0.5 } else { [1.1, 5.0][(i / 64) % 2] }).collect(), &[]);
    let uniform = evaluate(&gpu, "test_integrate", &input, 1, &occluding)[0];
    let stepped = evaluate(&gpu, "test_integrate", &input, 1, &edge)[0];
    println!("uniform: {} reads; edge: {} reads, V = {}", uniform[3], stepped[3], stepped[0] / stepped[1]);
    assert_eq!((uniform[0], uniform[3]), (0.0, 4.0), "{uniform:?}");
    assert!(stepped[3] <= 268.0, "{stepped:?}");
    assert!(close(stepped[0] / stepped[1], 29.0 / 60.0, F32_TOLERANCE), "{stepped:?}: V against {}", 29.0 / 60.0);
}

/// A two-layer block on the filter's edge costs its near counts, by hand. A 64² tile, the filter of
/// [`a_decided_block_costs_one_read_and_an_edge_its_boundary`] (texels [2, 62)², start level 5:
/// the four 32² blocks), one bar at 0.5 over columns 8 to 11 on a floor at 3, a receiver at 1. The
/// right blocks are all floor: lit, one read each. The left ones are two layers around the receiver
/// and cross the filter's edge: their depths and near counts, two reads each. Of their 16²
/// children, those holding the bar (columns 0 to 15, four of them) cross the edge at column 2 and
/// are walked, one read each (their near counts only); the others are floor (lit) or inside the
/// filter, settled unread. Of those four's 8² children, columns 8 to 15 hold the bar, walked only
/// where they cross the filter's top or bottom edge (rows 0 to 7 and 56 to 63: two, one read each);
/// columns 0 to 7 are floor, settled. Their 4² children are all bar, all floor or inside: settled.
/// 4 + 2 + 4 + 2 = 12 reads against 3,600 texels, V = 56 / 60 exactly (columns 8 to 11 occlude).
#[test]
fn a_two_layer_block_on_the_filters_edge_costs_its_near_counts() {
    let gpu = ssm_testing::gpu();
    let texel = 1.0 / 64.0;
    let input = filter_input(32.0 * texel, 32.0 * texel, [30.0 * texel, 0.0], 30.0 * texel, 1.0);
    let bar = Tile::new(64, (0..64 * 64).map(|i| if (8..12).contains(&(i % 64)) { 0.5 } else { 3.0 }).collect(), &[]);
    let got = evaluate(&gpu, "test_integrate", &input, 1, &bar)[0];
    println!("bar over a floor across the filter's edge: {got:?}");
    assert!(close(got[0] / got[1], 56.0 / 60.0, F32_TOLERANCE), "{got:?}: V against {}", 56.0 / 60.0);
    assert_eq!((got[2], got[3]), (0.0, 12.0), "{got:?}");
}

/// The walks are bounded whatever the map: past MAX_WALK_STEPS = 32,768 loop iterations a walk stops
/// and says so (pvsm_capped_pixels). On a 512² map of three layers in every 2×2 block, an occluder
/// at depth 0.5 and lit texels at 1.1 and 5 for a receiver at 1 (every block mixed down to the
/// texels, and no block two layers around the receiver: the widest gap, 1.1 to 5, is behind it),
/// a filter 400 texels square (160,000 texels): the per-texel walk
/// reads 400 of every 401 steps (one per column), so 32,768 × 400 / 401 − 400 to 32,768 texels; the
/// hierarchy stops descending after 32,768 steps (blocks and climbs to a parent) and counts the
/// blocks left, at most three siblings per level (under 256 more steps). The same filter over a
/// uniform map: 4 reads, not capped. (llvmpipe leaves a loop silently
/// after 65,535 iterations: a cap above that was never reached there, and the walk ended unflagged.)
#[test]
fn a_walk_past_its_cap_stops_and_says_so() {
    let gpu = ssm_testing::gpu();
    let side = 512usize;
    let layered: Vec<f32> = (0..side * side).map(|i| [0.5, 1.1, 5.0, 0.5][i % 2 + 2 * ((i / side) % 2)]).collect();
    let texel = 1.0 / side as f32;
    let input = filter_input(256.0 * texel, 256.0 * texel, [200.0 * texel, 0.0], 200.0 * texel, 1.0);
    let run = |depths: &[f32], walk: &str| {
        evaluate(&gpu, "test_integrate", &input, 1, &Tile::new(512, depths.to_vec(), &[("filter_walk", walk)]))[0]
    };
    let texels = run(&layered, "texels");
    let hierarchy = run(&layered, "hierarchy");
    let uniform = run(&vec![0.5; side * side], "hierarchy");
    println!("layered: texels {texels:?}, hierarchy {hierarchy:?}; uniform {uniform:?}");
    assert!(texels[2] == 1.0 && texels[3] >= 32_768.0 * 400.0 / 401.0 - 400.0 && texels[3] <= 32_768.0, "{texels:?}");
    assert!(hierarchy[2] == 1.0 && hierarchy[3] <= 32_768.0 + 256.0, "{hierarchy:?}");
    assert!(close(hierarchy[1], uniform[1], F32_TOLERANCE), "a capped walk still covers the whole filter: {hierarchy:?}");
    assert_eq!((uniform[2], uniform[3]), (0.0, 4.0));
}

/// Each read of a walk counts its texture's texel size, by hand, with the filter of
/// [`a_decided_block_costs_one_read_and_an_edge_its_boundary`] (texels [2, 62)² of a 64² tile):
/// over a uniform occluding map the hierarchy decides the four 32² blocks from their pyramid texels
/// (4 reads of an Rgba32Float texel, 16 bytes each: 64 bytes) and the per-texel walk reads the
/// 3,600 texels under the filter from the map (R32Float, 4 bytes each: 14,400 bytes); over the bar of
/// [`a_two_layer_block_on_the_filters_edge_costs_its_near_counts`] the hierarchy's 12 reads are
/// pyramid depths and near counts (Rgba32Uint), 16 bytes each: 192 bytes.
#[test]
fn each_read_of_a_walk_counts_its_texels_bytes() {
    let gpu = ssm_testing::gpu();
    let texel = 1.0 / 64.0;
    let input = filter_input(32.0 * texel, 32.0 * texel, [30.0 * texel, 0.0], 30.0 * texel, 1.0);
    let bytes = |depths: Vec<f32>, walk: &str| {
        evaluate(&gpu, "test_integrate_bytes", &input, 1, &Tile::new(64, depths, &[("filter_walk", walk)]))[0]
    };
    let uniform = vec![0.5; 64 * 64];
    let bar: Vec<f32> = (0..64 * 64).map(|i| if (8..12).contains(&(i % 64)) { 0.5 } else { 3.0 }).collect();
    let (hierarchy, texels, two_layers) = (bytes(uniform.clone(), "hierarchy"), bytes(uniform, "texels"), bytes(bar, "hierarchy"));
    println!("(reads, bytes): uniform, hierarchy {hierarchy:?}, every texel {texels:?}; bar {two_layers:?}");
    assert_eq!((hierarchy[0], hierarchy[1]), (4.0, 4.0 * 16.0), "{hierarchy:?}");
    assert_eq!((texels[0], texels[1]), (3600.0, 3600.0 * 4.0), "{texels:?}");
    assert_eq!((two_layers[0], two_layers[1]), (12.0, 12.0 * 16.0), "{two_layers:?}");
}
