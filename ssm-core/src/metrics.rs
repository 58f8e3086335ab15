//! Error metrics of a visibility image against the ground truth, on the same
//! pixels, and the error heat map.

use serde::Serialize;

/// Below this, a reference value counts as umbra; above `1 - UMBRA_EPSILON`, as lit.
/// (The reference's values are multiples of 1/N², so exact 0 and 1 are reached.)
pub const UMBRA_EPSILON: f32 = 1e-6;

/// A pixel's class in the reference.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum ShadowClass {
    /// No surface: not compared.
    Background,
    /// The whole light is visible.
    Lit,
    /// Part of the light is visible.
    Penumbra,
    /// None of the light is visible.
    Umbra,
}

/// Classifies each pixel of a reference image; `covered[i]` says whether geometry covers pixel i.
#[must_use]
pub fn classify(reference: &[f32], covered: &[bool]) -> Vec<ShadowClass> {
    reference
        .iter()
        .zip(covered)
        .map(|(&r, &c)| match (c, r) {
            (false, _) => ShadowClass::Background,
            (true, r) if r >= 1.0 - UMBRA_EPSILON => ShadowClass::Lit,
            (true, r) if r <= UMBRA_EPSILON => ShadowClass::Umbra,
            _ => ShadowClass::Penumbra,
        })
        .collect()
}

/// Below this visibility a pixel counts as shadowed for the headline error ([`ErrorMetrics::mae`]):
/// it would show darker than a lit one in an 8-bit image (half a step of 1/255 below 1).
pub const SHADOWED_BELOW: f32 = 1.0 - 0.5 / 255.0;

/// The error numbers of one image against the reference.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct ErrorMetrics {
    /// The headline error: mean absolute error over the covered pixels that the reference or the
    /// image shadows (visibility below [`SHADOWED_BELOW`] in either), so that a false shadow on a
    /// lit surface costs as much as a missing one. Every covered pixel would dilute it with the
    /// lit area the camera happens to frame; the union keeps it to where a shadow is, in either.
    pub mae: f64,
    /// Mean absolute error over the pixels in umbra or penumbra in the
    /// reference (the metric of Atty et al., Sec. 5.2.1): blind to false shadows.
    pub mae_penumbra: f64,
    /// The ground truth's own error for [`ErrorMetrics::mae`]'s pixels and metric: the mean of its
    /// per-pixel noise there (`reference::ReferenceImage::noise`), when known.
    pub truth_noise: Option<f64>,
    /// The same for [`ErrorMetrics::mae_penumbra`]'s pixels.
    pub truth_noise_penumbra: Option<f64>,
    /// Pixels [`ErrorMetrics::mae`] covers.
    pub shadowed_pixels: usize,
    /// Root-mean-square error over covered pixels.
    pub rmse: f64,
    /// Largest absolute error.
    pub max_abs: f64,
    /// Peak signal-to-noise ratio, dB (peak 1; infinite when identical).
    pub psnr: f64,
    /// Mean structural similarity (Wang et al. 2004; 11×11 Gaussian window, σ = 1.5) over covered pixels.
    pub ssim: f64,
    /// Share of covered pixels off by more than 0.05.
    pub frac_over_0_05: f64,
    /// Mean signed error over covered pixels: negative when the technique over-shadows.
    pub mean_signed: f64,
    /// Light bleeding: the technique's mean visibility over the pixels in umbra in the reference
    /// (0 when every one of them is dark; pre-filtered shadow maps leak light there).
    pub umbra_leak: f64,
    /// Covered pixels compared.
    pub pixels: usize,
    /// Pixels in penumbra in the reference.
    pub penumbra_pixels: usize,
    /// Pixels in umbra in the reference.
    pub umbra_pixels: usize,
}

/// Compares `image` with `reference` (both `width` × `height`, row-major) over the covered pixels,
/// without the reference's noise (its `truth_noise` fields are `None`).
///
/// # Panics
/// If the slices' lengths differ from `width * height`.
#[must_use]
pub fn compare(reference: &[f32], image: &[f32], covered: &[bool], width: usize, height: usize) -> ErrorMetrics {
    compare_with_noise(reference, None, image, covered, width, height)
}

