//! Buades, Gumbau and Chover, *Separable soft shadow mapping*, The Visual
//! Computer, 2015.
//!
//! PCSS's two O(n²) filters made separable (Sec. 3, 4): the blocker search
//! sums n×1 rows of the depth map per pixel, then each pixel adds up the n
//! rows of its window by reusing the row of the pixel that sees it when their
//! light depths differ by less than α (else reading the row); the penumbra from
//! Eq. 1 sizes a separable screen-space blur of the hard shadow, whose vertical
//! half reuses each tap pixel's horizontal result when its normal-adjusted
//! depth differs by less than β (else re-sampling the shadow map). Three
//! passes after the depth map, as the paper's Table 1.
//!
//! # Example
//!
//! From the command line: `ssm render --scene contact --technique sssm --set
//! sssm.alpha=0.1 --out out` (`ssm list` gives every parameter). From Rust, through the
//! framework, as every technique crate is used (`ssm_sssm::link()` keeps its registration in
//! the binary; `ssm_techniques::link_all()` links every crate of the workspace):
//!
//! ```
//! # fn main() -> Result<(), Box<dyn std::error::Error>> {
//! use ssm_core::{GpuContext, Registry, Renderer};
//!
//! ssm_sssm::link();
//! let gpu = GpuContext::new()?;
//! let scene = ssm_scene::builtin("contact")?.build();
//! let info = Registry::global()?.get("sssm")?;
//! let params = info.params_from([("alpha", "0.1")])?;
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

use bytemuck::{Pod, Zeroable};
use ssm_core::passes::{
    bind_group_layout, compute_pipeline, labelled_view, render_texture, texture_entry, uniform_buffer, uniform_entry,
    write_storage_texture_entry,
};
use ssm_core::read_counts::ReadCounts;
use ssm_core::readback::read_texture;
use ssm_core::shader::create_shader_with_imports;
use ssm_core::{
    Choice, DebugOutput, ExtraImage, Frame, GpuContext, LightDepthMap, ParamValues, ReceiverModel, Requirements, Result,
    SHADOW_MAP_MAX_SIZE, SHADOW_MAP_MIN_SIZE, ScreenPass, Settings, ShaderWork, ShadowMapBias, ShadowTechnique, TechniqueInfo,
    TechniqueKind, TechniqueSetup, UniformCheck, UniformStruct, VISIBILITY_FORMAT, register_technique, screen_space_requirements,
};

/// The registered name.
pub const NAME: &str = "sssm";

/// WGSL files the SSSM passes import besides `common/`.
const LOCAL_SHADERS: &[(&str, &str)] = &[
    (SssmSettingsUniform::WGSL_IMPORT, SssmSettingsUniform::WGSL),
    ("sssm/sssm_common.wgsl", ssm_shaders::sssm::SSSM_COMMON),
    ("sssm/sssm_blocker_blur.wgsl", ssm_shaders::sssm::SSSM_BLOCKER_BLUR),
    ("sssm/sssm_vertical_blur.wgsl", ssm_shaders::sssm::SSSM_VERTICAL_BLUR),
    ("sssm/sssm_segment.wgsl", ssm_shaders::sssm::SSSM_SEGMENT),
];
/// Step 1: hard shadow and horizontal partial blocker sums.
const HORIZONTAL_BLOCKER_SHADER: &str = ssm_shaders::sssm::SSSM_HORIZONTAL_BLOCKER;
/// Step 2 (blocker average, penumbra size, horizontal blur) as a fragment pass.
const BLOCKER_BLUR_FRAGMENT_SHADER: &str = ssm_shaders::sssm::SSSM_BLOCKER_BLUR_FRAGMENT;
/// Step 2 as a compute pass sharing each workgroup's screen row.
const BLOCKER_BLUR_COMPUTE_SHADER: &str = ssm_shaders::sssm::SSSM_BLOCKER_BLUR_COMPUTE;
/// Step 3 (vertical blur) as a fragment pass.
const VERTICAL_BLUR_FRAGMENT_SHADER: &str = ssm_shaders::sssm::SSSM_VERTICAL_BLUR_FRAGMENT;
/// Step 3 as a compute pass sharing each workgroup's screen column.
const VERTICAL_BLUR_COMPUTE_SHADER: &str = ssm_shaders::sssm::SSSM_VERTICAL_BLUR_COMPUTE;
/// The format of the four screen-sized targets the passes hand on to each other and read
/// (`horizontal_blocker`, `blur_source`, `horizontal_blur`, `vertical_tap_source`): a texel read
/// of one costs 16 bytes (`SCREEN_TARGET_TEXEL_BYTES` in `shaders/sssm/sssm_common.wgsl`). The
/// reuse share and the penumbra error are `R32Float`, written and read back, never read by a pass.
pub const SCREEN_TARGET_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rgba32Float;
/// Pixels per workgroup of the compute passes: along the row in step 2, down the column in step 3
/// (`SEGMENT_PIXELS` of `sssm_segment.wgsl`; step 3's workgroup grid is (row runs, columns)).
const SHARED_SEGMENT_PIXELS: u32 = 64;

/// The blur's weights (Sec. 4.4).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Choice)]
pub enum BlurFilter {
    /// Gaussian weights of standard deviation `sigma` half-widths.
    Gaussian,
    /// Equal weights: the box filter PCSS applies.
    Mean,
    /// Gaussian where the blurs run along the screen's rows and columns (the paper's choice,
    /// which hides a box's alignment to the screen), equal weights where they run along the
    /// light's sides (`blur_axes`): there the box is the uniform light's own profile.
    Auto,
}

/// The directions of the two separable blurs (steps 2 and 3).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Choice)]
pub enum BlurAxes {
    /// The screen's rows, then its columns (the paper, Sec. 4.2), each as wide as the projected
    /// PCF kernel's extent along it (the root-sum-square of its two half-axes' components).
    Screen,
    /// The light's two sides as the screen sees them on the receiver's tangent plane: the blur is
    /// the projected kernel's own parallelogram, so a tube light's penumbra is blurred along the
    /// tube and not across it at any angle to the screen. Rows leave the screen's rows and
    /// columns, so the shared-row compute passes read such taps from the textures.
    Light,
    /// `light` for a light at least twice as long as it is wide (`ELONGATED_LIGHT_RATIO` in
    /// `shaders/sssm/sssm_common.wgsl`), `screen` for the others: the paper's screen-aligned
    /// Gaussian emulates a round light (Sec. 4.4), which a tube is not.
    Auto,
}

