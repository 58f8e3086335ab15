//! Atty, Holzschuch, Lapierre, Hasenfratz, Hansen and Sillion, *Soft Shadow
//! Maps: Efficient Sampling of Light Source Visibility*, Computer Graphics
//! Forum 25(4), 2006.
//!
//! The occluders, seen from the light's centre, become one micro-patch per
//! occluder-map texel, parallel to the light at that texel's depth (Sec. 3.2).
//! Each patch's penumbra extent is a pyramid whose section on the soft shadow
//! map (SSM) is an axis-aligned rectangle (Sec. 3.3); for every SSM texel in
//! it, the patch is projected back onto the light from the receiver there, and
//! the hidden fraction, a product of two clamped 1-D overlaps, is added into a
//! float map by blending (Sec. 3.4, 4.2). The SSM is then projected onto the
//! receivers. The two-sided variant does this for the nearest front faces and
//! the farthest back faces and keeps the larger occlusion (Sec. 3.5).
//!
//! Unlike the paper, nothing goes back to the CPU: a compute pass lists the
//! micro-patches and an indirect instanced draw accumulates them (the paper's
//! stated next step, Sec. 4.3 and 7), so the cost no longer grows with a
//! readback. Neighbouring texels at one depth are listed as one patch (their
//! back-projections join exactly, Sec. 5.1.2). And, where the paper separates
//! occluders from receivers (Sec. 1, 7), a surface in both maps is kept from
//! shadowing itself through its own micro-patches: the receiver map carries
//! each receiver's tangent plane, and a patch on or behind it hides nothing
//! (`receiver_plane`, on by default).
//!
//! # Example
//!
//! From the command line: `ssm render --scene contact --technique atty --set
//! atty.occluder_map_size=128 --out out` (`ssm list` gives every parameter). From Rust, through the
//! framework, as every technique crate is used (`ssm_atty::link()` keeps its registration in
//! the binary; `ssm_techniques::link_all()` links every crate of the workspace):
//!
//! ```
//! # fn main() -> Result<(), Box<dyn std::error::Error>> {
//! use ssm_core::{GpuContext, Registry, Renderer};
//!
//! ssm_atty::link();
//! let gpu = GpuContext::new()?;
//! let scene = ssm_scene::builtin("contact")?.build();
//! let info = Registry::global()?.get("atty")?;
//! let params = info.params_from([("occluder_map_size", "128")])?;
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

pub mod geometry;

mod accumulation;
mod counts;
mod gpu;
mod micro_patches;
mod occluder_map;
mod patch_merge;
mod projection;
mod receiver_bounds;
mod receiver_map;

use bytemuck::{Pod, Zeroable};
use ssm_core::work::ShaderWork;
use ssm_core::{
    Error, Frame, GpuContext, ParamValues, Requirements, Result, Settings, ShadowMapBias, ShadowTechnique, TechniqueInfo, TechniqueKind,
    TechniqueSetup, UniformCheck, UniformStruct, register_technique,
};

pub use accumulation::Accumulation;
pub use gpu::SoftShadowMaps;
pub use receiver_bounds::PenumbraBound;

/// The registered name.
pub const NAME: &str = "atty";

/// The micro-patch geometry the list pass and the accumulation evaluate, twin of [`geometry`].
pub const GEOMETRY_SHADER: &str = ssm_shaders::atty::ATTY_GEOMETRY;
/// WGSL files the Atty shaders import besides `common/`, as `(path under shaders/, text)`.
pub const LOCAL_SHADERS: &[(&str, &str)] = &[
    (AttySettingsUniform::WGSL_IMPORT, AttySettingsUniform::WGSL),
    ("atty/atty_settings.wgsl", ssm_shaders::atty::ATTY_SETTINGS),
    ("atty/atty_geometry.wgsl", GEOMETRY_SHADER),
    ("atty/atty_counts.wgsl", ssm_shaders::atty::ATTY_COUNTS),
];

