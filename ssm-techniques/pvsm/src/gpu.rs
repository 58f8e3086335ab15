//! The GPU plumbing the steps share: the WGSL they import, the work they count, the bind-group
//! layouts and pipelines (made once), the buffers several passes read or write, the bind groups
//! that do not change per light or tile, each tile's uniforms (written by step 7, read by step 8),
//! and `PredictedVirtualShadowMaps::new`, which builds them with each step's own resources.

use ssm_core::passes::{
    bind_group, bind_group_layout, compute_pipeline, readback_buffer, storage_buffer, storage_entry, texture_entry, uniform_buffer,
    uniform_entry, visibility_storage_entry, write_storage_texture_entry,
};
use ssm_core::read_counts::ReadCounts;
use ssm_core::shader::create_shader_with_imports;
use ssm_core::{
    DepthBiasUniform, Error, Frame, GpuContext, LightDepthMap, LightFrameUniform, Result, Settings, TechniqueSetup, UniformStruct,
};

use crate::filter::{
    ACCUMULATED_BYTES, CAPPED_BYTES, FILTER_PYRAMID_SHADER, FILTER_SHADER, TILE_PYRAMID_COUNTS_FORMAT, TILE_PYRAMID_FORMAT, TilePyramid,
    TileSettingsUniform,
};
use crate::kernel::{KERNEL_BYTES, KERNEL_SHADER};
use crate::low_res_map::{LOW_RES_MAP_MIPS_SHADER, LOW_RES_MAP_SHADER, LowResMap, RasterSettingsUniform};
use crate::smtg::{PyramidSettingsUniform, SMTG_CELL_BYTES, SMTG_SHADER};
use crate::tile_maps::TILE_MAPS_SHADER;
use crate::{Conservative, LastFrame, NAME, PredictedVirtualShadowMaps, Prediction, PvsmSettings, PvsmSettingsUniform};

/// WGSL files the PVSM shaders import besides `common/`.
pub(crate) const LOCAL_SHADERS: &[(&str, &str)] = &[
    ("pvsm/pvsm_common.wgsl", ssm_shaders::pvsm::PVSM_COMMON),
    // The uniforms and records, declared once in Rust: their derives write the WGSL structs.
    (crate::PvsmSettingsUniform::WGSL_IMPORT, crate::PvsmSettingsUniform::WGSL),
    (crate::KernelRecord::WGSL_IMPORT, crate::KernelRecord::WGSL),
    (crate::RasterSettingsUniform::WGSL_IMPORT, crate::RasterSettingsUniform::WGSL),
    (crate::PyramidSettingsUniform::WGSL_IMPORT, crate::PyramidSettingsUniform::WGSL),
    (crate::CullSettingsUniform::WGSL_IMPORT, crate::CullSettingsUniform::WGSL),
    (crate::TileSettingsUniform::WGSL_IMPORT, crate::TileSettingsUniform::WGSL),
    (crate::TilePyramidLevelUniform::WGSL_IMPORT, crate::TilePyramidLevelUniform::WGSL),
];

