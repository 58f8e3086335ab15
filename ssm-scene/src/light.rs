//! Rectangular area lights.

use std::path::Path;

use glam::{Vec2, Vec3};

use crate::error::{Result, SceneError};

/// A one-sided rectangular area light, emitting towards `u_axis × v_axis`.
///
/// The rectangle is `centre + s * half_size.x * u_axis + t * half_size.y * v_axis`
/// for `s, t` in `[-1, 1]`. A light with `half_size == 0` is a point light: it keeps
/// its axes, so that its shadow-map frame is still defined.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RectLight {
    /// Centre of the rectangle, world space.
    pub centre: Vec3,
    /// Unit direction of the rectangle's first side (light-space x).
    pub u_axis: Vec3,
    /// Unit direction of the second side (light-space y), orthogonal to `u_axis`.
    pub v_axis: Vec3,
    /// Half the width along `u_axis` and half the height along `v_axis`, world units, `>= 0`.
    pub half_size: Vec2,
    /// Radiant intensity scale used by the composite shading, `>= 0`.
    pub intensity: f32,
    /// Linear RGB colour the composite shading multiplies the light's radiance by, each
    /// component finite and `>= 0` (white: `Vec3::ONE`). Visibility does not depend on it.
    pub colour: Vec3,
}

impl RectLight {
    /// A light at `centre` facing `normal`, `size` wide and high (full extents).
    ///
    /// `u_hint` picks the direction of the first side; it is projected onto the
    /// light's plane. Returns `None` when `normal` is zero or non-finite or
    /// `u_hint` is parallel to it.
    #[must_use]
    pub fn try_facing(centre: Vec3, normal: Vec3, u_hint: Vec3, size: Vec2, intensity: f32) -> Option<Self> {
        let normal = normal.try_normalize()?;
        let u_axis = (u_hint - normal * u_hint.dot(normal)).try_normalize()?;
        // u × v = normal, so v = normal × u.
        let v_axis = normal.cross(u_axis);
        Some(Self { centre, u_axis, v_axis, half_size: size * 0.5, intensity, colour: Vec3::ONE })
    }

    /// The same light with colour `colour` (linear RGB).
    #[must_use]
    pub fn with_colour(self, colour: Vec3) -> Self {
        Self { colour, ..self }
    }

    /// The direction the light emits towards.
    #[must_use]
    pub fn normal(&self) -> Vec3 {
        self.u_axis.cross(self.v_axis)
    }

    /// Area of the rectangle; zero for a point light.
    #[must_use]
    pub fn area(&self) -> f32 {
        4.0 * self.half_size.x * self.half_size.y
    }

    /// True when the light has no extent.
    #[must_use]
    pub fn is_point(&self) -> bool {
        self.half_size == Vec2::ZERO
    }

    /// The point at `(s, t)` in `[-1, 1]^2` on the rectangle.
    #[must_use]
    pub fn point(&self, s: f32, t: f32) -> Vec3 {
        self.centre + s * self.half_size.x * self.u_axis + t * self.half_size.y * self.v_axis
    }

    /// True when the whole rectangle lies strictly behind the plane through `point` with normal
    /// `normal` (its highest corner is below the plane). The CPU twin of `light_behind_surface`
    /// in `shaders/common/light_frame.wgsl`.
    #[must_use]
    pub fn is_behind_plane(&self, point: Vec3, normal: Vec3) -> bool {
        let reach = (self.half_size.x * self.u_axis.dot(normal)).abs() + (self.half_size.y * self.v_axis.dot(normal)).abs();
        (self.centre - point).dot(normal) + reach < 0.0
    }