/// Settings of [`SoftShadowMaps`]: its parameters.
#[derive(Clone, Copy, Debug, PartialEq, Settings)]
pub struct AttySettings {
    /// Side of the occluder map, texels: one micro-patch per texel (cost grows with its square).
    #[param(default = 256, min = 32, max = 2048)]
    pub occluder_map_size: u32,
    /// Side of the soft shadow map and of the receiver map, texels.
    #[param(default = 512, min = 32, max = 4096)]
    pub ssm_size: u32,
    /// Also discretise the farthest back faces and keep the larger occlusion (Sec. 3.5; about twice the cost).
    #[param(default = false)]
    pub two_sided: bool,
    /// Format of the soft shadow map the patches are summed into: f32 (needs FLOAT32_BLENDABLE) or f16 (the paper's hardware; see Appendix A).
    #[param(choice, default = "f32")]
    pub accumulation: Accumulation,
    /// Projection lookup point moved off the surface along its normal, in receiver-map texels.
    #[param(default = 0.5, min = 0.0, max = 8.0)]
    pub normal_offset: f32,
    /// Receiver-map depths within this many texel footprints (world size of one receiver-map texel at the depth looked up) of a receiver count as that receiver: the SSM's bilinear lookup blends only those, and (without `receiver_plane`) a point farther behind is hidden (in umbra). With `receiver_plane` it is measured from each texel's plane along the point's own ray.
    #[param(default = 2.0, min = 0.0, max = 64.0)]
    pub receiver_tolerance: f32,
    /// A micro-patch less than this many of its widths in front of a receiver hides nothing: without `receiver_plane`, removes the moiré of objects with role `both` shadowing themselves, but also the shadow of an occluder that close to a receiver (0: the paper).
    #[param(default = 0.0, min = 0.0, max = 16.0)]
    pub self_shadow_tolerance: f32,
    /// What bounds each micro-patch's penumbra rectangle: the far plane, or the deepest receiver under it (same result; fewer accumulation fragments, for a pyramid pass whose texel reads exceed what they save).
    #[param(choice, default = "far_plane")]
    pub penumbra_bound: PenumbraBound,
    /// Aligned blocks of occluder texels whose depths differ by at most this many micro-patch widths are drawn as one micro-patch (Sec. 5.1.2: neighbours at one depth join exactly; 0: one patch per texel).
    #[param(default = 0.01, min = 0.0, max = 16.0)]
    pub merge_tolerance: f32,
    /// A micro-patch on or behind a receiver's tangent plane (the receiver map carries each texel's, from its triangle) hides nothing from it, so a surface in both maps does not shadow itself through its own micro-patches; and the projection finds each point's own receiver by its plane (false: the receiver's depth alone decides, the paper).
    #[param(default = true)]
    pub receiver_plane: bool,
    /// With `receiver_plane`: a micro-patch less than this many of its widths (one texel's) in front of a receiver's tangent plane, beyond its own surface's depth spread across the patch, counts as lying on it (a margin for rounding).
    #[param(default = 0.05, min = 0.0, max = 16.0)]
    pub receiver_plane_tolerance: f32,
}

