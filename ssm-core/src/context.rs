//! The GPU context: instance, adapter, device and queue, with the optional
//! features this adapter offers negotiated once.

use std::collections::HashMap;
use std::sync::{Arc, Mutex};

use crate::passes::{texture_entry, uniform_entry};

/// Optional device features ssm asks for when the adapter has them.
///
/// Techniques declare the ones they cannot do without in their
/// [`Requirements`](crate::Requirements); the rest are used when present
/// (timestamps for per-pass timing, for instance).
pub const OPTIONAL_FEATURES: wgpu::Features = wgpu::Features::FLOAT32_BLENDABLE
    .union(wgpu::Features::FLOAT32_FILTERABLE)
    .union(wgpu::Features::TIMESTAMP_QUERY)
    .union(wgpu::Features::PIPELINE_STATISTICS_QUERY)
    .union(wgpu::Features::SHADER_F16)
    .union(wgpu::Features::CONSERVATIVE_RASTERIZATION)
    .union(wgpu::Features::DEPTH32FLOAT_STENCIL8)
    .union(wgpu::Features::DEPTH_CLIP_CONTROL)
    .union(wgpu::Features::POLYGON_MODE_LINE)
    // `--count-work`: wedges forces its wedge fragments' depth test before the shader that counts
    // them (a side effect would otherwise move the test after it, and more fragments would run).
    .union(wgpu::Features::SHADER_EARLY_DEPTH_TEST);

/// Why no GPU context could be made.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum ContextError {
    /// No adapter at all: neither a GPU nor a software rasteriser.
    #[error(
        "no graphics adapter found ({source}). ssm needs Vulkan: on a machine without a GPU install Mesa's software driver \
         with `sudo apt-get install mesa-vulkan-drivers` (Debian/Ubuntu), then check with `vulkaninfo --summary`"
    )]
    NoAdapter {
        /// What wgpu said.
        #[source]
        source: wgpu::RequestAdapterError,
    },
    /// No surface could be made for a window (`ssm view`).
    #[error("no drawing surface could be made for the window ({source}); is a display (X11 or Wayland) available?")]
    NoSurface {
        /// What wgpu said.
        #[source]
        source: wgpu::CreateSurfaceError,
    },
    /// The adapter refused to make a device.
    #[error("the adapter `{adapter}` could not create a device")]
    NoDevice {
        /// Adapter name.
        adapter: String,
        /// What wgpu said.
        #[source]
        source: wgpu::RequestDeviceError,
    },
}

/// The instance, adapter, device and queue every pass is recorded with.
///
/// wgpu reports validation errors asynchronously; this context captures them
/// instead of letting wgpu panic, and [`GpuContext::take_errors`] hands them
/// to the caller, which turns them into typed errors.
#[derive(Clone, Debug)]
pub struct GpuContext {
    /// The wgpu instance.
    pub instance: wgpu::Instance,
    /// The adapter in use.
    pub adapter: wgpu::Adapter,
    /// The device.
    pub device: wgpu::Device,
    /// Its queue.
    pub queue: wgpu::Queue,
    /// The adapter's description.
    pub info: wgpu::AdapterInfo,
    errors: Arc<Mutex<Vec<String>>>,
    shared: Arc<SharedObjects>,
}

/// GPU objects every renderer and technique on one device shares, made once:
/// the common bind group layouts and the pipelines of the shared passes.
#[derive(Debug)]
struct SharedObjects {
    uniform_layout: wgpu::BindGroupLayout,
    gbuffer_layout: wgpu::BindGroupLayout,
    texture_layout: wgpu::BindGroupLayout,
    render_pipelines: Mutex<HashMap<String, wgpu::RenderPipeline>>,
    compute_pipelines: Mutex<HashMap<String, wgpu::ComputePipeline>>,
}