/// The work the passes count with `count_reads` ([`ReadCounts`]), in the order the shaders index
/// them: `(WGSL constant, shader, pass, unit)`. A texel read is one texel fetched (a `textureLoad`,
/// or one element of a storage array read as a map's texel or a pixel's record), every read of
/// every invocation, the G-buffer's two texels included; beside each pass's reads, the bytes they
/// fetched (unit `read_bytes`): each read its texture's texel size or its storage element's size
/// (`*_BYTES` constants of the shaders, checked against the formats and records here by
/// `the_shaders_byte_sizes_are_the_formats_and_records`). `pvsm_tile_filter_walk` is no pass: the
/// filter's walk's reads alone per filter evaluation (unit `texels`, a diagnostic only), whose total
/// is `pvsm_texels_filtered`. The tile maps' texels rendered are the `pvsm_texels_rendered`
/// diagnostic, counted on the CPU from the tiles' sizes; the bytes the render passes store to
/// them the framework counts as target bytes.
pub(crate) const READ_COUNTERS: [(&str, &str, &str, &str); 16] = [
    ("READ_COUNTER_LOW_RES_MIPS", LOW_RES_MAP_MIPS_SHADER, "pvsm_low_res_mips", "reads"),
    ("READ_COUNTER_LOW_RES_MIPS_READ_BYTES", LOW_RES_MAP_MIPS_SHADER, "pvsm_low_res_mips", "read_bytes"),
    ("READ_COUNTER_KERNEL_SHAPE", KERNEL_SHADER, "pvsm_kernel_shape", "reads"),
    ("READ_COUNTER_KERNEL_SHAPE_READ_BYTES", KERNEL_SHADER, "pvsm_kernel_shape", "read_bytes"),
    ("READ_COUNTER_KERNEL_SHAPE_ATOMICS", KERNEL_SHADER, "pvsm_kernel_shape", "atomics"),
    ("READ_COUNTER_SMTG_PYRAMID", SMTG_SHADER, "pvsm_smtg_pyramid", "reads"),
    ("READ_COUNTER_SMTG_PYRAMID_READ_BYTES", SMTG_SHADER, "pvsm_smtg_pyramid", "read_bytes"),
    ("READ_COUNTER_TILE_PYRAMID", FILTER_PYRAMID_SHADER, "pvsm_tile_pyramid", "reads"),
    ("READ_COUNTER_TILE_PYRAMID_READ_BYTES", FILTER_PYRAMID_SHADER, "pvsm_tile_pyramid", "read_bytes"),
    ("READ_COUNTER_TILE_PYRAMID_STORAGE_BYTES", FILTER_PYRAMID_SHADER, "pvsm_tile_pyramid", "storage_bytes"),
    ("READ_COUNTER_TILE_FILTER", FILTER_SHADER, "pvsm_tile_filter", "reads"),
    ("READ_COUNTER_TILE_FILTER_READ_BYTES", FILTER_SHADER, "pvsm_tile_filter", "read_bytes"),
    ("READ_COUNTER_TILE_FILTER_WALK", FILTER_SHADER, "pvsm_tile_filter_walk", "texels"),
    ("READ_COUNTER_RESOLVE", FILTER_SHADER, "pvsm_resolve", "reads"),
    ("READ_COUNTER_RESOLVE_READ_BYTES", FILTER_SHADER, "pvsm_resolve", "read_bytes"),
    ("READ_COUNTER_PREDICTED_TEXELS", KERNEL_SHADER, "pvsm_predicted", "texels_under_filter"),
];

/// The `COUNTER_*` slots of `pvsm_common.wgsl`, in order: pixels filtered, skipped as lit, whose
/// filter's walk reached its cap, and not covered by any tile.
pub(crate) const COUNTER_NAMES: [&str; 4] = ["COUNTER_FILTERED", "COUNTER_LIT", "COUNTER_CAPPED", "COUNTER_UNCOVERED"];
/// Bytes of the counters buffer.
const COUNTER_BYTES: u64 = COUNTER_NAMES.len() as u64 * 4;

/// The uniforms of one tile of one light, written when the kd-tree has decided it.
pub(crate) struct TileSlot {
    pub(crate) frame: wgpu::Buffer,
    pub(crate) frame_group: wgpu::BindGroup,
    pub(crate) bias: wgpu::Buffer,
    pub(crate) bias_group: wgpu::BindGroup,
    pub(crate) settings: wgpu::Buffer,
    /// The tile's settings alone, for the pyramid's passes.
    pub(crate) pyramid_group: wgpu::BindGroup,
    /// One per tile map size (`tile_maps`): the tile's settings, that map and the pyramid.
    pub(crate) filter_groups: Vec<wgpu::BindGroup>,
}

/// A bind-group-layout entry for a `texture_2d<u32>` read with `textureLoad`.
pub(crate) const fn uint_texture_entry(binding: u32) -> wgpu::BindGroupLayoutEntry {
    wgpu::BindGroupLayoutEntry {
        binding,
        visibility: wgpu::ShaderStages::COMPUTE,
        ty: wgpu::BindingType::Texture {
            sample_type: wgpu::TextureSampleType::Uint,
            view_dimension: wgpu::TextureViewDimension::D2,
            multisampled: false,
        },
        count: None,
    }
}

/// The pipelines, made once.
pub(crate) struct Pipelines {
    pub(crate) low_res: wgpu::RenderPipeline,
    pub(crate) mip: wgpu::ComputePipeline,
    pub(crate) kernel: wgpu::ComputePipeline,
    pub(crate) pyramid: wgpu::ComputePipeline,
    pub(crate) filter: wgpu::ComputePipeline,
    pub(crate) resolve: wgpu::ComputePipeline,
    pub(crate) cull: wgpu::ComputePipeline,
    pub(crate) tile_pyramid: wgpu::ComputePipeline,
}

