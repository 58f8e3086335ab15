//! A technique that ssm-core and the `ssm` tool have never heard of, defined
//! and registered from outside: the subject of the plug-in test, and the
//! smallest complete example of a technique crate.
//!
//! `plugin-hard` is a hard shadow map built from ssm-core's two building
//! blocks: a [`LightDepthMap`] over every triangle and a [`ScreenPass`] that
//! compares each pixel's light depth with it. It needs the G-buffer and
//! nothing else, and keeps its WGSL in the crate to show that a plug-in needs
//! nothing of ours but the `common/` imports. Built for `--count-work`, its lookup counts the
//! texels it reads ([`ReadCounts`]).

use ssm_core::passes::texture_entry;
use ssm_core::read_counts::ReadCounts;
use ssm_core::shader::create_shader;
use ssm_core::{
    Frame, Geometry, GpuContext, LightDepthMap, LightDepthMapDesc, ParamKind, ParamSpec, ParamValues, Requirements, Result, ScreenPass,
    ShadowTechnique, TechniqueInfo, TechniqueKind, TechniqueSetup, VISIBILITY_FORMAT, register_technique,
};

/// The registered name.
pub const NAME: &str = "plugin-hard";

/// The lookup pass's label, and its read counter's.
pub const LOOKUP_PASS: &str = "plugin_hard_lookup";

/// The lookup: lit where the surface is no farther from the light than the nearest surface the
/// depth map saw along the same ray (one texel of normal offset against acne). With COUNT_READS
/// (a counting frame) it counts the texels it loads: the G-buffer's two at every pixel, the depth
/// map's one where it looks up (the normal offset takes the map's size only).
const SHADER: &str = r"
// #import common/screen_pass.wgsl
// #import common/shadow_map.wgsl
// #import common/read_counts.wgsl

@group(2) @binding(0) var depth_map: texture_2d<f32>;
@group(2) @binding(1) var<storage, read_write> read_counts: array<atomic<u32>>;

// Texels this invocation loads.
var<private> reads: u32 = 0u;

fn plugin_hard_visibility(point: ScreenPoint) -> f32 {
    let trivial = trivial_visibility(point);
    if (trivial >= 0.0) {
        return trivial;
    }
    let lookup = normal_offset_position(frame, depth_map, point.position, point.normal, 1.0);
    let uvd = light_uv_depth(frame, lookup);
    reads += 1u;
    return select(0.0, 1.0, uvd.z <= shadow_map_depth(depth_map, uvd.xy));
}

@fragment
fn plugin_hard(in: FullscreenVertex) -> @location(0) f32 {
    let point = screen_point(in);
    reads = 2u;
    let visibility = plugin_hard_visibility(point);
    if (COUNT_READS) {
        let word = read_count_word(0u, point.texel);
        atomicAdd(&read_counts[word], 1u);
        atomicAdd(&read_counts[word + 1u], reads);
    }
    return visibility;
}
";

/// The plug-in's parameters.
pub const PARAMS: &[ParamSpec] =
    &[ParamSpec { name: "map_size", kind: ParamKind::Int { default: 1024, min: 16, max: 8192 }, doc: "side of the depth map, texels" }];

struct PluginHard {
    depth_map: LightDepthMap,
    lookup: ScreenPass,
    depth_map_group: wgpu::BindGroup,
    read_counts: ReadCounts,
}

impl ShadowTechnique for PluginHard {
    fn render(&mut self, frame: &mut Frame<'_>, light: usize, output: &wgpu::TextureView) -> Result<()> {
        self.read_counts.clear(frame, light);
        self.depth_map.encode(frame, light);
        self.lookup.encode(frame, light, output, Some(&self.depth_map_group), None);
        Ok(())
    }

    fn counted_work(&mut self, gpu: &GpuContext) -> Result<Option<Vec<ssm_core::ShaderWork>>> {
        self.read_counts.work(gpu)
    }
}

fn map_size(params: &ParamValues) -> Result<u32> {
    Ok(u32::try_from(params.int("map_size")?).unwrap_or(1024))
}

fn create(setup: &TechniqueSetup<'_>) -> Result<Box<dyn ShadowTechnique>> {
    let size = map_size(setup.params)?;
    let depth_map = LightDepthMap::new(
        setup.gpu,
        setup.scene,
        &LightDepthMapDesc {
            label: "plugin_hard_depth_map",
            width: size,
            height: size,
            geometry: Geometry::All,
            cull_mode: None,
            farthest: false,
            constant_bias: 1e-3 * setup.scene.bounds.size().length(),
            slope_bias: 0.0,
        },
    )?;
    let device = &setup.gpu.device;
    let read_counts = ReadCounts::new(device, "plugin_hard_read_counts", &[LOOKUP_PASS], setup.count_work);
    let layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
        label: Some("plugin_hard_layout"),
        entries: &[texture_entry(0), ReadCounts::layout_entry(1)],
    });
    let depth_map_group = device.create_bind_group(&wgpu::BindGroupDescriptor {
        label: Some("plugin_hard_bind_group"),
        layout: &layout,
        entries: &[
            wgpu::BindGroupEntry { binding: 0, resource: wgpu::BindingResource::TextureView(&depth_map.linear_depth_view) },
            wgpu::BindGroupEntry { binding: 1, resource: read_counts.buffer().as_entire_binding() },
        ],
    });
    let module = create_shader(setup.gpu, "plugin_hard_shader", SHADER)?;
    let lookup = ScreenPass::new(
        setup,
        NAME,
        LOOKUP_PASS,
        (&module, "plugin_hard"),
        Some(&layout),
        VISIBILITY_FORMAT.into(),
        &read_counts.pipeline_constants(),
    )?;
    Ok(Box::new(PluginHard { depth_map, lookup, depth_map_group, read_counts }))
}

/// The registration.
pub const INFO: TechniqueInfo = TechniqueInfo {
    name: NAME,
    summary: "plug-in example: a hard shadow map from ssm-core's LightDepthMap and ScreenPass",
    paper: "Williams 1978 (as a plug-in example)",
    kind: TechniqueKind::Realtime,
    // One view of the light from its centre: the framework adds the own surface's share.
    light_sampling: ssm_core::LightSampling::Centre,
    light_view: ssm_core::LightView::Frame,
    params: PARAMS,
    requirements: |params| Ok(Requirements { gbuffer: true, max_texture_size: map_size(params)?, ..Requirements::NONE }),
    create,
    presets: &[],
    trade: None,
    debug_outputs: &[],
    uniforms: &[],
    limits: &[],
    paper_configuration: ssm_core::PaperConfiguration::DEFAULTS,
};

register_technique!(INFO);