/// How steps 2 and 3 run (the same pixels either way).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Choice)]
pub enum BlurPasses {
    /// Full-screen fragment passes: every blur tap reads its pixel from a texture (one texel: step 1 and step 2 each hand on what the next step's taps read, packed).
    Fragment,
    /// Compute passes whose workgroups (64 pixels of a row in step 2, of a column in step 3) load
    /// the screen segment their blurs reach into workgroup memory once; taps read it from there.
    /// Slower on lavapipe, where workgroup memory is the same memory as a texture and the
    /// barriers cost; meant for GPUs, where it has not been measured yet.
    SharedRows,
}

/// Where steps 2 and 3 take the blocker rows and blur rows that fall past the screen's edges
/// (`CLAMP_EDGE_ROWS` in `shaders/sssm/sssm_common.wgsl`). Each such row costs n or m
/// depth-map taps when recomputed; the horizontal blur's single taps past the edges are
/// shadow-tested either way.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Choice)]
pub enum EdgeRows {
    /// From the depth map, as a row that fails its reuse test (a blocker row's n taps compared
    /// with the receiver, a blur row's m taps shadow-tested on the pixel's tangent plane): the
    /// same result at the borders as inside the screen, at n or m reads a row (the cost in texel
    /// reads: `ssm sweep --preset sssm-edges --count-work`; docs/notes/sssm.md).
    Recompute,
    /// From the nearest pixel on the screen, reused when it passes the reuse test (α, β), as a
    /// screen-space pass reading through a clamp-to-edge sampler would; a reused one counts as
    /// reused in the reuse share (Fig. 10). The paper says filtering is "not possible" at the
    /// borders (Sec. 4.2): its passes read only the screen. Wrong near the borders where the
    /// shadow changes past them.
    Clamp,
}

/// Settings of [`SeparableSoftShadowMaps`]: its parameters.
#[derive(Clone, Copy, Debug, PartialEq, Settings)]
pub struct SssmSettings {
    /// Side of the square shadow map, texels.
    #[param(default = 1024, min = SHADOW_MAP_MIN_SIZE, max = SHADOW_MAP_MAX_SIZE)]
    pub shadow_map_size: u32,
    /// n: samples per axis of the blocker search window.
    #[param(default = 7, min = 1, max = 64)]
    pub blocker_kernel: u32,
    /// m: taps per axis of the screen-space blur.
    #[param(default = 15, min = 1, max = 128)]
    pub blur_kernel: u32,
    /// α: blocker rows are reused when light depths differ by less than this fraction of the scene's diagonal (0: never).
    #[param(default = 0.01, min = 0.0, max = 1.0)]
    pub alpha: f32,
    /// β: blur rows are reused when normal-adjusted camera depths differ by less than this fraction of the scene's diagonal (0: never).
    #[param(default = 0.01, min = 0.0, max = 1.0)]
    pub beta: f32,
    /// Blur weights (Sec. 4.4): gaussian, mean, or auto (gaussian along the screen's rows and columns, the paper's; mean along the light's sides, the uniform light's own profile).
    #[param(choice, default = "auto")]
    pub filter: BlurFilter,
    /// Gaussian standard deviation in units of the blur's half-width (the paper's N(0, 0.5)).
    #[param(default = 0.5, min = 0.05, max = 4.0)]
    pub sigma: f32,
    /// Directions of the two blurs: screen (the screen's rows and columns, the paper), light (the light's two sides as projected on the receiver's tangent plane, which follow a tube light at any angle to the screen), or auto (light for a light at least twice as long as wide, screen for the others).
    #[param(choice, default = "auto")]
    pub blur_axes: BlurAxes,
    /// What the blocker taps are compared with (as pcss's).
    #[param(flatten)]
    pub receiver: ReceiverModel,
    /// Blur taps are weighted by exp(-(Δ/t)²) for a camera-distance gap Δ to this pixel's tangent plane, t this fraction of the scene's diagonal, and by their normals' agreement, so shadow does not leak across silhouettes (0: the paper's unweighted blur).
    #[param(default = 0.005, min = 0.0, max = 1.0)]
    pub bilateral_depth: f32,
    /// How steps 2 and 3 run: fragment passes or shared-row compute passes (same result).
    #[param(choice, default = "fragment")]
    pub blur_passes: BlurPasses,
    /// Where blocker rows and blur rows past the screen's edges come from: recompute (the depth map, as Sec. 4.1 recomputes a row that cannot be reused: exact borders, at n or m reads a row) or clamp (the nearest pixel on the screen when it passes the reuse test, as a clamp-to-edge read would: fewer reads, wrong where the shadow changes past the edge).
    #[param(choice, default = "recompute")]
    pub edge_rows: EdgeRows,
    /// Count each pass's texel reads per pixel of the screen, the G-buffer's and the previous step's own texel included at every pixel (diagnostics `sssm_<pass>_reads_per_pixel`), and the kernel rows that failed their reuse test per computed pixel, by cause (`sssm_blocker_rows_failed_<cause>_rows_per_pixel` for step 2, `sssm_blur_rows_failed_<cause>_rows_per_pixel` for step 3; causes `off_screen`, `no_data`, `depth`; with `edge_rows = clamp`, `off_screen` counts only blocker rows behind the eye, the others being read from the edge); the atomics cost time, so off when timing.
    #[param(default = false)]
    pub count_reads: bool,
    /// Also search every blocker row of each pixel (no reuse, PCSS's search) and measure the squared difference of the two penumbra widths in shadow-map texels (diagnostics `sssm_penumbra_mse_texels2` over the pixels either search finds a blocker for and `sssm_penumbra_mse_all_texels2` over every pixel computed, debug output `penumbra_error`: the paper's Table 5); a full search per pixel, so off when timing.
    #[param(default = false)]
    pub penumbra_error: bool,
    /// Depth bias and normal offset.
    #[param(flatten)]
    pub bias: ShadowMapBias,
}

