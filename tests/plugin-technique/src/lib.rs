//! A technique that ssm-core and the `ssm` tool have never heard of, defined
//! and registered from outside: the subject of the plug-in test, and the
//! smallest complete example of a technique crate.
//!
//! `plugin-hard` is a hard shadow map built from ssm-core's two building
//! blocks: a [`LightDepthMap`] over every triangle and a [`ScreenPass`] that
//! compares each pixel's light depth with it. It needs the G-buffer and
//! nothing else, and keeps its WGSL in the crate to show that a plug-in needs
//! nothing of ours but the `common/` imports.

use ssm_core::passes::texture_entry;
use ssm_core::shader::create_shader;
use ssm_core::{
    Frame, Geometry, LightDepthMap, LightDepthMapDesc, ParamKind, ParamSpec, ParamValues, Requirements, Result, ScreenPass,
    ShadowTechnique, TechniqueInfo, TechniqueKind, TechniqueSetup, VISIBILITY_FORMAT, register_technique,
};

/// The registered name.
pub const NAME: &str = "plugin-hard";

/// The lookup: lit where the surface is no farther from the light than the nearest surface the
/// depth map saw along the same ray (one texel of normal offset against acne).
const SHADER: &str = r"
// #import common/screen_pass.wgsl
// #import common/shadow_map.wgsl

@group(2) @binding(0) var depth_map: texture_2d<f32>;

@fragment
fn plugin_hard(in: FullscreenVertex) -> @location(0) f32 {
    let point = screen_point(in);
    let trivial = trivial_visibility(point);
    if (trivial >= 0.0) {
        return trivial;
    }
    let lookup = normal_offset_position(frame, depth_map, point.position, point.normal, 1.0);
    let uvd = light_uv_depth(frame, lookup);
    return select(0.0, 1.0, uvd.z <= shadow_map_depth(depth_map, uvd.xy));
}
";

/// The plug-in's parameters.
pub const PARAMS: &[ParamSpec] =
    &[ParamSpec { name: "map_size", kind: ParamKind::Int { default: 1024, min: 16, max: 8192 }, doc: "side of the depth map, texels" }];

struct PluginHard {
    depth_map: LightDepthMap,
    lookup: ScreenPass,
    depth_map_group: wgpu::BindGroup,
}

impl ShadowTechnique for PluginHard {
    fn render(&mut self, frame: &mut Frame<'_>, light: usize, output: &wgpu::TextureView) -> Result<()> {
        self.depth_map.encode(frame, light);
        self.lookup.encode(frame, light, output, Some(&self.depth_map_group), None);
        Ok(())
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
    let layout = device
        .create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor { label: Some("plugin_hard_layout"), entries: &[texture_entry(0)] });
    let depth_map_group = device.create_bind_group(&wgpu::BindGroupDescriptor {
        label: Some("plugin_hard_bind_group"),
        layout: &layout,
        entries: &[wgpu::BindGroupEntry { binding: 0, resource: wgpu::BindingResource::TextureView(&depth_map.linear_depth_view) }],
    });
    let module = create_shader(setup.gpu, "plugin_hard_shader", SHADER)?;
    let lookup =
        ScreenPass::new(setup, NAME, "plugin_hard_lookup", (&module, "plugin_hard"), Some(&layout), VISIBILITY_FORMAT.into(), &[])?;
    Ok(Box::new(PluginHard { depth_map, lookup, depth_map_group }))
}

/// The registration.
pub const INFO: TechniqueInfo = TechniqueInfo {
    name: NAME,
    summary: "plug-in example: a hard shadow map from ssm-core's LightDepthMap and ScreenPass",
    paper: "Williams 1978 (as a plug-in example)",
    kind: TechniqueKind::Realtime,
    params: PARAMS,
    requirements: |params| Ok(Requirements { gbuffer: true, max_texture_size: map_size(params)?, ..Requirements::NONE }),
    create,
    presets: &[],
    trade: None,
    debug_outputs: &[],
    uniforms: &[],
    limits: &[],
};

register_technique!(INFO);
