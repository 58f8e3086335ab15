//! Test support for ssm: what every technique crate's tests and the
//! cross-crate tests share, so that none of them writes it again.
//!
//! - [`gpu`]: the GPU context; a missing adapter fails the test (a silently
//!   skipped GPU test proves nothing, and CI has lavapipe).
//! - [`render`]: a technique with settings on a scene, light 0's visibility
//!   read back and checked finite and in [0, 1].
//! - [`parallel_square_exact`] and [`Rendered::parallel_square_exact`]: the
//!   analytic case and its exact visibility at the rendered pixels;
//!   [`penumbra_mask`] the pixels strictly inside a penumbra.
//! - [`error_against_reference`]: a technique's error against the ray-traced
//!   ground truth on the same pixels.
//! - [`compare_with_reference`]: image comparison with a tolerance, writing
//!   `-actual` and `-diff` images on failure; a missing reference image
//!   fails unless blessed (`SSM_BLESS=1`).
//!
//! # Example
//!
//! A technique's penumbra against the analytic visibility of `parallel-square` (here the ground
//! truth, which this crate can reach without a technique crate):
//!
//! ```
//! # fn main() -> Result<(), Box<dyn std::error::Error>> {
//! let gpu = ssm_testing::gpu();
//! ssm_core::reference::link();
//! let info = ssm_core::Registry::global()?.get("reference")?;
//! let scene = ssm_scene::builtin("parallel-square")?.build();
//! let rendered = ssm_testing::render(&gpu, &scene, info, &[("samples", "8"), ("cache", "false")], 48, 48)?;
//! let exact = rendered.parallel_square_exact();
//! let penumbra = ssm_testing::penumbra_mask(&exact);
//! let error = ssm_testing::mean_abs_difference(&rendered.visibility, &exact, &penumbra);
//! assert!(error < 0.05, "8x8 stratified rays per pixel: {error}");
//! # Ok(())
//! # }
//! ```

use glam::Vec3;
use ssm_core::metrics::{ErrorMetrics, compare};
use ssm_core::{GpuContext, Renderer, Requirements, TechniqueInfo};
use ssm_scene::Scene;

/// The GPU context. A missing adapter fails the test with the install hint.
///
/// # Panics
/// When no adapter can be found: in CI there must be one (lavapipe).
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
    technique: &'static TechniqueInfo,
    settings: &[(&str, &str)],
    width: u32,
    height: u32,
) -> ssm_core::Result<Rendered> {
    let params = technique.params_from(settings.iter().copied())?;
    let needs = technique.needs(&params)?.union(Requirements { gbuffer: true, ..Requirements::NONE });
    let mut renderer = Renderer::new(gpu, scene, width, height, &needs)?;
    let mut instance = renderer.create_technique(technique, &params)?;
    renderer.render(instance.as_mut(), technique.name)?;
    let visibility = renderer.read_visibility(0, technique.name)?;
    Ok(Rendered { renderer, visibility })
}

/// The ground truth of `scene` with `samples`² rays per pixel, uncached (tests trace afresh).
///
/// # Panics
/// If tracing fails.
#[must_use]
pub fn reference(gpu: &GpuContext, scene: &Scene, samples: u32, (width, height): (u32, u32)) -> Rendered {
    let samples = samples.to_string();
    render(gpu, scene, &ssm_core::reference::INFO, &[("samples", &samples), ("cache", "false")], width, height)
        .unwrap_or_else(|e| panic!("reference: {e}"))
}

/// Error metrics of `technique` with `settings` against a `samples`²-ray ground truth on
/// `scene`, over the pixels a surface covers.
///
/// # Panics
/// If rendering fails.
#[must_use]
pub fn error_against_reference(
    scene: &Scene,
    technique: &'static TechniqueInfo,
    settings: &[(&str, &str)],
    samples: u32,
    size: (u32, u32),
) -> ErrorMetrics {
    let gpu = gpu();
    let truth = reference(&gpu, scene, samples, size);
    let rendered = render(&gpu, scene, technique, settings, size.0, size.1).unwrap_or_else(|e| panic!("{}: {e}", technique.name));
    compare(&truth.visibility, &rendered.visibility, &rendered.coverage(), size.0 as usize, size.1 as usize)
}

