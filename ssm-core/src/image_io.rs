//! Writing images: visibility as 32-bit float OpenEXR and 16-bit PNG, shaded
//! images as 8-bit sRGB PNG, world positions as OpenEXR. Every EXR carries a
//! coverage channel ([`COVERAGE_CHANNEL`]); [`read_exr`] reads them back.

use std::path::Path;

use exr::prelude::{AnyChannel, AnyChannels, Encoding, FlatSamples, Image, Layer, LayerAttributes, SmallVec, WritableImage};

use crate::error::{Error, Reason, Result};

fn write_error(file: &Path, source: impl Into<crate::error::BoxedError>) -> Error {
    Error::write(file, source)
}

fn check_len(file: &Path, len: usize, width: u32, height: u32, channels: usize) -> Result<()> {
    if len == width as usize * height as usize * channels {
        Ok(())
    } else {
        Err(write_error(file, Reason(format!("{len} values for a {width}x{height} image of {channels} channels"))))
    }
}

/// Name of the coverage channel ssm writes into every EXR: 1 where geometry
/// covers the pixel, 0 for background. Needed because a background pixel's
/// other channels (position (0, 0, 0), visibility 1) are also valid values for
/// a surface.
pub const COVERAGE_CHANNEL: &str = "A";

/// Writes named float channels (`("Y", values)`, ...) of one image as lossless
/// OpenEXR, in a layer called `layer`. Every channel has `width × height`
/// values, row-major from the top-left.
///
/// # Errors
/// [`Error::Write`] naming the file.
pub fn write_exr_channels(file: &Path, width: u32, height: u32, layer: &str, channels: &[(&str, &[f32])]) -> Result<()> {
    let mut list: SmallVec<[AnyChannel<FlatSamples>; 4]> = SmallVec::new();
    for (name, values) in channels {
        check_len(file, values.len(), width, height, 1)?;
        list.push(AnyChannel::new(*name, FlatSamples::F32(values.to_vec())));
    }
    let layer =
        Layer::new((width as usize, height as usize), LayerAttributes::named(layer), Encoding::FAST_LOSSLESS, AnyChannels::sort(list));
    Image::from_layer(layer).write().to_file(file).map_err(|e| write_error(file, e))
}

/// Writes a single-channel float image as lossless OpenEXR: channel `Y` the
/// values and channel `A` ([`COVERAGE_CHANNEL`]) the coverage (1 where
/// `covered`), so that readers can tell background pixels from surfaces.
///
/// # Errors
/// [`Error::Write`] naming the file.
pub fn write_exr_gray(file: &Path, width: u32, height: u32, values: &[f32], covered: &[bool]) -> Result<()> {
    let coverage: Vec<f32> = covered.iter().map(|c| f32::from(u8::from(*c))).collect();
    write_exr_channels(file, width, height, "visibility", &[("Y", values), (COVERAGE_CHANNEL, &coverage)])
}

/// Writes world positions as lossless OpenEXR: channels `R`, `G`, `B` the
/// position (0 for background) and `A` ([`COVERAGE_CHANNEL`]) the coverage.
///
/// # Errors
/// [`Error::Write`] naming the file.
pub fn write_exr_positions(file: &Path, width: u32, height: u32, positions: &[[f32; 3]], covered: &[bool]) -> Result<()> {
    check_len(file, positions.len(), width, height, 1)?;
    let channel = |k: usize| -> Vec<f32> { positions.iter().zip(covered).map(|(p, c)| if *c { p[k] } else { 0.0 }).collect() };
    let (x, y, z) = (channel(0), channel(1), channel(2));
    let coverage: Vec<f32> = covered.iter().map(|c| f32::from(u8::from(*c))).collect();
    write_exr_channels(file, width, height, "position", &[("R", &x), ("G", &y), ("B", &z), (COVERAGE_CHANNEL, &coverage)])
}

/// An OpenEXR image read back: its size and every channel of its first layer, as `f32`.
#[derive(Clone, Debug, PartialEq)]
pub struct ExrImage {
    /// Width in pixels.
    pub width: u32,
    /// Height in pixels.
    pub height: u32,
    /// `(name, values)`, values row-major from the top-left.
    pub channels: Vec<(String, Vec<f32>)>,
}

impl ExrImage {
    /// The channel called `name`.
    #[must_use]
    pub fn channel(&self, name: &str) -> Option<&[f32]> {
        self.channels.iter().find(|(n, _)| n == name).map(|(_, v)| v.as_slice())
    }

    /// Coverage per pixel from the [`COVERAGE_CHANNEL`]; every pixel counts as covered in a file without one.
    #[must_use]
    pub fn coverage(&self) -> Vec<bool> {
        match self.channel(COVERAGE_CHANNEL) {
            Some(alpha) => alpha.iter().map(|a| *a > 0.5).collect(),
            None => vec![true; self.width as usize * self.height as usize],
        }
    }
}

/// Reads the first layer of an OpenEXR file (as ssm writes them), every channel converted to `f32`.
///
/// # Errors
/// [`Error::Read`] naming the file.
pub fn read_exr(file: &Path) -> Result<ExrImage> {
    let image = exr::prelude::read_first_flat_layer_from_file(file).map_err(|e| Error::Read { file: file.into(), source: e.into() })?;
    let layer = image.layer_data;
    let size = layer.size;
    let channels =
        layer.channel_data.list.iter().map(|channel| (channel.name.to_string(), channel.sample_data.values_as_f32().collect())).collect();
    Ok(ExrImage { width: size.width() as u32, height: size.height() as u32, channels })
}

/// Writes values in `[0, 1]` as a 16-bit grey PNG (clamped).
///
/// # Errors
/// [`Error::Write`] naming the file.
pub fn write_png_gray16(file: &Path, width: u32, height: u32, values: &[f32]) -> Result<()> {
    check_len(file, values.len(), width, height, 1)?;
    let pixels: Vec<u16> = values.iter().map(|v| (v.clamp(0.0, 1.0) * 65535.0).round() as u16).collect();
    let image = image::ImageBuffer::<image::Luma<u16>, _>::from_raw(width, height, pixels)
        .ok_or_else(|| write_error(file, Reason("buffer size".into())))?;
    image.save(file).map_err(|e| write_error(file, e))
}

/// Writes 8-bit RGBA pixels (sRGB-encoded) as PNG.
///
/// # Errors
/// [`Error::Write`] naming the file.
pub fn write_png_rgba8(file: &Path, width: u32, height: u32, rgba: &[u8]) -> Result<()> {
    check_len(file, rgba.len(), width, height, 4)?;
    let image = image::RgbaImage::from_raw(width, height, rgba.to_vec()).ok_or_else(|| write_error(file, Reason("buffer size".into())))?;
    image.save(file).map_err(|e| write_error(file, e))
}
