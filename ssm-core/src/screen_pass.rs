//! A full-screen pass over the G-buffer for one light: the shape of every
//! screen-space step (a shadow-map lookup, a blocker search and filter, the
//! passes of a separable filter).

use crate::error::Result;
use crate::frame::Frame;
use crate::passes::{color_attachment, fullscreen_pipeline};
use crate::technique::TechniqueSetup;

/// A full-screen pass with the binding convention of
/// `shaders/common/screen_pass.wgsl`: group 0 the light frame, group 1 the
/// G-buffer, group 2 (optional) the technique's own resources. Built once;
/// [`ScreenPass::encode`] records it, labelled and timed under its label.
#[derive(Debug)]
pub struct ScreenPass {
    label: String,
    pipeline: wgpu::RenderPipeline,
    gbuffer_bind_group: wgpu::BindGroup,
}

impl ScreenPass {
    /// Builds the pipeline of fragment entry point `fragment` in `module`,
    /// writing one `target`, with values for its pipeline-overridable constants
    /// (WGSL `override`, by name; `&[]` for none; [`fullscreen_pipeline`]).
    /// `technique` names the caller in errors; `label` names the pass and
    /// prefixes its GPU objects.
    ///
    /// # Errors
    /// [`Error::UndeclaredRequirement`](crate::Error::UndeclaredRequirement) if
    /// the technique did not declare the G-buffer.
    pub fn new(
        setup: &TechniqueSetup<'_>,
        technique: &str,
        label: &str,
        (module, fragment): (&wgpu::ShaderModule, &str),
        own_layout: Option<&wgpu::BindGroupLayout>,
        target: wgpu::ColorTargetState,
        constants: &[(&str, f64)],
    ) -> Result<Self> {
        Self::with_targets(setup, technique, label, (module, fragment), own_layout, &[target], constants)
    }

    /// [`ScreenPass::new`] writing several `targets` at once, the fragment's `@location(0)`,
    /// `@location(1)`, ... in order: what a pass hands on in more than one texture, written as
    /// render targets (cheaper than a storage-texture store per pixel on a CPU rasteriser).
    ///
    /// # Errors
    /// As [`ScreenPass::new`].
    pub fn with_targets(
        setup: &TechniqueSetup<'_>,
        technique: &str,
        label: &str,
        (module, fragment): (&wgpu::ShaderModule, &str),
        own_layout: Option<&wgpu::BindGroupLayout>,
        targets: &[wgpu::ColorTargetState],
        constants: &[(&str, f64)],
    ) -> Result<Self> {
        let gbuffer = setup.shared.gbuffer(technique)?;
        let mut layouts = vec![&setup.scene.uniform_layout, &gbuffer.layout];
        layouts.extend(own_layout);
        let pipeline = fullscreen_pipeline(&setup.gpu.device, &format!("{label}_pipeline"), module, fragment, &layouts, targets, constants);
        Ok(Self { label: label.to_owned(), pipeline, gbuffer_bind_group: gbuffer.bind_group.clone() })
    }

    /// Records the pass for `light` into `target`, with `own_group` at group 2.
    /// `clear` clears the target first; `None` keeps what it holds.
    pub fn encode(
        &self,
        frame: &mut Frame<'_>,
        light: usize,
        target: &wgpu::TextureView,
        own_group: Option<&wgpu::BindGroup>,
        clear: Option<wgpu::Color>,
    ) {
        self.encode_targets(frame, light, &[target], own_group, clear);
    }

    /// [`ScreenPass::encode`] into the targets of a pass built
    /// [`with_targets`](ScreenPass::with_targets), in the same order; `clear` clears them all.
    pub fn encode_targets(
        &self,
        frame: &mut Frame<'_>,
        light: usize,
        targets: &[&wgpu::TextureView],
        own_group: Option<&wgpu::BindGroup>,
        clear: Option<wgpu::Color>,
    ) {
        let light_frame = &frame.scene.light_bind_groups[light];
        let attachments: Vec<_> = targets.iter().map(|target| color_attachment(target, clear)).collect();
        let mut pass = frame.render_pass(&self.label, &attachments, None);
        pass.set_pipeline(&self.pipeline);
        pass.set_bind_group(0, light_frame, &[]);
        pass.set_bind_group(1, &self.gbuffer_bind_group, &[]);
        if let Some(group) = own_group {
            pass.set_bind_group(2, group, &[]);
        }
        pass.draw(0..3, 0..1);
    }
}
