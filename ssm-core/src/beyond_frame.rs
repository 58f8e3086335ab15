//! The receivers past the light frame's widest angle, answered by the framework after every
//! technique whose maps see the light through that one frame
//! ([`LightView::Frame`](crate::LightView::Frame)).
//!
//! A perspective frustum cannot reach 90° off its axis: the shared [`LightFrame`] stops at
//! [`MAX_HALF_ANGLE_TANGENT`](crate::MAX_HALF_ANGLE_TANGENT) (about 84°), and a receiver past it
//! has no texel in any of the technique's maps; what the technique writes there is whatever its
//! sampler's clamp finds (a floor beside a light resting on it read 0.75–0.89 where it is lit or
//! umbra). Such receivers are common (under a light on a wall, the floor and the wall near it lie
//! close to 90° off the light's normal), so where a light's frame reached that angle the framework
//! renders the rest of the light's front hemisphere as four side faces around its centre
//! ([`SideFaceMaps`]), and answers every receiver past the frame with a hard shadow from the
//! centre through them (`shaders/core/beyond_frame.wgsl`). The same answer for every such
//! technique: it is not the technique's own method, so the pass counts the pixels it answered and
//! the reports say how many ([`BEYOND_FRAME_DIAGNOSTIC`]). A technique that answers them itself
//! ([`LightView::SideFaces`](crate::LightView::SideFaces)) gets no pass. Lights whose frame stays
//! inside the widest angle get no faces and no pass: their cost and memory are unchanged.
//!
//! [`LightFrame`]: crate::LightFrame

use crate::context::GpuContext;
use crate::error::{Error, Result};
use crate::frame::Frame;
use crate::passes::{
    bind_group, bind_group_layout, compute_pipeline, storage_buffer, storage_entry, texture_entry, uniform_buffer, uniform_entry,
    visibility_storage_entry,
};
use crate::read_counts::ReadCounts;
use crate::shader::create_shader;
use crate::side_faces::{SideFaceFrames, SideFaceMaps};
use crate::technique::TechniqueSetup;
use crate::work::ShaderWork;

/// The pass's name after the technique's: `<technique>_beyond_frame`.
pub const BEYOND_FRAME_PASS: &str = "beyond_frame";

/// The diagnostic that reports how many pixels the framework answered past the frame, summed
/// over the lights, in the last frame.
pub const BEYOND_FRAME_DIAGNOSTIC: &str = "pixels_beyond_frame";

/// Texels of the receiver's own depth change across a side face's texel that its bias allows
/// (`side_face_hard_visibility` in `shaders/common/side_faces.wgsl`: from the receiver's plane, so
/// unclamped at grazing angles).
const SIDE_FACE_RECEIVER_BIAS_TEXELS: f32 = 0.75;

/// What the pass counts in a counting frame, in the order its shader indexes them: its texel reads,
/// the bytes it stores, and the bytes its reads fetched (the G-buffer's Rgba32Float texels, 16
/// bytes each, and a side face's R32Float, 4).
const COUNTERS: &[(&str, &str)] = &[(BEYOND_FRAME_PASS, "reads"), (BEYOND_FRAME_PASS, "storage_bytes"), (BEYOND_FRAME_PASS, "read_bytes")];

/// The label of the beyond-frame pass run after technique `technique`: `<technique>_beyond_frame`.
#[must_use]
pub fn beyond_frame_label(technique: &str) -> String {
    format!("{}_{BEYOND_FRAME_PASS}", technique.replace('-', "_"))
}

/// One light's side faces and the lookup's bindings.
struct LightFaces {
    faces: SideFaceMaps,
    face_frames: SideFaceFrames,
    group: wgpu::BindGroup,
}

/// The pass, built for one technique's visibility targets, for the lights whose frame reached
/// the widest angle.
pub(crate) struct BeyondFrame {
    /// `<technique>_beyond_frame`.
    label: String,
    pipeline: wgpu::ComputePipeline,
    gbuffer_bind_group: wgpu::BindGroup,
    /// Per light: its faces, or `None` where its frame stays inside the widest angle.
    lights: Vec<Option<LightFaces>>,
    /// One counter per light: the pixels answered in the last frame.
    answered: wgpu::Buffer,
    /// The label of the counters' clearing, made once.
    answered_clear_label: String,
    read_counts: ReadCounts,
    width: u32,
    height: u32,
}