/// As [`compare`], with the reference's own error per pixel (`noise`), averaged over the pixels of
/// each error into its `truth_noise` fields.
///
/// # Panics
/// If the slices' lengths differ from `width * height`.
#[must_use]
pub fn compare_with_noise(
    reference: &[f32],
    noise: Option<&[f32]>,
    image: &[f32],
    covered: &[bool],
    width: usize,
    height: usize,
) -> ErrorMetrics {
    assert!(reference.len() == width * height && image.len() == reference.len() && covered.len() == reference.len(), "image sizes differ");
    assert!(noise.is_none_or(|n| n.len() == reference.len()), "noise image size differs");
    let classes = classify(reference, covered);
    let (mut count, mut squared, mut max_abs, mut over, mut signed) = (0usize, 0.0f64, 0.0f64, 0usize, 0.0f64);
    let (mut shadow_sum, mut shadow_count, mut shadow_noise) = (0.0f64, 0usize, 0.0f64);
    let (mut union_sum, mut union_count, mut union_noise) = (0.0f64, 0usize, 0.0f64);
    let (mut umbra_light, mut umbra_count) = (0.0f64, 0usize);
    for (index, ((&r, &v), class)) in reference.iter().zip(image).zip(&classes).enumerate() {
        if *class == ShadowClass::Background {
            continue;
        }
        let pixel_noise = noise.map_or(0.0, |n| f64::from(n[index]));
        let error = f64::from(v) - f64::from(r);
        if r < SHADOWED_BELOW || v < SHADOWED_BELOW {
            union_sum += error.abs();
            union_noise += pixel_noise;
            union_count += 1;
        }
        count += 1;
        squared += error * error;
        signed += error;
        max_abs = max_abs.max(error.abs());
        over += usize::from(error.abs() > 0.05);
        if matches!(class, ShadowClass::Penumbra | ShadowClass::Umbra) {
            shadow_sum += error.abs();
            shadow_noise += pixel_noise;
            shadow_count += 1;
        }
        if *class == ShadowClass::Umbra {
            umbra_light += f64::from(v);
            umbra_count += 1;
        }
    }
    let n = count.max(1) as f64;
    let mse = squared / n;
    let mean = |sum: f64, count: usize| if count == 0 { 0.0 } else { sum / count as f64 };
    ErrorMetrics {
        mae: mean(union_sum, union_count),
        mae_penumbra: mean(shadow_sum, shadow_count),
        truth_noise: noise.map(|_| mean(union_noise, union_count)),
        truth_noise_penumbra: noise.map(|_| mean(shadow_noise, shadow_count)),
        shadowed_pixels: union_count,
        rmse: mse.sqrt(),
        max_abs,
        psnr: if mse == 0.0 { f64::INFINITY } else { -10.0 * mse.log10() },
        ssim: ssim(reference, image, covered, width, height),
        frac_over_0_05: over as f64 / n,
        mean_signed: signed / n,
        umbra_leak: if umbra_count == 0 { 0.0 } else { umbra_light / umbra_count as f64 },
        pixels: count,
        penumbra_pixels: classes.iter().filter(|c| **c == ShadowClass::Penumbra).count(),
        umbra_pixels: classes.iter().filter(|c| **c == ShadowClass::Umbra).count(),
    }
}

/// Whether two errors measured against the same noisy ground truth are a tie: they differ by
/// less than the truth's combined noise over their pixels (`noise_a + noise_b`, each the
/// `truth_noise` of its error). Without a noise estimate, only equal errors tie.
#[must_use]
pub fn is_tie(error_a: f64, noise_a: Option<f64>, error_b: f64, noise_b: Option<f64>) -> bool {
    (error_a - error_b).abs() < noise_a.unwrap_or(0.0) + noise_b.unwrap_or(0.0) || error_a == error_b
}

