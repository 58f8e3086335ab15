//! Writing images: visibility as 32-bit float OpenEXR and 16-bit PNG, shaded
//! images as 8-bit sRGB PNG, world positions as OpenEXR.

use std::path::Path;

use exr::prelude::{AnyChannel, AnyChannels, Encoding, FlatSamples, Image, Layer, LayerAttributes, SmallVec, WritableImage};

use crate::error::{Error, Result};

fn write_error(file: &Path, message: impl std::fmt::Display) -> Error {
    Error::Write { file: file.into(), message: message.to_string() }
}

fn check_len(file: &Path, len: usize, width: u32, height: u32, channels: usize) -> Result<()> {
    if len == width as usize * height as usize * channels {
        Ok(())
    } else {
        Err(write_error(file, format!("{len} values for a {width}x{height} image of {channels} channels")))
    }
}

/// Writes a single-channel float image (channel `Y`) as lossless OpenEXR.
///
/// # Errors
/// [`Error::Write`] naming the file.
pub fn write_exr_gray(file: &Path, width: u32, height: u32, values: &[f32]) -> Result<()> {
    check_len(file, values.len(), width, height, 1)?;
    let mut channels: SmallVec<[AnyChannel<FlatSamples>; 4]> = SmallVec::new();
    channels.push(AnyChannel::new("Y", FlatSamples::F32(values.to_vec())));
    let layer = Layer::new(
        (width as usize, height as usize),
        LayerAttributes::named("visibility"),
        Encoding::FAST_LOSSLESS,
        AnyChannels::sort(channels),
    );
    Image::from_layer(layer).write().to_file(file).map_err(|e| write_error(file, e))
}

/// Writes RGB float triples as lossless OpenEXR.
///
/// # Errors
/// [`Error::Write`] naming the file.
pub fn write_exr_rgb(file: &Path, width: u32, height: u32, rgb: &[[f32; 3]]) -> Result<()> {
    check_len(file, rgb.len(), width, height, 1)?;
    exr::prelude::write_rgb_file(file, width as usize, height as usize, |x, y| {
        let [r, g, b] = rgb[y * width as usize + x];
        (r, g, b)
    })
    .map_err(|e| write_error(file, e))
}

/// Writes values in `[0, 1]` as a 16-bit grey PNG (clamped).
///
/// # Errors
/// [`Error::Write`] naming the file.
pub fn write_png_gray16(file: &Path, width: u32, height: u32, values: &[f32]) -> Result<()> {
    check_len(file, values.len(), width, height, 1)?;
    let pixels: Vec<u16> = values.iter().map(|v| (v.clamp(0.0, 1.0) * 65535.0).round() as u16).collect();
    let image =
        image::ImageBuffer::<image::Luma<u16>, _>::from_raw(width, height, pixels).ok_or_else(|| write_error(file, "buffer size"))?;
    image.save(file).map_err(|e| write_error(file, e))
}

/// Writes 8-bit RGBA pixels (sRGB-encoded) as PNG.
///
/// # Errors
/// [`Error::Write`] naming the file.
pub fn write_png_rgba8(file: &Path, width: u32, height: u32, rgba: &[u8]) -> Result<()> {
    check_len(file, rgba.len(), width, height, 4)?;
    let image = image::RgbaImage::from_raw(width, height, rgba.to_vec()).ok_or_else(|| write_error(file, "buffer size"))?;
    image.save(file).map_err(|e| write_error(file, e))
}