impl BeyondFrame {
    /// The pass for `technique`, or `None` when no light's frame reaches the widest angle.
    pub(crate) fn new(setup: &TechniqueSetup<'_>, technique: &str) -> Result<Option<Self>> {
        let scene = setup.scene;
        if !scene.light_frames.iter().any(crate::LightFrame::reaches_widest_angle) {
            return Ok(None);
        }
        let gpu = setup.gpu;
        let device = &gpu.device;
        let label = beyond_frame_label(technique);
        let gbuffer = setup.shared.gbuffer(technique)?;
        let read_counts = ReadCounts::with_units(device, &format!("{label}_read_counts"), COUNTERS, setup.count_work);
        let key = if setup.count_work { "beyond_frame_counting_pipeline" } else { "beyond_frame_pipeline" };
        let constants = read_counts.pipeline_constants();
        let pipeline = gpu.cached_compute_pipeline(key, |gpu| {
            let module = create_shader(gpu, "beyond_frame_shader", ssm_shaders::core::BEYOND_FRAME)?;
            let own_layout = bind_group_layout(
                &gpu.device,
                "beyond_frame_own_layout",
                &[
                    visibility_storage_entry(0),
                    texture_entry(1),
                    texture_entry(2),
                    texture_entry(3),
                    texture_entry(4),
                    storage_entry(5, false),
                    ReadCounts::layout_entry(6),
                    uniform_entry(7),
                ],
            );
            Ok(compute_pipeline(
                &gpu.device,
                key,
                &module,
                "beyond_frame_visibility",
                &[gpu.uniform_layout(), gpu.gbuffer_layout(), &own_layout],
                &constants,
            ))
        })?;
        let own_layout = pipeline.get_bind_group_layout(2);
        let answered = storage_buffer(device, &format!("{label}_answered"), 4 * scene.light_frames.len() as u64);
        let mut lights = Vec::with_capacity(scene.light_frames.len());
        for (light, output) in setup.outputs.iter().enumerate() {
            let Some((faces, face_frames)) = SideFaceMaps::for_light(gpu, scene, light, &label)? else {
                lights.push(None);
                continue;
            };
            let settings = uniform_buffer(
                device,
                &format!("{label}_light{light}_settings"),
                &[light as f32, SIDE_FACE_RECEIVER_BIAS_TEXELS, 0.0, 0.0],
            );
            // The visibility, the four faces, the counters and the settings (bindings 0 to 7).
            let entries: Vec<_> = std::iter::once(wgpu::BindingResource::TextureView(output))
                .chain(faces.bindings())
                .chain([answered.as_entire_binding(), read_counts.buffer().as_entire_binding(), settings.as_entire_binding()])
                .collect();
            let group = bind_group(device, &format!("{label}_light{light}_bind_group"), &own_layout, &entries);
            lights.push(Some(LightFaces { faces, face_frames, group }));
        }
        Ok(Some(Self {
            answered_clear_label: format!("{label}_answered_clear"),
            label,
            pipeline,
            gbuffer_bind_group: gbuffer.bind_group.clone(),
            lights,
            answered,
            read_counts,
            width: scene.width,
            height: scene.height,
        }))
    }

    /// Records the faces and the pass for `light` (nothing where its frame stays inside the widest
    /// angle), after the technique's passes.
    pub(crate) fn encode(&self, frame: &mut Frame<'_>, light: usize) -> Result<()> {
        let Some(faces) = self.lights.get(light).and_then(Option::as_ref) else {
            return Ok(());
        };
        let light_frame = frame
            .scene
            .light_bind_groups
            .get(light)
            .ok_or_else(|| Error::Technique { technique: self.label.clone(), message: format!("no light {light}") })?;
        // The counters sum over the frame's lights: cleared at the first light that has faces
        // (the renderer renders the lights in order).
        if self.lights[..light].iter().all(Option::is_none) {
            frame.clear_buffer(&self.answered_clear_label, &self.answered, 0, None);
            self.read_counts.clear(frame, 0);
        }
        faces.faces.encode(frame, &faces.face_frames);
        let mut pass = frame.compute_pass(&self.label);
        pass.set_pipeline(&self.pipeline);
        pass.set_bind_group(0, light_frame, &[]);
        pass.set_bind_group(1, &self.gbuffer_bind_group, &[]);
        pass.set_bind_group(2, &faces.group, &[]);
        pass.dispatch_workgroups(self.width.div_ceil(8), self.height.div_ceil(8), 1);
        Ok(())
    }

    /// The pixels answered past the frame in the last frame, over every light
    /// ([`BEYOND_FRAME_DIAGNOSTIC`]).
    pub(crate) fn answered_pixels(&self, gpu: &GpuContext) -> Result<u64> {
        let bytes = crate::readback::read_buffer(gpu, &self.answered, self.answered.size(), "pixels answered past the light frame")?;
        Ok(bytes.chunks_exact(4).map(|word| u64::from(u32::from_le_bytes([word[0], word[1], word[2], word[3]]))).sum())
    }

    /// What the pass counted in the last frame, under its label; `None` when not counting.
    pub(crate) fn work(&self, gpu: &GpuContext) -> Result<Option<Vec<ShaderWork>>> {
        let mut work = self.read_counts.work(gpu)?;
        for pass in work.iter_mut().flatten() {
            pass.pass.clone_from(&self.label);
        }
        Ok(work)
    }
}

#[cfg(test)]
mod tests {
    use crate::{GBuffer, LightDepthMap, VISIBILITY_FORMAT};

    /// The shader counts each texel it reads at its format's size (the side faces are
    /// [`LightDepthMap`]s).
    #[test]
    fn the_shaders_texel_bytes_are_the_formats_sizes() {
        let constants = [
            ("GBUFFER_TEXEL_BYTES", GBuffer::POSITION_FORMAT),
            ("GBUFFER_TEXEL_BYTES", GBuffer::NORMAL_FORMAT),
            ("SIDE_FACE_TEXEL_BYTES", LightDepthMap::FORMAT),
            ("VISIBILITY_TEXEL_BYTES", VISIBILITY_FORMAT),
        ];
        let missing = crate::read_counts::missing_texel_byte_constants(ssm_shaders::core::BEYOND_FRAME, &constants);
        assert!(missing.is_empty(), "beyond_frame.wgsl lacks {missing:?}");
    }
}