    /// The fraction of the rectangle's area strictly in front of the plane through `point` with
    /// normal `normal` (on the side `normal` points to): 1 for a light wholly in front, 0 for one
    /// wholly behind (or touching it from behind, [`RectLight::is_behind_plane`]). The light's points
    /// are at heights `h + a A + b B` above the plane, with `h` the centre's height,
    /// `A = |half_size.x (u·n)|`, `B = |half_size.y (v·n)|` and `a`, `b` uniform in `[-1, 1]`, so the
    /// fraction is [`sum_of_uniforms_cdf`]`(h, A, B)`. The CPU twin of `light_share_in_front` in
    /// `shaders/common/light_frame.wgsl`.
    #[must_use]
    pub fn share_in_front_of_plane(&self, point: Vec3, normal: Vec3) -> f32 {
        let reach_u = (self.half_size.x * self.u_axis.dot(normal)).abs();
        let reach_v = (self.half_size.y * self.v_axis.dot(normal)).abs();
        sum_of_uniforms_cdf((self.centre - point).dot(normal), reach_u, reach_v)
    }

    /// Checks the invariants listed on the type.
    ///
    /// # Errors
    /// [`SceneError::InvalidLight`] naming `file`, the light's `index` and the problem.
    pub fn validate(&self, file: &Path, index: usize) -> Result<()> {
        let fail = |problem: String| Err(SceneError::InvalidLight { file: file.into(), index, problem });
        if !(self.centre.is_finite() && self.u_axis.is_finite() && self.v_axis.is_finite()) {
            return fail(format!("centre or axes are not finite (centre {}, u {}, v {})", self.centre, self.u_axis, self.v_axis));
        }
        if !self.half_size.is_finite() || self.half_size.min_element() < 0.0 {
            return fail(format!("size must be finite and non-negative, got {}", self.half_size * 2.0));
        }
        // One zero side and one non-zero side is a line light, which none of the techniques model.
        if (self.half_size.x == 0.0) != (self.half_size.y == 0.0) {
            return fail(format!("size {} is a line, not a rectangle; use [0, 0] for a point light", self.half_size * 2.0));
        }
        if !self.intensity.is_finite() || self.intensity < 0.0 {
            return fail(format!("intensity must be finite and non-negative, got {}", self.intensity));
        }
        if !self.colour.is_finite() || self.colour.min_element() < 0.0 {
            return fail(format!("colour must be finite and non-negative in every component, got {}", self.colour));
        }
        let orthonormal = (self.u_axis.length() - 1.0).abs() < 1e-4
            && (self.v_axis.length() - 1.0).abs() < 1e-4
            && self.u_axis.dot(self.v_axis).abs() < 1e-4;
        if !orthonormal {
            return fail(format!("axes u {} and v {} are not orthonormal", self.u_axis, self.v_axis));
        }
        Ok(())
    }
}