/// The settings as the shaders read them: the WGSL struct `SssmSettings`, which the derive writes
/// and `shaders/sssm/sssm_common.wgsl` imports (`// #import rust/SssmSettings`).
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable, UniformStruct)]
pub struct SssmSettingsUniform {
    /// Samples per axis of the blocker search (n).
    blocker_kernel: u32,
    /// Samples per axis of the blur (m).
    blur_kernel: u32,
    /// 1: blocker taps compare with the receiver's tangent plane (as pcss's receiver_plane); 0: with its depth.
    receiver_plane: u32,
    /// Reuse threshold α, a fraction of the scene's diagonal (scene_length): light-depth difference.
    alpha: f32,
    /// Reuse threshold β, a fraction of the scene's diagonal: normal-adjusted camera-depth difference.
    beta: f32,
    /// Normal offset of shadow-map lookups, texels.
    normal_offset: f32,
    /// Depth tolerance of the blurs' bilateral weights, a fraction of the scene's diagonal; 0: no bilateral weighting.
    bilateral_depth: f32,
    /// a in a blur tap's weight exp(-a x²) at its offset x in [-1, 1] (Sec. 4.4): 1 / (2σ²) for the
    /// Gaussian of σ kernel half-widths, 0 for the mean filter.
    blur_weight_exponent: f32,
    /// BLUR_ALONG_SCREEN (the paper's rows and columns), BLUR_ALONG_LIGHT (the light's two sides as
    /// the screen sees them on the receiver's tangent plane), or BLUR_AXES_AUTO (the light's sides
    /// for a light ELONGATED_LIGHT_RATIO times longer than wide or more, else the screen's).
    blur_axes: u32,
    /// 1 (the settings' filter = auto): blurs along the light's sides weigh their taps equally
    /// (blur_weight_exponent 0), whatever blur_weight_exponent says.
    box_along_light: u32,
}

impl From<&SssmSettings> for SssmSettingsUniform {
    fn from(settings: &SssmSettings) -> Self {
        Self {
            blocker_kernel: settings.blocker_kernel,
            blur_kernel: settings.blur_kernel,
            receiver_plane: u32::from(settings.receiver.receiver_plane),
            alpha: settings.alpha,
            beta: settings.beta,
            normal_offset: settings.bias.normal_offset,
            bilateral_depth: settings.bilateral_depth,
            // Sec. 4.4: exp(-x²/2σ²) at tap offset x in half-widths; exp(0) = 1 for the mean.
            blur_weight_exponent: match settings.filter {
                BlurFilter::Gaussian | BlurFilter::Auto => 0.5 / (settings.sigma.max(1e-3) * settings.sigma.max(1e-3)),
                BlurFilter::Mean => 0.0,
            },
            blur_axes: match settings.blur_axes {
                BlurAxes::Screen => 0,
                BlurAxes::Light => 1,
                BlurAxes::Auto => 2,
            },
            box_along_light: u32::from(settings.filter == BlurFilter::Auto),
        }
    }
}

/// Separable soft shadow mapping.
pub struct SeparableSoftShadowMaps {
    depth_map: LightDepthMap,
    horizontal_blocker: ScreenPass,
    /// Steps 2 and 3, as fragment or compute passes.
    blur_steps: BlurSteps,
    /// Step 1's bind group (the light frame is the screen pass's group 0).
    horizontal_blocker_group: wgpu::BindGroup,
    horizontal_blocker_view: wgpu::TextureView,
    /// Step 1's second target.
    blur_source_view: wgpu::TextureView,
    horizontal_blur_view: wgpu::TextureView,
    /// Step 2's second target (written by the fragment pass as a render target).
    vertical_tap_source_view: wgpu::TextureView,
    reuse: wgpu::Texture,
    /// Step 3's second target (written by the fragment pass as a render target).
    reuse_view: wgpu::TextureView,
    /// Step 2's squared penumbra-width error per pixel, with `penumbra_error`; `None` without.
    penumbra_error: Option<wgpu::Texture>,
    read_counts: ReadCounts,
}

/// Steps 2 and 3 as [`BlurPasses`] says.
enum BlurSteps {
    Fragment {
        blocker_blur: ScreenPass,
        vertical_blur: ScreenPass,
        /// Step 2's and step 3's own bind groups.
        groups: [wgpu::BindGroup; 2],
    },
    SharedRows {
        blocker_blur: wgpu::ComputePipeline,
        vertical_blur: wgpu::ComputePipeline,
        gbuffer_group: wgpu::BindGroup,
        blocker_blur_group: wgpu::BindGroup,
        /// Per light: step 3's group, binding that light's visibility target.
        vertical_blur_groups: Vec<wgpu::BindGroup>,
        width: u32,
        height: u32,
    },
}

/// What `count_reads` counts, in the shaders' order (`record_reads_of`, `record_failed_rows` and
/// `count_failed_row` in sssm_common.wgsl): each pass's texel reads per pixel of the screen, then,
/// per computed pixel, the rows of step 2's blocker search and of step 3's blur that failed their
/// reuse test, by cause (off the screen, no data in the pixel there, a depth difference of α or β
/// or more), then each pass's bytes read (its reads, each texel its format's size: 16 for a
/// G-buffer texel or one of [`SCREEN_TARGET_FORMAT`]'s, 4 for a shadow-map depth).
const COUNTED: &[(&str, &str)] = &[
    ("sssm_horizontal_blocker", "reads"),
    ("sssm_blocker_and_horizontal_blur", "reads"),
    ("sssm_vertical_blur", "reads"),
    ("sssm_blocker_rows_failed_off_screen", "rows"),
    ("sssm_blocker_rows_failed_no_data", "rows"),
    ("sssm_blocker_rows_failed_depth", "rows"),
    ("sssm_blur_rows_failed_off_screen", "rows"),
    ("sssm_blur_rows_failed_no_data", "rows"),
    ("sssm_blur_rows_failed_depth", "rows"),
    ("sssm_horizontal_blocker", "read_bytes"),
    ("sssm_blocker_and_horizontal_blur", "read_bytes"),
    ("sssm_vertical_blur", "read_bytes"),
];

