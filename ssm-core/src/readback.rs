//! Copying GPU buffers and textures back to the CPU.

use crate::context::GpuContext;
use crate::error::{Error, Reason, Result};

/// Maps `size` bytes of a `COPY_SRC` buffer through a staging buffer and returns them.
///
/// # Errors
/// [`Error::Readback`] if mapping fails or the device is lost.
pub fn read_buffer(gpu: &GpuContext, source: &wgpu::Buffer, size: u64, what: &str) -> Result<Vec<u8>> {
    let staging = gpu.device.create_buffer(&wgpu::BufferDescriptor {
        label: Some("readback_staging_buffer"),
        size,
        usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
        mapped_at_creation: false,
    });
    let mut encoder = gpu.device.create_command_encoder(&wgpu::CommandEncoderDescriptor { label: Some("readback_encoder") });
    encoder.copy_buffer_to_buffer(source, 0, &staging, 0, size);
    gpu.queue.submit([encoder.finish()]);
    map_and_read(gpu, &staging, what)
}

/// Waits for the GPU, maps a whole `MAP_READ` buffer, copies its bytes out and unmaps it.
///
/// # Errors
/// [`Error::Readback`] if mapping fails or the device is lost.
pub fn map_and_read(gpu: &GpuContext, staging: &wgpu::Buffer, what: &str) -> Result<Vec<u8>> {
    let (sender, receiver) = std::sync::mpsc::channel();
    staging.map_async(wgpu::MapMode::Read, .., move |result| {
        // The receiver outlives the wait below; a send failure only means nobody listens any more.
        let _ = sender.send(result);
    });
    gpu.wait_idle().map_err(|e| Error::readback(what, Reason(e)))?;
    receiver.recv().map_err(|e| Error::readback(what, e))?.map_err(|e| Error::readback(what, e))?;
    let bytes = staging.get_mapped_range(..).map_err(|e| Error::readback(what, e))?.to_vec();
    staging.unmap();
    Ok(bytes)
}

/// Reads a whole 2D texture of `bytes_per_pixel` bytes per texel, rows tightly packed.
///
/// # Errors
/// [`Error::Readback`] if mapping fails.
pub fn read_texture(gpu: &GpuContext, texture: &wgpu::Texture, bytes_per_pixel: u32, what: &str) -> Result<Vec<u8>> {
    let (width, height) = (texture.width(), texture.height());
    let row = width * bytes_per_pixel;
    // Copies need rows padded to 256 bytes.
    let padded_row = row.div_ceil(wgpu::COPY_BYTES_PER_ROW_ALIGNMENT) * wgpu::COPY_BYTES_PER_ROW_ALIGNMENT;
    let staging = gpu.device.create_buffer(&wgpu::BufferDescriptor {
        label: Some("readback_texture_staging_buffer"),
        size: u64::from(padded_row) * u64::from(height),
        usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
        mapped_at_creation: false,
    });
    let mut encoder = gpu.device.create_command_encoder(&wgpu::CommandEncoderDescriptor { label: Some("readback_texture_encoder") });
    encoder.copy_texture_to_buffer(
        wgpu::TexelCopyTextureInfo { texture, mip_level: 0, origin: wgpu::Origin3d::ZERO, aspect: wgpu::TextureAspect::All },
        wgpu::TexelCopyBufferInfo {
            buffer: &staging,
            layout: wgpu::TexelCopyBufferLayout { offset: 0, bytes_per_row: Some(padded_row), rows_per_image: Some(height) },
        },
        wgpu::Extent3d { width, height, depth_or_array_layers: 1 },
    );
    gpu.queue.submit([encoder.finish()]);
    let padded = map_and_read(gpu, &staging, what)?;
    let mut packed = Vec::with_capacity((row * height) as usize);
    for y in 0..height as usize {
        let start = y * padded_row as usize;
        packed.extend_from_slice(&padded[start..start + row as usize]);
    }
    Ok(packed)
}
