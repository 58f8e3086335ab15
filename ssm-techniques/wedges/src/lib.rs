//! Forest, Barthe and Paulin, *Realistic soft shadows by penumbra-wedges
//! blending*, Graphics Hardware 2006, on the penumbra-wedges (soft shadow
//! volumes) algorithm of Akenine-Möller and Assarsson 2002 and Assarsson and
//! Akenine-Möller 2003, with Lengyel's 2005 fill-rate tests.
//!
//! Per light and frame, entirely on the GPU:
//!
//! 1. **Silhouettes** (`wedges_silhouettes`, compute): each closed
//!    component's winding number around the light's centre tells whether the
//!    centre is inside it; faces are classified from the centre (those a ray
//!    from it crosses first take part: turned towards it, or away from it in
//!    a closed component around it), connected into *silhouette regions* (the
//!    faces that take part, joined across the edges whose volume sides cancel;
//!    each region is bounded by its silhouette loops), ranked, and given
//!    round-robin to `silhouette_buffers` groups; each group's silhouette
//!    half-edges, with their penumbra wedges, and cap faces are written into
//!    lists drawn with indirect draws (wgpu has no geometry shaders).
//! 2. Per group: **shadow volumes** (`wedges_shadow_volumes`): z-fail
//!    (Carmack's reverse) into the technique's Depth24PlusStencil8 target,
//!    whose depth is the G-buffer's (`wedges_depth_copy`), caps included;
//!    **wedges** (`wedges_wedges`), at the point the stencil judged (the
//!    G-buffer's moved by the depth copy's bias): each half-edge's inner and
//!    outer half-wedge, Lengyel's bounding-plane rejection, the local near plane,
//!    and per radial part of the light the occluded area integrated exactly
//!    from the centre, its bounding rectangle, the inner edges' maximum X and
//!    Y (Sec. 3.1, 4.2, 4.3); **blend** (`wedges_blend`): the group's buffer
//!    into the final one, summed (`blending=none`) or by Forest et al.'s
//!    ε = (A_f/B_f)(A_s/B_s)β (Sec. 3.2).
//! 3. **Resolve** (`wedges_resolve`): visibility = 1 − occluded share.
//!
//! No CPU work per frame depends on the triangle count. Everything is sized
//! and checked against the device's limits before anything is allocated
//! ([`AllocationPlan`]). `blending=none silhouette_buffers=1` is the plain
//! penumbra wedges of Akenine-Möller and Assarsson, the paper's baseline.
//!
//! # Example
//!
//! From the command line: `ssm render --scene contact --technique wedges --set
//! wedges.silhouette_buffers=4 --out out` (`ssm list` gives every parameter). From Rust, through the
//! framework, as every technique crate is used (`ssm_wedges::link()` keeps its registration in
//! the binary; `ssm_techniques::link_all()` links every crate of the workspace):
//!
//! ```
//! # fn main() -> Result<(), Box<dyn std::error::Error>> {
//! use ssm_core::{GpuContext, Registry, Renderer};
//!
//! ssm_wedges::link();
//! let gpu = GpuContext::new()?;
//! let scene = ssm_scene::builtin("contact")?.build();
//! let info = Registry::global()?.get("wedges")?;
//! let params = info.params_from([("silhouette_buffers", "4")])?;
//! let mut renderer = Renderer::new(&gpu, &scene, 64, 48, &(info.requirements)(&params)?)?;
//! let mut technique = renderer.create_technique(info, &params)?;
//! let timings = renderer.render(technique.as_mut(), info.name)?;
//! // One value per pixel for the scene's first light: 1 lit, 0 in shadow.
//! let visibility = renderer.read_visibility(0, info.name)?;
//! assert_eq!(visibility.len(), 64 * 48);
//! assert!(visibility.iter().all(|v| (0.0..=1.0).contains(v)));
//! println!("{} in {:.2} ms", info.name, timings.frame_ms());
//! # Ok(())
//! # }
//! ```

mod blend;
mod depth_copy;
mod gpu;
mod mesh;
mod plan;
pub mod scenes;
mod silhouettes;
mod volumes;
mod wedges;

use bytemuck::{Pod, Zeroable};
use ssm_core::passes::{labelled_view, render_texture, uniform_buffer};
use ssm_core::read_counts::ReadCounts;
use ssm_core::work::ShaderWork;
use ssm_core::{
    Choice, Error, Frame, GpuContext, ParamValues, Preset, Requirements, Result, Settings, ShadowTechnique, TechniqueInfo, TechniqueKind,
    TechniqueSetup, UniformCheck, UniformStruct, register_technique,
};