/// The intermediate targets between the three passes.
struct Targets {
    horizontal_blocker: wgpu::TextureView,
    /// Step 1's packed blur source per pixel (normal, eye distance signed by the hard value), read by step 2's blur taps and by step 3 for a pixel's own hard value.
    blur_source: wgpu::TextureView,
    horizontal_blur: wgpu::TextureView,
    /// Step 2's packed vertical tap source per pixel (its horizontal result, eye distance and normal), read by step 3's taps.
    vertical_tap_source: wgpu::TextureView,
    reuse: wgpu::Texture,
    reuse_view: wgpu::TextureView,
    /// Step 2's squared penumbra-width error per pixel (written with `penumbra_error`).
    penumbra_error: wgpu::Texture,
    penumbra_error_view: wgpu::TextureView,
}

impl Targets {
    fn new(device: &wgpu::Device, width: u32, height: u32) -> Self {
        let target = |label: &str, usage: wgpu::TextureUsages| {
            let texture = render_texture(device, label, width, height, SCREEN_TARGET_FORMAT, usage);
            labelled_view(&texture, label)
        };
        // Per-pixel values a pass writes and the CPU reads back.
        let readable = |label: &str| {
            render_texture(
                device,
                label,
                width,
                height,
                wgpu::TextureFormat::R32Float,
                wgpu::TextureUsages::STORAGE_BINDING | wgpu::TextureUsages::COPY_SRC,
            )
        };
        let reuse = readable("sssm_reuse_share");
        let penumbra_error = readable("sssm_penumbra_error");
        Self {
            horizontal_blocker: target("sssm_horizontal_blocker_target", wgpu::TextureUsages::empty()),
            // Step 1's second render target.
            blur_source: target("sssm_blur_source", wgpu::TextureUsages::empty()),
            // Written by step 2's compute pass as a storage texture.
            horizontal_blur: target("sssm_horizontal_blur_target", wgpu::TextureUsages::STORAGE_BINDING),
            // Step 2's second render target, or written by its compute pass as a storage texture.
            vertical_tap_source: target("sssm_vertical_tap_source", wgpu::TextureUsages::STORAGE_BINDING),
            reuse_view: labelled_view(&reuse, "sssm_reuse_share"),
            reuse,
            penumbra_error_view: labelled_view(&penumbra_error, "sssm_penumbra_error"),
            penumbra_error,
        }
    }
}

impl SeparableSoftShadowMaps {
    /// Builds the depth map, the intermediate targets and the three passes.
    ///
    /// # Errors
    /// A parameter or GPU error.
    pub fn new(setup: &TechniqueSetup<'_>) -> Result<Self> {
        let settings = SssmSettings::from_params(setup.params)?;
        let device = &setup.gpu.device;
        let depth_map = settings.bias.depth_map(setup, "sssm_shadow_map", settings.shadow_map_size)?;
        let targets = Targets::new(device, setup.scene.width, setup.scene.height);
        let settings_buffer = uniform_buffer(device, "sssm_settings_uniform", &SssmSettingsUniform::from(&settings));
        // Counting pipelines for count_reads, and for the framework's counting frame (--count-work).
        let read_counts = ReadCounts::with_units(device, "sssm_read_counts", COUNTED, settings.count_reads || setup.count_work);
        let shared = Shared {
            setup,
            settings: &settings_buffer,
            depth_map: &depth_map,
            read_counts: &read_counts,
            measure_penumbra_error: settings.penumbra_error,
            edge_rows: settings.edge_rows,
            targets: &targets,
        };
        let horizontal_blocker_layout = shared.layout("sssm_horizontal_blocker_layout", &[]);
        let horizontal_blocker_group = shared.group("sssm_horizontal_blocker_bind_group", &horizontal_blocker_layout, &[]);
        // Its partial blocker sums and its blur sources, as two render targets.
        let horizontal_blocker = ScreenPass::with_targets(
            setup,
            NAME,
            "sssm_horizontal_blocker",
            (&shared.module("sssm_horizontal_blocker_shader", HORIZONTAL_BLOCKER_SHADER)?, "sssm_horizontal_blocker"),
            Some(&horizontal_blocker_layout),
            &[SCREEN_TARGET_FORMAT.into(), SCREEN_TARGET_FORMAT.into()],
            &shared.constants(),
        )?;
        let blur_steps = match settings.blur_passes {
            BlurPasses::Fragment => shared.fragment_steps()?,
            BlurPasses::SharedRows => shared.shared_row_steps()?,
        };
        Ok(Self {
            depth_map,
            horizontal_blocker,
            blur_steps,
            horizontal_blocker_group,
            horizontal_blocker_view: targets.horizontal_blocker,
            blur_source_view: targets.blur_source,
            horizontal_blur_view: targets.horizontal_blur,
            vertical_tap_source_view: targets.vertical_tap_source,
            reuse: targets.reuse,
            reuse_view: targets.reuse_view,
            penumbra_error: settings.penumbra_error.then_some(targets.penumbra_error),
            read_counts,
        })
    }

    /// Step 2's squared penumbra-width error per pixel (texels²; -1 where no penumbra was
    /// computed), when measured.
    fn penumbra_error(&self, gpu: &GpuContext) -> Result<Option<Vec<f32>>> {
        let Some(texture) = &self.penumbra_error else { return Ok(None) };
        Ok(Some(bytemuck::pod_collect_to_vec(&read_texture(gpu, texture, 4, "SSSM penumbra error")?)))
    }

    /// The reuse share per pixel of the last light rendered (-1 where nothing was computed).
    fn reuse_share(&self, gpu: &GpuContext) -> Result<Vec<f32>> {
        let bytes = read_texture(gpu, &self.reuse, 4, "SSSM reuse share")?;
        Ok(bytemuck::pod_collect_to_vec(&bytes))
    }
}

/// What the three passes' bind groups share (binding 0 camera, 1 settings, 2 depth map, 3 read
/// counts) and their pipelines' constants, and the builders of steps 2 and 3.
struct Shared<'a> {
    setup: &'a TechniqueSetup<'a>,
    settings: &'a wgpu::Buffer,
    depth_map: &'a LightDepthMap,
    read_counts: &'a ReadCounts,
    /// The settings' `penumbra_error` (step 2's `MEASURE_PENUMBRA_ERROR`).
    measure_penumbra_error: bool,
    /// The settings' `edge_rows` (every pass's `CLAMP_EDGE_ROWS`).
    edge_rows: EdgeRows,
    targets: &'a Targets,
}

