//! What the technique allocates for an image size and a casting mesh, checked
//! against a device's limits before anything is allocated, so that what a
//! device cannot hold is a typed error ([`Error::LimitTooLow`]) naming the
//! limit and the largest size that fits, never wgpu's validation text.
//!
//! The per-pixel state that no render target holds (the final buffer's four
//! areas and four rectangles, Sec. 3.2) is split into one storage buffer of
//! one `vec4<f32>` per pixel for the areas and one per radial part's
//! rectangle: 16 bytes per pixel per binding, so 128 MiB bindings hold
//! 8,388,608 pixels (3840 × 2160 is 8,294,400).

use ssm_core::{Error, Result};

use crate::blend::SILHOUETTE_BYTES;
use crate::gpu::WORKGROUP;
use crate::{CastingMesh, NAME, SILHOUETTE_TARGETS, WEDGE_RECORD_BYTES};

/// Bytes per pixel of each final-buffer binding (one `vec4<f32>`).
pub const FINAL_BINDING_BYTES_PER_PIXEL: u64 = 16;
/// Storage buffers bound in one shader stage at most: the silhouette step's compute passes
/// (twelve in the mesh's group and the counters of `--count-work`, the indirect arguments in another).
pub const STORAGE_BUFFERS_PER_STAGE: u32 = 14;

/// What one storage buffer holds: `units` of `bytes_per_unit` each, and what a unit is.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct PlannedBuffer {
    /// The buffer's label.
    pub label: &'static str,
    /// What it holds one record per (`"pixel"`, `"half-edge"`, `"face"` ...).
    pub unit: &'static str,
    /// How many.
    pub units: u64,
    /// Bytes per record.
    pub bytes_per_unit: u64,
}

impl PlannedBuffer {
    /// Its size in bytes.
    #[must_use]
    pub fn bytes(&self) -> u64 {
        self.units * self.bytes_per_unit
    }
}

/// The sizes the technique allocates for a `width` × `height` view and a casting mesh.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct AllocationPlan {
    /// The view's width, pixels.
    pub width: u32,
    /// The view's height, pixels.
    pub height: u32,
    /// Casting faces.
    pub faces: u64,
    /// Every storage buffer, each bound whole.
    pub buffers: Vec<PlannedBuffer>,
}

impl AllocationPlan {
    /// The plan for a `width` × `height` view and `mesh` (`None`: nothing casts).
    #[must_use]
    pub fn new(width: u32, height: u32, mesh: Option<&CastingMesh>) -> Self {
        let pixels = u64::from(width) * u64::from(height);
        let per_pixel = |label, bytes_per_unit| PlannedBuffer { label, unit: "pixel", units: pixels, bytes_per_unit };
        let mut buffers = vec![
            per_pixel("wedges_final_areas", FINAL_BINDING_BYTES_PER_PIXEL),
            per_pixel("wedges_final_rectangles_0", FINAL_BINDING_BYTES_PER_PIXEL),
            per_pixel("wedges_final_rectangles_1", FINAL_BINDING_BYTES_PER_PIXEL),
            per_pixel("wedges_final_rectangles_2", FINAL_BINDING_BYTES_PER_PIXEL),
            per_pixel("wedges_final_rectangles_3", FINAL_BINDING_BYTES_PER_PIXEL),
            per_pixel("wedges_fragment_counts", 4),
        ];
        let faces = mesh.map_or(0, |m| m.faces.len() as u64);
        if let Some(mesh) = mesh {
            let buffer = |label, unit, units: u64, bytes_per_unit| PlannedBuffer { label, unit, units, bytes_per_unit };
            let records = mesh.records.len() as u64;
            buffers.extend([
                buffer("wedges_half_edges", "half-edge", u64::from(mesh.half_edge_capacity), WEDGE_RECORD_BYTES),
                buffer("wedges_positions", "vertex", mesh.positions.len() as u64, 16),
                buffer("wedges_faces", "face", faces, 16),
                buffer("wedges_edge_records", "edge record", records, std::mem::size_of::<crate::EdgeRecord>() as u64),
                buffer("wedges_face_state", "face", faces, 4),
                buffer("wedges_region_labels", "face", faces, 4),
                buffer("wedges_region_ranks", "face", faces, 4),
                buffer("wedges_cap_faces", "face", faces, 4),
                buffer("wedges_component_winding", "closed component", mesh.report.closed_components() as u64, 4),
                buffer("wedges_component_convex", "closed component", mesh.report.closed_components() as u64, 4),
            ]);
        }
        Self { width, height, faces, buffers }
    }

