//! The micro-patch geometry of Atty et al. 2006 (Sec. 3.3, 3.4 and 4.2) on the CPU: the paper's
//! formulas as written, and the forms the shaders evaluate.
//!
//! `shaders/atty/atty_geometry.wgsl` is this module's twin: the list pass
//! (`atty_micro_patches.wgsl`) bounds every penumbra rectangle with its `penumbra_half_ndc`, and
//! the accumulation (`atty_accumulation.wgsl`) adds `hidden_fraction` and applies
//! `on_or_behind_receiver_plane`.
//! The crate's tests check these functions against hand-computed cases and the paper's own form,
//! then run the WGSL functions on the GPU against them.
//!
//! Coordinates are the light's view space: `x` along the light's `u` axis, `y` along `v`, depth
//! along its normal from the light's centre `C_L` (the origin). A micro-patch is an axis-aligned
//! rectangle parallel to the light (Sec. 3.2); `ndc` coordinates are those of the shared light
//! frame's maps, lateral position divided by depth and by the frame's half-angle tangents.

use glam::{Vec2, Vec3};

/// A micro-patch (Sec. 3.2): the rectangle parallel to the light that one occluder-map texel (or an
/// aligned block of them) becomes, at that texel's depth, covering its image area.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct MicroPatch {
    /// Its centre `C_P` across the light, at its depth.
    pub centre: Vec2,
    /// Its half extents along `u` and `v`: `PP'/2` per axis.
    pub half_size: Vec2,
    /// Its depth `z_P`, > 0.
    pub depth: f32,
}

/// An axis-aligned rectangle across the light: the penumbra extent's section at one depth.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Rectangle {
    /// Its centre.
    pub centre: Vec2,
    /// Its half extents.
    pub half_size: Vec2,
}

/// The apex `O` of a micro-patch's penumbra pyramid (Sec. 3.3, Fig. 6):
/// `C_L O = r/(1+r) · C_L C_P` with `r = LL'/PP'`, the light's width over the patch's, per axis
/// (the same on both when the patch has the light's aspect ratio, as the shared frame's texels
/// do). `None` for a point light (`r = 0`: the apex is the light's centre and the pyramid
/// degenerates to the patch's shadow frustum), where the paper's rectangle formulas divide by zero.
#[must_use]
pub fn penumbra_apex(light_half: Vec2, patch: &MicroPatch) -> Option<(Vec2, f32)> {
    if light_half.min_element() <= 0.0 {
        return None;
    }
    let ratio = light_half / patch.half_size;
    let t = ratio / (1.0 + ratio);
    // Per axis, the apex's lateral position and depth both scale C_P by r/(1+r); with equal
    // ratios on both axes they are one point. Its depth is taken along `u`.
    let apex = Vec3::new(t.x * patch.centre.x, t.y * patch.centre.y, t.x * patch.depth);
    Some((apex.truncate(), apex.z))
}

/// The penumbra rectangle on the plane at depth `z_r` (> the patch's depth) in the paper's own
/// form (Sec. 3.3, Fig. 8): centre `C_L C_R = (z_R/z_O) · C_L O` and width
/// `RR' = LL' · (z_R − z_O)/z_O`, with `z_O` the depth of the apex `O` (similar triangles from the
/// light through the apex). `None` for a point light (no apex off the light).
#[must_use]
pub fn penumbra_rectangle_from_apex(light_half: Vec2, patch: &MicroPatch, z_r: f32) -> Option<Rectangle> {
    let (apex, apex_depth) = penumbra_apex(light_half, patch)?;
    Some(Rectangle { centre: apex * (z_r / apex_depth), half_size: light_half * ((z_r - apex_depth) / apex_depth) })
}

/// The same rectangle written without dividing by `r`, so that a point light (`r = 0`) needs no
/// special case: with `z_O = r/(1+r)·z_P` the centre `(z_R/z_O)·C_L O` is `(z_R/z_P)·C_P` and the
/// half width `l·(z_R − z_O)/z_O` is `(l + p)·z_R/z_P − l` (`l`, `p`: the light's and the
/// patch's half widths).
#[must_use]
pub fn penumbra_rectangle(light_half: Vec2, patch: &MicroPatch, z_r: f32) -> Rectangle {
    let scale = z_r / patch.depth;
    Rectangle { centre: patch.centre * scale, half_size: (light_half + patch.half_size) * scale - light_half }
}