/// The buffers of the screen-space and grid passes.
pub(crate) struct Buffers {
    pub(crate) kernels: wgpu::Buffer,
    pub(crate) accumulated: wgpu::Buffer,
    /// Per pixel, a u32: 1 once its filter's walk reached its cap in some tile.
    pub(crate) capped: wgpu::Buffer,
    pub(crate) grid: wgpu::Buffer,
    /// `COUNTER_*` of `pvsm_common.wgsl`, summed over the lights of the last frame.
    pub(crate) counters: wgpu::Buffer,
    pub(crate) pyramid: wgpu::Buffer,
    pub(crate) pyramid_readback: wgpu::Buffer,
    pub(crate) pyramid_cells: u64,
    /// Step 7: the indices of the triangles kept for the current tile, and its indirect draw.
    pub(crate) culled_indices: wgpu::Buffer,
    pub(crate) tile_draw: wgpu::Buffer,
}

impl PredictedVirtualShadowMaps {
    /// Builds the maps, buffers and pipelines.
    ///
    /// # Errors
    /// A parameter error (a tile grid that is not a power of two), a missing device feature, or a GPU error.
    pub fn new(setup: &TechniqueSetup<'_>) -> Result<Self> {
        let settings = PvsmSettings::from_params(setup.params)?;
        if !settings.grid_size.is_power_of_two() {
            return Err(Error::Technique {
                technique: NAME.into(),
                message: format!("grid_size = {} is not a power of two", settings.grid_size),
            });
        }
        let gpu = setup.gpu;
        let device = &gpu.device;
        let gbuffer = setup.shared.gbuffer(NAME)?;
        let limit = device.limits().max_texture_dimension_2d;
        let atlas_side = if settings.prediction == Prediction::Fixed { settings.fixed_size } else { settings.max_tile_size }.min(limit);
        let (width, height) = (setup.scene.width, setup.scene.height);
        let buffers = Self::buffers(device, &settings, width, height, setup.scene.triangle_count);
        let hardware = match settings.conservative {
            Conservative::Hardware => true,
            Conservative::Software | Conservative::Off => false,
            Conservative::Auto => gpu.features().contains(wgpu::Features::CONSERVATIVE_RASTERIZATION),
        };
        let layouts = Layouts::new(device);
        let counters: Vec<(&'static str, &'static str)> = READ_COUNTERS.iter().map(|(_, _, pass, unit)| (*pass, *unit)).collect();
        let counting = settings.count_reads || setup.count_work;
        let read_counts = ReadCounts::with_units(device, "pvsm_read_counts", &counters, counting);
        let low_res = LowResMap::new(device, settings.low_res_size, &layouts.mip, &read_counts);
        let groups = StepGroups::new(setup, &settings, &layouts, &buffers, &low_res, &read_counts, hardware);
        let tile_maps = Self::tile_maps(setup, atlas_side)?;
        let tile_pyramid =
            TilePyramid::new(device, &layouts.tile_pyramid_level, &tile_maps, &read_counts, atlas_side, settings.walks_hierarchy());
        let (cull_group, cull_triangles) = Self::cull_group(setup, &layouts, &buffers, &tile_maps);
        let slots = (0..setup.scene.light_count())
            .map(|light| Self::tile_slots(gpu, &layouts, &tile_maps, &tile_pyramid, light, settings.max_tiles))
            .collect();
        let resolve_groups = Self::resolve_groups(setup, &layouts.resolve);
        let pipelines = Pipelines::new(setup, &layouts, &gbuffer.layout, &read_counts, hardware)?;
        Ok(Self {
            settings,
            pipelines,
            buffers,
            low_res,
            low_res_group: groups.low_res,
            gbuffer_group: gbuffer.bind_group.clone(),
            kernel_group: groups.kernel,
            pyramid_group: groups.pyramid,
            cull_group,
            cull_triangles,
            slots,
            resolve_groups,
            common_group: groups.common,
            tile_maps,
            tile_pyramid,
            read_counts,
            counting,
            atlas_side,
            triangle_count: setup.scene.triangle_count,
            width,
            height,
            last: LastFrame::default(),
        })
    }