    /// Checks the plan against `limits`.
    ///
    /// # Errors
    /// [`Error::LimitTooLow`] for the first thing that does not fit, naming the limit and the
    /// largest size that would.
    pub fn check(&self, limits: &wgpu::Limits) -> Result<()> {
        let too_low = |what: String, allowed: String| Err(Error::LimitTooLow { technique: NAME.into(), what, allowed });
        if limits.max_color_attachments < SILHOUETTE_TARGETS as u32 || limits.max_color_attachment_bytes_per_sample < SILHOUETTE_BYTES {
            return too_low(
                format!("{SILHOUETTE_TARGETS} float colour targets ({SILHOUETTE_BYTES} bytes per sample) for the silhouette buffer"),
                format!(
                    "max_color_attachments = {} and max_color_attachment_bytes_per_sample = {}",
                    limits.max_color_attachments, limits.max_color_attachment_bytes_per_sample
                ),
            );
        }
        if limits.max_storage_buffers_per_shader_stage < STORAGE_BUFFERS_PER_STAGE {
            return too_low(
                format!("{STORAGE_BUFFERS_PER_STAGE} storage buffers in one shader stage (the silhouette step)"),
                format!("max_storage_buffers_per_shader_stage = {}", limits.max_storage_buffers_per_shader_stage),
            );
        }
        let side = self.width.max(self.height);
        if side > limits.max_texture_dimension_2d {
            return too_low(
                format!("{}×{} render targets", self.width, self.height),
                format!("max_texture_dimension_2d = {}", limits.max_texture_dimension_2d),
            );
        }
        let groups = self.faces.div_ceil(u64::from(WORKGROUP));
        if groups > u64::from(limits.max_compute_workgroups_per_dimension) {
            return too_low(
                format!("{groups} workgroups of {WORKGROUP} for {} casting faces", self.faces),
                format!(
                    "max_compute_workgroups_per_dimension = {}: at most {} faces",
                    limits.max_compute_workgroups_per_dimension,
                    u64::from(limits.max_compute_workgroups_per_dimension) * u64::from(WORKGROUP)
                ),
            );
        }
        // Every buffer is bound whole: the binding limit and the buffer limit both apply.
        let (binding, limit_name) = if limits.max_storage_buffer_binding_size <= limits.max_buffer_size {
            (limits.max_storage_buffer_binding_size, "max_storage_buffer_binding_size")
        } else {
            (limits.max_buffer_size, "max_buffer_size")
        };
        for buffer in &self.buffers {
            if buffer.bytes() <= binding {
                continue;
            }
            let fitting = binding / buffer.bytes_per_unit;
            let largest = if buffer.unit == "pixel" {
                let (width, height) = largest_view(fitting, self.width, self.height);
                format!("{fitting} pixels ({width}×{height} at this aspect ratio)")
            } else {
                format!("{fitting} {}s", buffer.unit)
            };
            return too_low(
                format!(
                    "a storage buffer `{}` of {} bytes ({} {}s of {} bytes, {}×{} view, {} casting faces)",
                    buffer.label,
                    buffer.bytes(),
                    buffer.units,
                    buffer.unit,
                    buffer.bytes_per_unit,
                    self.width,
                    self.height,
                    self.faces
                ),
                format!("{limit_name} = {binding} bytes: at most {largest}"),
            );
        }
        Ok(())
    }
}