/// The settings uniform every Atty shader reads: the WGSL struct `AttySettings`, which the derive writes
/// and `shaders/atty/atty_settings.wgsl` imports (`// #import rust/AttySettings`).
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable, UniformStruct)]
pub struct AttySettingsUniform {
    /// Side of the occluder map (N), texels.
    occluder_map_size: f32,
    /// Side of the soft shadow map (and of the receiver map), texels.
    soft_shadow_map_size: f32,
    /// Normal offset of the projection's lookup point, in receiver-map texels.
    normal_offset: f32,
    /// Depth tolerance, in receiver-map texel footprints, within which a receiver-map depth counts
    /// as the looked-up receiver (the hidden-receiver test and the SSM's depth-aware bilinear lookup).
    receiver_tolerance: f32,
    /// A micro-patch less than this many of its own widths in front of a receiver counts as the
    /// receiver's own surface and hides nothing (objects with the role `both` are in both maps).
    self_shadow_tolerance: f32,
    /// Constant depth tolerance of the hidden-receiver test, a fraction of the scene's diagonal (as the baselines' constant bias).
    receiver_bias: f32,
    /// 1: each micro-patch's penumbra rectangle is bounded by the deepest receiver under it (the
    /// receiver_bounds pyramid); 0: by the frame's far plane.
    receiver_bounded: f32,
    /// Neighbouring occluder texels whose depths differ by at most this many micro-patch widths
    /// are drawn as one micro-patch (0: never).
    merge_tolerance: f32,
    /// 1: a micro-patch on or behind a receiver's tangent plane hides nothing from it (the
    /// accumulation reads the receiver planes); 0: the receiver's depth alone decides.
    receiver_plane: f32,
    /// How far in front of a receiver's tangent plane, in widths of one texel's micro-patch, a patch
    /// still counts as lying on it.
    receiver_plane_tolerance: f32,
    _pad: [f32; 2],
}

impl From<&AttySettings> for AttySettingsUniform {
    fn from(settings: &AttySettings) -> Self {
        Self {
            occluder_map_size: settings.occluder_map_size as f32,
            soft_shadow_map_size: settings.ssm_size as f32,
            normal_offset: settings.normal_offset,
            receiver_tolerance: settings.receiver_tolerance,
            self_shadow_tolerance: settings.self_shadow_tolerance,
            // The baselines' default constant bias, a fraction of the scene's diagonal.
            receiver_bias: ShadowMapBias::default().constant_bias,
            receiver_bounded: if settings.penumbra_bound == PenumbraBound::Receivers { 1.0 } else { 0.0 },
            merge_tolerance: settings.merge_tolerance,
            receiver_plane: if settings.receiver_plane { 1.0 } else { 0.0 },
            receiver_plane_tolerance: settings.receiver_plane_tolerance,
            _pad: [0.0; 2],
        }
    }
}

/// Fewest receiver-map texels across the receivers for the SSM to represent a penumbra on them.
const MIN_RECEIVER_TEXELS: f32 = 4.0;

/// The SSM lives on the receiver map of the light's frame. When that frame must be very wide (an
/// occluder almost touching the light, which every technique's frame keeps), the receivers can
/// shrink below a texel of it and would silently read as lit: refuse instead.
fn check_receivers_resolved(setup: &TechniqueSetup<'_>, ssm_size: u32) -> Result<()> {
    for (light, frame) in setup.scene.light_frames.iter().enumerate() {
        let texels = frame.footprint_texels(&setup.scene.receiver_bounds, ssm_size);
        if !setup.scene.receiver_bounds.is_empty() && texels.min_element() < MIN_RECEIVER_TEXELS {
            return Err(Error::Unrepresentable {
                technique: NAME.into(),
                reason: format!(
                    "light {light}'s frame is {:.1}° wide (an occluder lies almost in the light's plane), so the receivers cover only {:.1}×{:.1} texels of the {ssm_size}² soft shadow map; at least {MIN_RECEIVER_TEXELS} are needed",
                    2.0 * frame.tan_half.max_element().atan().to_degrees(),
                    texels.x,
                    texels.y
                ),
            });
        }
    }
    Ok(())
}

impl ShadowTechnique for SoftShadowMaps {
    fn render(&mut self, frame: &mut Frame<'_>, light: usize, output: &wgpu::TextureView) -> Result<()> {
        let light_frame = frame
            .scene
            .light_bind_groups
            .get(light)
            .ok_or_else(|| Error::Technique { technique: NAME.into(), message: format!("no light {light}") })?;
        self.read_counts.clear(frame, light);
        self.receiver_map.encode(frame, light_frame);
        if let Some(bounds) = &self.receiver_bounds {
            bounds.encode(frame);
        }
        for side in &self.accumulations {
            side.occluder_map.encode(frame, light);
            if let Some(merge) = &side.patch_merge {
                merge.encode(frame);
            }
            micro_patches::encode(frame, light_frame, side, (&self.patches_pipeline, self.occluder_map_size));
            accumulation::encode(frame, light_frame, side, &self.accumulate_pipeline);
        }
        self.project.encode(frame, light, output, Some(&self.project_group), None);
        Ok(())
    }