    /// The resolve pass's output per light (binding 2: the filter's tile resources hold 0 and 1 of
    /// the same group in the same module).
    fn resolve_groups(setup: &TechniqueSetup<'_>, layout: &wgpu::BindGroupLayout) -> Vec<wgpu::BindGroup> {
        setup
            .outputs
            .iter()
            .enumerate()
            .map(|(light, output)| {
                setup.gpu.device.create_bind_group(&wgpu::BindGroupDescriptor {
                    label: Some(&format!("pvsm_resolve_bind_group_{light}")),
                    layout,
                    entries: &[wgpu::BindGroupEntry { binding: 2, resource: wgpu::BindingResource::TextureView(output) }],
                })
            })
            .collect()
    }

    fn buffers(device: &wgpu::Device, settings: &PvsmSettings, width: u32, height: u32, triangles: u32) -> Buffers {
        let pixels = u64::from(width) * u64::from(height);
        // Every level of the pyramid: a geometric series of the grid's cells.
        let mut pyramid_cells = 0u64;
        let mut side = u64::from(settings.grid_size);
        while side >= 1 {
            pyramid_cells += side * side;
            if side == 1 {
                break;
            }
            side /= 2;
        }
        let cells = u64::from(settings.grid_size).pow(2);
        Buffers {
            kernels: storage_buffer(device, "pvsm_kernel_buffer", pixels * KERNEL_BYTES),
            accumulated: storage_buffer(device, "pvsm_accumulated_buffer", pixels * ACCUMULATED_BYTES),
            capped: storage_buffer(device, "pvsm_capped_buffer", pixels * CAPPED_BYTES),
            grid: storage_buffer(device, "pvsm_smtg_buffer", cells * SMTG_CELL_BYTES),
            counters: storage_buffer(device, "pvsm_counters_buffer", COUNTER_BYTES),
            pyramid: storage_buffer(device, "pvsm_smtg_pyramid_buffer", pyramid_cells * SMTG_CELL_BYTES),
            pyramid_readback: readback_buffer(device, "pvsm_smtg_pyramid_readback", pyramid_cells * SMTG_CELL_BYTES),
            pyramid_cells,
            culled_indices: device.create_buffer(&wgpu::BufferDescriptor {
                label: Some("pvsm_tile_culled_indices"),
                size: (u64::from(triangles) * 12).max(12),
                usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::INDEX,
                mapped_at_creation: false,
            }),
            tile_draw: device.create_buffer(&wgpu::BufferDescriptor {
                label: Some("pvsm_tile_draw_arguments"),
                size: 20,
                usage: wgpu::BufferUsages::STORAGE
                    | wgpu::BufferUsages::INDIRECT
                    | wgpu::BufferUsages::COPY_DST
                    | wgpu::BufferUsages::COPY_SRC,
                mapped_at_creation: false,
            }),
        }
    }

    /// The uniforms and bind groups of `max_tiles` tiles of one light. Each light has its own:
    /// the writes of a tile's uniforms land before the next submission, and a light's tiles are
    /// recorded before the next light's readback submits them.
    fn tile_slots(
        gpu: &GpuContext,
        layouts: &Layouts,
        maps: &[LightDepthMap],
        pyramid: &TilePyramid,
        light: usize,
        max_tiles: u32,
    ) -> Vec<TileSlot> {
        let device = &gpu.device;
        (0..max_tiles)
            .map(|k| {
                let label = format!("pvsm_tile_{light}_{k}");
                let frame = uniform_buffer_writable(device, &format!("{label}_frame"), std::mem::size_of::<LightFrameUniform>() as u64);
                let bias = uniform_buffer_writable(device, &format!("{label}_bias"), std::mem::size_of::<DepthBiasUniform>() as u64);
                let settings =
                    uniform_buffer_writable(device, &format!("{label}_settings"), std::mem::size_of::<TileSettingsUniform>() as u64);
                TileSlot {
                    frame_group: bind_group(
                        device,
                        &format!("{label}_frame_bind_group"),
                        gpu.uniform_layout(),
                        &[frame.as_entire_binding()],
                    ),
                    bias_group: bind_group(device, &format!("{label}_bias_bind_group"), gpu.uniform_layout(), &[bias.as_entire_binding()]),
                    pyramid_group: bind_group(
                        device,
                        &format!("{label}_pyramid_bind_group"),
                        &layouts.tile_pyramid_tile,
                        &[settings.as_entire_binding()],
                    ),
                    filter_groups: maps
                        .iter()
                        .map(|map| {
                            // Binding 2 of the group is the resolve pass's target (the same module).
                            device.create_bind_group(&wgpu::BindGroupDescriptor {
                                label: Some(&format!("{label}_filter_bind_group_{}", map.linear_depth.width())),
                                layout: &layouts.tile,
                                entries: &[
                                    wgpu::BindGroupEntry { binding: 0, resource: settings.as_entire_binding() },
                                    wgpu::BindGroupEntry {
                                        binding: 1,
                                        resource: wgpu::BindingResource::TextureView(&map.linear_depth_view),
                                    },
                                    wgpu::BindGroupEntry { binding: 3, resource: wgpu::BindingResource::TextureView(&pyramid.view) },
                                    wgpu::BindGroupEntry { binding: 4, resource: wgpu::BindingResource::TextureView(&pyramid.counts_view) },
                                ],
                            })
                        })
                        .collect(),
                    frame,
                    bias,
                    settings,
                }
            })
            .collect()
    }

