//! Statistics, in one place: the median and quartiles a timed point is reported as ([`median`],
//! [`quartiles`]), the errors of several lights as one ([`average`]), and the Pareto front of
//! (time, error) a sweep marks ([`pareto_front`]).

use ssm_core::metrics::ErrorMetrics;

/// Median of `values` (the mean of the middle two for an even count); `None` when empty.
#[must_use]
pub fn median(values: &[f64]) -> Option<f64> {
    let mut sorted: Vec<f64> = values.iter().copied().filter(|v| v.is_finite()).collect();
    if sorted.is_empty() {
        return None;
    }
    sorted.sort_by(f64::total_cmp);
    let mid = sorted.len() / 2;
    Some(if sorted.len().is_multiple_of(2) { (sorted[mid - 1] + sorted[mid]) * 0.5 } else { sorted[mid] })
}

/// The first and third quartiles of `values` (linear interpolation between order statistics, as
/// numpy's default): the interquartile range a timed point's spread is reported as. `None` when
/// empty; one value is its own range.
#[must_use]
pub fn quartiles(values: &[f64]) -> Option<(f64, f64)> {
    let mut sorted: Vec<f64> = values.iter().copied().filter(|v| v.is_finite()).collect();
    if sorted.is_empty() {
        return None;
    }
    sorted.sort_by(f64::total_cmp);
    let at = |p: f64| {
        let position = p * (sorted.len() - 1) as f64;
        let (below, above) = (position.floor() as usize, position.ceil() as usize);
        sorted[below] + (sorted[above] - sorted[below]) * (position - below as f64)
    };
    Some((at(0.25), at(0.75)))
}

/// The errors of several lights as one: means of the per-pixel measures, the largest error, the pixel counts summed (the `all` row).
#[must_use]
pub fn average(all: &[ErrorMetrics]) -> ErrorMetrics {
    let n = all.len().max(1) as f64;
    let mean = |f: &dyn Fn(&ErrorMetrics) -> f64| all.iter().map(f).sum::<f64>() / n;
    let mean_noise = |f: &dyn Fn(&ErrorMetrics) -> Option<f64>| all.iter().map(f).sum::<Option<f64>>().map(|sum| sum / n);
    ErrorMetrics {
        mae: mean(&|m| m.mae),
        mae_penumbra: mean(&|m| m.mae_penumbra),
        truth_noise: mean_noise(&|m| m.truth_noise),
        truth_noise_penumbra: mean_noise(&|m| m.truth_noise_penumbra),
        shadowed_pixels: all.iter().map(|m| m.shadowed_pixels).sum(),
        rmse: mean(&|m| m.rmse),
        max_abs: all.iter().map(|m| m.max_abs).fold(0.0, f64::max),
        psnr: mean(&|m| m.psnr),
        ssim: mean(&|m| m.ssim),
        frac_over_0_05: mean(&|m| m.frac_over_0_05),
        mean_signed: mean(&|m| m.mean_signed),
        umbra_leak: mean(&|m| m.umbra_leak),
        pixels: all.iter().map(|m| m.pixels).sum(),
        penumbra_pixels: all.iter().map(|m| m.penumbra_pixels).sum(),
        umbra_pixels: all.iter().map(|m| m.umbra_pixels).sum(),
    }
}

/// Indices of the rows on the Pareto front of (time, error): no other row is
/// at least as fast and at least as accurate, and better in one. Sorted by time.
#[must_use]
pub fn pareto_front(points: &[(f64, f64)]) -> Vec<usize> {
    let dominated = |i: usize| {
        let (t, e) = points[i];
        points.iter().enumerate().any(|(j, &(u, f))| j != i && u <= t && f <= e && (u < t || f < e))
    };
    let mut front: Vec<usize> =
        (0..points.len()).filter(|&i| points[i].0.is_finite() && points[i].1.is_finite() && !dominated(i)).collect();
    front.sort_by(|&a, &b| points[a].0.total_cmp(&points[b].0));
    front
}

#[cfg(test)]
mod tests {
    use super::{median, pareto_front, quartiles};

    #[test]
    fn quartiles_interpolate_between_order_statistics() {
        assert_eq!(quartiles(&[5.0, 1.0, 4.0, 2.0, 3.0]), Some((2.0, 4.0)));
        assert_eq!(quartiles(&[4.0, 1.0, 3.0, 2.0]), Some((1.75, 3.25)));
        assert_eq!(quartiles(&[7.0, f64::NAN]), Some((7.0, 7.0)));
        assert_eq!(quartiles(&[]), None);
        assert_eq!(median(&[4.0, 1.0, 3.0, 2.0]), Some(2.5));
    }

    #[test]
    fn pareto_front_keeps_the_undominated_points_in_time_order() {
        let points = [(1.0, 0.5), (2.0, 0.2), (3.0, 0.3), (4.0, 0.1), (2.0, 0.6), (f64::NAN, 0.0)];
        assert_eq!(pareto_front(&points), vec![0, 1, 3]);
        // Ties are not domination.
        assert_eq!(pareto_front(&[(1.0, 1.0), (1.0, 1.0)]), vec![0, 1]);
    }
}