    /// Per counting pass (`CounterPlan`): texel reads, atomics and bytes written to storage, as
    /// its shader counted them (`atty_counts.wgsl`), when built for `--count-work`.
    fn counted_work(&mut self, gpu: &GpuContext) -> Result<Option<Vec<ShaderWork>>> {
        self.read_counts.work(gpu)
    }
}

fn requirements(params: &ParamValues) -> Result<Requirements> {
    let settings = AttySettings::from_params(params)?;
    // f32 accumulation blends into R32Float: never silently fall back to another precision.
    let features = if settings.accumulation == Accumulation::F32 { wgpu::Features::FLOAT32_BLENDABLE } else { wgpu::Features::empty() };
    Ok(Requirements {
        gbuffer: true,
        roles: true,
        features,
        max_texture_size: settings.occluder_map_size.max(settings.ssm_size),
        ..Requirements::NONE
    })
}

fn create(setup: &TechniqueSetup<'_>) -> Result<Box<dyn ShadowTechnique>> {
    Ok(Box::new(SoftShadowMaps::new(setup)?))
}

/// The registration.
pub const INFO: TechniqueInfo = TechniqueInfo {
    name: NAME,
    summary: "soft shadow maps: occluder micro-patches back-projected onto the light, accumulated on the GPU (one- and two-sided)",
    paper: "Atty et al. 2006, Soft Shadow Maps: Efficient Sampling of Light Source Visibility (CGF 25(4))",
    kind: TechniqueKind::Realtime,
    // One view of the light from its centre: the framework adds the own surface's share.
    light_sampling: ssm_core::LightSampling::Centre,
    light_view: ssm_core::LightView::Frame,
    params: AttySettings::PARAMS,
    requirements,
    create,
    presets: PRESETS,
    trade: Some("occluder_map_size=64,128,256,512"),
    debug_outputs: &[],
    uniforms: &[UniformCheck {
        wgsl_struct: AttySettingsUniform::WGSL_NAME,
        wgsl_source: projection::PROJECT_SHADER,
        imports: LOCAL_SHADERS,
        rust: AttySettingsUniform::LAYOUT,
    }],
    limits: &[
        ssm_core::KnownLimit {
            case: "three lights",
            mean_error: 0.3,
            reason: "the three lights shine on sphere-cube, whose 125 spheres are occluders only, and the method splits the scene into occluders and receivers and computes no shadow on the occluders (Atty et al. 2006, Sec. 1 and Sec. 7: no self-occlusion), so spheres that shadow each other read lit: over the receivers alone its error under the first light is 0.0433, over every pixel 0.1204; under the point light, whose hard shadow leaves few penumbra pixels, the spheres are most of the pixels either shadows (0.2463)",
        },
        ssm_core::KnownLimit {
            case: "wall lit at grazing angles",
            mean_error: 0.2,
            reason: "the block standing on the wall has the role both, so it is in the receiver map, and the soft shadow map holds the occlusion of one receiver per texel, the one nearest the light's centre (Atty et al. 2006, Sec. 3.1: the receiver map's depth is the receiver's; Sec. 7: occluders and receivers must be separated, self-occlusion is left to future work with layered depth images): the wall behind the block, in its hard shadow from the centre, has no value of its own and reads umbra, a band the truth shows as penumbra (0.1678 at 96x72); with the block an occluder only, the split the paper requires, the error is 0.0371 and hard shadows' 0.2369",
        },
        ssm_core::KnownLimit {
            case: "light resting on the receiver",
            mean_error: 0.25,
            reason: "past the light frame's widest angle (84 degrees off the light's normal) the framework answers with a hard shadow from the light's centre (counted: pixels_beyond_frame): the soft shadow map is one virtual plane parallel to the light, onto which each micro-patch's penumbra pyramid cuts an axis-aligned rectangle (Atty et al. 2006, Sec. 3.3, Fig. 7); the micro-patches are parallel to the light (Sec. 3), which a hemicube's side faces, perpendicular to it, are not",
        },
    ],
    paper_configuration: ssm_core::PaperConfiguration {
        // The receiver's depth alone decides, and the SSM is read at the point itself (Sec. 3.1's
        // projective texture lookup; the normal offset is this workspace's, Holbert 2011).
        settings: &["receiver_plane=false", "normal_offset=0"],
        scenes: &["parallel-square", "floating-sphere"],
        truth: &[],
        // Where the occluder's edges fall on the occluder map's grid moves the error several times
        // over (Sec. 5.1.1's half-texel bound, either way): a whole cycle of sizes around 256.
        averaged_over: Some("occluder_map_size=252,253,254,255,256,257,258,259"),
    },
};

