//! A technique that ssm-core and the `ssm` tool have never heard of, defined
//! and registered from outside: the subject of the plug-in test.
//!
//! `front-of-light` ignores occluders: a pixel is lit (1) when its surface lies
//! in front of the light's plane and unlit (0) behind it, the one-sided
//! emitter's own cut-off. It needs the G-buffer and nothing else.

use ssm_core::shader::create_shader;
use ssm_core::{
    Frame, ParamSpec, Requirements, Result, ScreenPass, ShadowTechnique, TechniqueInfo, TechniqueKind, TechniqueSetup, VISIBILITY_FORMAT,
    register_technique,
};

/// The registered name.
pub const NAME: &str = "front-of-light";

/// The shader, kept in the crate to show that a plug-in needs nothing of ours
/// but the `common/` imports.
const SHADER: &str = r"
// #import common/screen_pass.wgsl

@fragment
fn front_of_light(in: FullscreenVertex) -> @location(0) f32 {
    let point = screen_point(in);
    if (!point.covered) {
        return 1.0;
    }
    return select(0.0, 1.0, in_front_of_light(frame, point.position));
}
";

struct FrontOfLight {
    pass: ScreenPass,
}

impl ShadowTechnique for FrontOfLight {
    fn render(&mut self, frame: &mut Frame<'_>, light: usize, output: &wgpu::TextureView) -> Result<()> {
        self.pass.encode(frame, light, output, None, None);
        Ok(())
    }
}

fn create(setup: &TechniqueSetup<'_>) -> Result<Box<dyn ShadowTechnique>> {
    let module = create_shader(setup.gpu, "front_of_light_shader", SHADER)?;
    let pass = ScreenPass::new(setup, NAME, "front_of_light_test", (&module, "front_of_light"), None, VISIBILITY_FORMAT.into())?;
    Ok(Box::new(FrontOfLight { pass }))
}

const PARAMS: &[ParamSpec] = &[];

register_technique!(TechniqueInfo {
    name: NAME,
    summary: "test plug-in: lit in front of the light's plane, unlit behind; no occlusion",
    paper: "none (plug-in test)",
    kind: TechniqueKind::Realtime,
    params: PARAMS,
    requirements: |_| Ok(Requirements { gbuffer: true, ..Requirements::NONE }),
    create,
});
