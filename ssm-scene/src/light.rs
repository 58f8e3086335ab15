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

#[cfg(test)]
mod tests {
    use super::*;

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
