//! The viewing camera.

use std::path::Path;

use glam::{Mat4, Vec3};

use crate::error::{Result, SceneError};

/// A perspective pinhole camera.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Camera {
    /// Eye position, world space.
    pub position: Vec3,
    /// The point looked at.
    pub target: Vec3,
    /// Approximate up direction; must not be parallel to the view direction.
    pub up: Vec3,
    /// Vertical field of view in radians, in `(0, π)`.
    pub fov_y: f32,
    /// Near clip distance, `> 0`.
    pub near: f32,
    /// Far clip distance, `> near`.
    pub far: f32,
}

impl Camera {
    /// World-to-view matrix (right-handed, looking down -z).
    #[must_use]
    pub fn view(&self) -> Mat4 {
        glam::camera::rh::view::look_at_mat4(self.position, self.target, self.up)
    }

    /// View-to-clip matrix with depth in `[0, 1]` (wgpu's convention).
    #[must_use]
    pub fn projection(&self, aspect: f32) -> Mat4 {
        glam::camera::rh::proj::directx::perspective(self.fov_y, aspect, self.near, self.far)
    }

    /// Checks the invariants listed on the fields.
    ///
    /// # Errors
    /// [`SceneError::InvalidCamera`] naming `file` and the problem.
    pub fn validate(&self, file: &Path) -> Result<()> {
        let fail = |problem: String| Err(SceneError::InvalidCamera { file: file.into(), problem });
        if !(self.position.is_finite() && self.target.is_finite() && self.up.is_finite()) {
            return fail("position, target or up is not finite".into());
        }
        let Some(forward) = (self.target - self.position).try_normalize() else {
            return fail("position and target coincide".into());
        };
        if self.up.cross(forward).length_squared() < 1e-10 {
            return fail(format!("up {} is parallel to the view direction", self.up));
        }
        if !(self.fov_y > 0.0 && self.fov_y < std::f32::consts::PI) {
            return fail(format!("vertical field of view {}° is outside (0°, 180°)", self.fov_y.to_degrees()));
        }
        if !(self.near > 0.0 && self.far > self.near && self.far.is_finite()) {
            return fail(format!("near {} and far {} must satisfy 0 < near < far < ∞", self.near, self.far));
        }
        Ok(())
    }
}
