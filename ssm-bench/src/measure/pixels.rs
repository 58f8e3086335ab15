//! The pixels the error metrics cover ([`PixelSet`]), read from the renderer's G-buffer ([`pixel_mask`]).

use ssm_core::{GBuffer, Renderer, Result};

/// Which pixels the error metrics cover.
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum PixelSet {
    /// Every pixel a surface covers.
    All,
    /// Only pixels of receivers (role `receiver` or `both`): what techniques that split roles shadow.
    Receivers,
}

/// The pixels `set` selects, from the renderer's G-buffer.
///
/// # Errors
/// A readback error.
pub fn pixel_mask(renderer: &Renderer, set: PixelSet) -> Result<Vec<bool>> {
    // Coverage is the position's w channel: 1 where geometry was drawn.
    let positions = renderer.read_positions()?;
    Ok(match set {
        PixelSet::All => positions.iter().map(|p| p[3] > 0.5).collect(),
        PixelSet::Receivers => positions
            .iter()
            .zip(renderer.read_normals()?)
            .map(|(p, n)| p[3] > 0.5 && GBuffer::flags(n[3]) & GBuffer::RECEIVES != 0)
            .collect(),
    })
}
