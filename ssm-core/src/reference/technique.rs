//! The ground truth as the `reference` technique: its name, parameters and registration, and the
//! technique itself, which traces each light's image on the CPU once (through the cache unless
//! `cache = false`), uploads it, and copies it into the target every frame, with its noise as a
//! debug output.

use std::path::PathBuf;

use super::{GroundTruth, ReferenceImage, Sampling, SurfacePoint, Traversal, default_cache_dir, surface_points};

/// The registered name of the ground truth.
pub const NAME: &str = "reference";

/// Parameters of the `reference` technique.
pub const PARAMS: &[crate::ParamSpec] = &[
    crate::ParamSpec {
        name: "samples",
        kind: crate::ParamKind::Int { default: 12, min: 1, max: 256 },
        doc: "light samples per axis (N): two independent sets of N×N stratified, jittered shadow rays per pixel, whose difference is the noise reported",
    },
    crate::ParamSpec {
        name: "refine",
        kind: crate::ParamKind::Int { default: 2, min: 1, max: 16 },
        doc: "rays per axis (M) in a stratum where the visibility varies (its result in the other set differs from a neighbour's): M×M instead of one; 1 = plain stratified sampling",
    },
    crate::ParamSpec { name: "seed", kind: crate::ParamKind::Int { default: 1, min: 0, max: i64::MAX }, doc: "seed of the jitter" },
    crate::ParamSpec {
        name: "cache",
        kind: crate::ParamKind::Bool { default: true },
        doc: "read and write the on-disk cache (SSM_CACHE_DIR, else ~/.cache/ssm)",
    },
    crate::ParamSpec {
        name: "traversal",
        kind: crate::ParamKind::Choice { default: "shortcuts", options: <Traversal as crate::Choice>::OPTIONS },
        doc: "how rays are traced, with the same answer ray for ray: shortcuts (each pixel's pyramid to the light gathered from the BVH once, cut into quarters where it holds many triangles) or per_ray (every ray through the BVH, the definition: to time the shortcuts against, with cache = false)",
    },
    crate::ParamSpec {
        name: "footprint",
        kind: crate::ParamKind::Choice { default: "centre", options: &["centre", "pixel"] },
        doc: "where each pixel is sampled: at the G-buffer's point (centre), or over the pixel's footprint on the point's tangent plane (pixel: the prefiltered visibility that anti-aliasing aims at)",
    },
];

/// The ground truth as a technique: traces on the CPU, uploads, copies into the target.
struct ReferenceTechnique {
    truth: GroundTruth,
    sampling: Sampling,
    seed: u64,
    cache_dir: Option<PathBuf>,
    /// The G-buffer's points, read once: the scene and camera are static.
    points: Option<Vec<Option<SurfacePoint>>>,
    /// Whether each point carries its pixel's footprint (`footprint = pixel`).
    pixel_footprint: bool,
    /// One texture and bind group per light: an upload is recorded on the queue
    /// before the frame's commands run, so lights sharing one texture would all
    /// read the last light's upload.
    traced: Vec<(wgpu::Texture, wgpu::BindGroup)>,
    upload: crate::ScreenPass,
    /// Each light's traced image, kept: the scene and camera are static, so later frames only copy it into the target.
    traced_per_light: Vec<Option<ReferenceImage>>,
    /// The view's width and height.
    size: (u32, u32),
}

impl ReferenceTechnique {
    fn points(&mut self, frame: &crate::Frame<'_>) -> crate::Result<&[Option<SurfacePoint>]> {
        if self.points.is_none() {
            let gbuffer = frame.shared.gbuffer(NAME)?;
            let positions = crate::readback::read_texture(frame.gpu, &gbuffer.position, 16, "G-buffer positions")?;
            let normals = crate::readback::read_texture(frame.gpu, &gbuffer.normal, 16, "G-buffer normals")?;
            let positions: Vec<[f32; 4]> = bytemuck::pod_collect_to_vec(&positions);
            let normals: Vec<[f32; 4]> = bytemuck::pod_collect_to_vec(&normals);
            self.points = Some(surface_points(&positions, &normals, &frame.scene.camera, self.pixel_footprint));
        }
        Ok(self.points.as_deref().unwrap_or_default())
    }
}