    pub(crate) fn dispatch(
        &self,
        frame: &mut Frame<'_>,
        label: &str,
        pipeline: &wgpu::ComputePipeline,
        groups: &[&wgpu::BindGroup],
        light: usize,
    ) {
        let light_group = &frame.scene.light_bind_groups[light];
        let mut pass = frame.compute_pass(label);
        pass.set_pipeline(pipeline);
        pass.set_bind_group(0, light_group, &[]);
        pass.set_bind_group(1, &self.gbuffer_group, &[]);
        for (index, group) in groups.iter().enumerate() {
            pass.set_bind_group(2 + index as u32, *group, &[]);
        }
        pass.dispatch_workgroups(self.width.div_ceil(8), self.height.div_ceil(8), 1);
    }

    /// The `COUNTER_*` slots summed over the last frame's lights: the pixels filtered, the share
    /// skipped as fully lit, the pixels whose filter's walk reached its cap and those no tile covered.
    pub(crate) fn counter_diagnostics(&self, gpu: &GpuContext) -> Vec<(String, f64)> {
        let mut out = Vec::new();
        if let Ok(bytes) = ssm_core::readback::read_buffer(gpu, &self.buffers.counters, COUNTER_BYTES, "PVSM counters") {
            let counts: Vec<u32> = bytemuck::pod_collect_to_vec(&bytes);
            if let [filtered, lit, capped, uncovered] = counts[..] {
                let total = f64::from(filtered) + f64::from(lit);
                if total > 0.0 {
                    out.push(("pvsm_lit_skipped".to_owned(), f64::from(lit) / total));
                }
                out.push(("pvsm_filtered_pixels".to_owned(), f64::from(filtered)));
                out.push(("pvsm_capped_pixels".to_owned(), f64::from(capped)));
                out.push(("pvsm_uncovered_pixels".to_owned(), f64::from(uncovered)));
            }
        }
        out
    }
}

/// A uniform buffer of `size` bytes written each frame.
fn uniform_buffer_writable(device: &wgpu::Device, label: &str, size: u64) -> wgpu::Buffer {
    device.create_buffer(&wgpu::BufferDescriptor {
        label: Some(label),
        size,
        usage: wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
        mapped_at_creation: false,
    })
}

/// The bind groups of steps 2 to 5 and 8 that do not change per light or tile.
struct StepGroups {
    low_res: wgpu::BindGroup,
    kernel: wgpu::BindGroup,
    pyramid: wgpu::BindGroup,
    common: wgpu::BindGroup,
}

