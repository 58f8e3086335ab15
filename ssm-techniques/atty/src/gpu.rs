//! The technique's GPU objects and the plumbing several steps share, no step of the paper of its
//! own: [`SoftShadowMaps`], which builds every step's maps and passes once, in the paper's order;
//! the light depth maps without bias (the occluder maps, Sec. 3.2, and the receiver map without
//! `receiver_plane`, Sec. 3.1); the depth pyramids (the patch merge's and the receiver bounds');
//! and each occluder side's maps, buffers and bind groups (one side, or two, Sec. 3.5), from its
//! occluder map to its soft shadow map, among them the micro-patch list and the indirect draw's
//! arguments that the list pass writes and the accumulation draws.

use ssm_core::passes::{
    bind_group, bind_group_layout, compute_pipeline, labelled_view, render_texture, texture_entry, uniform_buffer,
    write_storage_texture_entry,
};
use ssm_core::read_counts::ReadCounts;
use ssm_core::shader::create_shader_with_imports;
use ssm_core::{Error, Frame, Geometry, LightDepthMap, LightDepthMapDesc, Result, ScreenPass, Settings, TechniqueSetup};

use crate::accumulation::accumulate_layout;
use crate::counts::{CounterPlan, PATCHES_UNITS, PYRAMID_UNITS, READS, counter_slice, texel_bytes};
use crate::micro_patches::{PATCH_RECORD_BYTES, patches_layout};
use crate::occluder_map::{ONE_SIDED, Side, TWO_SIDED};
use crate::patch_merge::PATCH_MERGE;
use crate::receiver_bounds::RECEIVER_BOUNDS;
use crate::receiver_map::ReceiverMap;
use crate::{AttySettings, AttySettingsUniform, LOCAL_SHADERS, PenumbraBound, accumulation, micro_patches, projection};

/// Atty et al.'s soft shadow maps.
pub struct SoftShadowMaps {
    pub(crate) receiver_map: ReceiverMap,
    /// The receiver map's max-pyramid, when it bounds the penumbra rectangles.
    pub(crate) receiver_bounds: Option<DepthPyramid>,
    /// Front faces (or every face, one-sided), then back faces when two-sided.
    pub(crate) accumulations: Vec<SideAccumulation>,
    pub(crate) accumulate_pipeline: wgpu::RenderPipeline,
    pub(crate) patches_pipeline: wgpu::ComputePipeline,
    /// Occluder-map side, texels: the list pass runs one invocation per texel.
    pub(crate) occluder_map_size: u32,
    pub(crate) project: ScreenPass,
    pub(crate) project_group: wgpu::BindGroup,
    /// What the shaders count for `--count-work` ([`CounterPlan`]); enabled only then.
    pub(crate) read_counts: ReadCounts,
}

impl SoftShadowMaps {
    /// Builds the maps and pipelines.
    ///
    /// # Errors
    /// A parameter or GPU error, or [`Error::Unrepresentable`] when the receivers are too small in the light's frame.
    pub fn new(setup: &TechniqueSetup<'_>) -> Result<Self> {
        let settings = AttySettings::from_params(setup.params)?;
        crate::check_receivers_resolved(setup, settings.ssm_size)?;
        let settings_buffer = uniform_buffer(&setup.gpu.device, "atty_settings_uniform", &AttySettingsUniform::from(&settings));
        let receiver_map = ReceiverMap::new(setup, &settings, &settings_buffer)?;
        let bounded = settings.penumbra_bound == PenumbraBound::Receivers;
        let sides = if settings.two_sided { TWO_SIDED } else { ONE_SIDED };
        let plan = CounterPlan::new(&settings, sides);
        let read_counts = ReadCounts::with_units(&setup.gpu.device, "atty_read_counts", &plan.counters, setup.count_work);
        // Unbounded, the accumulation still binds a pyramid, of one texel, that it never reads (nor
        // builds: its counter slice is the first counters, never written by it).
        let receiver_bounds = DepthPyramid::new(
            setup,
            (&RECEIVER_BOUNDS, RECEIVER_BOUNDS.label),
            (receiver_map.view(), receiver_map.format()),
            if bounded { settings.ssm_size } else { 1 },
            (&read_counts, counter_slice(&read_counts, plan.receiver_bounds.unwrap_or(0), PYRAMID_UNITS.len())),
        )?;
        let accumulations = accumulations(
            setup,
            (&settings, sides, &plan),
            (receiver_map.view(), &receiver_bounds.view),
            (&settings_buffer, &read_counts),
        )?;
        let accumulate_pipeline = accumulation::accumulate_pipeline(setup, (settings.accumulation, receiver_map.format()), &read_counts)?;
        let patches_pipeline = micro_patches::patches_pipeline(setup, &read_counts)?;
        let (project, project_group) = projection::projection(
            setup,
            (&accumulations, settings.accumulation),
            &receiver_map,
            &settings_buffer,
            (&read_counts, plan.project),
        )?;
        Ok(Self {
            receiver_map,
            receiver_bounds: bounded.then_some(receiver_bounds),
            accumulations,
            accumulate_pipeline,
            patches_pipeline,
            occluder_map_size: settings.occluder_map_size,
            project,
            project_group,
            read_counts,
        })
    }
}