impl Rendered {
    /// Which pixels a surface covers.
    ///
    /// # Panics
    /// If the positions cannot be read back.
    #[must_use]
    pub fn coverage(&self) -> Vec<bool> {
        self.renderer.read_positions().unwrap_or_else(|e| panic!("{e}")).iter().map(|p| p[3] > 0.5).collect()
    }

    /// Which pixels show a surface with the receiver role.
    ///
    /// # Panics
    /// If the normals cannot be read back.
    #[must_use]
    pub fn receivers(&self) -> Vec<bool> {
        self.renderer
            .read_normals()
            .unwrap_or_else(|e| panic!("{e}"))
            .iter()
            .map(|n| ssm_core::GBuffer::flags(n[3]) & ssm_core::GBuffer::RECEIVES != 0)
            .collect()
    }

    /// Light 0's visibility at the pixels that geometry covers (background left out).
    #[must_use]
    pub fn covered_visibility(&self) -> Vec<f32> {
        self.visibility.iter().zip(self.coverage()).filter(|(_, c)| *c).map(|(v, _)| *v).collect()
    }

    /// The exact visibility of `parallel-square` at every pixel: on the ground (y = 0) from
    /// [`parallel_square_exact`], 1 elsewhere (the occluder's top sees all the light, the background reads 1).
    ///
    /// # Panics
    /// If the positions cannot be read back.
    #[must_use]
    pub fn parallel_square_exact(&self) -> Vec<f32> {
        self.renderer
            .read_positions()
            .unwrap_or_else(|e| panic!("{e}"))
            .iter()
            .map(|p| if p[3] > 0.5 && p[1].abs() < 1e-3 { parallel_square_exact(p[0], p[2]) } else { 1.0 })
            .collect()
    }
}

