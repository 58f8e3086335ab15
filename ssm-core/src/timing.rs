//! GPU timing: a timestamp pair around every named pass, read back after the frame.

use serde::Serialize;

use crate::context::GpuContext;
use crate::error::{Error, Reason, Result};
use crate::readback::read_buffer;

/// Most timed passes in one frame; later passes run untimed (and are counted in [`FrameTimings::untimed_passes`]).
pub const MAX_TIMED_PASSES: u32 = 2048;

/// The time one pass took.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct PassTiming {
    /// The pass's label.
    pub name: String,
    /// The light it was for.
    pub light: usize,
    /// Milliseconds of GPU time between its begin and end timestamps.
    pub ms: f64,
}

/// Where a frame's times come from.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum TimingSource {
    /// GPU timestamp queries around each pass.
    GpuTimestamps,
    /// The adapter has no timestamps: only the CPU wall time of submit-and-wait is known.
    CpuWallOnly,
}

/// The times of one frame of one technique.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct FrameTimings {
    /// Where the numbers come from.
    pub source: TimingSource,
    /// Each timed pass (empty with [`TimingSource::CpuWallOnly`]).
    pub passes: Vec<PassTiming>,
    /// Sum of the pass times, when timed on the GPU.
    pub gpu_ms: Option<f64>,
    /// CPU wall time from recording to the GPU going idle (includes driver overhead; the
    /// only figure without timestamps).
    pub cpu_wall_ms: f64,
    /// Passes that ran past [`MAX_TIMED_PASSES`] and were not timed.
    pub untimed_passes: u32,
    /// CPU work inside the frame, timed on the CPU: mid-frame readback stalls
    /// and the work a paper puts on the CPU (PVSM's kd-tree). Not in `gpu_ms`.
    pub cpu_scopes: Vec<PassTiming>,
}

impl FrameTimings {
    /// The frame's time: the GPU passes' sum plus the CPU scopes inside the
    /// frame (which stall the GPU), or the CPU wall time without timestamps.
    #[must_use]
    pub fn frame_ms(&self) -> f64 {
        match self.gpu_ms {
            Some(gpu) => gpu + self.cpu_scopes.iter().map(|s| s.ms).sum::<f64>(),
            None => self.cpu_wall_ms,
        }
    }
}

/// Allocates timestamp pairs for passes as they are recorded and turns them into [`PassTiming`]s.
#[derive(Debug)]
pub struct PassTimer {
    queries: Option<TimerQueries>,
    scopes: Vec<(String, usize)>,
    cpu_scopes: Vec<PassTiming>,
    untimed: u32,
    light: usize,
}

#[derive(Debug)]
struct TimerQueries {
    query_set: wgpu::QuerySet,
    resolve_buffer: wgpu::Buffer,
    period_ns: f64,
}

impl PassTimer {
    /// A timer that uses timestamps when the device has them.
    #[must_use]
    pub fn new(gpu: &GpuContext) -> Self {
        let queries = gpu.has_timestamps().then(|| TimerQueries {
            query_set: gpu.device.create_query_set(&wgpu::QuerySetDescriptor {
                label: Some("pass_timer_query_set"),
                ty: wgpu::QueryType::Timestamp,
                count: MAX_TIMED_PASSES * 2,
            }),
            resolve_buffer: gpu.device.create_buffer(&wgpu::BufferDescriptor {
                label: Some("pass_timer_resolve_buffer"),
                size: u64::from(MAX_TIMED_PASSES) * 2 * 8,
                usage: wgpu::BufferUsages::QUERY_RESOLVE | wgpu::BufferUsages::COPY_SRC,
                mapped_at_creation: false,
            }),
            period_ns: f64::from(gpu.queue.get_timestamp_period()),
        });
        Self { queries, scopes: Vec::new(), cpu_scopes: Vec::new(), untimed: 0, light: 0 }
    }

    /// True when passes are timed on the GPU.
    #[must_use]
    pub fn has_timestamps(&self) -> bool {
        self.queries.is_some()
    }