/// The largest view of about `width`:`height` with at most `pixels` pixels.
fn largest_view(pixels: u64, width: u32, height: u32) -> (u64, u64) {
    let aspect = f64::from(width.max(1)) / f64::from(height.max(1));
    let mut h = ((pixels as f64 / aspect).sqrt().floor() as u64).max(1);
    let mut w = ((h as f64 * aspect).floor() as u64).max(1);
    while w * h > pixels && h > 1 {
        h -= 1;
        w = ((h as f64 * aspect).floor() as u64).max(1);
    }
    (w, h)
}

#[cfg(test)]
mod tests {
    #![allow(clippy::unwrap_used)]

    use super::*;

    /// lavapipe's limits where they bind (Mesa 22.3.6: 128 MiB storage bindings, 2 GiB buffers,
    /// 32 storage buffers per stage, 128 bytes per sample).
    fn lavapipe() -> wgpu::Limits {
        wgpu::Limits {
            max_storage_buffer_binding_size: 1 << 27,
            max_buffer_size: (1 << 31) - 1,
            max_storage_buffers_per_shader_stage: 32,
            max_color_attachment_bytes_per_sample: 128,
            max_texture_dimension_2d: 16384,
            ..wgpu::Limits::default()
        }
    }

    fn sphere_cube() -> CastingMesh {
        let scene = crate::scenes::sphere_cube(5, 20, 20);
        let mut mesh = ssm_scene::Mesh::default();
        for instance in scene.instances.iter().filter(|i| i.role != ssm_scene::Role::Receiver) {
            let part = &scene.meshes[instance.mesh];
            let offset = mesh.positions.len() as u32;
            mesh.positions.extend(part.positions.iter().map(|p| instance.transform.transform_point3(*p)));
            mesh.normals.extend(&part.normals);
            mesh.indices.extend(part.indices.iter().map(|i| i + offset));
        }
        CastingMesh::prepare(&ssm_scene::Adjacency::of(&mesh))
    }

    /// 80 bytes per pixel in one binding (the final buffer before the split) did not fit
    /// 1920 × 1080 in 128 MiB; 16 per binding fits 3840 × 2160.
    #[test]
    fn full_hd_and_4k_fit_lavapipe_limits() {
        let mesh = sphere_cube();
        for (width, height) in [(1920, 1080), (3840, 2160)] {
            let plan = AllocationPlan::new(width, height, Some(&mesh));
            plan.check(&lavapipe()).unwrap();
            let largest = plan.buffers.iter().filter(|b| b.unit == "pixel").map(PlannedBuffer::bytes).max().unwrap();
            assert_eq!(largest, u64::from(width) * u64::from(height) * 16);
        }
        assert_eq!(3840 * 2160 * FINAL_BINDING_BYTES_PER_PIXEL, 132_710_400, "under 134,217,728");
    }

    #[test]
    fn a_view_too_large_for_the_bindings_is_a_typed_error_naming_the_limit_and_what_fits() {
        let limits = wgpu::Limits { max_storage_buffer_binding_size: 1 << 24, ..lavapipe() };
        let error = AllocationPlan::new(1920, 1080, None).check(&limits).unwrap_err();
        let Error::LimitTooLow { technique, what, allowed } = &error else { panic!("{error}") };
        println!("{error}");
        assert_eq!(technique, NAME);
        assert!(what.contains("33177600 bytes") && what.contains("1920×1080"), "{what}");
        // 16 MiB / 16 bytes = 1,048,576 pixels: 1365 × 768 at 16:9 (1,048,320).
        assert!(allowed.contains("max_storage_buffer_binding_size = 16777216") && allowed.contains("1048576 pixels"), "{allowed}");
        assert!(allowed.contains("1365×768"), "{allowed}");
        // The buffer limit binds when it is the smaller.
        let limits = wgpu::Limits { max_buffer_size: 1 << 20, ..lavapipe() };
        let error = AllocationPlan::new(1920, 1080, None).check(&limits).unwrap_err();
        assert!(error.to_string().contains("max_buffer_size = 1048576"), "{error}");
    }