impl StepGroups {
    fn new(
        setup: &TechniqueSetup<'_>,
        settings: &PvsmSettings,
        layouts: &Layouts,
        buffers: &Buffers,
        low_res: &LowResMap,
        read_counts: &ReadCounts,
        hardware: bool,
    ) -> Self {
        let device = &setup.gpu.device;
        let settings_buffer = uniform_buffer(device, "pvsm_settings_uniform", &PvsmSettingsUniform::from(settings));
        let raster = RasterSettingsUniform {
            half_texel: [1.0 / settings.low_res_size as f32; 2],
            size: [settings.low_res_size as f32; 2],
            enlarge: u32::from(!hardware && settings.conservative != Conservative::Off),
            _pad0: 0,
            _pad1: 0,
            _pad2: 0,
        };
        let low_res_group = bind_group(
            device,
            "pvsm_low_res_bind_group",
            &layouts.low_res,
            &[
                setup.scene.vertex_buffer.as_entire_binding(),
                setup.scene.index_buffer.as_entire_binding(),
                uniform_buffer(device, "pvsm_raster_uniform", &raster).as_entire_binding(),
            ],
        );
        let kernel = bind_group(
            device,
            "pvsm_kernel_bind_group",
            &layouts.kernel,
            &[
                setup.scene.camera_buffer.as_entire_binding(),
                settings_buffer.as_entire_binding(),
                wgpu::BindingResource::TextureView(&low_res.all_levels),
                buffers.kernels.as_entire_binding(),
                buffers.grid.as_entire_binding(),
                buffers.counters.as_entire_binding(),
                read_counts.buffer().as_entire_binding(),
            ],
        );
        let pyramid_settings = PyramidSettingsUniform { grid_size: settings.grid_size, _pad0: 0, _pad1: 0, _pad2: 0 };
        let pyramid = bind_group(
            device,
            "pvsm_pyramid_bind_group",
            &layouts.pyramid,
            &[
                uniform_buffer(device, "pvsm_pyramid_uniform", &pyramid_settings).as_entire_binding(),
                buffers.grid.as_entire_binding(),
                buffers.pyramid.as_entire_binding(),
                read_counts.buffer().as_entire_binding(),
            ],
        );
        let common = bind_group(
            device,
            "pvsm_filter_common_bind_group",
            &layouts.common,
            &[
                setup.scene.camera_buffer.as_entire_binding(),
                settings_buffer.as_entire_binding(),
                buffers.kernels.as_entire_binding(),
                buffers.accumulated.as_entire_binding(),
                buffers.capped.as_entire_binding(),
                buffers.counters.as_entire_binding(),
                read_counts.buffer().as_entire_binding(),
            ],
        );
        Self { low_res: low_res_group, kernel, pyramid, common }
    }
}

/// The bind group layouts of the passes' own resources.
pub(crate) struct Layouts {
    pub(crate) low_res: wgpu::BindGroupLayout,
    pub(crate) mip: wgpu::BindGroupLayout,
    pub(crate) kernel: wgpu::BindGroupLayout,
    pub(crate) pyramid: wgpu::BindGroupLayout,
    pub(crate) common: wgpu::BindGroupLayout,
    pub(crate) tile: wgpu::BindGroupLayout,
    pub(crate) resolve: wgpu::BindGroupLayout,
    pub(crate) cull: wgpu::BindGroupLayout,
    /// The tile pyramid's passes: the tile's settings, and one level's resources.
    pub(crate) tile_pyramid_tile: wgpu::BindGroupLayout,
    pub(crate) tile_pyramid_level: wgpu::BindGroupLayout,
}

impl Layouts {
    fn new(device: &wgpu::Device) -> Self {
        Self {
            low_res: bind_group_layout(device, "pvsm_low_res_layout", &[storage_entry(0, true), storage_entry(1, true), uniform_entry(2)]),
            mip: bind_group_layout(
                device,
                "pvsm_low_res_mip_layout",
                &[texture_entry(0), write_storage_texture_entry(1, LightDepthMap::FORMAT), ReadCounts::layout_entry(2)],
            ),
            kernel: bind_group_layout(
                device,
                "pvsm_kernel_layout",
                &[
                    uniform_entry(0),
                    uniform_entry(1),
                    texture_entry(2),
                    storage_entry(3, false),
                    storage_entry(4, false),
                    storage_entry(5, false),
                    ReadCounts::layout_entry(6),
                ],
            ),
            pyramid: bind_group_layout(
                device,
                "pvsm_pyramid_layout",
                &[uniform_entry(0), storage_entry(1, true), storage_entry(2, false), ReadCounts::layout_entry(3)],
            ),
            common: bind_group_layout(
                device,
                "pvsm_filter_common_layout",
                &[
                    uniform_entry(0),
                    uniform_entry(1),
                    storage_entry(2, true),
                    storage_entry(3, false),
                    storage_entry(4, false),
                    storage_entry(5, false),
                    ReadCounts::layout_entry(6),
                ],
            ),
            tile: bind_group_layout(
                device,
                "pvsm_tile_layout",
                &[uniform_entry(0), texture_entry(1), texture_entry(3), uint_texture_entry(4)],
            ),
            tile_pyramid_tile: bind_group_layout(device, "pvsm_tile_pyramid_tile_layout", &[uniform_entry(0)]),
            tile_pyramid_level: bind_group_layout(
                device,
                "pvsm_tile_pyramid_level_layout",
                &[
                    uniform_entry(0),
                    texture_entry(1),
                    write_storage_texture_entry(2, TILE_PYRAMID_FORMAT),
                    ReadCounts::layout_entry(3),
                    uint_texture_entry(4),
                    write_storage_texture_entry(5, TILE_PYRAMID_COUNTS_FORMAT),
                ],
            ),
            cull: bind_group_layout(
                device,
                "pvsm_tile_cull_layout",
                &[uniform_entry(0), storage_entry(1, true), storage_entry(2, true), storage_entry(3, false), storage_entry(4, false)],
            ),
            resolve: bind_group_layout(
                device,
                "pvsm_resolve_layout",
                &[wgpu::BindGroupLayoutEntry { binding: 2, ..visibility_storage_entry(2) }],
            ),
        }
    }
}

