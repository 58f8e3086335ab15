//! The micro-patch geometry the shaders evaluate (`shaders/atty/atty_geometry.wgsl`) against its
//! Rust twin (`ssm_atty::geometry`), whose own unit tests check it against the paper's formulas
//! and hand-computed cases: a compute shader runs each WGSL function on the same inputs, and the
//! results must agree to the rounding of f32.

// Test helpers unwrap too: a failure should stop the test where it happens.
#![allow(clippy::unwrap_used, clippy::expect_used)]

use glam::{Vec2, Vec4};
use ssm_atty::geometry::{MicroPatch, ReceiverPlane, hidden_fraction, penumbra_half_ndc};
use ssm_core::passes::{bind_group, bind_group_layout, compute_pipeline, storage_entry};
use ssm_core::shader::create_shader_with_imports;
use ssm_testing::gpu;

/// Runs every geometry function of `atty_geometry.wgsl` on the cases: per case four vec4 in
/// (light_half, tan_half | patch centre, patch half | patch depth, receiver depth, receiver |
/// slope, q), one vec4 out (penumbra_half_ndc at the receiver's depth, hidden_fraction,
/// patch_ray_plane_depth with the receiver at ndc `receiver`).
const KERNEL: &str = r"
// #import atty/atty_geometry.wgsl

struct Case {
    lights: vec4<f32>,
    patch_rect: vec4<f32>,
    depths: vec4<f32>,
    plane: vec4<f32>,
};

@group(0) @binding(0) var<storage, read> cases: array<Case>;
@group(0) @binding(1) var<storage, read_write> results: array<vec4<f32>>;

@compute @workgroup_size(64, 1, 1)
fn geometry_twin(@builtin(global_invocation_id) id: vec3<u32>) {
    if (id.x >= arrayLength(&cases)) {
        return;
    }
    let c = cases[id.x];
    let half_ndc = penumbra_half_ndc(c.lights.xy, c.lights.zw, c.patch_rect.zw, c.depths.x, c.depths.y);
    let hidden = hidden_fraction(c.lights.xy, c.patch_rect.xy, c.patch_rect.zw, c.depths.x, c.depths.zw, c.depths.y);
    let plane = patch_ray_plane_depth(c.depths.zw, c.depths.y, c.plane.xy, c.plane.zw);
    results[id.x] = vec4<f32>(half_ndc, hidden, plane);
}
";

/// One case's inputs, as the kernel reads them.
#[derive(Clone, Copy, Debug)]
struct Case {
    light_half: Vec2,
    tan_half: Vec2,
    patch: MicroPatch,
    receiver: Vec2,
    receiver_depth: f32,
    slope: Vec2,
    q: Vec2,
}

impl Case {
    fn packed(&self) -> [f32; 16] {
        let p = &self.patch;
        [
            self.light_half.x,
            self.light_half.y,
            self.tan_half.x,
            self.tan_half.y,
            p.centre.x,
            p.centre.y,
            p.half_size.x,
            p.half_size.y,
            p.depth,
            self.receiver_depth,
            self.receiver.x,
            self.receiver.y,
            self.slope.x,
            self.slope.y,
            self.q.x,
            self.q.y,
        ]
    }

    /// What the Rust twin gives for the kernel's four outputs.
    fn expected(&self) -> Vec4 {
        let half = penumbra_half_ndc(self.light_half, self.tan_half, &self.patch, self.receiver_depth);
        let hidden = hidden_fraction(self.light_half, &self.patch, self.receiver, self.receiver_depth);
        let plane = ReceiverPlane { ndc: self.receiver, depth: self.receiver_depth, slope: self.slope }.depth_at(self.q);
        Vec4::new(half.x, half.y, hidden, plane)
    }
}

/// A deterministic stream of numbers in [0, 1) (a 32-bit LCG, Numerical Recipes' constants).
struct Stream(u32);

impl Stream {
    fn next(&mut self) -> f32 {
        self.0 = self.0.wrapping_mul(1_664_525).wrapping_add(1_013_904_223);
        (self.0 >> 8) as f32 / (1u32 << 24) as f32
    }

    fn range(&mut self, low: f32, high: f32) -> f32 {
        low + (high - low) * self.next()
    }
}

/// The hand-computed case of `geometry.rs`'s unit tests, then random cases: lights from a point
/// (half 0) to 2 units, patches of 0.001 to 0.5 at depths 0.5 to 5, receivers 1.25 to 10 times
/// as deep (so the back-projection scale z_R/(z_R − z_P) stays at most 5), planes of slopes up to
/// ±60 per ndc unit (a wall seen at a grazing angle) read up to 0.5 ndc away.
fn cases() -> Vec<Case> {
    let mut cases = vec![Case {
        light_half: Vec2::ONE,
        tan_half: Vec2::new(0.5, 0.25),
        patch: MicroPatch { centre: Vec2::new(1.0, 0.5), half_size: Vec2::splat(0.25), depth: 2.0 },
        receiver: Vec2::new(2.0, 1.0),
        receiver_depth: 4.0,
        slope: Vec2::new(-0.5, 0.0),
        q: Vec2::new(0.1, 0.2),
    }];
    let mut stream = Stream(39);
    for index in 0..4095 {
        let light = if index % 16 == 0 { Vec2::ZERO } else { Vec2::new(stream.range(0.01, 2.0), stream.range(0.01, 2.0)) };
        let depth = stream.range(0.5, 5.0);
        let receiver_depth = depth * stream.range(1.25, 10.0);
        let patch = MicroPatch {
            centre: Vec2::new(stream.range(-2.0, 2.0), stream.range(-2.0, 2.0)),
            half_size: Vec2::splat(stream.range(0.001, 0.5)),
            depth,
        };
        // Receivers around the patch's shadow, so that many see part of it.
        let receiver = patch.centre * (receiver_depth / depth) + Vec2::new(stream.range(-3.0, 3.0), stream.range(-3.0, 3.0));
        let slope = Vec2::new(stream.range(-60.0, 60.0), stream.range(-60.0, 60.0));
        let q = Vec2::new(stream.range(-0.5, 0.5), stream.range(-0.5, 0.5)) / slope.abs().max_element().max(1.0) * 2.0;
        cases.push(Case {
            light_half: light,
            tan_half: Vec2::new(stream.range(0.2, 10.0), stream.range(0.2, 10.0)),
            patch,
            receiver,
            receiver_depth,
            slope,
            q,
        });
    }
    cases
}