impl Shared<'_> {
    fn module(&self, label: &str, source: &str) -> Result<wgpu::ShaderModule> {
        create_shader_with_imports(self.setup.gpu, label, source, LOCAL_SHADERS)
    }

    /// Every pass's pipeline constants: whether it counts reads and where it takes the rows past
    /// the screen's edges.
    fn constants(&self) -> [(&'static str, f64); 2] {
        let [count_reads] = self.read_counts.pipeline_constants();
        [count_reads, ("CLAMP_EDGE_ROWS", f64::from(u8::from(self.edge_rows == EdgeRows::Clamp)))]
    }

    /// Step 2's pipeline constants: those of every pass, and whether it measures the penumbra error.
    fn blocker_blur_constants(&self) -> [(&'static str, f64); 3] {
        let [count_reads, edges] = self.constants();
        [count_reads, edges, ("MEASURE_PENUMBRA_ERROR", f64::from(u8::from(self.measure_penumbra_error)))]
    }

    /// A layout of the shared entries and `extra`.
    fn layout(&self, label: &str, extra: &[wgpu::BindGroupLayoutEntry]) -> wgpu::BindGroupLayout {
        let common = [uniform_entry(0), uniform_entry(1), texture_entry(2), ReadCounts::layout_entry(3)];
        let entries: Vec<wgpu::BindGroupLayoutEntry> = common.iter().chain(extra).copied().collect();
        bind_group_layout(&self.setup.gpu.device, label, &entries)
    }

    /// A group of the shared resources (bindings 0 to 3) and `extra` (bindings 4 on).
    fn group(&self, label: &str, layout: &wgpu::BindGroupLayout, extra: &[wgpu::BindingResource<'_>]) -> wgpu::BindGroup {
        let map = wgpu::BindingResource::TextureView(&self.depth_map.linear_depth_view);
        let resources = [
            self.setup.scene.camera_buffer.as_entire_binding(),
            self.settings.as_entire_binding(),
            map,
            self.read_counts.buffer().as_entire_binding(),
        ];
        let entries: Vec<wgpu::BindGroupEntry<'_>> = resources
            .into_iter()
            .chain(extra.iter().cloned())
            .zip(0..)
            .map(|(resource, binding)| wgpu::BindGroupEntry { binding, resource })
            .collect();
        self.setup.gpu.device.create_bind_group(&wgpu::BindGroupDescriptor { label: Some(label), layout, entries: &entries })
    }

    /// Step 2's inputs (bindings 4 and 5): step 1's target and its blur sources.
    fn blocker_blur_inputs(&self) -> [wgpu::BindingResource<'_>; 2] {
        [
            wgpu::BindingResource::TextureView(&self.targets.horizontal_blocker),
            wgpu::BindingResource::TextureView(&self.targets.blur_source),
        ]
    }

    /// Step 2's penumbra-error target, after the entry point's other bindings (6 in the fragment
    /// pass, 7 in the compute pass).
    fn penumbra_error_entry(binding: u32) -> wgpu::BindGroupLayoutEntry {
        write_storage_texture_entry(binding, wgpu::TextureFormat::R32Float)
    }

    /// Step 2's vertical tap sources in the compute pass (the fragment pass renders them).
    fn vertical_tap_source_entry(binding: u32) -> wgpu::BindGroupLayoutEntry {
        write_storage_texture_entry(binding, SCREEN_TARGET_FORMAT)
    }

    /// Step 3's inputs (bindings 4 to 6): step 2's target, step 1's blur sources (for each
    /// pixel's own hard value) and step 2's vertical tap sources.
    fn vertical_inputs(&self) -> [wgpu::BindingResource<'_>; 3] {
        [
            wgpu::BindingResource::TextureView(&self.targets.horizontal_blur),
            wgpu::BindingResource::TextureView(&self.targets.blur_source),
            wgpu::BindingResource::TextureView(&self.targets.vertical_tap_source),
        ]
    }

    fn vertical_entries() -> [wgpu::BindGroupLayoutEntry; 3] {
        [texture_entry(4), texture_entry(5), texture_entry(6)]
    }

    fn fragment_steps(&self) -> Result<BlurSteps> {
        let blocker_blur_layout =
            self.layout("sssm_blocker_blur_layout", &[texture_entry(4), texture_entry(5), Self::penumbra_error_entry(6)]);
        let vertical_blur_layout = self.layout("sssm_vertical_blur_layout", &Self::vertical_entries());
        let groups = [
            self.group(
                "sssm_blocker_blur_bind_group",
                &blocker_blur_layout,
                &[self.blocker_blur_inputs().as_slice(), &[wgpu::BindingResource::TextureView(&self.targets.penumbra_error_view)]].concat(),
            ),
            self.group("sssm_vertical_blur_bind_group", &vertical_blur_layout, &self.vertical_inputs()),
        ];
        // Its horizontal blur and the vertical blur's tap sources, as two render targets.
        let blocker_blur = ScreenPass::with_targets(
            self.setup,
            NAME,
            "sssm_blocker_and_horizontal_blur",
            (&self.module("sssm_blocker_blur_fragment_shader", BLOCKER_BLUR_FRAGMENT_SHADER)?, "sssm_blocker_blur"),
            Some(&blocker_blur_layout),
            &[SCREEN_TARGET_FORMAT.into(), SCREEN_TARGET_FORMAT.into()],
            &self.blocker_blur_constants(),
        )?;
        // The visibility and the reuse share, as two render targets.
        let vertical_blur = ScreenPass::with_targets(
            self.setup,
            NAME,
            "sssm_vertical_blur",
            (&self.module("sssm_vertical_blur_fragment_shader", VERTICAL_BLUR_FRAGMENT_SHADER)?, "sssm_vertical_blur"),
            Some(&vertical_blur_layout),
            &[VISIBILITY_FORMAT.into(), wgpu::TextureFormat::R32Float.into()],
            &self.constants(),
        )?;
        Ok(BlurSteps::Fragment { blocker_blur, vertical_blur, groups })
    }

    fn shared_row_steps(&self) -> Result<BlurSteps> {
        let setup = self.setup;
        let device = &setup.gpu.device;
        let gbuffer = setup.shared.gbuffer(NAME)?;
        let blocker_blur_layout = self.layout(
            "sssm_blocker_blur_rows_layout",
            &[
                texture_entry(4),
                texture_entry(5),
                write_storage_texture_entry(6, SCREEN_TARGET_FORMAT),
                Self::penumbra_error_entry(7),
                Self::vertical_tap_source_entry(8),
            ],
        );
        // What the fragment pass renders: the reuse share and the visibility.
        let mut vertical_entries = Self::vertical_entries().to_vec();
        vertical_entries.push(write_storage_texture_entry(7, wgpu::TextureFormat::R32Float));
        vertical_entries.push(write_storage_texture_entry(8, VISIBILITY_FORMAT));
        let vertical_blur_layout = self.layout("sssm_vertical_blur_columns_layout", &vertical_entries);
        let blocker_blur_group = self.group(
            "sssm_blocker_blur_rows_bind_group",
            &blocker_blur_layout,
            &[
                self.blocker_blur_inputs().as_slice(),
                &[
                    wgpu::BindingResource::TextureView(&self.targets.horizontal_blur),
                    wgpu::BindingResource::TextureView(&self.targets.penumbra_error_view),
                    wgpu::BindingResource::TextureView(&self.targets.vertical_tap_source),
                ],
            ]
            .concat(),
        );
        let vertical_blur_groups = setup
            .outputs
            .iter()
            .enumerate()
            .map(|(light, output)| {
                let mut resources = self.vertical_inputs().to_vec();
                resources.push(wgpu::BindingResource::TextureView(&self.targets.reuse_view));
                resources.push(wgpu::BindingResource::TextureView(output));
                self.group(&format!("sssm_vertical_blur_columns_bind_group_{light}"), &vertical_blur_layout, &resources)
            })
            .collect();
        let blocker_blur = compute_pipeline(
            device,
            "sssm_blocker_blur_rows_pipeline",
            &self.module("sssm_blocker_blur_compute_shader", BLOCKER_BLUR_COMPUTE_SHADER)?,
            "sssm_blocker_blur_rows",
            &[&setup.scene.uniform_layout, &gbuffer.layout, &blocker_blur_layout],
            &self.blocker_blur_constants(),
        );
        let vertical_blur = compute_pipeline(
            device,
            "sssm_vertical_blur_columns_pipeline",
            &self.module("sssm_vertical_blur_compute_shader", VERTICAL_BLUR_COMPUTE_SHADER)?,
            "sssm_vertical_blur_columns",
            &[&setup.scene.uniform_layout, &gbuffer.layout, &vertical_blur_layout],
            &self.constants(),
        );
        let messages = setup.gpu.take_errors();
        if !messages.is_empty() {
            return Err(ssm_core::Error::Gpu { during: "building SSSM's shared-row compute passes".into(), messages });
        }
        Ok(BlurSteps::SharedRows {
            blocker_blur,
            vertical_blur,
            gbuffer_group: gbuffer.bind_group.clone(),
            blocker_blur_group,
            vertical_blur_groups,
            width: setup.scene.width,
            height: setup.scene.height,
        })
    }
}

impl ShadowTechnique for SeparableSoftShadowMaps {
    fn render(&mut self, frame: &mut Frame<'_>, light: usize, output: &wgpu::TextureView) -> Result<()> {
        self.read_counts.clear(frame, light);
        self.depth_map.encode(frame, light);
        self.horizontal_blocker.encode_targets(
            frame,
            light,
            &[&self.horizontal_blocker_view, &self.blur_source_view],
            Some(&self.horizontal_blocker_group),
            Some(wgpu::Color::TRANSPARENT),
        );
        match &self.blur_steps {
            BlurSteps::Fragment { blocker_blur, vertical_blur, groups: [blocker_blur_group, vertical_blur_group] } => {
                blocker_blur.encode_targets(
                    frame,
                    light,
                    &[&self.horizontal_blur_view, &self.vertical_tap_source_view],
                    Some(blocker_blur_group),
                    Some(wgpu::Color::TRANSPARENT),
                );
                vertical_blur.encode_targets(frame, light, &[output, &self.reuse_view], Some(vertical_blur_group), None);
            }
            BlurSteps::SharedRows {
                blocker_blur,
                vertical_blur,
                gbuffer_group,
                blocker_blur_group,
                vertical_blur_groups,
                width,
                height,
            } => {
                let vertical_blur_group = vertical_blur_groups.get(light).ok_or_else(|| ssm_core::Error::Gpu {
                    during: format!("SSSM rendering light {light}"),
                    messages: vec![format!("only {} visibility targets", vertical_blur_groups.len())],
                })?;
                let light_group = &frame.scene.light_bind_groups[light];
                // The same labels as the fragment passes, so the per-pass times line up.
                let steps = [
                    (
                        "sssm_blocker_and_horizontal_blur",
                        blocker_blur,
                        blocker_blur_group,
                        [width.div_ceil(SHARED_SEGMENT_PIXELS), *height],
                    ),
                    ("sssm_vertical_blur", vertical_blur, vertical_blur_group, [height.div_ceil(SHARED_SEGMENT_PIXELS), *width]),
                ];
                for (label, pipeline, group, [x, y]) in steps {
                    let mut pass = frame.compute_pass(label);
                    pass.set_pipeline(pipeline);
                    pass.set_bind_group(0, light_group, &[]);
                    pass.set_bind_group(1, gbuffer_group, &[]);
                    pass.set_bind_group(2, group, &[]);
                    pass.dispatch_workgroups(x, y, 1);
                }
            }
        }
        Ok(())
    }

    /// Each pass's texel reads and invocations (one per pixel of the screen, trivial ones
    /// included), from the counters the shaders keep when built for counting. Reads follow
    /// `ReadCounts`' convention: every `textureLoad` (G-buffer, shadow map, the passes' own
    /// targets) is one texel, at every pixel; a blur tap that reads a shared segment's workgroup
    /// memory is none, the segment's loads are; and the bytes of those reads, each texel its
    /// format's size (`sssm_common.wgsl`'s `*_TEXEL_BYTES`). The failed-row counters (`rows`) are diagnostics,
    /// not work of a pass of their own: `ReadCounts::work` leaves them out.
    fn counted_work(&mut self, gpu: &GpuContext) -> Result<Option<Vec<ShaderWork>>> {
        self.read_counts.work(gpu)
    }

    /// `sssm_reuse_share`: the mean share of rows reused, over the pixels computed (the paper's Fig. 10).
    fn diagnostics(&mut self, gpu: &GpuContext) -> Vec<(String, f64)> {
        let Ok(share) = self.reuse_share(gpu) else { return Vec::new() };
        let computed: Vec<f64> = share.iter().filter(|v| **v >= 0.0).map(|v| f64::from(*v)).collect();
        if computed.is_empty() {
            return Vec::new();
        }
        let mut out = vec![("sssm_reuse_share".to_owned(), computed.iter().sum::<f64>() / computed.len() as f64)];
        out.extend(self.read_counts.diagnostics(gpu));
        if let Ok(Some(errors)) = self.penumbra_error(gpu) {
            // Table 5: the mean over the pixels where either search found a blocker, and over every
            // pixel computed (the reuse share is -1 where nothing was), the lit ones counting 0.
            let measured: Vec<f64> = errors.iter().filter(|v| **v >= 0.0).map(|v| f64::from(*v)).collect();
            if !measured.is_empty() {
                let total: f64 = measured.iter().sum();
                out.push(("sssm_penumbra_mse_texels2".to_owned(), total / measured.len() as f64));
                out.push(("sssm_penumbra_mse_all_texels2".to_owned(), total / computed.len() as f64));
            }
        }
        out
    }

    fn debug_outputs(&mut self, gpu: &GpuContext, requested: &[&str]) -> Result<Vec<ExtraImage>> {
        let (width, height) = (self.reuse.width(), self.reuse.height());
        let mut images = Vec::new();
        if requested.contains(&"reuse_share") {
            let values = self.reuse_share(gpu)?.into_iter().map(|v| v.max(0.0)).collect();
            images.push(ExtraImage { name: "reuse_share".into(), width, height, values, overlay: false });
        }
        if requested.contains(&"penumbra_error") {
            // Zero where not measured: the parameter is off, or no penumbra was computed.
            let values = self
                .penumbra_error(gpu)?
                .map_or_else(|| vec![0.0; (width * height) as usize], |v| v.into_iter().map(|e| e.max(0.0)).collect());
            images.push(ExtraImage { name: "penumbra_error".into(), width, height, values, overlay: false });
        }
        Ok(images)
    }
}

fn create(setup: &TechniqueSetup<'_>) -> Result<Box<dyn ShadowTechnique>> {
    Ok(Box::new(SeparableSoftShadowMaps::new(setup)?))
}

fn requirements(params: &ParamValues) -> Result<Requirements> {
    Ok(screen_space_requirements(SssmSettings::from_params(params)?.shadow_map_size))
}

/// The viewport of Buades et al.'s measurements (Sec. 5: "1,024 × 1,024 shadow maps rendered
/// to a 1,280 × 720 HD viewport"): the image size of the presets that reproduce them.
const PAPER_VIEWPORT: (u32, u32) = (1280, 720);

/// Table 4's own viewport, which its caption gives ("Depth map size is 1,024 × 1,024 and
/// rendering viewport is 1,280 × 960"), unlike Sec. 5's for the others.
const TABLE4_VIEWPORT: (u32, u32) = (1280, 960);

/// Buades et al.'s evaluations, as sweeps.
const PRESETS: &[ssm_core::Preset] = &[
    ssm_core::Preset {
        name: "sssm-table4",
        summary: "Buades et al., Table 4: PCSS and SSSM at kernel pairs 7/15, 11/21, 29/41, SSSM at the table's thresholds (alpha = beta = 0.01, 0.1, 0.15, 0.2, 0.5; 0.1 is the paper's headline, 3.2x PCSS's frame rate at 29/41); both with the receiver-plane model (on leaves, the plant scene's nearest); the rows past the screen's edges recomputed from the depth map, as Sec. 4.1 recomputes a row it cannot reuse; and the pre-filtered VSSM, whose cost does not depend on a kernel. With --count-work, texel reads per frame beside the times (the test sssm_reads_six_times_fewer_texels_than_pcss_at_table_4s_largest_kernels asserts at least 6x fewer than PCSS at 29/41 per pixel)",
        scenes: &["leaves"],
        varies: &[
            "pcss.blocker_kernel:pcf_kernel=7:15,11:21,29:41",
            "sssm.blocker_kernel:blur_kernel=7:15,11:21,29:41",
            "sssm.alpha:beta=0.01:0.01,0.1:0.1,0.15:0.15,0.2:0.2,0.5:0.5",
            "sssm.edge_rows=recompute",
            "vssm",
        ],
        size: Some(TABLE4_VIEWPORT),
        ..ssm_core::Preset::DEFAULT
    },
    ssm_core::Preset {
        name: "sssm-passes",
        summary: "SSSM's steps 2 and 3 as fragment passes and as shared-row compute passes (the same pixels), beside PCSS, at Table 4's kernel pairs with alpha = beta = 0.1 (on leaves): the shared rows read each screen texel once per workgroup instead of once per tap (with count_reads, fewer texel reads; their time is this adapter's)",
        scenes: &["leaves"],
        varies: &[
            "pcss.blocker_kernel:pcf_kernel=7:15,11:21,29:41",
            "sssm.blocker_kernel:blur_kernel=7:15,11:21,29:41",
            "sssm.blur_passes=fragment,shared_rows",
            "sssm.alpha:beta=0.1:0.1",
        ],
        ..ssm_core::Preset::DEFAULT
    },
    ssm_core::Preset {
        name: "sssm-edges",
        summary: "PCSS and SSSM with the blocker and blur rows past the screen's edges clamped to the nearest pixel on the screen (as a clamp-to-edge read would) or recomputed from the depth map (the default, Sec. 4.1), at Table 4's kernel pairs with alpha = beta = 0.1 and Table 4's 1280x960 (on leaves): what exact borders cost (with --count-work, in texel reads) and gain in error",
        scenes: &["leaves"],
        varies: &[
            "pcss.blocker_kernel:pcf_kernel=7:15,11:21,29:41",
            "sssm.blocker_kernel:blur_kernel=7:15,11:21,29:41",
            "sssm.edge_rows=clamp,recompute",
            "sssm.alpha:beta=0.1:0.1",
        ],
        size: Some(TABLE4_VIEWPORT),
        ..ssm_core::Preset::DEFAULT
    },
    ssm_core::Preset {
        name: "sssm-steps",
        summary: "Buades et al., Tables 2 and 3: milliseconds per step (depth map, horizontal blocker, blocker + horizontal blur, vertical blur) at 29/41 as alpha = beta grow, with a 1024² and a 4096² depth map (on leaves; the per-pass times are in sweep.csv's passes_ms; with --count-work, the texel reads fall as alpha = beta grow, the same with either map)",
        scenes: &["leaves"],
        varies: &[
            "sssm.alpha:beta=0:0,0.01:0.01,0.02:0.02,0.05:0.05,0.1:0.1,0.15:0.15,0.2:0.2,0.5:0.5",
            "sssm.shadow_map_size=1024,4096",
            "sssm.blocker_kernel:blur_kernel=29:41",
        ],
        x_axis: "sssm.alpha",
        y_axis: "time",
        size: Some(PAPER_VIEWPORT),
        ..ssm_core::Preset::DEFAULT
    },
    ssm_core::Preset {
        name: "sssm-table5",
        summary: "Buades et al., Table 5: the mean squared error, in shadow-map texels², that reusing rows (alpha) brings into the penumbra width, against every row searched (PCSS's search), for 7, 11 and 29 blocker rows (diagnostic sssm_penumbra_mse_texels2; on leaves)",
        scenes: &["leaves"],
        varies: &["sssm.alpha=0.01,0.1,0.15,0.2,0.5", "sssm.blocker_kernel=7,11,29", "sssm.penumbra_error=true"],
        x_axis: "sssm.alpha",
        size: Some(PAPER_VIEWPORT),
        ..ssm_core::Preset::DEFAULT
    },
    ssm_core::Preset {
        name: "sssm-table6",
        summary: "Buades et al., Table 6: PSNR and SSIM against the ground truth of PCSS and SSSM (several alpha = beta) at 29/41, for the default light and one 2.5 times larger (their 0.04 and 0.10)",
        scenes: &["leaves"],
        varies: &[
            "scene.light_scale=1,2.5",
            "pcss.blocker_kernel:pcf_kernel=29:41",
            "sssm.blocker_kernel:blur_kernel=29:41",
            "sssm.alpha:beta=0.01:0.01,0.1:0.1,0.15:0.15,0.2:0.2,0.5:0.5",
        ],
        size: Some(PAPER_VIEWPORT),
        ..ssm_core::Preset::DEFAULT
    },
    ssm_core::Preset {
        name: "sssm-lights",
        summary: "Buades et al., Fig. 11: a scene lit by 1, 2 and 3 lights of different size and colour (the manifest's first N), SSSM and PCSS; frame time against the lights (run from the workspace's root)",
        scenes: &["ssm-techniques/sssm/scenes/fig11-three-lights.toml"],
        varies: &["scene.lights=1,2,3", "sssm", "pcss"],
        x_axis: "scene.lights",
        y_axis: "time",
        size: Some(PAPER_VIEWPORT),
        ..ssm_core::Preset::DEFAULT
    },
    ssm_core::Preset {
        name: "sssm-filter",
        summary: "Buades et al., Fig. 5: the mean filter against the Gaussian, error against the ground truth at Table 4's kernel pairs (the images: ssm compare with --set sssm.filter=mean)",
        scenes: &["leaves"],
        varies: &["sssm.filter=mean,gaussian", "sssm.blocker_kernel:blur_kernel=7:15,11:21,29:41"],
        size: Some(PAPER_VIEWPORT),
        ..ssm_core::Preset::DEFAULT
    },
];

/// Why the receivers past the light frame's widest angle get the framework's hard shadow (the
/// extremes matrix's light resting on the receiver).
const ONE_FRAME_LIMIT: &str = "past the light frame's widest angle (84 degrees off the light's normal) the framework answers with a hard shadow from the light's centre (counted: pixels_beyond_frame): the separable blocker search runs along the rows, then the columns, of one shadow map, and the paper leaves cube shadow maps to future work (Buades et al. 2015, Sec. 7); a hemicube's side faces are four maps whose rows do not continue across their edges";

/// The registration.
pub const INFO: TechniqueInfo = TechniqueInfo {
    name: NAME,
    summary: "separable soft shadow mapping: separable blocker search reusing rows (α) and separable screen-space blur (β)",
    paper: "Buades, Gumbau and Chover 2015, Separable soft shadow mapping (The Visual Computer)",
    kind: TechniqueKind::Realtime,
    // One view of the light from its centre: the framework adds the own surface's share.
    light_sampling: ssm_core::LightSampling::Centre,
    light_view: ssm_core::LightView::Frame,
    params: SssmSettings::PARAMS,
    requirements,
    create,
    presets: PRESETS,
    trade: Some("blocker_kernel:blur_kernel=3:5,7:15,11:21,29:41"),
    debug_outputs: &[
        DebugOutput {
            name: "reuse_share",
            doc: "the share of blocker and blur rows reused (not recomputed) per pixel, 0 to 1, of the last light; 0 where not computed (the paper's Fig. 10: white reused, black recomputed)",
            overlay: false,
        },
        DebugOutput {
            name: "penumbra_error",
            doc: "with penumbra_error=true, the squared difference between the penumbra width from the reused rows and from every row, shadow-map texels², of the last light (the paper's Table 5); 0 where not measured",
            overlay: false,
        },
    ],
    uniforms: &[UniformCheck {
        wgsl_struct: SssmSettingsUniform::WGSL_NAME,
        wgsl_source: HORIZONTAL_BLOCKER_SHADER,
        imports: LOCAL_SHADERS,
        rust: SssmSettingsUniform::LAYOUT,
    }],
    limits: &[ssm_core::KnownLimit { case: "light resting on the receiver", mean_error: 0.25, reason: ONE_FRAME_LIMIT }],
    paper_configuration: ssm_core::PaperConfiguration {
        // Table 4's headline thresholds, the plain (unweighted) blur, the Gaussian along the
        // screen's rows and columns (Sec. 4.4).
        settings: &["alpha=0.1", "beta=0.1", "bilateral_depth=0", "filter=gaussian", "blur_axes=screen"],
        scenes: &["leaves"],
        truth: &[],
        averaged_over: None,
    },
};

register_technique!(INFO);