impl crate::ShadowTechnique for ReferenceTechnique {
    fn render(&mut self, frame: &mut crate::Frame<'_>, light: usize, output: &wgpu::TextureView) -> crate::Result<()> {
        let rect = frame
            .scene
            .light_frames
            .get(light)
            .map(|f| f.light)
            .ok_or_else(|| crate::Error::Technique { technique: NAME.into(), message: format!("no light {light}") })?;
        let (traced, traced_group) = self
            .traced
            .get(light)
            .cloned()
            .ok_or_else(|| crate::Error::Technique { technique: NAME.into(), message: format!("no light {light}") })?;
        if self.traced_per_light.len() <= light {
            self.traced_per_light.resize(light + 1, None);
        }
        if self.traced_per_light[light].is_none() {
            let (samples, seed) = (self.sampling, self.seed);
            let cache_dir = self.cache_dir.clone();
            let points = self.points(frame)?.to_vec();
            let image = match &cache_dir {
                Some(dir) => self.truth.trace_cached(&rect, &points, samples, seed, dir),
                None => self.truth.trace(&rect, &points, samples, seed),
            };
            // Uploaded once, into this light's own texture: the scene and camera are static.
            let (width, height) = (traced.width(), traced.height());
            frame.gpu.queue.write_texture(
                traced.as_image_copy(),
                bytemuck::cast_slice(&image.visibility),
                wgpu::TexelCopyBufferLayout { offset: 0, bytes_per_row: Some(width * 4), rows_per_image: Some(height) },
                wgpu::Extent3d { width, height, depth_or_array_layers: 1 },
            );
            self.traced_per_light[light] = Some(image);
        }
        self.upload.encode(frame, light, output, Some(&traced_group), None);
        Ok(())
    }

    /// The noise of light 0 as `truth_noise`, and of light k as `truth_noise-light<k>`.
    fn debug_outputs(&mut self, _gpu: &crate::GpuContext, requested: &[&str]) -> crate::Result<Vec<crate::ExtraImage>> {
        if !requested.contains(&NOISE_OUTPUT) {
            return Ok(Vec::new());
        }
        let (width, height) = self.size;
        Ok(self
            .traced_per_light
            .iter()
            .enumerate()
            .filter_map(|(light, image)| {
                let image = image.as_ref()?;
                let name = if light == 0 { NOISE_OUTPUT.to_owned() } else { format!("{NOISE_OUTPUT}-light{light}") };
                Some(crate::ExtraImage { name, width, height, values: image.noise.clone(), overlay: false })
            })
            .collect())
    }

    /// Totals over the lights traced so far: rays, trace time, rays per second, and how many came from the cache.
    fn diagnostics(&mut self, _gpu: &crate::GpuContext) -> Vec<(String, f64)> {
        let images: Vec<&ReferenceImage> = self.traced_per_light.iter().flatten().collect();
        if images.is_empty() {
            return Vec::new();
        }
        let rays: u64 = images.iter().map(|i| i.rays).sum();
        let seconds: f64 = images.iter().map(|i| i.elapsed.as_secs_f64()).sum();
        let mut out = vec![
            ("reference_lights_from_cache".to_owned(), images.iter().filter(|i| i.cached).count() as f64),
            ("reference_rays".to_owned(), rays as f64),
            ("reference_trace_ms".to_owned(), seconds * 1e3),
        ];
        if rays > 0 && seconds > 0.0 {
            out.push(("reference_rays_per_second".to_owned(), rays as f64 / seconds));
        }
        out
    }
}