/// [`penumbra_rectangle`] projected into the soft shadow map from the light's centre (divided by
/// `z_R · tan`), in ndc units: the centre is the patch's own (`C_P / (z_P · tan)`), the half extent
/// `(l + p)/(z_P · tan) − l/(z_R · tan)`, which grows with `z_R`, so the rectangle at the deepest
/// receiver (or the far plane) holds every receiver's. The list pass evaluates this form
/// (`penumbra_half_ndc` in `atty_geometry.wgsl`).
#[must_use]
pub fn penumbra_rectangle_ndc(light_half: Vec2, tan_half: Vec2, patch: &MicroPatch, z_r: f32) -> Rectangle {
    Rectangle { centre: patch.centre / (patch.depth * tan_half), half_size: penumbra_half_ndc(light_half, tan_half, patch, z_r) }
}

/// The half extent of [`penumbra_rectangle_ndc`], as the shader computes it.
#[must_use]
pub fn penumbra_half_ndc(light_half: Vec2, tan_half: Vec2, patch: &MicroPatch, z_r: f32) -> Vec2 {
    let reach = (light_half + patch.half_size) / (patch.depth * tan_half);
    let shrink = light_half / tan_half;
    reach - shrink / z_r
}

/// Length of `[low, high] ∩ [−half, half]` over `2·half` (Sec. 4.2: the light normalised to
/// `[0, 1]` and the interval clamped, the paper's saturating `MOV`); a point light (`half = 0`)
/// is hidden, 1, when it lies inside the interval.
#[must_use]
pub fn light_overlap(low: f32, high: f32, half: f32) -> f32 {
    if half <= 0.0 {
        return if low <= 0.0 && 0.0 <= high { 1.0 } else { 0.0 };
    }
    let a = ((low + half) / (2.0 * half)).clamp(0.0, 1.0);
    let b = ((high + half) / (2.0 * half)).clamp(0.0, 1.0);
    (b - a).max(0.0)
}

/// The fraction of the light a micro-patch hides from a receiver point at lateral position
/// `receiver`, depth `receiver_depth` (Sec. 3.4, 4.2): the patch projected from the point back
/// onto the light's plane (a scaling about the point by `z_R/(z_R − z_P)`, Drettakis and Fiume
/// 1994), then the product of the two clamped 1-D overlaps with the light. 0 for a point not
/// behind the patch.
#[must_use]
pub fn hidden_fraction(light_half: Vec2, patch: &MicroPatch, receiver: Vec2, receiver_depth: f32) -> f32 {
    if receiver_depth <= patch.depth {
        return 0.0;
    }
    let scale = receiver_depth / (receiver_depth - patch.depth);
    let low = receiver + (patch.centre - patch.half_size - receiver) * scale;
    let high = receiver + (patch.centre + patch.half_size - receiver) * scale;
    light_overlap(low.x, high.x, light_half.x) * light_overlap(low.y, high.y, light_half.y)
}

/// A receiver's tangent plane as the soft shadow map sees it: along the ray from the light's
/// centre through ndc `q`, a plane's `1/depth` is affine in `q` (perspective), so the plane through
/// the receiver at ndc `q_R`, depth `z_R` is `1/z(q) = (1 + slope·(q − q_R))/z_R`, with
/// `slope = z_R · ∇_q(1/z)`. `atty_receiver_map.wgsl` measures `slope` from the receiver map.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ReceiverPlane {
    /// The receiver's ndc position `q_R` in the soft shadow map.
    pub ndc: Vec2,
    /// Its depth `z_R`.
    pub depth: f32,
    /// `z_R · ∇_q(1/z)`, per ndc unit.
    pub slope: Vec2,
}

impl ReceiverPlane {
    /// The plane's depth along the ray through ndc `q`; infinite where that ray meets it behind
    /// the light or runs along it (every point of the ray in front of the light is then on the
    /// light's side of the plane).
    #[must_use]
    pub fn depth_at(&self, q: Vec2) -> f32 {
        let denominator = 1.0 + self.slope.dot(q - self.ndc);
        if denominator > 0.0 { self.depth / denominator } else { f32::INFINITY }
    }