/// Mean SSIM over covered pixels: local means, variances and covariance from
/// an 11×11 Gaussian window (σ = 1.5, clamped at the borders), with
/// C1 = (0.01)² and C2 = (0.03)² for a dynamic range of 1 (Wang et al. 2004).
#[must_use]
pub fn ssim(reference: &[f32], image: &[f32], covered: &[bool], width: usize, height: usize) -> f64 {
    const RADIUS: i64 = 5;
    const SIGMA: f64 = 1.5;
    let weights: Vec<f64> = (-RADIUS..=RADIUS).map(|i| (-((i * i) as f64) / (2.0 * SIGMA * SIGMA)).exp()).collect();
    let total: f64 = weights.iter().sum();
    let weights: Vec<f64> = weights.iter().map(|w| w / total).collect();
    // Separable blur with clamped borders.
    let blur = |values: &[f64]| -> Vec<f64> {
        let clamp = |v: i64, max: usize| v.clamp(0, max as i64 - 1) as usize;
        let mut horizontal = vec![0.0; values.len()];
        for y in 0..height {
            for x in 0..width {
                horizontal[y * width + x] =
                    (-RADIUS..=RADIUS).map(|k| weights[(k + RADIUS) as usize] * values[y * width + clamp(x as i64 + k, width)]).sum();
            }
        }
        let mut out = vec![0.0; values.len()];
        for y in 0..height {
            for x in 0..width {
                out[y * width + x] =
                    (-RADIUS..=RADIUS).map(|k| weights[(k + RADIUS) as usize] * horizontal[clamp(y as i64 + k, height) * width + x]).sum();
            }
        }
        out
    };
    let x: Vec<f64> = reference.iter().map(|v| f64::from(*v)).collect();
    let y: Vec<f64> = image.iter().map(|v| f64::from(*v)).collect();
    let product = |a: &[f64], b: &[f64]| a.iter().zip(b).map(|(p, q)| p * q).collect::<Vec<f64>>();
    let (mean_x, mean_y) = (blur(&x), blur(&y));
    let (mean_xx, mean_yy, mean_xy) = (blur(&product(&x, &x)), blur(&product(&y, &y)), blur(&product(&x, &y)));
    let (c1, c2) = (0.01f64.powi(2), 0.03f64.powi(2));
    let (mut sum, mut count) = (0.0, 0usize);
    for i in 0..x.len() {
        if !covered[i] {
            continue;
        }
        let (mx, my) = (mean_x[i], mean_y[i]);
        let (vx, vy, cov) = (mean_xx[i] - mx * mx, mean_yy[i] - my * my, mean_xy[i] - mx * my);
        sum += ((2.0 * mx * my + c1) * (2.0 * cov + c2)) / ((mx * mx + my * my + c1) * (vx + vy + c2));
        count += 1;
    }
    if count == 0 { 1.0 } else { sum / count as f64 }
}

/// Mean FLIP error (Andersson et al. 2020, NVIDIA's ꟻLIP) of a shaded image
/// against the shaded reference, both RGBA8 sRGB, at the default viewing
/// condition (about 67 pixels per degree). 0 is identical; 1 is the largest error.
///
/// # Panics
/// If the slices are not `width * height * 4` bytes.
#[must_use]
pub fn flip_mean(reference_rgba: &[u8], image_rgba: &[u8], width: u32, height: u32) -> f64 {
    let rgb = |rgba: &[u8]| rgba.chunks_exact(4).flat_map(|p| [p[0], p[1], p[2]]).collect::<Vec<u8>>();
    let reference = nv_flip::FlipImageRgb8::with_data(width, height, &rgb(reference_rgba));
    let image = nv_flip::FlipImageRgb8::with_data(width, height, &rgb(image_rgba));
    let error = nv_flip::flip(reference, image, nv_flip::DEFAULT_PIXELS_PER_DEGREE);
    f64::from(nv_flip::FlipPool::from_image(&error).mean())
}

/// Per-pixel FLIP error of `image_rgba` against `reference_rgba` (both RGBA8
/// sRGB, the viewing condition of [`flip_mean`]) in FLIP's own magma colour
/// map (black 0, through purple and orange, to pale yellow 1): row-major RGB8.
///
/// # Panics
/// If the slices are not `width * height * 4` bytes.
#[must_use]
pub fn flip_map(reference_rgba: &[u8], image_rgba: &[u8], width: u32, height: u32) -> Vec<u8> {
    let rgb = |rgba: &[u8]| rgba.chunks_exact(4).flat_map(|p| [p[0], p[1], p[2]]).collect::<Vec<u8>>();
    let reference = nv_flip::FlipImageRgb8::with_data(width, height, &rgb(reference_rgba));
    let image = nv_flip::FlipImageRgb8::with_data(width, height, &rgb(image_rgba));
    nv_flip::flip(reference, image, nv_flip::DEFAULT_PIXELS_PER_DEGREE).apply_color_lut(&nv_flip::magma_lut()).to_vec()
}