    #[test]
    fn a_mesh_too_large_for_the_silhouette_list_names_the_half_edges_that_fit() {
        let mesh = sphere_cube();
        let plan = AllocationPlan::new(320, 240, Some(&mesh));
        let needed = plan.buffers.iter().find(|b| b.label == "wedges_half_edges").unwrap().bytes();
        // 125 spheres of 760 closed triangles: 3 half-edges per triangle, 96 bytes each.
        assert_eq!(needed, 125 * 760 * 3 * 96);
        let limits = wgpu::Limits { max_storage_buffer_binding_size: needed - 1, ..lavapipe() };
        let error = plan.check(&limits).unwrap_err().to_string();
        println!("{error}");
        assert!(error.contains("wedges_half_edges") && error.contains(&format!("at most {} half-edges", (needed - 1) / 96)), "{error}");
    }

    /// The sizes of a closed mesh of `faces` triangles (`faces` even): 3/2 edges per face, each
    /// paired (two half-edges), and by Euler's formula faces / 2 + 2 vertices.
    fn closed_mesh_sizes(faces: usize) -> CastingMesh {
        CastingMesh {
            positions: vec![[0.0; 4]; faces / 2 + 2],
            faces: vec![[0; 4]; faces],
            records: vec![crate::EdgeRecord { v0: 0, v1: 0, face_a: 0, face_b: 0, face_b_winds_forward: 0 }; faces * 3 / 2],
            closed_convex: vec![1],
            half_edge_capacity: (faces * 3) as u32,
            report: crate::MeshReport { faces, components: 1, ..crate::MeshReport::default() },
        }
    }

    /// lavapipe's 128 MiB bindings hold 2^27 / 288 = 466,033 closed triangles' silhouette list
    /// (three half-edges of 96 bytes each), and 2^27 / 16 = 8,388,608 pixels (the README's figures).
    #[test]
    fn lavapipe_holds_466_033_closed_triangles() {
        let fits = AllocationPlan::new(320, 240, Some(&closed_mesh_sizes(466_032)));
        fits.check(&lavapipe()).unwrap();
        let error = AllocationPlan::new(320, 240, Some(&closed_mesh_sizes(466_034))).check(&lavapipe()).unwrap_err().to_string();
        assert!(error.contains("wedges_half_edges") && error.contains("at most 1398101 half-edges"), "{error}");
        assert_eq!((1u64 << 27) / (3 * WEDGE_RECORD_BYTES), 466_033);
        let pixels = (1u64 << 27) / FINAL_BINDING_BYTES_PER_PIXEL;
        assert_eq!(pixels, 8_388_608);
    }

    #[test]
    fn too_few_storage_buffers_or_colour_bytes_are_typed_errors() {
        let error = AllocationPlan::new(64, 64, None).check(&wgpu::Limits::default()).unwrap_err().to_string();
        // WebGPU's defaults: 8 storage buffers per stage, 32 bytes per sample.
        assert!(error.contains("max_color_attachment_bytes_per_sample = 32"), "{error}");
        let limits = wgpu::Limits { max_storage_buffers_per_shader_stage: 8, ..lavapipe() };
        let error = AllocationPlan::new(64, 64, None).check(&limits).unwrap_err().to_string();
        assert!(error.contains("max_storage_buffers_per_shader_stage = 8"), "{error}");
        let limits = wgpu::Limits { max_texture_dimension_2d: 2048, ..lavapipe() };
        let error = AllocationPlan::new(3840, 2160, None).check(&limits).unwrap_err().to_string();
        assert!(error.contains("max_texture_dimension_2d = 2048"), "{error}");
    }

    #[test]
    fn the_largest_view_keeps_the_aspect_ratio_within_the_pixels() {
        assert_eq!(largest_view(1_048_576, 1920, 1080), (1365, 768));
        assert_eq!(largest_view(8_388_608, 3840, 2160), (3861, 2172));
        for (pixels, w, h) in [(100, 16, 9), (1, 1920, 1080), (5_000_000, 1000, 1000)] {
            let (fw, fh) = largest_view(pixels, w, h);
            assert!(fw * fh <= pixels, "{fw}×{fh} > {pixels}");
        }
    }
}