impl Pipelines {
    fn new(
        setup: &TechniqueSetup<'_>,
        layouts: &Layouts,
        gbuffer_layout: &wgpu::BindGroupLayout,
        read_counts: &ReadCounts,
        hardware: bool,
    ) -> Result<Self> {
        let gpu = setup.gpu;
        // COUNT_READS: the counting code compiled in only with count_reads.
        let counting = read_counts.pipeline_constants();
        let device = &gpu.device;
        let module = |label: &str, source: &str| create_shader_with_imports(gpu, label, source, LOCAL_SHADERS);
        let conservative = module("pvsm_conservative_shader", LOW_RES_MAP_SHADER)?;
        let low_res_layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: Some("pvsm_low_res_pipeline_layout"),
            bind_group_layouts: &[Some(gpu.uniform_layout()), Some(&layouts.low_res)],
            immediate_size: 0,
        });
        let low_res = device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
            label: Some("pvsm_low_res_pipeline"),
            layout: Some(&low_res_layout),
            vertex: wgpu::VertexState {
                module: &conservative,
                entry_point: Some("pvsm_conservative_vertex"),
                compilation_options: Default::default(),
                buffers: &[],
            },
            primitive: wgpu::PrimitiveState { conservative: hardware, ..Default::default() },
            depth_stencil: Some(LightDepthMap::depth_test(false)),
            multisample: wgpu::MultisampleState::default(),
            fragment: Some(wgpu::FragmentState {
                module: &conservative,
                entry_point: Some("pvsm_conservative_fragment"),
                compilation_options: Default::default(),
                targets: &[Some(LightDepthMap::FORMAT.into())],
            }),
            multiview_mask: None,
            cache: None,
        });
        let screen = [gpu.uniform_layout(), gbuffer_layout];
        let kernel_module = module("pvsm_kernel_shader", KERNEL_SHADER)?;
        let pyramid_module = module("pvsm_pyramid_shader", SMTG_SHADER)?;
        let filter_module = module("pvsm_filter_shader", FILTER_SHADER)?;
        let mip_module = module("pvsm_mips_shader", LOW_RES_MAP_MIPS_SHADER)?;
        let cull_module = module("pvsm_cull_shader", TILE_MAPS_SHADER)?;
        let tile_pyramid_module = module("pvsm_tile_pyramid_shader", FILTER_PYRAMID_SHADER)?;
        Ok(Self {
            low_res,
            mip: compute_pipeline(device, "pvsm_low_res_mip_pipeline", &mip_module, "pvsm_low_res_mip", &[&layouts.mip], &counting),
            kernel: compute_pipeline(
                device,
                "pvsm_kernel_pipeline",
                &kernel_module,
                "pvsm_kernel",
                &[screen[0], screen[1], &layouts.kernel],
                &counting,
            ),
            pyramid: compute_pipeline(device, "pvsm_pyramid_pipeline", &pyramid_module, "pvsm_pyramid", &[&layouts.pyramid], &counting),
            filter: compute_pipeline(
                device,
                "pvsm_tile_filter_pipeline",
                &filter_module,
                "pvsm_tile_filter",
                &[screen[0], screen[1], &layouts.common, &layouts.tile],
                &counting,
            ),
            resolve: compute_pipeline(
                device,
                "pvsm_resolve_pipeline",
                &filter_module,
                "pvsm_resolve",
                &[screen[0], screen[1], &layouts.common, &layouts.resolve],
                &counting,
            ),
            cull: compute_pipeline(
                device,
                "pvsm_tile_cull_pipeline",
                &cull_module,
                "pvsm_tile_cull",
                &[gpu.uniform_layout(), &layouts.cull],
                &[],
            ),
            tile_pyramid: compute_pipeline(
                device,
                "pvsm_tile_pyramid_pipeline",
                &tile_pyramid_module,
                "pvsm_tile_pyramid",
                &[&layouts.tile_pyramid_tile, &layouts.tile_pyramid_level],
                &counting,
            ),
        })
    }
}

