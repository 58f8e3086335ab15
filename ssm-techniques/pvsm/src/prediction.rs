//! Step 4 of Sec. 5.2 (on the GPU in step 3's pass, [`crate::kernel`]): the
//! perceptual resolution prediction of Sec. 5.1: how many shadow-map
//! texels a filter `n` pixels wide on screen needs for its penumbra to look
//! like the reference (the user study's ρ), and the predicted texel size of
//! Eq. 5. The WGSL twin is `shaders/pvsm/pvsm_common.wgsl` (`texels_needed`);
//! these CPU versions document it and let tests check it.

use ssm_core::Choice;

/// Which ρ turns a filter's screen size into the texels it needs (Sec. 5.1).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Choice)]
pub enum Prediction {
    /// ρ_dynamic: the user study's rule for moving occluders (the paper's results use it).
    Dynamic,
    /// ρ_static: the rule for static scenes (texture masking aside, less conservative).
    Static,
    /// A straight line in log₂ n through ρ_dynamic's ends (Fig. 8(b)'s cheaper model).
    Linear,
    /// No prediction: one map of `fixed_size`² covering the frame (Fig. 8(c), Table 2's fixed row).
    Fixed,
}

impl Prediction {
    /// The number as the shaders read it.
    #[must_use]
    pub fn code(self) -> u32 {
        match self {
            Self::Dynamic => 0,
            Self::Static => 1,
            Self::Linear => 2,
            Self::Fixed => 3,
        }
    }
}

/// ρ_dynamic as a cubic in x = log₂ n (Sec. 5.1).
#[must_use]
pub fn rho_dynamic(x: f32) -> f32 {
    0.667 + 0.7794 * x + 0.3967 * x * x - 0.02716 * x * x * x
}

/// ρ_static as a cubic in x = log₂ n (Sec. 5.1).
#[must_use]
pub fn rho_static(x: f32) -> f32 {
    0.5477 + 1.406 * x - 0.04687 * x * x - 0.003944 * x * x * x
}

/// Where each fitted cubic peaks: past it the polynomial turns down, outside
/// the study's data, so x is clamped there (n ≈ 1,550 and 200 pixels).
pub const DYNAMIC_PEAK: f32 = 10.6;
/// See [`DYNAMIC_PEAK`].
pub const STATIC_PEAK: f32 = 7.64;

/// The linear model: ρ_dynamic's values at log₂ n = 0 and at its peak, joined.
#[must_use]
pub fn rho_linear(x: f32) -> f32 {
    let (start, end) = (rho_dynamic(0.0), rho_dynamic(DYNAMIC_PEAK));
    start + (end - start) * x / DYNAMIC_PEAK
}

/// Texels a filter `pixels` wide on screen needs across it (ρ(n)), for
/// `model`; n below one pixel counts as one (the hard-shadow 1:1 rule).
#[must_use]
pub fn texels_needed(model: Prediction, pixels: f32) -> f32 {
    let x = pixels.max(1.0).log2();
    match model {
        Prediction::Dynamic | Prediction::Fixed => rho_dynamic(x.min(DYNAMIC_PEAK)),
        Prediction::Static => rho_static(x.min(STATIC_PEAK)),
        Prediction::Linear => rho_linear(x.min(DYNAMIC_PEAK)),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_models_grow_with_the_filter_and_static_needs_fewer_texels() {
        for model in [Prediction::Dynamic, Prediction::Static, Prediction::Linear] {
            let values: Vec<f32> = [1.0, 2.0, 4.0, 16.0, 64.0, 256.0, 1e6].iter().map(|n| texels_needed(model, *n)).collect();
            assert!(values.windows(2).all(|w| w[1] >= w[0]), "{model:?}: {values:?}");
            assert!(values[0] > 0.5 && values[0] < 0.7, "{model:?}: one pixel needs about two thirds of a texel: {}", values[0]);
        }
        // The study: a 16-pixel penumbra needs about 8 texels for moving occluders, fewer for static ones.
        let (dynamic, fixed) = (texels_needed(Prediction::Dynamic, 16.0), texels_needed(Prediction::Static, 16.0));
        assert!((dynamic - 8.4).abs() < 0.1, "{dynamic}");
        assert!(fixed < dynamic);
        // Sub-pixel filters need what one pixel needs.
        assert_eq!(texels_needed(Prediction::Dynamic, 0.01), texels_needed(Prediction::Dynamic, 1.0));
        // Past the peak the value holds.
        assert_eq!(texels_needed(Prediction::Dynamic, 1e9), texels_needed(Prediction::Dynamic, 2f32.powf(DYNAMIC_PEAK)));
    }
}
