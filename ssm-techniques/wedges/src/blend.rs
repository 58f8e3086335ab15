//! The silhouette buffers and their blending (Forest et al., Sec. 3.2 and 4.3;
//! `wedges_blend.wgsl`): step 3's last two passes per silhouette buffer and step 4. Here are the
//! silhouette buffer that the wedges write (the paper's seven parameters per radial part of the
//! light, Sec. 3.1, Figs. 6 and 10), the umbra mask that turns a buffer's stencil count into a
//! colour, the blend of each buffer into the final buffer (summed, or Forest et al.'s
//! ε = (A_f/B_f)(A_s/B_s)β with the union of the bounding rectangles), and the resolve of the
//! final buffer into visibility.

use ssm_core::passes::{
    bind_group, bind_group_layout, color_attachment, compute_pipeline, labelled_view, render_texture, texture_entry, uniform_entry,
};
use ssm_core::read_counts::ReadCounts;
use ssm_core::shader::create_shader_with_imports;
use ssm_core::{Frame, GpuContext, Result, ScreenPass, TechniqueSetup, VISIBILITY_FORMAT};

use crate::gpu::{LOCAL_SHADERS, STENCIL_FORMAT, draw_offset, storage, storage_entry};
use crate::{FINAL_BINDING_BYTES_PER_PIXEL, NAME, PenumbraWedges};

/// Blending and resolve.
const BLEND_SHADER: &str = ssm_shaders::wedges::WEDGES_BLEND;

/// Format of the silhouette buffer's seven parameter targets: full-precision floats (the paper packed 8 bits).
pub const SILHOUETTE_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rgba32Float;
/// Format of the eighth target, the count of wedge fragments shaded.
pub const SHADED_COUNT_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::R32Float;
/// Format of the umbra mask (1 where the stencil count is not zero).
pub const UMBRA_MASK_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::R8Unorm;
/// Targets of the silhouette buffer: areas, four rectangles, two pairs of inner maxima (the paper's
/// seven parameters per radial part, Sec. 4.3, in seven Rgba32Float targets), and the count of fragments shaded.
pub const SILHOUETTE_TARGETS: usize = 8;
/// Bytes per pixel of the silhouette buffer's targets.
pub(crate) const SILHOUETTE_BYTES: u32 = 7 * 16 + 4;
/// Radial parts of the light (Sec. 3.1, Fig. 6): the final buffer has one rectangle buffer per part.
pub(crate) const RADIAL_PARTS: usize = 4;

/// The silhouette buffer's targets, the umbra mask, the final buffer, and the blend and resolve passes.
pub(crate) struct BlendPasses {
    pub(crate) silhouette_views: Vec<wgpu::TextureView>,
    pub(crate) umbra_mask_view: wgpu::TextureView,
    pub(crate) umbra_mask_pipeline: wgpu::RenderPipeline,
    pub(crate) blend_pipeline: wgpu::ComputePipeline,
    pub(crate) blend_group: wgpu::BindGroup,
    pub(crate) resolve: ScreenPass,
    /// The final buffer (Sec. 3.2): per pixel, the four radial parts' occluded areas ...
    pub(crate) final_areas: wgpu::Buffer,
    /// ... and each part's bounding rectangle, one buffer per part (16 bytes per pixel each, so
    /// that every binding stays under the storage binding limit: [`AllocationPlan`](crate::AllocationPlan)).
    pub(crate) final_rectangles: [wgpu::Buffer; RADIAL_PARTS],
    pub(crate) fragment_counts: wgpu::Buffer,
}