impl SharedObjects {
    fn new(device: &wgpu::Device) -> Self {
        Self {
            uniform_layout: device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
                label: Some("shared_uniform_layout"),
                entries: &[uniform_entry(0)],
            }),
            gbuffer_layout: device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
                label: Some("gbuffer_layout"),
                entries: &[texture_entry(0), texture_entry(1)],
            }),
            texture_layout: device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
                label: Some("shared_texture_layout"),
                entries: &[texture_entry(0)],
            }),
            render_pipelines: Mutex::new(HashMap::new()),
            compute_pipelines: Mutex::new(HashMap::new()),
        }
    }
}

impl GpuContext {
    /// A headless context on the best adapter: a hardware one when present,
    /// otherwise the software one (lavapipe). `WGPU_BACKEND` and `WGPU_ADAPTER_NAME`
    /// select another, as in wgpu's own tools.
    ///
    /// # Errors
    /// [`ContextError::NoAdapter`] with the command that installs Mesa's software
    /// driver; [`ContextError::NoDevice`] if the adapter refuses.
    pub fn new() -> Result<Self, ContextError> {
        let instance = wgpu::Instance::new(wgpu::InstanceDescriptor::new_without_display_handle_from_env());
        Self::on_instance(instance, None)
    }

    /// A context whose adapter can present to `window` (a window handle such
    /// as winit's `Arc<Window>`), with the surface made for it: what a live
    /// viewer draws into. Adapter selection is as in [`GpuContext::new`].
    ///
    /// # Errors
    /// [`ContextError::NoSurface`] if no surface can be made for the window, else as [`GpuContext::new`].
    pub fn for_window<'w>(window: impl Into<wgpu::SurfaceTarget<'w>>) -> Result<(Self, wgpu::Surface<'w>), ContextError> {
        let instance = wgpu::Instance::new(wgpu::InstanceDescriptor::new_without_display_handle_from_env());
        let surface = instance.create_surface(window).map_err(|source| ContextError::NoSurface { source })?;
        let context = Self::on_instance(instance, Some(&surface))?;
        Ok((context, surface))
    }

    fn on_instance(instance: wgpu::Instance, surface: Option<&wgpu::Surface<'_>>) -> Result<Self, ContextError> {
        let adapter = pollster::block_on(wgpu::util::initialize_adapter_from_env_or_default(&instance, surface))
            .map_err(|source| ContextError::NoAdapter { source })?;
        let info = adapter.get_info();
        let features = adapter.features() & OPTIONAL_FEATURES;
        let descriptor = wgpu::DeviceDescriptor {
            label: Some("ssm_device"),
            required_features: features,
            // Take whatever the adapter allows: shadow maps of 8192² and large storage buffers are normal here.
            required_limits: adapter.limits(),
            experimental_features: wgpu::ExperimentalFeatures::disabled(),
            memory_hints: wgpu::MemoryHints::Performance,
            trace: wgpu::Trace::Off,
        };
        let (device, queue) = pollster::block_on(adapter.request_device(&descriptor))
            .map_err(|source| ContextError::NoDevice { adapter: info.name.clone(), source })?;
        let errors = Arc::new(Mutex::new(Vec::new()));
        let sink = Arc::clone(&errors);
        device.on_uncaptured_error(Arc::new(move |error: wgpu::Error| {
            if let Ok(mut list) = sink.lock() {
                list.push(error.to_string());
            }
        }));
        let shared = Arc::new(SharedObjects::new(&device));
        Ok(Self { instance, adapter, device, queue, info, errors, shared })
    }

    /// The layout of a bind group holding one uniform buffer at binding 0,
    /// visible to every stage: the camera's and each light frame's.
    #[must_use]
    pub fn uniform_layout(&self) -> &wgpu::BindGroupLayout {
        &self.shared.uniform_layout
    }

    /// The layout of the G-buffer's bind group: world position (binding 0)
    /// and normal (binding 1), as `common/screen_pass.wgsl` declares them.
    #[must_use]
    pub fn gbuffer_layout(&self) -> &wgpu::BindGroupLayout {
        &self.shared.gbuffer_layout
    }

    /// The layout of a bind group holding one unfilterable float 2D texture at binding 0.
    #[must_use]
    pub fn texture_layout(&self) -> &wgpu::BindGroupLayout {
        &self.shared.texture_layout
    }

    /// The render pipeline cached under `key`, built by `build` the first time
    /// it is asked for on this device: the shared passes (light depth maps,
    /// G-buffer, composite) compile their shaders once however many renderers
    /// and techniques use them.
    ///
    /// # Errors
    /// Whatever `build` returns.
    pub fn cached_render_pipeline(
        &self,
        key: &str,
        build: impl FnOnce(&Self) -> crate::Result<wgpu::RenderPipeline>,
    ) -> crate::Result<wgpu::RenderPipeline> {
        self.cached(&self.shared.render_pipelines, key, build)
    }

    /// The compute pipeline cached under `key`, built by `build` the first time it is asked for
    /// on this device, as [`GpuContext::cached_render_pipeline`] (the framework's own-surface
    /// share, run after every technique that samples the light from its centre).
    ///
    /// # Errors
    /// Whatever `build` returns.
    pub fn cached_compute_pipeline(
        &self,
        key: &str,
        build: impl FnOnce(&Self) -> crate::Result<wgpu::ComputePipeline>,
    ) -> crate::Result<wgpu::ComputePipeline> {
        self.cached(&self.shared.compute_pipelines, key, build)
    }

    /// The pipeline cached in `cache` under `key`, built by `build` the first time (a cache that
    /// cannot be locked is passed by: the pipeline is built and not kept).
    fn cached<P: Clone>(
        &self,
        cache: &Mutex<HashMap<String, P>>,
        key: &str,
        build: impl FnOnce(&Self) -> crate::Result<P>,
    ) -> crate::Result<P> {
        if let Some(pipeline) = cache.lock().ok().and_then(|cache| cache.get(key).cloned()) {
            return Ok(pipeline);
        }
        let pipeline = build(self)?;
        if let Ok(mut cache) = cache.lock() {
            cache.insert(key.to_owned(), pipeline.clone());
        }
        Ok(pipeline)
    }

    /// The features the device was created with.
    #[must_use]
    pub fn features(&self) -> wgpu::Features {
        self.device.features()
    }

    /// True when each pass's invocations can be counted on the GPU (`ssm --count-work`).
    #[must_use]
    pub fn has_pipeline_statistics(&self) -> bool {
        self.features().contains(wgpu::Features::PIPELINE_STATISTICS_QUERY)
    }

    /// True when passes can be timed on the GPU.
    #[must_use]
    pub fn has_timestamps(&self) -> bool {
        self.features().contains(wgpu::Features::TIMESTAMP_QUERY)
    }

    /// One line naming the adapter, its driver and backend, e.g. `llvmpipe (LLVM 15.0.6, 256 bits) [Vulkan Cpu, Mesa 22.3.6]`.
    #[must_use]
    pub fn describe(&self) -> String {
        let i = &self.info;
        format!("{} [{:?} {:?}, {} {}]", i.name, i.backend, i.device_type, i.driver, i.driver_info)
    }

    /// Errors wgpu reported since the last call, oldest first.
    #[must_use]
    pub fn take_errors(&self) -> Vec<String> {
        self.errors.lock().map(|mut list| std::mem::take(&mut *list)).unwrap_or_default()
    }

    /// GPU memory held by live buffers and textures, bytes (wgpu's allocation counters: the
    /// memory bound to them, whatever the backend's allocator rounds up to).
    #[must_use]
    pub fn allocated_bytes(&self) -> i64 {
        let counters = self.device.get_internal_counters();
        (counters.hal.buffer_memory.read() + counters.hal.texture_memory.read()) as i64
    }

    /// Blocks until the GPU has finished everything submitted so far.
    ///
    /// # Errors
    /// The poll error as text (device lost, timeout).
    pub fn wait_idle(&self) -> Result<(), String> {
        self.device.poll(wgpu::PollType::Wait { submission_index: None, timeout: None }).map(|_| ()).map_err(|e| e.to_string())
    }
}
