//! Step 3, optional (`merge_tolerance > 0`, the default): each occluder map's min-max pyramid
//! (`shaders/atty/atty_patch_merge.wgsl`), with which the list pass draws an aligned block of
//! occluder texels whose depths agree as one micro-patch: neighbours at one depth join exactly
//! (Atty et al. 2006, Sec. 5.1.2). Built by [`crate::gpu::DepthPyramid`].

use crate::gpu::PyramidKind;

/// An occluder map's min-max pyramid.
const PATCH_MERGE_SHADER: &str = ssm_shaders::atty::ATTY_PATCH_MERGE;

/// An occluder map's depth range per block.
pub(crate) const PATCH_MERGE: PyramidKind = PyramidKind {
    label: "atty_patch_merge",
    format: wgpu::TextureFormat::Rg32Float,
    shader: PATCH_MERGE_SHADER,
    base: "atty_merge_base",
    reduce: "atty_merge_reduce",
};
