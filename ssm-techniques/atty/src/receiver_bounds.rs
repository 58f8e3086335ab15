//! Step 3, optional (`penumbra_bound = receivers`; this workspace's, not the paper's): the
//! receiver map's max-pyramid (`shaders/atty/atty_receiver_bounds.wgsl`), with which the list pass
//! bounds each micro-patch's penumbra rectangle (Atty et al. 2006, Sec. 3.3) by the deepest
//! receiver under it instead of the frame's far plane: the same soft shadow map, fewer
//! accumulation fragments. Built by [`crate::gpu::DepthPyramid`].

use ssm_core::Choice;

use crate::gpu::PyramidKind;

/// What bounds each micro-patch's penumbra rectangle on the soft shadow map (the same SSM either way).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Choice)]
pub enum PenumbraBound {
    /// The frame's far plane, conservative for every receiver (the straightforward bound).
    FarPlane,
    /// The deepest receiver under the rectangle, from a max-pyramid of the receiver map: smaller
    /// rectangles, and no quad at all for a patch with no receiver behind it.
    Receivers,
}

/// The receiver map's max-pyramid.
const RECEIVER_BOUNDS_SHADER: &str = ssm_shaders::atty::ATTY_RECEIVER_BOUNDS;

/// The receiver map's largest depth per block.
pub(crate) const RECEIVER_BOUNDS: PyramidKind = PyramidKind {
    label: "atty_receiver_bounds",
    format: wgpu::TextureFormat::R32Float,
    shader: RECEIVER_BOUNDS_SHADER,
    base: "atty_bounds_base",
    reduce: "atty_bounds_reduce",
};
