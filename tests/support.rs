//! Helpers shared by the cross-crate tests: a GPU context that fails loudly,
//! rendering a technique to visibility, locating world points in the image,
//! and the analytic answer of `parallel-square`.

use glam::Vec3;
use ssm_core::{GpuContext, Registry, Renderer, Requirements};
use ssm_scene::Scene;

/// Keeps every technique crate linked into the test binaries, so that their registrations are present.
pub fn link_techniques() {
    ssm_hard::link();
    ssm_pcss::link();
    ssm_plugin_technique::link();
}

/// The GPU context. A missing adapter fails the test with the install hint:
/// in CI there must be one (lavapipe), and a silently skipped GPU test proves nothing.
#[must_use]
pub fn gpu() -> GpuContext {
    match GpuContext::new() {
        Ok(gpu) => gpu,
        Err(e) => panic!("{e}"),
    }
}

/// A rendered frame: the renderer (for further reads) and light 0's visibility.
pub struct Rendered {
    /// The renderer, with the technique's output still in its targets.
    pub renderer: Renderer,
    /// Light 0's visibility, row-major from the top-left.
    pub visibility: Vec<f32>,
}

/// Renders `technique` with `settings` (`name=value`) on `scene` at `width` × `height`.
///
/// # Errors
/// Whatever the framework or the technique reports.
pub fn render(
    gpu: &GpuContext,
    scene: &Scene,
    technique: &str,
    settings: &[(&str, &str)],
    width: u32,
    height: u32,
) -> ssm_core::Result<Rendered> {
    link_techniques();
    let info = Registry::global()?.get(technique)?;
    let params = info.params_from(settings.iter().copied())?;
    let needs = (info.requirements)(&params)?.union(Requirements {
        gbuffer: true,
        ..Requirements::NONE
    });
    let mut renderer = Renderer::new(gpu, scene, width, height, &needs)?;
    let mut instance = renderer.create_technique(info, &params)?;
    renderer.render(instance.as_mut(), technique)?;
    let visibility = renderer.read_visibility(0, technique)?;
    Ok(Rendered {
        renderer,
        visibility,
    })
}

/// The pixel (column, row) where the camera sees world point `world`.
#[must_use]
pub fn pixel_of(scene: &Scene, width: u32, height: u32, world: Vec3) -> (u32, u32) {
    let view_proj = scene.camera.projection(width as f32 / height as f32) * scene.camera.view();
    let ndc = view_proj.project_point3(world);
    let x = ((ndc.x * 0.5 + 0.5) * width as f32)
        .floor()
        .clamp(0.0, width as f32 - 1.0);
    let y = ((0.5 - ndc.y * 0.5) * height as f32)
        .floor()
        .clamp(0.0, height as f32 - 1.0);
    (x as u32, y as u32)
}

/// Visibility at pixel (x, y).
#[must_use]
pub fn at(rendered: &Rendered, (x, y): (u32, u32)) -> f32 {
    rendered.visibility[(y * rendered.renderer.width() + x) as usize]
}

/// Exact visibility of `parallel-square` at receiver point (x, 0, z): the
/// occluder [-0.5, 0.5]² at y = 2 seen from the point projects onto the light
/// plane y = 4 as [-1 - x, 1 - x] × [-1 - z, 1 - z]; the hidden fraction of the
/// unit light is the product of the two 1-D overlaps (Atty et al., Sec. 4.2).
#[must_use]
pub fn parallel_square_exact(x: f32, z: f32) -> f32 {
    let overlap = |c: f32| ((1.0 - c).min(0.5) - (-1.0 - c).max(-0.5)).max(0.0);
    1.0 - overlap(x) * overlap(z)
}
