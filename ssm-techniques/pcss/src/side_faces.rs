//! PCSS past the light frame's widest angle: its blocker search and filter on the side face of a
//! hemicube around the light's centre that a receiver lies in (`shaders/pcss/pcss_side_faces.wgsl`),
//! for the lights whose frame reached that angle ([`ssm_core::LightView::SideFaces`]).

use bytemuck::{Pod, Zeroable};
use ssm_core::passes::{
    bind_group, bind_group_layout, compute_pipeline, texture_entry, uniform_buffer, uniform_entry, visibility_storage_entry,
};
use ssm_core::read_counts::ReadCounts;
use ssm_core::shader::create_shader;
use ssm_core::{Frame, GpuContext, Result, SideFaceFrames, SideFaceMaps, TechniqueSetup, UniformStruct};

use crate::PcssSettings;

/// The label of the pass, and of its read counts.
pub const SIDE_FACES_PASS: &str = "pcss_side_faces";

/// What the pass counts in a counting frame, in the order its shader indexes them: texel reads,
/// bytes stored, and the bytes the reads fetched.
const COUNTERS: &[(&str, &str)] = &[(SIDE_FACES_PASS, "reads"), (SIDE_FACES_PASS, "storage_bytes"), (SIDE_FACES_PASS, "read_bytes")];

/// A tap is a blocker where it is nearer the light's centre than the receiver's tangent plane by
/// more than this share of the plane's depth (the maps' own bias is a hundred-thousandth of the
/// scene's diagonal): the plane is read on the ray through the tap's texel centre, where the map
/// holds the receiver's own surface, so what is left is rounding and curvature.
const RELATIVE_BIAS: f32 = 1e-3;

/// The uniform of `shaders/pcss/pcss_side_faces.wgsl`.
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable, UniformStruct)]
pub struct PcssSideFaceSettings {
    /// Samples per axis of the blocker search (n).
    pub blocker_kernel: u32,
    /// Samples per axis of the filter (m).
    pub pcf_kernel: u32,
    /// The faces' near plane, depth along each face's axis.
    pub near: f32,
    /// Relative depth bias of a tap against the receiver's plane.
    pub relative_bias: f32,
}

/// One light's faces and the pass's bindings.
struct LightFaces {
    faces: SideFaceMaps,
    face_frames: SideFaceFrames,
    group: wgpu::BindGroup,
}

/// The side faces and the pass, for the lights whose frame reaches the widest angle.
pub struct SideFaces {
    pipeline: wgpu::ComputePipeline,
    gbuffer_bind_group: wgpu::BindGroup,
    /// Per light: its faces, or `None` where its frame stays inside the widest angle.
    lights: Vec<Option<LightFaces>>,
    read_counts: ReadCounts,
    width: u32,
    height: u32,
}

impl SideFaces {
    /// The faces and the pass, or `None` when no light's frame reaches the widest angle: a scene
    /// inside it keeps PCSS's cost and memory.
    ///
    /// # Errors
    /// A GPU or shader error.
    pub fn new(setup: &TechniqueSetup<'_>, settings: &PcssSettings) -> Result<Option<Self>> {
        let scene = setup.scene;
        if !scene.light_frames.iter().any(ssm_core::LightFrame::reaches_widest_angle) {
            return Ok(None);
        }
        let gpu = setup.gpu;
        let device = &gpu.device;
        let gbuffer = setup.shared.gbuffer(crate::NAME)?;
        let read_counts = ReadCounts::with_units(device, "pcss_side_faces_read_counts", COUNTERS, settings.count_reads || setup.count_work);
        let module = create_shader(gpu, "pcss_side_faces_shader", ssm_shaders::pcss::PCSS_SIDE_FACES)?;
        let own_layout = bind_group_layout(
            device,
            "pcss_side_faces_layout",
            &[
                visibility_storage_entry(0),
                texture_entry(1),
                texture_entry(2),
                texture_entry(3),
                texture_entry(4),
                ReadCounts::layout_entry(5),
                uniform_entry(6),
            ],
        );
        let pipeline = compute_pipeline(
            device,
            "pcss_side_faces_pipeline",
            &module,
            "pcss_side_faces",
            &[&scene.uniform_layout, &gbuffer.layout, &own_layout],
            &read_counts.pipeline_constants(),
        );
        let mut lights = Vec::with_capacity(scene.light_frames.len());
        for (light, output) in setup.outputs.iter().enumerate() {
            let Some((faces, face_frames)) = SideFaceMaps::for_light(gpu, scene, light, crate::NAME)? else {
                lights.push(None);
                continue;
            };
            let near = scene.light_frames[light].side_face_uniform(0).projection[2];
            let uniform = PcssSideFaceSettings {
                blocker_kernel: settings.blocker_kernel,
                pcf_kernel: settings.pcf_kernel,
                near,
                relative_bias: RELATIVE_BIAS,
            };
            let settings_buffer = uniform_buffer(device, &format!("pcss_side_faces_light{light}_settings"), &uniform);
            // The visibility, the four faces, the counters and the settings (bindings 0 to 6).
            let entries: Vec<_> = std::iter::once(wgpu::BindingResource::TextureView(output))
                .chain(faces.bindings())
                .chain([read_counts.buffer().as_entire_binding(), settings_buffer.as_entire_binding()])
                .collect();
            let group = bind_group(device, &format!("pcss_side_faces_light{light}_bind_group"), &own_layout, &entries);
            lights.push(Some(LightFaces { faces, face_frames, group }));
        }
        Ok(Some(Self {
            pipeline,
            gbuffer_bind_group: gbuffer.bind_group.clone(),
            lights,
            read_counts,
            width: scene.width,
            height: scene.height,
        }))
    }

    /// Records light `light`'s faces and the pass (nothing where its frame stays inside the
    /// widest angle), after PCSS's pass in the frame.
    pub fn encode(&self, frame: &mut Frame<'_>, light: usize) {
        self.read_counts.clear(frame, light);
        let Some(faces) = self.lights.get(light).and_then(Option::as_ref) else {
            return;
        };
        faces.faces.encode(frame, &faces.face_frames);
        let light_group = &frame.scene.light_bind_groups[light];
        let mut pass = frame.compute_pass(SIDE_FACES_PASS);
        pass.set_pipeline(&self.pipeline);
        pass.set_bind_group(0, light_group, &[]);
        pass.set_bind_group(1, &self.gbuffer_bind_group, &[]);
        pass.set_bind_group(2, &faces.group, &[]);
        pass.dispatch_workgroups(self.width.div_ceil(8), self.height.div_ceil(8), 1);
    }

    /// What the pass counted in the last frame; `None` when not counting.
    ///
    /// # Errors
    /// A readback error.
    pub fn work(&self, gpu: &GpuContext) -> Result<Option<Vec<ssm_core::ShaderWork>>> {
        self.read_counts.work(gpu)
    }
}