/// One soft shadow map and the pass that fills it from one occluder map.
pub(crate) struct SideAccumulation {
    pub(crate) occluder_map: LightDepthMap,
    /// The indirect draw's arguments: 4 vertices, then the patch count the list pass counts up.
    pub(crate) draw_arguments: wgpu::Buffer,
    /// The list pass's bind group (occluder map, settings, pyramids, patch list, draw arguments).
    pub(crate) patches_group: wgpu::BindGroup,
    /// The list pass's name, `<label>_patches`.
    pub(crate) patches_label: &'static str,
    /// The occluder map's depth range per block, when micro-patches merge.
    pub(crate) patch_merge: Option<DepthPyramid>,
    pub(crate) soft_shadow_map: wgpu::TextureView,
    pub(crate) bind_group: wgpu::BindGroup,
    pub(crate) label: &'static str,
}

/// A linear depth map of the occluders or receivers, without bias: micro-patches and receivers sit at their true depths.
pub(crate) fn unbiased_depth_map(
    setup: &TechniqueSetup<'_>,
    label: &str,
    size: u32,
    geometry: Geometry,
    (cull_mode, farthest): (Option<wgpu::Face>, bool),
) -> Result<LightDepthMap> {
    LightDepthMap::new(
        setup.gpu,
        setup.scene,
        &LightDepthMapDesc { label, width: size, height: size, geometry, cull_mode, farthest, constant_bias: 0.0, slope_bias: 0.0 },
    )
}

/// One occluder map and SSM per side: one-sided, the nearest surface of every occluder face;
/// two-sided (Sec. 3.5), the nearest front faces and the farthest back faces.
pub(crate) fn accumulations(
    setup: &TechniqueSetup<'_>,
    (settings, sides, plan): (&AttySettings, &[Side], &CounterPlan),
    (receivers, receiver_bounds): (&wgpu::TextureView, &wgpu::TextureView),
    (settings_buffer, read_counts): (&wgpu::Buffer, &ReadCounts),
) -> Result<Vec<SideAccumulation>> {
    let device = &setup.gpu.device;
    let layout = accumulate_layout(device);
    sides
        .iter()
        .zip(&plan.sides)
        .map(|(side, counters)| {
            let (pass_label, farthest) = (side.accumulate, side.farthest);
            let occluder_map =
                unbiased_depth_map(setup, side.occluder_map, settings.occluder_map_size, Geometry::Occluders, (side.cull, farthest))?;
            let merging = settings.merge_tolerance > 0.0;
            // Without merging, the accumulation still binds a pyramid, of one texel, that it
            // never reads (nor builds: its counter slice is the first counters, never written
            // by it).
            let patch_merge = DepthPyramid::new(
                setup,
                (&PATCH_MERGE, side.patch_merge),
                (&occluder_map.linear_depth_view, LightDepthMap::FORMAT),
                if merging { settings.occluder_map_size } else { 1 },
                (read_counts, counter_slice(read_counts, counters.patch_merge.unwrap_or(0), PYRAMID_UNITS.len())),
            )?;
            let texture_label = format!("{pass_label}_soft_shadow_map");
            let texture = render_texture(
                device,
                &texture_label,
                settings.ssm_size,
                settings.ssm_size,
                settings.accumulation.format(),
                wgpu::TextureUsages::empty(),
            );
            let patches = device.create_buffer(&wgpu::BufferDescriptor {
                label: Some(&format!("{pass_label}_patches")),
                size: u64::from(settings.occluder_map_size).pow(2) * PATCH_RECORD_BYTES,
                usage: wgpu::BufferUsages::STORAGE,
                mapped_at_creation: false,
            });
            let draw_arguments = wgpu::util::DeviceExt::create_buffer_init(
                device,
                &wgpu::util::BufferInitDescriptor {
                    label: Some(&format!("{pass_label}_draw_arguments")),
                    contents: bytemuck::cast_slice(&[4u32, 0, 0, 0]),
                    usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::INDIRECT | wgpu::BufferUsages::COPY_DST,
                },
            );
            let patches_group = bind_group(
                device,
                &format!("{pass_label}_patches_bind_group"),
                &patches_layout(device),
                &[
                    wgpu::BindingResource::TextureView(&occluder_map.linear_depth_view),
                    settings_buffer.as_entire_binding(),
                    wgpu::BindingResource::TextureView(receiver_bounds),
                    wgpu::BindingResource::TextureView(&patch_merge.view),
                    patches.as_entire_binding(),
                    draw_arguments.as_entire_binding(),
                    counter_slice(read_counts, counters.patches, PATCHES_UNITS.len()),
                ],
            );
            let bind_group = bind_group(
                device,
                &format!("{pass_label}_bind_group"),
                &layout,
                &[
                    patches.as_entire_binding(),
                    wgpu::BindingResource::TextureView(receivers),
                    settings_buffer.as_entire_binding(),
                    counter_slice(read_counts, counters.accumulate, READS.len()),
                ],
            );
            Ok(SideAccumulation {
                occluder_map,
                draw_arguments,
                patches_group,
                patches_label: side.patches,
                patch_merge: merging.then_some(patch_merge),
                soft_shadow_map: labelled_view(&texture, &texture_label),
                bind_group,
                label: pass_label,
            })
        })
        .collect()
}