/// `P(a A + b B < t)` for `a`, `b` independent and uniform in `[-1, 1]` and `A`, `B >= 0`: the
/// cumulative distribution of a sum of two uniforms, a trapezoid's integral. With `A >= B` (the
/// arguments are swapped otherwise) it is 0 up to `-(A + B)`, `(t + A + B)² / 8AB` up to
/// `-(A - B)`, `(t + A) / 2A` up to `A - B`, `1 - (A + B - t)² / 8AB` up to `A + B`, and 1 beyond.
/// Each piece is written without a difference of nearly equal terms, so a tube light
/// (`B` far below `A`) keeps its precision; the tests come in an order where `B = 0` never divides
/// (the corner pieces are then empty), and `A = B = 0` gives the step `t > 0`. The CPU twin of
/// `sum_of_uniforms_cdf` in `shaders/common/light_frame.wgsl`.
#[must_use]
pub fn sum_of_uniforms_cdf(t: f32, a: f32, b: f32) -> f32 {
    let (a, b) = if a >= b { (a, b) } else { (b, a) };
    // Below the lowest height and above the highest: also the whole answer when A = B = 0. Each
    // distance to an end adds B last, so a tube's small B is not lost in A's rounding.
    let below = (t + a) + b;
    if below <= 0.0 {
        return 0.0;
    }
    let above = (a - t) + b;
    if above <= 0.0 {
        return 1.0;
    }
    // A > 0 here, and B > 0 in the corners (with B = 0, t <= -A and t > A returned above). Each
    // corner is half a product of two ratios in (0, 1]: no overflow.
    if t <= b - a {
        return 0.5 * (below / (2.0 * a)).min(1.0) * (below / (2.0 * b)).min(1.0);
    }
    if t <= a - b {
        return ((t + a) / (2.0 * a)).clamp(0.0, 1.0);
    }
    1.0 - 0.5 * (above / (2.0 * a)).min(1.0) * (above / (2.0 * b)).min(1.0)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The fraction of an `n` × `n` grid of points (cell centres) on the light in front of the plane.
    fn counted_share(light: &RectLight, point: Vec3, normal: Vec3, n: u32) -> f64 {
        let mut front = 0u64;
        for j in 0..n {
            for i in 0..n {
                let s = (f64::from(i) + 0.5) / f64::from(n) * 2.0 - 1.0;
                let t = (f64::from(j) + 0.5) / f64::from(n) * 2.0 - 1.0;
                let sample = light.centre.as_dvec3()
                    + s * f64::from(light.half_size.x) * light.u_axis.as_dvec3()
                    + t * f64::from(light.half_size.y) * light.v_axis.as_dvec3();
                if (sample - point.as_dvec3()).dot(normal.as_dvec3()) > 0.0 {
                    front += 1;
                }
            }
        }
        front as f64 / f64::from(n * n)
    }

    /// The closed form against a count over a 2000 × 2000 grid of light points (error of the
    /// count: about one row or column of cells, 1 / 1000), for planes through every part of the
    /// distribution: each corner piece, the middle, wholly in front and behind, a square light, a
    /// 1000:1 tube in both orientations, a plane parallel to the light and a point light.
    #[test]
    fn the_share_in_front_of_a_plane_matches_a_count_of_light_points() {
        let square = RectLight::try_facing(Vec3::new(0.0, 4.0, 0.0), -Vec3::Y, Vec3::X, Vec2::new(2.0, 2.0), 1.0).unwrap();
        let wide = RectLight::try_facing(Vec3::new(0.3, 3.0, -0.2), -Vec3::Y, Vec3::new(1.0, 0.0, 0.4), Vec2::new(3.0, 1.0), 1.0).unwrap();
        let tube = RectLight::try_facing(Vec3::new(0.0, 4.0, 0.0), -Vec3::Y, Vec3::X, Vec2::new(4.0, 0.004), 1.0).unwrap();
        let tube_along_v = RectLight::try_facing(Vec3::new(0.0, 4.0, 0.0), -Vec3::Y, Vec3::X, Vec2::new(0.004, 4.0), 1.0).unwrap();
        let mut checked = 0;
        for light in [square, wide, tube, tube_along_v] {
            for normal in [
                Vec3::new(1.0, 0.0, 0.0),
                Vec3::new(1.0, 0.3, 0.5),
                Vec3::new(-0.4, 0.2, 1.0),
                Vec3::new(0.7, -0.2, -0.7),
                Vec3::new(0.05, 1.0, 0.02),
                Vec3::new(0.0, 0.0, 1.0),
            ] {
                let normal = normal.normalize();
                let reach = (light.half_size.x * light.u_axis.dot(normal)).abs() + (light.half_size.y * light.v_axis.dot(normal)).abs();
                // Heights of the centre above the plane across and beyond the light's span.
                for k in -12..=12 {
                    let height = reach * k as f32 / 10.0 + if k == 0 { 0.01 * reach } else { 0.0 };
                    let point = light.centre - normal * height;
                    let share = light.share_in_front_of_plane(point, normal);
                    let counted = counted_share(&light, point, normal, 2000);
                    assert!(
                        (f64::from(share) - counted).abs() < 2e-3,
                        "light {:?}, normal {normal}, height {height}: {share} against {counted} counted",
                        light.half_size
                    );
                    if light.is_behind_plane(point, normal) {
                        assert_eq!(share, 0.0, "height {height}");
                    }
                    checked += 1;
                }
            }
        }
        assert_eq!(checked, 4 * 6 * 25);
        // A plane parallel to the light: all of it on one side, by the sign of the centre's height.
        let up = Vec3::Y;
        assert_eq!(square.share_in_front_of_plane(Vec3::new(5.0, 3.0, 1.0), up), 1.0);
        assert_eq!(square.share_in_front_of_plane(Vec3::new(5.0, 5.0, 1.0), up), 0.0);
        assert_eq!(counted_share(&square, Vec3::new(5.0, 3.0, 1.0), up, 100), 1.0);
        // A point light: the step at the plane.
        let point_light = RectLight { half_size: Vec2::ZERO, ..square };
        assert_eq!(point_light.share_in_front_of_plane(Vec3::new(1.0, 3.9, 0.0), Vec3::X), 0.0);
        assert_eq!(point_light.share_in_front_of_plane(Vec3::new(-1e-3, 3.9, 0.0), Vec3::X), 1.0);
        assert_eq!(point_light.share_in_front_of_plane(Vec3::new(0.0, 3.9, 0.0), Vec3::X), 0.0);
    }

    /// The pieces of the distribution meet, and a tube's corners (B a millionth of A) keep their
    /// precision: a difference of squares, `((t + A + B)² - (t + A - B)²) / 8AB`, would lose it.
    #[test]
    fn the_sum_of_uniforms_is_continuous_and_exact_for_a_tube() {
        let (a, b) = (2.0_f32, 0.5_f32);
        for knot in [-(a + b), -(a - b), a - b, a + b] {
            let (below, above) = (sum_of_uniforms_cdf(knot - 1e-4, a, b), sum_of_uniforms_cdf(knot + 1e-4, a, b));
            assert!((below - above).abs() < 1e-4, "a jump at {knot}: {below} to {above}");
        }
        assert_eq!(sum_of_uniforms_cdf(0.0, a, b), 0.5);
        assert_eq!(sum_of_uniforms_cdf(0.3, b, a), sum_of_uniforms_cdf(0.3, a, b), "the arguments' order does not matter");
        // A 10⁶:1 tube: the lower corner piece, halfway into it, is a quarter of the corner's mass B / 2A.
        let (a, b) = (1.0_f32, 1e-6_f32);
        let mass = b / (2.0 * a);
        let quarter = sum_of_uniforms_cdf(-a, a, b);
        assert!((quarter / mass - 0.25).abs() < 1e-6, "{quarter} against {}", mass * 0.25);
        assert!((sum_of_uniforms_cdf(a, a, b) - (1.0 - mass * 0.25)).abs() < 1e-7);
        // B = 0: the uniform on [-A, A], no division by zero; A = B = 0: the step.
        assert_eq!(sum_of_uniforms_cdf(-0.5, 1.0, 0.0), 0.25);
        assert_eq!(sum_of_uniforms_cdf(-1.0, 1.0, 0.0), 0.0);
        assert_eq!(sum_of_uniforms_cdf(1.0, 1.0, 0.0), 1.0);
        assert_eq!(sum_of_uniforms_cdf(1e-30, 0.0, 0.0), 1.0);
        assert_eq!(sum_of_uniforms_cdf(0.0, 0.0, 0.0), 0.0);
        assert_eq!(sum_of_uniforms_cdf(-1e-30, 0.0, 0.0), 0.0);
    }

    #[test]
    fn facing_down_gives_right_handed_axes() {
        let light = RectLight::try_facing(Vec3::new(0.0, 4.0, 0.0), -Vec3::Y, Vec3::X, Vec2::ONE, 1.0).unwrap();
        assert!((light.normal() + Vec3::Y).length() < 1e-6);
        assert!((light.u_axis - Vec3::X).length() < 1e-6);
        assert_eq!(light.area(), 1.0);
        light.validate(Path::new("x"), 0).unwrap();
    }

    #[test]
    fn rejects_line_lights_and_nan() {
        let mut light = RectLight::try_facing(Vec3::ZERO, -Vec3::Y, Vec3::X, Vec2::new(1.0, 0.0), 1.0).unwrap();
        assert!(light.validate(Path::new("x"), 3).unwrap_err().to_string().contains("light 3"));
        light.half_size = Vec2::ONE;
        light.centre.y = f32::NAN;
        assert!(light.validate(Path::new("x"), 0).is_err());
        assert!(RectLight::try_facing(Vec3::ZERO, Vec3::ZERO, Vec3::X, Vec2::ONE, 1.0).is_none());
        assert!(RectLight::try_facing(Vec3::ZERO, Vec3::X, Vec3::X, Vec2::ONE, 1.0).is_none());
    }
}