/// The pixel (column, row) where the camera sees world point `world`.
#[must_use]
pub fn pixel_of(scene: &Scene, width: u32, height: u32, world: Vec3) -> (u32, u32) {
    let view_proj = scene.camera.projection(width as f32 / height as f32) * scene.camera.view();
    let ndc = view_proj.project_point3(world);
    let x = ((ndc.x * 0.5 + 0.5) * width as f32).floor().clamp(0.0, width as f32 - 1.0);
    let y = ((0.5 - ndc.y * 0.5) * height as f32).floor().clamp(0.0, height as f32 - 1.0);
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

/// The pixels strictly inside a penumbra of `exact` (visibility between 0.02 and 0.98).
#[must_use]
pub fn penumbra_mask(exact: &[f32]) -> Vec<bool> {
    exact.iter().map(|v| *v > 0.02 && *v < 0.98).collect()
}

/// Mean of `|a - b|` over the pixels `mask` selects (0 when none is).
#[must_use]
pub fn mean_abs_difference(a: &[f32], b: &[f32], mask: &[bool]) -> f32 {
    let selected: Vec<f32> = a.iter().zip(b).zip(mask).filter(|(_, m)| **m).map(|((x, y), _)| (x - y).abs()).collect();
    if selected.is_empty() { 0.0 } else { selected.iter().sum::<f32>() / selected.len() as f32 }
}

/// A scene from manifest text, for tests that build their own.
///
/// # Panics
/// If the text is not a valid manifest.
#[must_use]
pub fn scene_from_manifest(text: &str) -> Scene {
    let origin = std::path::Path::new("inline.toml");
    ssm_scene::Manifest::parse(text, origin)
        .and_then(|manifest| manifest.build(origin, std::path::Path::new(".")))
        .unwrap_or_else(|e| panic!("{e}"))
}
/// Environment variable that (re)writes reference images instead of comparing.
pub const BLESS_VARIABLE: &str = "SSM_BLESS";

/// Tolerances of an image comparison.
#[derive(Clone, Copy, Debug)]
pub struct ImageTolerance {
    /// Largest mean absolute difference.
    pub mean: f32,
    /// A pixel differing by more than this counts as wrong...
    pub pixel: f32,
    /// ...and at most this share of pixels may be wrong (edges rasterise slightly differently across drivers).
    pub wrong_share: f32,
}

/// True when the run was asked to (re)write references (`SSM_BLESS=1`).
#[must_use]
pub fn bless_requested() -> bool {
    std::env::var_os(BLESS_VARIABLE).is_some_and(|v| v == "1")
}

/// Compares single-channel `values` in [0, 1] (row-major, `width` × `height`) with
/// the 16-bit PNG reference `<directory>/<name>.png`.
///
/// With `bless` the reference is written instead. A missing reference fails.
/// On failure, `<name>-actual.png` and `<name>-diff.png` (red where the image
/// is darker than the reference, blue where lighter) are written beside the
/// reference, and the error says where.
///
/// # Errors
/// A message describing the mismatch.
pub fn compare_with_reference(
    directory: &std::path::Path,
    name: &str,
    values: &[f32],
    (width, height): (u32, u32),
    tolerance: ImageTolerance,
    bless: bool,
) -> Result<(), String> {
    let reference_path = directory.join(format!("{name}.png"));
    let to_png = |values: &[f32]| {
        let pixels: Vec<u16> = values.iter().map(|v| (v.clamp(0.0, 1.0) * 65535.0).round() as u16).collect();
        image::ImageBuffer::<image::Luma<u16>, _>::from_raw(width, height, pixels)
    };
    let Some(actual) = to_png(values) else {
        return Err(format!("{name}: {} values for {width}x{height}", values.len()));
    };
    if bless {
        std::fs::create_dir_all(directory).map_err(|e| e.to_string())?;
        return actual.save(&reference_path).map_err(|e| format!("{}: {e}", reference_path.display()));
    }
    let reference = match image::open(&reference_path) {
        Ok(image) => image.into_luma16(),
        Err(e) => {
            return Err(format!("{}: {e}; render it with {BLESS_VARIABLE}=1 and review it before committing", reference_path.display()));
        }
    };
    if reference.dimensions() != (width, height) {
        return Err(format!("{name}: reference is {:?}, image is {width}x{height}", reference.dimensions()));
    }
    let differences: Vec<f32> =
        actual.pixels().zip(reference.pixels()).map(|(a, r)| (f32::from(a.0[0]) - f32::from(r.0[0])) / 65535.0).collect();
    let mean = differences.iter().map(|d| d.abs()).sum::<f32>() / differences.len() as f32;
    let wrong_share = differences.iter().filter(|d| d.abs() > tolerance.pixel).count() as f32 / differences.len() as f32;
    if mean <= tolerance.mean && wrong_share <= tolerance.wrong_share {
        return Ok(());
    }
    let actual_path = directory.join(format!("{name}-actual.png"));
    let diff_path = directory.join(format!("{name}-diff.png"));
    let _ = actual.save(&actual_path);
    let diff = image::RgbImage::from_fn(width, height, |x, y| {
        let d = differences[(y * width + x) as usize];
        let strength = (d.abs() * 4.0).min(1.0) * 255.0;
        // Red: darker than the reference (more shadow); blue: lighter.
        if d < 0.0 { image::Rgb([strength as u8, 0, 0]) } else { image::Rgb([0, 0, strength as u8]) }
    });
    let _ = diff.save(&diff_path);
    Err(format!(
        "{name}: mean difference {mean:.5} (allowed {}), {:.3}% of pixels off by more than {} (allowed {:.3}%); wrote {} and {}",
        tolerance.mean,
        wrong_share * 100.0,
        tolerance.pixel,
        tolerance.wrong_share * 100.0,
        actual_path.display(),
        diff_path.display()
    ))
}

/// Renders every built-in scene with `info` at `width` × `height` and checks that each casts a
/// shadow on a lit receiver: more than 50 pixels below 0.5, and more lit pixels than shadowed ones.
///
/// # Panics
/// Naming the first scene that fails to render or to cast its shadow.
pub fn every_builtin_scene_casts_a_shadow(gpu: &GpuContext, info: &'static TechniqueInfo, width: u32, height: u32) {
    for entry in ssm_scene::BUILTIN_SCENES {
        let rendered = render(gpu, &entry.build(), info, &[], width, height).unwrap_or_else(|e| panic!("{}: {e}", entry.name));
        let shadowed = rendered.visibility.iter().filter(|v| **v < 0.5).count();
        let lit = rendered.visibility.iter().filter(|v| **v > 0.5).count();
        assert!(shadowed > 50, "{} / {}: only {shadowed} shadowed pixels", info.name, entry.name);
        assert!(lit > shadowed, "{} / {}: {lit} lit vs {shadowed} shadowed", info.name, entry.name);
    }
}