/// A pyramid of depth bounds over a light map: the receiver map's largest depth per block
/// (`atty_receiver_bounds.wgsl`, bounding the penumbra rectangles) or an occluder map's depth
/// range per block (`atty_patch_merge.wgsl`, merging micro-patches). Level 0 is built from the
/// map by the shader's `base` entry point, each level above from the one below by `reduce`.
pub(crate) struct DepthPyramid {
    /// Every level, for the accumulation's vertex stage.
    pub(crate) view: wgpu::TextureView,
    base: wgpu::ComputePipeline,
    reduce: wgpu::ComputePipeline,
    /// Per level: its bind group (the level below, or the map, and this level) and size.
    levels: Vec<(wgpu::BindGroup, u32)>,
    label: &'static str,
}

/// What a [`DepthPyramid`] holds and how it is built.
pub(crate) struct PyramidKind {
    pub(crate) label: &'static str,
    pub(crate) format: wgpu::TextureFormat,
    pub(crate) shader: &'static str,
    pub(crate) base: &'static str,
    pub(crate) reduce: &'static str,
}

impl DepthPyramid {
    /// The pyramid of `kind` over `map` (of format `map_format`), `size`² texels at level 0 (1
    /// where it is bound but not read), counting into `counts` (its slice of `read_counts`: reads,
    /// their bytes, storage bytes).
    pub(crate) fn new(
        setup: &TechniqueSetup<'_>,
        (kind, label): (&PyramidKind, &'static str),
        (map, map_format): (&wgpu::TextureView, wgpu::TextureFormat),
        size: u32,
        (read_counts, counts): (&ReadCounts, wgpu::BindingResource<'_>),
    ) -> Result<Self> {
        let device = &setup.gpu.device;
        let level_count = u32::BITS - size.leading_zeros();
        let texture = device.create_texture(&wgpu::TextureDescriptor {
            label: Some(label),
            size: wgpu::Extent3d { width: size, height: size, depth_or_array_layers: 1 },
            mip_level_count: level_count,
            sample_count: 1,
            dimension: wgpu::TextureDimension::D2,
            format: kind.format,
            usage: wgpu::TextureUsages::TEXTURE_BINDING | wgpu::TextureUsages::STORAGE_BINDING,
            view_formats: &[],
        });
        let layout = bind_group_layout(
            device,
            &format!("{}_layout", kind.label),
            &[texture_entry(0), write_storage_texture_entry(1, kind.format), ReadCounts::layout_entry(2)],
        );
        let views: Vec<wgpu::TextureView> = (0..level_count)
            .map(|level| {
                texture.create_view(&wgpu::TextureViewDescriptor {
                    label: Some(&format!("{label}_level_{level}_view")),
                    base_mip_level: level,
                    mip_level_count: Some(1),
                    ..Default::default()
                })
            })
            .collect();
        let levels = views
            .iter()
            .enumerate()
            .map(|(level, view)| {
                let finer = if level == 0 { map } else { &views[level - 1] };
                let group = bind_group(
                    device,
                    &format!("{label}_level_{level}_bind_group"),
                    &layout,
                    &[wgpu::BindingResource::TextureView(finer), wgpu::BindingResource::TextureView(view), counts.clone()],
                );
                (group, (size >> level).max(1))
            })
            .collect();
        let module = create_shader_with_imports(setup.gpu, &format!("{}_shader", kind.label), kind.shader, LOCAL_SHADERS)?;
        // The bytes a texel read fetches: level 0 reads the map, each level above the one below.
        let [count_reads] = read_counts.pipeline_constants();
        let constants = [count_reads, ("MAP_TEXEL_BYTES", texel_bytes(map_format)), ("PYRAMID_TEXEL_BYTES", texel_bytes(kind.format))];
        let base = compute_pipeline(device, &format!("{}_pipeline", kind.base), &module, kind.base, &[&layout], &constants);
        let reduce = compute_pipeline(device, &format!("{}_pipeline", kind.reduce), &module, kind.reduce, &[&layout], &constants);
        let messages = setup.gpu.take_errors();
        if !messages.is_empty() {
            return Err(Error::Gpu { during: format!("building Atty's {label}"), messages });
        }
        let view = texture.create_view(&wgpu::TextureViewDescriptor { label: Some(&format!("{label}_view")), ..Default::default() });
        Ok(Self { view, base, reduce, levels, label })
    }

    /// Builds the pyramid from its map just rendered, in one timed compute pass.
    pub(crate) fn encode(&self, frame: &mut Frame<'_>) {
        let mut pass = frame.compute_pass(self.label);
        for (level, (group, size)) in self.levels.iter().enumerate() {
            pass.set_pipeline(if level == 0 { &self.base } else { &self.reduce });
            pass.set_bind_group(0, group, &[]);
            pass.dispatch_workgroups(size.div_ceil(8), size.div_ceil(8), 1);
        }
    }
}