/// The error Atty et al.'s figures plot (Sec. 5.2.1): the mean absolute error over the pixels in
/// umbra or penumbra in the ground truth, not the workspace's headline error.
const PAPER_ERROR: &str = "mae-penumbra";

/// The paper's own receiver model and lookup, which every reproduction of its figures runs: a
/// receiver's depth alone decides (no receiver plane; `receiver_plane` is this workspace's model for
/// objects that both cast and receive, which the paper leaves out, Sec. 7), and the SSM is read at
/// the point itself (Sec. 3.1; no normal offset).
const PAPER_MODE: &str = "atty.receiver_plane:normal_offset=false:0";

/// Atty et al.'s studies (Sec. 5.2 and 6.2), as sweeps, in the paper's mode.
const PRESETS: &[ssm_core::Preset] = &[
    ssm_core::Preset {
        name: "atty-map-size",
        summary: "Atty et al., Fig. 17 (error) and Fig. 22 (time, with --error time) against the occluder map's size, one- and two-sided; in counted work (--count-work) the accumulation's fragments grow with the micro-patches, n², while each patch covers fewer",
        scenes: &["floating-sphere"],
        varies: &["atty.occluder_map_size=33,63,127,200,255,383,511", "atty.two_sided=false,true", PAPER_MODE],
        x_axis: "atty.occluder_map_size",
        y_axis: PAPER_ERROR,
        pixels: "receivers",
        ..ssm_core::Preset::DEFAULT
    },
    ssm_core::Preset {
        name: "atty-map-size-time",
        summary: "Atty et al., Fig. 22: frame time against the occluder map's size (128², 256², 512²), one- and two-sided",
        scenes: &["floating-sphere"],
        varies: &["atty.occluder_map_size=128,256,512", "atty.two_sided=false,true", PAPER_MODE],
        x_axis: "atty.occluder_map_size",
        y_axis: "time",
        ..ssm_core::Preset::DEFAULT
    },
    ssm_core::Preset {
        name: "atty-light-size",
        summary: "Atty et al., Fig. 18 and Fig. 24(b) (error; Fig. 24(a), time, with --error time) against the light's size for 63², 127², 255² maps (not powers of two, as the paper notes in Sec. 5.2.3; a thick occluder such as floating-sphere)",
        scenes: &["floating-sphere"],
        varies: &["scene.light_scale=0.02,0.25,0.5,1,1.5,2", "atty.occluder_map_size=63,127,255", PAPER_MODE],
        x_axis: "scene.light_scale",
        y_axis: PAPER_ERROR,
        pixels: "receivers",
        ..ssm_core::Preset::DEFAULT
    },
    ssm_core::Preset {
        name: "atty-occluder-height",
        summary: "Atty et al., Fig. 20: error as the occluders move from the receiver towards the light (on floating-sphere: from 0.05 above the ground to 0.45 below the light; a little higher every micro-patch's rectangle covers most of the soft shadow map and a frame takes tens of seconds on lavapipe)",
        scenes: &["floating-sphere"],
        varies: &["scene.occluder_lift=-0.75,-0.5,0,0.5,1,1.25,1.5,1.55", "atty.two_sided=false,true", PAPER_MODE],
        x_axis: "scene.occluder_lift",
        y_axis: PAPER_ERROR,
        pixels: "receivers",
        ..ssm_core::Preset::DEFAULT
    },
    ssm_core::Preset {
        name: "atty-occluder-shift",
        summary: "Atty et al., Fig. 19: error as the occluder moves sideways under the light (scene.occluder_shift, in light widths from its centre), 128² map, one- and two-sided",
        scenes: &["floating-sphere"],
        varies: &["scene.occluder_shift=-1,-0.5,-0.25,0,0.25,0.5,1", "atty.occluder_map_size=128", "atty.two_sided=false,true", PAPER_MODE],
        x_axis: "scene.occluder_shift",
        y_axis: PAPER_ERROR,
        pixels: "receivers",
        ..ssm_core::Preset::DEFAULT
    },
    ssm_core::Preset {
        name: "atty-polygons",
        summary: "Atty et al., Fig. 21: error (and time, with --error time) against the occluder's polygon count, a sphere tessellated from 16 to 261,632 triangles (scene.segments, rings in step), 128² map",
        scenes: &["floating-sphere"],
        varies: &[
            "scene.segments:rings=4:3,16:8,64:32,256:128,512:256",
            "atty.occluder_map_size=128",
            "atty.two_sided=false,true",
            PAPER_MODE,
        ],
        x_axis: "scene.segments",
        y_axis: PAPER_ERROR,
        pixels: "receivers",
        ..ssm_core::Preset::DEFAULT
    },
    ssm_core::Preset {
        name: "atty-small-maps",
        summary: "Atty et al., Fig. 23: large lights with small occluder maps, the error of 32², 64², 128² maps as the light grows (one to four times floating-sphere's)",
        scenes: &["floating-sphere"],
        varies: &["scene.light_scale=1,2,3,4", "atty.occluder_map_size=32,64,128", "atty.two_sided=true", PAPER_MODE],
        x_axis: "scene.light_scale",
        y_axis: PAPER_ERROR,
        pixels: "receivers",
        ..ssm_core::Preset::DEFAULT
    },
    ssm_core::Preset {
        name: "atty-paper-mode",
        summary: "The default receiver model (receiver_plane) against the paper's mode (read at the point, and with this workspace's normal offset) on the paper's analytic case, parallel-square (exact truth), and on floating-sphere, over a whole cycle of the occluder map's grid phase near 256² and near 1024² (compare the means over each eight sizes: one size alone is decided by where the square's edges fall on the texel grid), with FP32 and Appendix A's FP16 accumulation, one patch per texel (merge_tolerance 0, as the paper)",
        scenes: &["parallel-square", "floating-sphere"],
        varies: &[
            "atty.receiver_plane:normal_offset=false:0,false:0.5,true:0.5",
            "atty.occluder_map_size=252,253,254,255,256,257,258,259,1020,1021,1022,1023,1024,1025,1026,1027",
            "atty.accumulation=f32,f16",
            "atty.merge_tolerance=0",
        ],
        x_axis: "atty.occluder_map_size",
        y_axis: PAPER_ERROR,
        ..ssm_core::Preset::DEFAULT
    },
];

register_technique!(INFO);

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn f32_accumulation_declares_float32_blendable_and_f16_does_not() {
        let mut params = INFO.default_params();
        params.set("accumulation", "f32").unwrap();
        let f32_needs = requirements(&params).unwrap();
        assert!(f32_needs.features.contains(wgpu::Features::FLOAT32_BLENDABLE) && f32_needs.roles && f32_needs.gbuffer);
        params.set("accumulation", "f16").unwrap();
        assert!(requirements(&params).unwrap().features.is_empty(), "f16 blends on any device");
        params.set("occluder_map_size", "2048").unwrap();
        assert_eq!(requirements(&params).unwrap().max_texture_size, 2048);
    }
}