#[cfg(test)]
mod tests {
    /// Each shader indexes its ReadCounts counters as `READ_COUNTERS` orders them.
    #[test]
    fn the_read_counters_are_numbered_as_the_shaders_number_them() {
        for (index, (name, shader, _, _)) in super::READ_COUNTERS.iter().enumerate() {
            let line = format!("const {name}: u32 = {index}u;");
            assert!(shader.contains(&line), "the shader counting {name} lacks `{line}`");
        }
    }

    /// Every pass that counts its reads counts their bytes too.
    #[test]
    fn every_pass_that_counts_reads_counts_their_bytes() {
        for (_, _, pass, unit) in super::READ_COUNTERS {
            if unit == "reads" {
                let bytes = super::READ_COUNTERS.iter().filter(|(_, _, p, u)| *p == pass && *u == "read_bytes").count();
                assert_eq!(bytes, 1, "{pass} counts reads, and {bytes} read_bytes counters");
            }
        }
    }

    /// The bytes the shaders count per read are the sizes of what they read: the textures' texel
    /// sizes (their formats here and in ssm-core) and the storage elements' (the records and cells
    /// the buffers are sized by).
    #[test]
    fn the_shaders_byte_sizes_are_the_formats_and_records() {
        use super::{
            FILTER_PYRAMID_SHADER, FILTER_SHADER, KERNEL_SHADER, LOCAL_SHADERS, LOW_RES_MAP_MIPS_SHADER as MIPS_SHADER,
            SMTG_SHADER as PYRAMID_SHADER,
        };
        let texel = |format: wgpu::TextureFormat| u64::from(format.block_copy_size(None).unwrap());
        let low_res = texel(ssm_core::LightDepthMap::FORMAT);
        let tile_map = texel(ssm_core::LightDepthMap::FORMAT);
        let pyramid = texel(super::TILE_PYRAMID_FORMAT);
        let counts = texel(super::TILE_PYRAMID_COUNTS_FORMAT);
        let gbuffer = texel(ssm_core::GBuffer::POSITION_FORMAT);
        assert_eq!(gbuffer, texel(ssm_core::GBuffer::NORMAL_FORMAT));
        let common = LOCAL_SHADERS[0].1;
        let expected: [(&str, &str, u64); 13] = [
            (common, "GBUFFER_TEXEL_BYTES", gbuffer),
            (common, "KERNEL_RECORD_BYTES", super::KERNEL_BYTES),
            (MIPS_SHADER, "LOW_RES_TEXEL_BYTES", low_res),
            (KERNEL_SHADER, "LOW_RES_TEXEL_BYTES", low_res),
            (PYRAMID_SHADER, "SMTG_CELL_BYTES", super::SMTG_CELL_BYTES),
            (FILTER_PYRAMID_SHADER, "TILE_MAP_TEXEL_BYTES", tile_map),
            (FILTER_PYRAMID_SHADER, "TILE_PYRAMID_TEXEL_BYTES", pyramid),
            (FILTER_PYRAMID_SHADER, "TILE_PYRAMID_COUNTS_TEXEL_BYTES", counts),
            (FILTER_SHADER, "TILE_MAP_TEXEL_BYTES", tile_map),
            (FILTER_SHADER, "TILE_PYRAMID_TEXEL_BYTES", pyramid),
            (FILTER_SHADER, "TILE_PYRAMID_COUNTS_TEXEL_BYTES", counts),
            (FILTER_SHADER, "ACCUMULATED_BYTES", super::ACCUMULATED_BYTES),
            (FILTER_SHADER, "CAPPED_BYTES", super::CAPPED_BYTES),
        ];
        for (shader, name, bytes) in expected {
            let line = format!("const {name}: u32 = {bytes}u;");
            assert!(shader.contains(&line), "a shader lacks `{line}`");
        }
    }

    /// The diagnostics read the counters in the order the WGSL numbers them.
    #[test]
    fn the_counters_are_numbered_as_the_shaders_number_them() {
        let common = super::LOCAL_SHADERS[0].1;
        assert!(common.contains(&format!("const COUNTERS: u32 = {}u;", super::COUNTER_NAMES.len())));
        for (index, name) in super::COUNTER_NAMES.iter().enumerate() {
            let line = format!("const {name}: u32 = {index}u;");
            assert!(common.contains(&line), "pvsm_common.wgsl lacks `{line}`");
        }
    }
}