    /// True when a micro-patch whose centre lies at ndc `q`, depth `depth`, lies on this plane or
    /// behind it, within `slack` (a depth): then it hides nothing the receiver sees. Every segment from
    /// the receiver to a point of the light in front of its tangent plane stays in front of that
    /// plane, so what lies behind it can hide only the part of the light the receiver's own surface
    /// already hides; and a flat surface's own micro-patches, centred on it, cannot hide it.
    #[must_use]
    pub fn holds_patch(&self, q: Vec2, depth: f32, slack: f32) -> bool {
        depth >= self.depth_at(q) - slack
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Tolerance of comparisons of computed f32 values of order 1 against hand-computed ones:
    /// a few operations, each rounding by at most 2⁻²⁴ of its magnitude.
    const ROUNDING: f32 = 1e-6;

    fn close(a: f32, b: f32) -> bool {
        (a - b).abs() <= ROUNDING * (1.0 + a.abs().max(b.abs()))
    }

    fn close2(a: Vec2, b: Vec2) -> bool {
        close(a.x, b.x) && close(a.y, b.y)
    }

    /// The hand-computed case: a light of width LL' = 2 (half 1), a micro-patch of width PP' = 0.5
    /// (half 0.25) centred at C_P = (1, 0.5) at depth 2.
    fn patch() -> MicroPatch {
        MicroPatch { centre: Vec2::new(1.0, 0.5), half_size: Vec2::splat(0.25), depth: 2.0 }
    }

    #[test]
    fn the_apex_is_r_over_1_plus_r_of_the_patch_centre() {
        // r = 2/0.5 = 4, r/(1+r) = 0.8: O = 0.8 · (1, 0.5, 2) = (0.8, 0.4, 1.6).
        let (apex, depth) = penumbra_apex(Vec2::ONE, &patch()).unwrap();
        assert!(close2(apex, Vec2::new(0.8, 0.4)) && close(depth, 1.6), "{apex} {depth}");
        // The apex is where the lines through opposite edges cross (Fig. 6): along u, from the
        // light's edge L' = 1 (depth 0) through the patch's P = 0.75 (depth 2), 1 − 0.25·t at
        // depth 2t, and from L = −1 through P' = 1.25, −1 + 2.25·t: equal at t = 0.8, x = 0.8.
        assert!(close(1.0 - 0.25 * 0.8, apex.x) && close(-1.0 + 2.25 * 0.8, apex.x));
        assert_eq!(penumbra_apex(Vec2::ZERO, &patch()), None, "a point light has no apex off the light");
    }

    #[test]
    fn the_penumbra_rectangle_follows_the_papers_formulas() {
        // At z_R = 4: C_L C_R = (4/1.6) · (0.8, 0.4) = (2, 1); RR' = 2 · (4 − 1.6)/1.6 = 3, half 1.5.
        let from_apex = penumbra_rectangle_from_apex(Vec2::ONE, &patch(), 4.0).unwrap();
        assert!(close2(from_apex.centre, Vec2::new(2.0, 1.0)), "{from_apex:?}");
        assert!(close2(from_apex.half_size, Vec2::splat(1.5)), "{from_apex:?}");
        // Its edges are the penumbra's: the line from the light's edge −1 (depth 0) through the
        // patch's far edge 1.25 (depth 2) reaches −1 + 2.25 · 2 = 3.5 = 2 + 1.5 at depth 4, and the
        // one from 1 through 0.75 reaches 1 − 0.25 · 2 = 0.5 = 2 − 1.5.
        assert!(close(from_apex.centre.x + from_apex.half_size.x, 3.5) && close(from_apex.centre.x - from_apex.half_size.x, 0.5));
        // The form without r gives the same: centre (4/2)·(1, 0.5), half (1 + 0.25)·2 − 1 = 1.5.
        let rectangle = penumbra_rectangle(Vec2::ONE, &patch(), 4.0);
        assert!(close2(rectangle.centre, from_apex.centre) && close2(rectangle.half_size, from_apex.half_size), "{rectangle:?}");
        // A point light: the patch's hard shadow, its image scaled by z_R/z_P about the light.
        let point = penumbra_rectangle(Vec2::ZERO, &patch(), 4.0);
        assert!(close2(point.centre, Vec2::new(2.0, 1.0)) && close2(point.half_size, Vec2::splat(0.5)), "{point:?}");
        // In the SSM, through a frame of tan 0.5 / 0.25: centre C_P/(z_P tan) = (1, 1), half
        // (l + p)/(z_P tan) − l/(z_R tan) = 1.25/1 − 1/2 = 0.75 along u, 1.25/0.5 − 1/1 = 1.5 along v,
        // which is the world rectangle's at depth 4 divided by 4·tan: 2/2, 1/1; 1.5/2, 1.5/1.
        let ndc = penumbra_rectangle_ndc(Vec2::ONE, Vec2::new(0.5, 0.25), &patch(), 4.0);
        assert!(close2(ndc.centre, Vec2::ONE) && close2(ndc.half_size, Vec2::new(0.75, 1.5)), "{ndc:?}");
    }

    #[test]
    fn the_form_without_r_is_the_papers_for_any_patch_and_light() {
        for light in [0.01f32, 0.3, 1.0, 7.0] {
            for (half, depth) in [(0.001f32, 0.5f32), (0.05, 2.0), (0.4, 3.0), (2.0, 10.0)] {
                for centre in [Vec2::ZERO, Vec2::new(-1.5, 0.7), Vec2::new(4.0, -3.0)] {
                    let patch = MicroPatch { centre, half_size: Vec2::splat(half), depth };
                    for z_r in [depth * 1.001, depth * 1.5, depth * 40.0] {
                        let paper = penumbra_rectangle_from_apex(Vec2::splat(light), &patch, z_r).unwrap();
                        let used = penumbra_rectangle(Vec2::splat(light), &patch, z_r);
                        // Both are a few f32 operations from the same inputs; values up to
                        // 4 · 40 = 160 in magnitude, so relative rounding of 1e-5 with slack.
                        let scale = 1.0 + paper.centre.abs().max_element().max(paper.half_size.max_element());
                        let gap = (paper.centre - used.centre).abs().max((paper.half_size - used.half_size).abs()).max_element();
                        assert!(gap <= 1e-5 * scale, "light {light}, {patch:?}, z_R {z_r}: {paper:?} vs {used:?}");
                    }
                }
            }
        }
    }

    #[test]
    fn a_patch_hides_its_back_projection_from_the_receiver() {
        // From (2, 1) at depth 4 the patch back-projects (scale 4/(4 − 2) = 2) to
        // [2 + (0.75 − 2)·2, 2 + (1.25 − 2)·2] = [−0.5, 0.5] along u and [1 + (0.25 − 1)·2,
        // 1 + (0.75 − 1)·2] = [−0.5, 0.5] along v: a quarter of the light [−1, 1]².
        assert!(close(hidden_fraction(Vec2::ONE, &patch(), Vec2::new(2.0, 1.0), 4.0), 0.25));
        // From the rectangle's edges the back-projection just touches the light: nothing hidden;
        // just inside, something.
        let rectangle = penumbra_rectangle(Vec2::ONE, &patch(), 4.0);
        for sign in [-1.0f32, 1.0] {
            let edge = rectangle.centre + Vec2::new(sign * rectangle.half_size.x, 0.0);
            assert_eq!(hidden_fraction(Vec2::ONE, &patch(), edge + Vec2::new(sign * 1e-4, 0.0), 4.0), 0.0);
            assert!(hidden_fraction(Vec2::ONE, &patch(), edge - Vec2::new(sign * 1e-3, 0.0), 4.0) > 0.0);
        }
        // A receiver in front of the patch, or at its depth, is hidden by nothing.
        assert_eq!(hidden_fraction(Vec2::ONE, &patch(), Vec2::new(2.0, 1.0), 2.0), 0.0);
        // A point light: all or nothing.
        assert_eq!(hidden_fraction(Vec2::ZERO, &patch(), Vec2::new(2.0, 1.0), 4.0), 1.0);
        assert_eq!(hidden_fraction(Vec2::ZERO, &patch(), Vec2::new(3.1, 1.0), 4.0), 0.0);
    }

    #[test]
    fn a_plane_tilted_to_the_light_is_found_at_its_own_depth_along_every_ray() {
        // The plane x + 2 = z (view space), seen through tan = (1, 1): along the ray through ndc
        // q its depth is z = 2/(1 − q.x), so 1/z = (1 − q.x)/2, slope = z_R · ∇(1/z) = z_R · (−½, 0).
        let at = |q: Vec2| 2.0 / (1.0 - q.x);
        let q_r = Vec2::new(0.2, -0.3);
        let plane = ReceiverPlane { ndc: q_r, depth: at(q_r), slope: at(q_r) * Vec2::new(-0.5, 0.0) };
        for q in [Vec2::new(-0.9, 0.5), Vec2::new(0.0, 0.0), Vec2::new(0.6, 0.9)] {
            assert!(close(plane.depth_at(q), at(q)), "{q}: {} vs {}", plane.depth_at(q), at(q));
            // A patch on the plane hides nothing; one a little in front of it may.
            assert!(plane.holds_patch(q, at(q), 1e-5));
            assert!(!plane.holds_patch(q, at(q) * 0.99, 1e-5));
        }
        // Past q.x = 1 the ray runs parallel to the plane or meets it behind the light.
        assert_eq!(plane.depth_at(Vec2::new(1.5, 0.0)), f32::INFINITY);
    }
}