/// The signed error `image - reference` as an RGB heat map: white where
/// equal, red where the technique is darker than the reference
/// (over-shadowing), blue where it is lighter (under-shadowing), saturated at
/// an error of `full_scale`; background pixels grey. Row-major RGB8.
#[must_use]
pub fn heat_map(reference: &[f32], image: &[f32], covered: &[bool], full_scale: f32) -> Vec<u8> {
    let mut out = Vec::with_capacity(reference.len() * 3);
    for ((&r, &v), &c) in reference.iter().zip(image).zip(covered) {
        if !c {
            out.extend_from_slice(&[96, 96, 96]);
            continue;
        }
        let t = ((v - r) / full_scale).clamp(-1.0, 1.0);
        let fade = ((1.0 - t.abs()) * 255.0).round() as u8;
        // Towards red (255, 0, 0) for t < 0, towards blue (0, 0, 255) for t > 0.
        out.extend_from_slice(&if t < 0.0 { [255, fade, fade] } else { [fade, fade, 255] });
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    fn ramp(width: usize, height: usize) -> Vec<f32> {
        (0..width * height).map(|i| (i % width) as f32 / (width - 1) as f32).collect()
    }

    #[test]
    fn identical_images_are_perfect() {
        let (w, h) = (24, 16);
        let reference = ramp(w, h);
        let m = compare(&reference, &reference, &vec![true; w * h], w, h);
        assert_eq!((m.mae_penumbra, m.rmse, m.max_abs, m.frac_over_0_05), (0.0, 0.0, 0.0, 0.0));
        assert!(m.psnr.is_infinite());
        assert!((m.ssim - 1.0).abs() < 1e-12, "{}", m.ssim);
    }

    #[test]
    fn a_constant_offset_gives_known_numbers() {
        let (w, h) = (24, 16);
        let reference: Vec<f32> = vec![0.5; w * h];
        let image: Vec<f32> = vec![0.6; w * h];
        let m = compare(&reference, &image, &vec![true; w * h], w, h);
        assert!((m.rmse - 0.1).abs() < 1e-6 && (m.max_abs - 0.1).abs() < 1e-6 && (m.mae_penumbra - 0.1).abs() < 1e-6);
        assert!((m.mean_signed - 0.1).abs() < 1e-6);
        // A flat 0.5 reference has no umbra: nothing to leak into.
        assert_eq!((m.umbra_pixels, m.umbra_leak), (0, 0.0));
        assert!((m.psnr - 20.0).abs() < 1e-4, "PSNR of a 0.1 offset is 20 dB, got {}", m.psnr);
        assert_eq!(m.frac_over_0_05, 1.0);
        // Flat images: variances are 0, so SSIM is the luminance term (2·0.5·0.6 + C1)/(0.25 + 0.36 + C1).
        let expected = (2.0 * 0.5 * 0.6 + 1e-4) / (0.25 + 0.36 + 1e-4);
        assert!((m.ssim - expected).abs() < 1e-5, "{} vs {expected}", m.ssim);
    }

    #[test]
    fn a_single_wrong_pixel() {
        let (w, h) = (30, 30);
        let reference: Vec<f32> = vec![0.0; w * h];
        let mut image = reference.clone();
        image[15 * w + 15] = 1.0;
        let m = compare(&reference, &image, &vec![true; w * h], w, h);
        assert_eq!(m.max_abs, 1.0);
        assert!((m.rmse - (1.0f64 / 900.0).sqrt()).abs() < 1e-9, "{}", m.rmse);
        assert!((m.mae_penumbra - 1.0 / 900.0).abs() < 1e-9);
        assert!((m.frac_over_0_05 - 1.0 / 900.0).abs() < 1e-9);
        assert!((m.psnr - 10.0 * 900f64.log10()).abs() < 1e-9);
        assert_eq!(m.umbra_pixels, 900);
        // Windows away from the pixel are perfect; those around it are not; a smaller error hurts less.
        assert!(m.ssim < 1.0 && m.ssim > 0.5, "{}", m.ssim);
        image[15 * w + 15] = 0.2;
        assert!(compare(&reference, &image, &vec![true; w * h], w, h).ssim > m.ssim);
    }

    #[test]
    fn background_is_ignored_and_lit_pixels_do_not_count_in_the_penumbra_mean() {
        let reference = vec![1.0, 1.0, 0.5, 0.0];
        let image = vec![0.0, 0.8, 0.4, 0.0];
        let covered = vec![false, true, true, true];
        let m = compare(&reference, &image, &covered, 4, 1);
        assert_eq!(m.pixels, 3);
        assert!((m.max_abs - 0.2).abs() < 1e-6, "the background pixel's error of 1 is not counted");
        assert!((m.mae_penumbra - 0.05).abs() < 1e-6, "mean of 0.1 and 0.0 over the penumbra and umbra pixels");
        assert_eq!(
            classify(&reference, &covered),
            vec![ShadowClass::Background, ShadowClass::Lit, ShadowClass::Penumbra, ShadowClass::Umbra]
        );
    }

    #[test]
    fn a_false_shadow_costs_the_headline_error_what_a_missing_one_does() {
        // Lit, lit, a false shadow of 0.4, and a missing one (reference 0.6, image lit).
        let reference = vec![1.0, 1.0, 1.0, 0.6];
        let image = vec![1.0, 0.999, 0.6, 1.0];
        let m = compare(&reference, &image, &[true; 4], 4, 1);
        assert_eq!(m.shadowed_pixels, 2, "0.999 shows as lit in 8 bits: not a shadow");
        assert!((m.mae - 0.4).abs() < 1e-6, "{}", m.mae);
        assert!((m.mae_penumbra - 0.4).abs() < 1e-6, "the penumbra error sees only the missing shadow");
        let swapped = compare(&image, &reference, &[true; 4], 4, 1);
        assert!((swapped.mae - m.mae).abs() < 1e-9, "the headline error is symmetric in what it counts");
        assert!(m.truth_noise.is_none());
    }

    #[test]
    fn the_truth_noise_is_averaged_over_each_errors_own_pixels() {
        let reference = vec![1.0, 0.5, 0.0, 1.0];
        let image = vec![0.5, 0.5, 0.0, 1.0];
        let noise = vec![0.0, 0.02, 0.0, 0.0];
        let m = compare_with_noise(&reference, Some(&noise), &image, &[true; 4], 4, 1);
        // Headline pixels: 0 (false shadow), 1 and 2; penumbra-and-umbra pixels: 1 and 2.
        assert!((m.truth_noise.unwrap() - 0.02 / 3.0).abs() < 1e-9, "{:?}", m.truth_noise);
        assert!((m.truth_noise_penumbra.unwrap() - 0.01).abs() < 1e-9, "{:?}", m.truth_noise_penumbra);
    }

    #[test]
    fn errors_closer_than_the_combined_noise_tie() {
        assert!(is_tie(0.010, Some(0.002), 0.013, Some(0.002)));
        assert!(!is_tie(0.010, Some(0.001), 0.013, Some(0.001)));
        assert!(!is_tie(0.010, None, 0.0101, None));
        assert!(is_tie(0.01, None, 0.01, None));
    }

    #[test]
    fn umbra_leak_is_the_mean_visibility_over_the_reference_umbra() {
        // Two umbra pixels (0.3 and 0.1 of light leaked), a penumbra and a lit one that do not count.
        let reference = vec![0.0, 0.0, 0.5, 1.0];
        let image = vec![0.3, 0.1, 0.9, 0.6];
        let m = compare(&reference, &image, &[true; 4], 4, 1);
        assert_eq!(m.umbra_pixels, 2);
        assert!((m.umbra_leak - 0.2).abs() < 1e-6, "{}", m.umbra_leak);
    }

    #[test]
    fn flip_is_zero_for_identical_images_and_grows_with_the_difference() {
        let (w, h) = (32u32, 32u32);
        let grey: Vec<u8> = (0..w * h).flat_map(|_| [128, 128, 128, 255]).collect();
        let mut dotted = grey.clone();
        let mut dark = grey.clone();
        for (i, pixel) in dotted.chunks_exact_mut(4).enumerate() {
            if i % 7 == 0 {
                pixel[..3].copy_from_slice(&[0, 0, 0]);
            }
        }
        for pixel in dark.chunks_exact_mut(4) {
            pixel[..3].copy_from_slice(&[0, 0, 0]);
        }
        assert!(flip_mean(&grey, &grey, w, h) < 1e-6);
        let (some, all) = (flip_mean(&grey, &dotted, w, h), flip_mean(&grey, &dark, w, h));
        assert!(some > 0.01 && all > some, "{some} {all}");
    }

    #[test]
    fn heat_map_colours_say_which_way() {
        let map = heat_map(&[0.5, 0.5, 0.5, 0.5], &[0.5, 0.0, 1.0, 0.5], &[true, true, true, false], 0.5);
        assert_eq!(&map[0..3], &[255, 255, 255]);
        assert_eq!(&map[3..6], &[255, 0, 0], "darker than the reference: red");
        assert_eq!(&map[6..9], &[0, 0, 255], "lighter: blue");
        assert_eq!(&map[9..12], &[96, 96, 96]);
    }
}