impl BlendPasses {
    /// Allocates the silhouette buffer's targets, the umbra mask and the final buffer for `pixels`,
    /// and builds the umbra mask's, the blend's and the resolve's pipelines.
    pub(crate) fn new(setup: &TechniqueSetup<'_>, pixels: u64, settings_buffer: &wgpu::Buffer, read_counts: &ReadCounts) -> Result<Self> {
        let gpu = setup.gpu;
        let device = &gpu.device;
        let (width, height) = (setup.scene.width, setup.scene.height);
        let final_size = pixels * FINAL_BINDING_BYTES_PER_PIXEL;
        let final_areas = storage(device, "wedges_final_areas", final_size, wgpu::BufferUsages::COPY_DST);
        let final_rectangles =
            [0, 1, 2, 3].map(|part| storage(device, &format!("wedges_final_rectangles_{part}"), final_size, wgpu::BufferUsages::COPY_DST));
        let fragment_counts =
            storage(device, "wedges_fragment_counts", pixels * 4, wgpu::BufferUsages::COPY_DST | wgpu::BufferUsages::COPY_SRC);
        let silhouette_views: Vec<wgpu::TextureView> = (0..SILHOUETTE_TARGETS)
            .map(|k| {
                let label = format!("wedges_silhouette_buffer_{k}");
                let format = if k + 1 == SILHOUETTE_TARGETS { SHADED_COUNT_FORMAT } else { SILHOUETTE_FORMAT };
                labelled_view(&render_texture(device, &label, width, height, format, wgpu::TextureUsages::empty()), &label)
            })
            .collect();
        let umbra_mask = render_texture(device, "wedges_umbra_mask", width, height, UMBRA_MASK_FORMAT, wgpu::TextureUsages::empty());
        let umbra_mask_view = labelled_view(&umbra_mask, "wedges_umbra_mask");
        let blend_layout = blend_layout(device);
        let mut blend_resources: Vec<wgpu::BindingResource<'_>> = silhouette_views.iter().map(wgpu::BindingResource::TextureView).collect();
        blend_resources.push(final_areas.as_entire_binding());
        blend_resources.push(settings_buffer.as_entire_binding());
        blend_resources.push(wgpu::BindingResource::TextureView(&umbra_mask_view));
        blend_resources.push(fragment_counts.as_entire_binding());
        blend_resources.extend(final_rectangles.iter().map(wgpu::Buffer::as_entire_binding));
        blend_resources.push(read_counts.buffer().as_entire_binding());
        let blend_group = bind_group(device, "wedges_blend_bind_group", &blend_layout, &blend_resources);
        let blend_module = create_shader_with_imports(gpu, "wedges_blend_shader", BLEND_SHADER, LOCAL_SHADERS)?;
        let blend_pipeline = compute_pipeline(
            device,
            "wedges_blend_pipeline",
            &blend_module,
            "wedges_blend",
            &[gpu.uniform_layout(), gpu.gbuffer_layout(), &blend_layout],
            &read_counts.pipeline_constants(),
        );
        let umbra_mask_pipeline = umbra_mask_pipeline(gpu, &blend_module);
        let resolve = ScreenPass::new(
            setup,
            NAME,
            "wedges_resolve",
            (&blend_module, "wedges_resolve"),
            Some(&blend_layout),
            VISIBILITY_FORMAT.into(),
            &read_counts.pipeline_constants(),
        )?;
        Ok(Self {
            silhouette_views,
            umbra_mask_view,
            umbra_mask_pipeline,
            blend_pipeline,
            blend_group,
            resolve,
            final_areas,
            final_rectangles,
            fragment_counts,
        })
    }

    /// Clears the final buffer and the fragment counts before a light's first silhouette buffer.
    pub(crate) fn clear(&self, frame: &mut Frame<'_>) {
        frame.clear_buffer("wedges_final_areas_clear", &self.final_areas, 0, None);
        for rectangles in &self.final_rectangles {
            frame.clear_buffer("wedges_final_rectangles_clear", rectangles, 0, None);
        }
        frame.clear_buffer("wedges_fragment_counts_clear", &self.fragment_counts, 0, None);
    }
}

fn blend_layout(device: &wgpu::Device) -> wgpu::BindGroupLayout {
    let mut entries: Vec<wgpu::BindGroupLayoutEntry> = (0..SILHOUETTE_TARGETS as u32).map(texture_entry).collect();
    let areas = SILHOUETTE_TARGETS as u32;
    entries.push(storage_entry(areas, false, wgpu::ShaderStages::FRAGMENT | wgpu::ShaderStages::COMPUTE));
    entries.push(uniform_entry(areas + 1));
    entries.push(texture_entry(areas + 2));
    entries.push(storage_entry(areas + 3, false, wgpu::ShaderStages::COMPUTE));
    entries.extend((0..RADIAL_PARTS as u32).map(|part| storage_entry(areas + 4 + part, false, wgpu::ShaderStages::COMPUTE)));
    entries.push(ReadCounts::layout_entry(areas + 4 + RADIAL_PARTS as u32));
    bind_group_layout(device, "wedges_blend_layout", &entries)
}