fn create(setup: &crate::TechniqueSetup<'_>) -> crate::Result<Box<dyn crate::ShadowTechnique>> {
    let params = setup.params;
    let device = &setup.gpu.device;
    let (width, height) = (setup.scene.width, setup.scene.height);
    let layout = setup.gpu.texture_layout();
    let traced = (0..setup.scene.light_count())
        .map(|light| {
            let label = format!("reference_traced_light{light}");
            let texture =
                crate::passes::render_texture(device, &label, width, height, crate::VISIBILITY_FORMAT, wgpu::TextureUsages::COPY_DST);
            let view = crate::passes::labelled_view(&texture, &label);
            let group = device.create_bind_group(&wgpu::BindGroupDescriptor {
                label: Some(&format!("{label}_bind_group")),
                layout,
                entries: &[wgpu::BindGroupEntry { binding: 0, resource: wgpu::BindingResource::TextureView(&view) }],
            });
            (texture, group)
        })
        .collect();
    let module = crate::shader::create_shader(setup.gpu, "reference_upload_shader", ssm_shaders::core::REFERENCE_UPLOAD)?;
    let upload = crate::ScreenPass::new(
        setup,
        NAME,
        "reference_upload",
        (&module, "reference_upload"),
        Some(layout),
        crate::VISIBILITY_FORMAT.into(),
        &[],
    )?;
    Ok(Box::new(ReferenceTechnique {
        truth: GroundTruth::new(setup.cpu_scene).with_traversal(
            <Traversal as crate::Choice>::from_name(params.choice("traversal")?).ok_or(crate::ParamError::WrongType {
                technique: NAME.into(),
                name: "traversal".into(),
                wanted: "Traversal",
            })?,
        ),
        sampling: Sampling {
            samples_per_axis: u32::try_from(params.int("samples")?).unwrap_or(Sampling::DEFAULT.samples_per_axis),
            refine: u32::try_from(params.int("refine")?).unwrap_or(Sampling::DEFAULT.refine),
        },
        seed: u64::try_from(params.int("seed")?).unwrap_or(1),
        cache_dir: params.bool("cache")?.then(default_cache_dir),
        points: None,
        pixel_footprint: params.choice("footprint")? == "pixel",
        traced,
        upload,
        traced_per_light: Vec::new(),
        size: (width, height),
    }))
}

/// The registration of the ground truth.
pub const INFO: crate::TechniqueInfo = crate::TechniqueInfo {
    name: NAME,
    summary: "ground truth: two independent sets of N×N stratified jittered shadow rays per pixel, refined where the visibility varies, on the CPU (CWBVH, all cores), cached on disk, with its own noise per pixel",
    paper: "Monte Carlo estimate of the visible fraction of the light (stratified sampling, refined where the visibility varies)",
    kind: crate::TechniqueKind::GroundTruth,
    // Rays to points all over the light, blocked behind a closed surface (SurfacePoint::closed).
    light_sampling: crate::LightSampling::PerSample,
    light_view: crate::LightView::Hemisphere,
    params: PARAMS,
    requirements: |_| Ok(crate::Requirements { gbuffer: true, ..crate::Requirements::NONE }),
    create,
    presets: &[],
    trade: None,
    debug_outputs: &[crate::DebugOutput { name: NOISE_OUTPUT, doc: NOISE_DOC, overlay: false }],
    uniforms: &[],
    limits: &[],
    paper_configuration: crate::PaperConfiguration::DEFAULTS,
};

/// The debug output holding the ground truth's own error per pixel ([`ReferenceImage::noise`]);
/// every command that measures errors asks for it.
pub const NOISE_OUTPUT: &str = "truth_noise";

const NOISE_DOC: &str = "the ground truth's own error per pixel, |A − B|/2 of its two independent estimates (visibility units): its mean over pixels estimates the truth's mean absolute error there";

crate::register_technique!(INFO);