use blend::BlendPasses;
use depth_copy::depth_copy;
use gpu::{COUNTERS, COUNTERS_WITHOUT_MESH, INDIRECT_WORDS, LOCAL_SHADERS, MeshPasses, storage};
use silhouettes::SILHOUETTES_SHADER;

pub use blend::{SHADED_COUNT_FORMAT, SILHOUETTE_FORMAT, SILHOUETTE_TARGETS, UMBRA_MASK_FORMAT};
pub use gpu::STENCIL_FORMAT;
pub use mesh::{CastingMesh, EdgeRecord, MeshReport, NO_FACE, TWO_SIDED_COMPONENT};
pub use plan::{AllocationPlan, FINAL_BINDING_BYTES_PER_PIXEL, PlannedBuffer, STORAGE_BUFFERS_PER_STAGE};
pub use scenes::{FIG12_SCENES, FIG25_SCENES};
pub use silhouettes::{MAX_LABEL_ROUNDS, WEDGE_RECORD_BYTES, WedgesMeshUniform};

/// The registered name.
pub const NAME: &str = "wedges";

/// Most silhouette buffers (`MAX_SILHOUETTE_BUFFERS` in the WGSL).
pub const MAX_SILHOUETTE_BUFFERS: u32 = 64;

/// How the silhouette buffers' occlusions combine.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Choice)]
pub enum Blending {
    /// Summed. Within a buffer every silhouette is summed, as the plain penumbra wedges sum (one
    /// stencil test, every wedge's area added or subtracted); the buffers, each clamped to the
    /// light, are then added. With `silhouette_buffers = 1` this is Akenine-Möller and
    /// Assarsson's plain penumbra wedges, the paper's baseline (Forest et al., Figs. 1(a), 2(a));
    /// with more buffers it is a per-buffer sum, not a published method.
    None,
    /// Forest et al.'s blending of overlapping penumbrae (Sec. 3.2).
    Forest,
}

/// Settings of [`PenumbraWedges`]: its parameters.
#[derive(Clone, Copy, Debug, PartialEq, Settings)]
pub struct WedgesSettings {
    /// How the silhouette buffers' occlusions combine: none (summed; with silhouette_buffers=1 the plain penumbra wedges of Akenine-Möller and Assarsson, the paper's baseline; with more, each buffer clamped, then added) or forest (Forest et al.'s blending, Sec. 3.2).
    #[param(choice, default = "forest")]
    pub blending: Blending,
    /// Silhouette buffers: the silhouette regions, ranked by their first face, go round-robin to this many buffers, each one shadow-volume, wedge and blend pass; regions sharing a buffer are summed (the paper: one buffer per silhouette; 1 with blending=none: the plain penumbra wedges).
    #[param(default = 16, min = 1, max = MAX_SILHOUETTE_BUFFERS)]
    pub silhouette_buffers: u32,
}

/// The technique's parameters as the shaders read them: the WGSL struct `WedgesSettings`, which the
/// derive writes and `shaders/wedges/wedges_common.wgsl` imports (`// #import rust/WedgesSettings`).
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable, UniformStruct)]
pub struct WedgesSettingsUniform {
    /// 0: none, the silhouettes' occlusions summed (Akenine-Möller and Assarsson); 1: Forest et al.'s blending.
    blending: u32,
    /// Silhouette buffers K: silhouette regions are blended in K groups.
    silhouette_buffers: u32,
    _pad0: u32,
    _pad1: u32,
    /// Depth in front of the light's plane below which silhouette edges are clipped (the
    /// geometric near plane), and the local near plane's offset, as fractions of the scene's diagonal.
    near_fraction: f32,
    /// Slack of Lengyel's bounding-plane rejection, a fraction of the scene's diagonal.
    plane_tolerance: f32,
    /// Camera depth the G-buffer's is moved by, to the surface's side facing the light, when it is copied for the volumes (NDC units).
    depth_bias: f32,
    _pad2: f32,
}