/// Runs the kernel on `cases` on the GPU and reads back its results.
fn run_on_gpu(cases: &[Case]) -> Vec<Vec4> {
    let gpu = gpu();
    let device = &gpu.device;
    let packed: Vec<f32> = cases.iter().flat_map(Case::packed).collect();
    let input = wgpu::util::DeviceExt::create_buffer_init(
        device,
        &wgpu::util::BufferInitDescriptor {
            label: Some("atty_geometry_twin_cases"),
            contents: bytemuck::cast_slice(&packed),
            usage: wgpu::BufferUsages::STORAGE,
        },
    );
    // One vec4<f32> of results per case.
    let size = (cases.len() * 16) as u64;
    let output = device.create_buffer(&wgpu::BufferDescriptor {
        label: Some("atty_geometry_twin_results"),
        size,
        usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_SRC,
        mapped_at_creation: false,
    });
    let layout = bind_group_layout(device, "atty_geometry_twin_layout", &[storage_entry(0, true), storage_entry(1, false)]);
    let group = bind_group(device, "atty_geometry_twin_bind_group", &layout, &[input.as_entire_binding(), output.as_entire_binding()]);
    let module = create_shader_with_imports(&gpu, "atty_geometry_twin_shader", KERNEL, ssm_atty::LOCAL_SHADERS).unwrap();
    let pipeline = compute_pipeline(device, "atty_geometry_twin_pipeline", &module, "geometry_twin", &[&layout], &[]);
    let mut encoder = device.create_command_encoder(&wgpu::CommandEncoderDescriptor { label: Some("atty_geometry_twin_encoder") });
    {
        let mut pass =
            encoder.begin_compute_pass(&wgpu::ComputePassDescriptor { label: Some("atty_geometry_twin"), timestamp_writes: None });
        pass.set_pipeline(&pipeline);
        pass.set_bind_group(0, &group, &[]);
        pass.dispatch_workgroups((cases.len() as u32).div_ceil(64), 1, 1);
    }
    gpu.queue.submit([encoder.finish()]);
    let bytes = ssm_core::readback::read_buffer(&gpu, &output, size, "atty geometry twin").unwrap();
    bytes
        .chunks_exact(16)
        .map(|c| Vec4::from_array(std::array::from_fn(|i| f32::from_le_bytes(c[4 * i..4 * i + 4].try_into().unwrap()))))
        .collect()
}

/// The WGSL functions compute what the Rust twin computes. Both evaluate the same expressions in
/// f32, in the same order; WGSL lets a multiply and an add fuse (one rounding instead of two), so
/// each operation may differ by 2⁻²³ of its magnitude. With at most 8 operations on values up to
/// 60 × 0.5 (the plane's denominator) or scaled by z_R/(z_R − z_P) ≤ 5 (the back-projection,
/// normalised by the light's width), that is below 1e-4 of the result's magnitude, plus 1e-4 of
/// an interval's length where a clamp to the light's edge cuts it (a hidden fraction of order 1).
#[test]
fn the_shaders_geometry_is_the_rust_twins() {
    let cases = cases();
    let results = run_on_gpu(&cases);
    let mut worst = [0.0f32; 4];
    let mut hidden_somewhere = 0;
    for (case, got) in cases.iter().zip(&results) {
        let expected = case.expected();
        hidden_somewhere += usize::from(expected.z > 0.0);
        for axis in 0..4 {
            let (e, g) = (expected[axis], got[axis]);
            // patch_ray_plane_depth returns NO_SURFACE where the Rust twin returns infinity.
            let (e, g) = if axis == 3 && e.is_infinite() { (f32::MAX, g) } else { (e, g) };
            let error = (e - g).abs() / (1.0 + e.abs());
            worst[axis] = worst[axis].max(error);
            assert!(error <= 1e-4, "case {case:?}, output {axis}: Rust {e}, WGSL {g}");
        }
    }
    println!("{} cases, {hidden_somewhere} with a hidden fraction; largest relative differences {worst:?}", cases.len());
    assert!(hidden_somewhere > cases.len() / 10, "the cases must exercise the back-projection: {hidden_somewhere}");
    // The hand-computed case: half extents (l + p)/(z_P tan) − l/(z_R tan) = (0.75, 1.5), a
    // quarter of the light hidden, and the plane 1/z(q) = (1 − 0.5 · (0.1 − 2))/4 → 4/1.95.
    let first = results[0];
    assert!((first.x - 0.75).abs() < 1e-6 && (first.y - 1.5).abs() < 1e-6 && (first.z - 0.25).abs() < 1e-6, "{first}");
    assert!((first.w - 4.0 / 1.95).abs() < 1e-5, "{first}");
}