    /// Forgets the last frame's passes.
    pub fn reset(&mut self) {
        self.scopes.clear();
        self.cpu_scopes.clear();
        self.untimed = 0;
    }

    /// Records `ms` of CPU work named `name` for the current light.
    pub fn cpu_scope(&mut self, name: &str, ms: f64) {
        self.cpu_scopes.push(PassTiming { name: name.to_owned(), light: self.light, ms });
    }

    /// The light that subsequent passes belong to.
    pub fn set_light(&mut self, light: usize) {
        self.light = light;
    }

    fn allocate(&mut self, name: &str) -> Option<(&wgpu::QuerySet, u32)> {
        let queries = self.queries.as_ref()?;
        let index = self.scopes.len() as u32;
        if index >= MAX_TIMED_PASSES {
            self.untimed += 1;
            return None;
        }
        self.scopes.push((name.to_owned(), self.light));
        Some((&queries.query_set, index * 2))
    }

    /// Timestamp writes for a render pass called `name`.
    pub fn render_pass(&mut self, name: &str) -> Option<wgpu::RenderPassTimestampWrites<'_>> {
        self.allocate(name).map(|(query_set, first)| wgpu::RenderPassTimestampWrites {
            query_set,
            beginning_of_pass_write_index: Some(first),
            end_of_pass_write_index: Some(first + 1),
        })
    }

    /// Timestamp writes for a compute pass called `name`.
    pub fn compute_pass(&mut self, name: &str) -> Option<wgpu::ComputePassTimestampWrites<'_>> {
        self.allocate(name).map(|(query_set, first)| wgpu::ComputePassTimestampWrites {
            query_set,
            beginning_of_pass_write_index: Some(first),
            end_of_pass_write_index: Some(first + 1),
        })
    }

    /// Records the resolve of this frame's queries; call once, last, in the frame's final encoder.
    pub fn resolve(&self, encoder: &mut wgpu::CommandEncoder) {
        if let Some(queries) = &self.queries
            && !self.scopes.is_empty()
        {
            encoder.resolve_query_set(&queries.query_set, 0..self.scopes.len() as u32 * 2, &queries.resolve_buffer, 0);
        }
    }

    /// Reads the resolved timestamps (after the frame was submitted) into timings.
    ///
    /// # Errors
    /// [`Error::Readback`] if the buffer cannot be mapped.
    pub fn read(&self, gpu: &GpuContext, cpu_wall_ms: f64) -> Result<FrameTimings> {
        let Some(queries) = &self.queries else {
            return Ok(FrameTimings {
                source: TimingSource::CpuWallOnly,
                passes: Vec::new(),
                gpu_ms: None,
                cpu_wall_ms,
                untimed_passes: self.untimed,
                cpu_scopes: self.cpu_scopes.clone(),
            });
        };
        let mut passes = Vec::with_capacity(self.scopes.len());
        if !self.scopes.is_empty() {
            let bytes = read_buffer(gpu, &queries.resolve_buffer, self.scopes.len() as u64 * 16, "pass timestamps")?;
            let stamps: &[u64] = bytemuck::try_cast_slice(&bytes).map_err(|e| Error::readback("pass timestamps", Reason(e.to_string())))?;
            for ((name, light), pair) in self.scopes.iter().zip(stamps.chunks_exact(2)) {
                // Some drivers return an end before the begin for empty passes: count those as zero.
                let ticks = pair[1].saturating_sub(pair[0]);
                passes.push(PassTiming { name: name.clone(), light: *light, ms: ticks as f64 * queries.period_ns * 1e-6 });
            }
        }
        let gpu_ms = Some(passes.iter().map(|p| p.ms).sum());
        Ok(FrameTimings {
            source: TimingSource::GpuTimestamps,
            passes,
            gpu_ms,
            cpu_wall_ms,
            untimed_passes: self.untimed,
            cpu_scopes: self.cpu_scopes.clone(),
        })
    }
}