/// Depth in front of the light's plane where silhouette edges are clipped, as a fraction of the scene's diagonal.
const NEAR_FRACTION: f32 = 1e-6;
/// Slack of the bounding-plane rejection, a fraction of the scene's diagonal (it only lets more fragments through).
const PLANE_TOLERANCE: f32 = 1e-5;
/// Camera depth (NDC) the G-buffer's depth is moved by, to the surface's side facing the light, for the volumes: 16 units of 2^-24.
/// The wedges integrate at the point so moved along the view ray, where the stencil judged the umbra.
pub const DEPTH_BIAS: f32 = 16.0 / 16_777_216.0;

impl From<&WedgesSettings> for WedgesSettingsUniform {
    fn from(settings: &WedgesSettings) -> Self {
        Self {
            blending: match settings.blending {
                Blending::None => 0,
                Blending::Forest => 1,
            },
            silhouette_buffers: settings.silhouette_buffers.clamp(1, MAX_SILHOUETTE_BUFFERS),
            _pad0: 0,
            _pad1: 0,
            near_fraction: NEAR_FRACTION,
            plane_tolerance: PLANE_TOLERANCE,
            depth_bias: DEPTH_BIAS,
            _pad2: 0.0,
        }
    }
}

fn technique_error(message: impl Into<String>) -> Error {
    Error::Technique { technique: NAME.into(), message: message.into() }
}

/// Forest et al.'s penumbra-wedges blending (and, with `blending=none`, the plain penumbra wedges).
pub struct PenumbraWedges {
    settings: WedgesSettings,
    mesh: Option<MeshPasses>,
    indirect: wgpu::Buffer,
    depth_copy_pipeline: wgpu::RenderPipeline,
    depth_copy_group: wgpu::BindGroup,
    stencil_view: wgpu::TextureView,
    /// The silhouette buffer, the umbra mask, the final buffer, and the blend and resolve passes.
    blend: BlendPasses,
    gbuffer_group: wgpu::BindGroup,
    passes_issued: u32,
    pixels: u64,
    /// What the shaders count for `--count-work` ([`COUNTERS`]); enabled only then.
    read_counts: ReadCounts,
}

impl PenumbraWedges {
    /// Prepares the casting mesh (once: welding, records, the two-sided rule), uploads it, and builds every pipeline.
    ///
    /// # Errors
    /// A parameter or GPU error; [`Error::LimitTooLow`], before anything is allocated, when the
    /// device's limits cannot hold what [`AllocationPlan`] sizes for this view and mesh.
    pub fn new(setup: &TechniqueSetup<'_>) -> Result<Self> {
        let settings = WedgesSettings::from_params(setup.params)?;
        let gpu = setup.gpu;
        let device = &gpu.device;
        let (width, height) = (setup.scene.width, setup.scene.height);
        let pixels = u64::from(width) * u64::from(height);
        let gbuffer = setup.shared.gbuffer(NAME)?;
        // Everything is sized first and checked against the device's limits, before any allocation.
        let casting = CastingMesh::prepare(setup.shared.adjacency(NAME)?);
        let casting = (!casting.faces.is_empty()).then_some(casting);
        AllocationPlan::new(width, height, casting.as_ref()).check(&device.limits())?;
        let settings_buffer = uniform_buffer(device, "wedges_settings_uniform", &WedgesSettingsUniform::from(&settings));
        let counters = if casting.is_some() { COUNTERS } else { &COUNTERS[..COUNTERS_WITHOUT_MESH] };
        let read_counts = ReadCounts::with_units(device, "wedges_read_counts", counters, setup.count_work);

        let indirect = storage(device, "wedges_indirect_arguments", INDIRECT_WORDS * 4, wgpu::BufferUsages::INDIRECT);
        let stencil = render_texture(device, "wedges_stencil", width, height, STENCIL_FORMAT, wgpu::TextureUsages::empty());
        let stencil_view = labelled_view(&stencil, "wedges_stencil");
        let (depth_copy_pipeline, depth_copy_group) =
            depth_copy(gpu, gbuffer, (&settings_buffer, &setup.scene.camera_buffer), &read_counts)?;
        let blend = BlendPasses::new(setup, pixels, &settings_buffer, &read_counts)?;

        let mesh = match &casting {
            Some(casting) => {
                let uniform = WedgesMeshUniform::new(casting, (width, height), &setup.scene.bounds);
                Some(MeshPasses::new(setup, casting, uniform, (&settings_buffer, &indirect, &read_counts))?)
            }
            None => None,
        };
        Ok(Self {
            settings,
            mesh,
            indirect,
            depth_copy_pipeline,
            depth_copy_group,
            stencil_view,
            blend,
            gbuffer_group: gbuffer.bind_group.clone(),
            passes_issued: 0,
            pixels,
            read_counts,
        })
    }

