//! A technique that ssm-core and the `ssm` tool have never heard of, defined
//! and registered from outside: the subject of the plug-in test.
//!
//! `front-of-light` ignores occluders: a pixel is lit (1) when its surface lies
//! in front of the light's plane and unlit (0) behind it, the one-sided
//! emitter's own cut-off. It needs the G-buffer and nothing else.

use ssm_core::passes::{color_attachment, fullscreen_pipeline};
use ssm_core::shader::create_shader;
use ssm_core::{
    Frame, ParamSpec, Requirements, Result, ShadowTechnique, TechniqueInfo, TechniqueSetup,
    VISIBILITY_FORMAT, register_technique,
};

/// The registered name.
pub const NAME: &str = "front-of-light";

/// The shader, kept in the crate to show that a plug-in needs nothing of ours
/// but the `common/` imports.
const SHADER: &str = r"
// #import common/fullscreen.wgsl
// #import common/light_frame.wgsl

@group(0) @binding(0) var<uniform> frame: LightFrame;
@group(1) @binding(0) var gbuffer_position: texture_2d<f32>;
@group(1) @binding(1) var gbuffer_normal: texture_2d<f32>;

@fragment
fn front_of_light(in: FullscreenVertex) -> @location(0) f32 {
    let position = textureLoad(gbuffer_position, vec2<i32>(in.clip.xy), 0);
    if (position.w < 0.5) {
        return 1.0;
    }
    return select(0.0, 1.0, in_front_of_light(frame, position.xyz));
}
";

struct FrontOfLight {
    pipeline: wgpu::RenderPipeline,
    gbuffer_bind_group: wgpu::BindGroup,
}

impl ShadowTechnique for FrontOfLight {
    fn render(
        &mut self,
        frame: &mut Frame<'_>,
        light: usize,
        output: &wgpu::TextureView,
    ) -> Result<()> {
        let light_frame = &frame.scene.light_bind_groups[light];
        let mut pass = frame.render_pass(
            "front_of_light_test",
            &[color_attachment(output, None)],
            None,
        );
        pass.set_pipeline(&self.pipeline);
        pass.set_bind_group(0, light_frame, &[]);
        pass.set_bind_group(1, &self.gbuffer_bind_group, &[]);
        pass.draw(0..3, 0..1);
        Ok(())
    }
}

fn create(setup: &TechniqueSetup<'_>) -> Result<Box<dyn ShadowTechnique>> {
    let gbuffer = setup.shared.gbuffer(NAME)?;
    let module = create_shader(setup.gpu, "front_of_light_shader", SHADER)?;
    let pipeline = fullscreen_pipeline(
        &setup.gpu.device,
        "front_of_light_pipeline",
        &module,
        "front_of_light",
        &[&setup.scene.uniform_layout, &gbuffer.layout],
        VISIBILITY_FORMAT.into(),
    );
    Ok(Box::new(FrontOfLight {
        pipeline,
        gbuffer_bind_group: gbuffer.bind_group.clone(),
    }))
}

const PARAMS: &[ParamSpec] = &[];

register_technique!(TechniqueInfo {
    name: NAME,
    summary: "test plug-in: lit in front of the light's plane, unlit behind; no occlusion",
    paper: "none (plug-in test)",
    params: PARAMS,
    requirements: |_| Ok(Requirements {
        gbuffer: true,
        ..Requirements::NONE
    }),
    create,
});

/// Call from a binary so that the linker keeps this crate, and with it the registration.
#[inline(never)]
pub fn link() -> &'static str {
    NAME
}