/// The umbra mask: 1 where this buffer's stencil count is not zero. Storage writes are not
/// gated by the stencil test (fragment tests run after a shader with side effects), colour writes are.
fn umbra_mask_pipeline(gpu: &GpuContext, module: &wgpu::ShaderModule) -> wgpu::RenderPipeline {
    let device = &gpu.device;
    let pipeline_layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
        label: Some("wedges_umbra_mask_pipeline_layout"),
        bind_group_layouts: &[Some(gpu.uniform_layout()), Some(gpu.gbuffer_layout())],
        immediate_size: 0,
    });
    let face = wgpu::StencilFaceState {
        compare: wgpu::CompareFunction::NotEqual,
        fail_op: wgpu::StencilOperation::Keep,
        depth_fail_op: wgpu::StencilOperation::Keep,
        pass_op: wgpu::StencilOperation::Keep,
    };
    device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
        label: Some("wedges_umbra_mask_pipeline"),
        layout: Some(&pipeline_layout),
        vertex: wgpu::VertexState { module, entry_point: Some("fullscreen_vertex"), compilation_options: Default::default(), buffers: &[] },
        primitive: wgpu::PrimitiveState::default(),
        depth_stencil: Some(wgpu::DepthStencilState {
            format: STENCIL_FORMAT,
            depth_write_enabled: Some(false),
            depth_compare: Some(wgpu::CompareFunction::Always),
            stencil: wgpu::StencilState { front: face, back: face, read_mask: 0xff, write_mask: 0 },
            bias: wgpu::DepthBiasState::default(),
        }),
        multisample: wgpu::MultisampleState::default(),
        fragment: Some(wgpu::FragmentState {
            module,
            entry_point: Some("wedges_umbra_mask"),
            compilation_options: Default::default(),
            targets: &[Some(UMBRA_MASK_FORMAT.into())],
        }),
        multiview_mask: None,
        cache: None,
    })
}

impl PenumbraWedges {
    /// One silhouette buffer's umbra mask, from its stencil count.
    pub(crate) fn encode_umbra_mask(&self, frame: &mut Frame<'_>, light_frame: &wgpu::BindGroup) {
        // The stencil count becomes a colour: one full-screen triangle through the stencil test.
        let mut pass = frame.render_pass(
            "wedges_shadow_volumes",
            &[color_attachment(&self.blend.umbra_mask_view, Some(wgpu::Color::TRANSPARENT))],
            Some(wgpu::RenderPassDepthStencilAttachment {
                view: &self.stencil_view,
                depth_ops: Some(wgpu::Operations { load: wgpu::LoadOp::Load, store: wgpu::StoreOp::Store }),
                stencil_ops: Some(wgpu::Operations { load: wgpu::LoadOp::Load, store: wgpu::StoreOp::Store }),
            }),
        );
        pass.set_pipeline(&self.blend.umbra_mask_pipeline);
        pass.set_bind_group(0, light_frame, &[]);
        pass.set_bind_group(1, &self.gbuffer_group, &[]);
        pass.set_stencil_reference(0);
        pass.draw(0..3, 0..1);
    }

    /// One silhouette buffer's blend into the final buffer (Sec. 3.2).
    pub(crate) fn encode_blend(&self, frame: &mut Frame<'_>, (light_frame, group): (&wgpu::BindGroup, u32)) {
        let mut pass = frame.compute_pass("wedges_blend");
        pass.set_pipeline(&self.blend.blend_pipeline);
        pass.set_bind_group(0, light_frame, &[]);
        pass.set_bind_group(1, &self.gbuffer_group, &[]);
        pass.set_bind_group(2, &self.blend.blend_group, &[]);
        pass.dispatch_workgroups_indirect(&self.indirect, draw_offset(group, 3));
    }
}