    /// What the setup found in the casting mesh (`None` when nothing casts).
    #[must_use]
    pub fn mesh_report(&self) -> Option<MeshReport> {
        self.mesh.as_ref().map(|m| m.report)
    }

    /// One silhouette buffer: its shadow volumes, its wedges, and its blend into the final buffer.
    fn encode_group(&self, frame: &mut Frame<'_>, mesh: &MeshPasses, (light_frame, group): (&wgpu::BindGroup, u32), point_light: bool) {
        self.encode_volumes(frame, mesh, (light_frame, group));
        self.encode_wedges(frame, mesh, (light_frame, group), point_light);
        self.encode_umbra_mask(frame, light_frame);
        self.encode_blend(frame, (light_frame, group));
    }
}

impl ShadowTechnique for PenumbraWedges {
    fn render(&mut self, frame: &mut Frame<'_>, light: usize, output: &wgpu::TextureView) -> Result<()> {
        let scene = frame.scene;
        let light_frame = scene.light_bind_groups.get(light).ok_or_else(|| technique_error(format!("no light {light}")))?;
        let point_light = scene.light_frames.get(light).is_some_and(|f| f.light.is_point());
        if light == 0 {
            self.passes_issued = 0;
        }
        self.read_counts.clear(frame, light);
        if let Some(mesh) = &self.mesh {
            mesh.encode_silhouettes(frame, light_frame, &self.indirect);
            self.passes_issued += 1;
        }
        self.encode_depth_copy(frame, light_frame);
        self.passes_issued += 1;
        self.blend.clear(frame);
        if let Some(mesh) = &self.mesh {
            for group in 0..self.settings.silhouette_buffers.clamp(1, MAX_SILHOUETTE_BUFFERS) {
                self.encode_group(frame, mesh, (light_frame, group), point_light);
                self.passes_issued += 4;
            }
        }
        self.blend.resolve.encode(frame, light, output, Some(&self.blend.blend_group), None);
        self.passes_issued += 1;
        Ok(())
    }

    /// Per counting pass (`COUNTERS`): texel reads, atomics and bytes written to storage, as its
    /// shader counted them (`wedges_counts.wgsl`), when built for `--count-work`.
    fn counted_work(&mut self, gpu: &GpuContext) -> Result<Option<Vec<ShaderWork>>> {
        self.read_counts.work(gpu)
    }

    fn diagnostics(&mut self, gpu: &GpuContext) -> Vec<(String, f64)> {
        let mut out = vec![("passes".to_owned(), f64::from(self.passes_issued))];
        let Some(mesh) = &self.mesh else { return out };
        mesh.diagnostics(gpu, &mut out);
        if let Ok(counts) = ssm_core::readback::read_buffer(gpu, &self.blend.fragment_counts, self.pixels * 4, "wedges fragment counts") {
            let total: u64 = counts.chunks_exact(4).map(|b| u64::from(u32::from_le_bytes([b[0], b[1], b[2], b[3]]))).sum();
            out.push(("wedge_fragments".to_owned(), total as f64));
        }
        out
    }
}

fn create(setup: &TechniqueSetup<'_>) -> Result<Box<dyn ShadowTechnique>> {
    Ok(Box::new(PenumbraWedges::new(setup)?))
}

fn requirements(params: &ParamValues) -> Result<Requirements> {
    WedgesSettings::from_params(params)?;
    Ok(Requirements {
        gbuffer: true,
        adjacency: true,
        // Additive and max blending into Rgba32Float; depth unclipped for the volumes at infinity.
        features: wgpu::Features::FLOAT32_BLENDABLE | wgpu::Features::DEPTH_CLIP_CONTROL,
        ..Requirements::NONE
    })
}

/// Forest et al.'s evaluations, as sweeps.
const PRESETS: &[Preset] = &[
    Preset {
        name: "wedges-fig1",
        summary: "Forest et al., Figs. 1 and 2: the plain penumbra wedges (blending=none, one silhouette buffer) against the blending (forest, 16 buffers), on sphere-cube; read mae_penumbra and mean_signed_error in sweep.csv",
        scenes: &["sphere-cube"],
        varies: &["wedges.blending:silhouette_buffers=none:1,forest:16"],
        ..Preset::DEFAULT
    },
    Preset {
        name: "wedges-buffers",
        summary: "penumbra error against the number of silhouette buffers (1 = every silhouette summed within one buffer, the blend between buffers only), on sphere-cube",
        scenes: &["sphere-cube"],
        varies: &["wedges.silhouette_buffers=1,2,4,8,16,32,64"],
        x_axis: "wedges.silhouette_buffers",
        ..Preset::DEFAULT
    },
    Preset {
        name: "wedges-fig12",
        summary: "Forest et al., Fig. 12: frame time of the plain penumbra wedges (blending=none, one silhouette buffer) and of the blending (forest, 16 buffers); one scene per sphere count (ssm-bench's wedges_fig12 example sweeps them all and plots time against triangles). In counted work (--count-work): the same wedge fragments, and per buffer a blend thread per pixel, a full-screen umbra mask and the silhouette targets written back",
        scenes: FIG12_SCENES,
        varies: &["wedges.blending:silhouette_buffers=none:1,forest:16"],
        y_axis: "time",
        ..Preset::DEFAULT
    },
    Preset {
        name: "wedges-atty-fig25",
        summary: "Atty et al., Fig. 25: soft shadow volumes (wedges, forest) against soft shadow maps (atty two-sided, 210² occluder map) as polygons grow; one scene per sphere count, time against error (ssm-bench's wedges_fig12 example sweeps them all)",
        scenes: FIG25_SCENES,
        varies: &["wedges.blending=forest", "atty.two_sided=true", "atty.occluder_map_size=210"],
        ..Preset::DEFAULT
    },
];

/// The registration.
pub const INFO: TechniqueInfo = TechniqueInfo {
    name: NAME,
    summary: "penumbra wedges (soft shadow volumes) with GPU silhouettes and z-fail umbra; blending=forest blends overlapping penumbrae, blending=none silhouette_buffers=1 is the plain penumbra wedges",
    paper: "Forest, Barthe and Paulin 2006, Realistic soft shadows by penumbra-wedges blending (Graphics Hardware); Akenine-Möller and Assarsson 2002; Assarsson and Akenine-Möller 2003",
    kind: TechniqueKind::Realtime,
    // One view of the light from its centre: the framework adds the own surface's share.
    light_sampling: ssm_core::LightSampling::Centre,
    light_view: ssm_core::LightView::Hemisphere,
    params: WedgesSettings::PARAMS,
    requirements,
    create,
    presets: PRESETS,
    trade: Some("silhouette_buffers=1,4,16,64"),
    debug_outputs: &[],
    uniforms: &[
        UniformCheck {
            wgsl_struct: WedgesSettingsUniform::WGSL_NAME,
            wgsl_source: SILHOUETTES_SHADER,
            imports: LOCAL_SHADERS,
            rust: WedgesSettingsUniform::LAYOUT,
        },
        UniformCheck {
            wgsl_struct: WedgesMeshUniform::WGSL_NAME,
            wgsl_source: SILHOUETTES_SHADER,
            imports: LOCAL_SHADERS,
            rust: WedgesMeshUniform::LAYOUT,
        },
    ],
    limits: &[],
    paper_configuration: ssm_core::PaperConfiguration::DEFAULTS,
};

register_technique!(INFO);

#[cfg(test)]
mod tests {
    #![allow(clippy::unwrap_used)]

    use super::*;

    #[test]
    fn requirements_declare_adjacency_and_the_features_used() {
        let needs = requirements(&INFO.default_params()).unwrap();
        assert!(needs.adjacency && needs.gbuffer && !needs.roles);
        assert!(needs.features.contains(wgpu::Features::FLOAT32_BLENDABLE | wgpu::Features::DEPTH_CLIP_CONTROL));
    }

    #[test]
    fn the_settings_uniform_carries_the_blending() {
        let mut params = INFO.default_params();
        assert_eq!(WedgesSettingsUniform::from(&WedgesSettings::from_params(&params).unwrap()).blending, 1);
        params.set("blending", "none").unwrap();
        params.set("silhouette_buffers", "3").unwrap();
        let uniform = WedgesSettingsUniform::from(&WedgesSettings::from_params(&params).unwrap());
        assert_eq!((uniform.blending, uniform.silhouette_buffers), (0, 3));
        assert!(params.set("blending", "probabilistic").is_err());
    }
}
