//! Triangle meshes.

use std::path::Path;

use glam::Vec3;

use crate::error::{Result, SceneError};

/// An indexed triangle mesh in its own (object) space.
///
/// Invariants after [`Mesh::validate`]: every position and normal is finite,
/// `normals.len() == positions.len()`, and `indices` holds whole triangles
/// whose entries are all `< positions.len()`.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Mesh {
    /// A name for messages; from the file where it has one.
    pub name: String,
    /// Vertex positions.
    pub positions: Vec<Vec3>,
    /// Unit vertex normals, one per position.
    pub normals: Vec<Vec3>,
    /// Triangle list, three indices per triangle, counter-clockwise when front-facing.
    pub indices: Vec<u32>,
}

impl Mesh {
    /// A mesh from positions and triangles, with angle-weighted smooth normals.
    #[must_use]
    pub fn with_generated_normals(name: impl Into<String>, positions: Vec<Vec3>, indices: Vec<u32>) -> Self {
        let normals = generate_normals(&positions, &indices);
        Self { name: name.into(), positions, normals, indices }
    }

    /// Number of triangles.
    #[must_use]
    pub fn triangle_count(&self) -> usize {
        self.indices.len() / 3
    }

    /// Iterates over the triangles as index triples.
    pub fn triangles(&self) -> impl Iterator<Item = [u32; 3]> + '_ {
        self.indices.chunks_exact(3).map(|t| [t[0], t[1], t[2]])
    }

    /// Checks the invariants listed on the type, naming `file` in the error.
    ///
    /// # Errors
    /// The first violated invariant, as a typed [`SceneError`].
    pub fn validate(&self, file: &Path) -> Result<()> {
        if !self.indices.len().is_multiple_of(3) {
            return Err(SceneError::PartialTriangle { file: file.into(), mesh: self.name.clone(), count: self.indices.len() });
        }
        if self.normals.len() != self.positions.len() {
            return Err(SceneError::NormalCountMismatch {
                file: file.into(),
                mesh: self.name.clone(),
                normals: self.normals.len(),
                positions: self.positions.len(),
            });
        }
        for (attribute, values) in [("position", &self.positions), ("normal", &self.normals)] {
            if let Some((vertex, value)) = values.iter().enumerate().find(|(_, v)| !v.is_finite()) {
                return Err(SceneError::NonFiniteVertex {
                    file: file.into(),
                    mesh: self.name.clone(),
                    vertex,
                    attribute,
                    value: value.to_array(),
                });
            }
        }
        check_indices(file, &self.name, self.indices.iter().map(|&i| u64::from(i)), self.positions.len())
    }
}

/// Fails on the first index `>= count`: loaders call it before they build a [`Mesh`].
pub(crate) fn check_indices(file: &Path, mesh: &str, indices: impl Iterator<Item = u64>, count: usize) -> Result<()> {
    for (position, index) in indices.enumerate() {
        if index >= count as u64 {
            return Err(SceneError::InvalidIndex { file: file.into(), mesh: mesh.into(), index, position, count });
        }
    }
    Ok(())
}

/// Angle-weighted vertex normals (Thürmer and Wüthrich 1998): each face adds
/// its unit normal times its corner angle, so the result does not depend on
/// how polygons were split into triangles. Vertices on no (or only
/// degenerate) triangles get +Y.
///
/// Indices must already be in range.
#[must_use]
pub fn generate_normals(positions: &[Vec3], indices: &[u32]) -> Vec<Vec3> {
    let mut normals = vec![Vec3::ZERO; positions.len()];
    for t in indices.chunks_exact(3) {
        let corners = [t[0] as usize, t[1] as usize, t[2] as usize];
        let [a, b, c] = corners.map(|i| positions[i]);
        let Some(face) = (b - a).cross(c - a).try_normalize() else {
            continue;
        };
        for (k, &vertex) in corners.iter().enumerate() {
            let here = positions[vertex];
            let next = positions[corners[(k + 1) % 3]] - here;
            let previous = positions[corners[(k + 2) % 3]] - here;
            let angle = next.angle_between(previous);
            if angle.is_finite() {
                normals[vertex] += face * angle;
            }
        }
    }
    normals.iter().map(|n| n.try_normalize().unwrap_or(Vec3::Y)).collect()
}

/// Turns a triangle strip into a triangle list, keeping every triangle's winding.
#[must_use]
pub fn strip_to_list(strip: &[u32]) -> Vec<u32> {
    let mut list = Vec::with_capacity(strip.len().saturating_sub(2) * 3);
    for i in 2..strip.len() {
        // Odd triangles of a strip have reversed winding; swapping the first two restores it.
        if i % 2 == 0 {
            list.extend_from_slice(&[strip[i - 2], strip[i - 1], strip[i]]);
        } else {
            list.extend_from_slice(&[strip[i - 1], strip[i - 2], strip[i]]);
        }
    }
    list
}

/// Turns a triangle fan into a triangle list.
#[must_use]
pub fn fan_to_list(fan: &[u32]) -> Vec<u32> {
    let mut list = Vec::with_capacity(fan.len().saturating_sub(2) * 3);
    for i in 2..fan.len() {
        list.extend_from_slice(&[fan[0], fan[i - 1], fan[i]]);
    }
    list
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn strip_and_fan_keep_winding() {
        assert_eq!(strip_to_list(&[0, 1, 2, 3]), vec![0, 1, 2, 2, 1, 3]);
        assert_eq!(fan_to_list(&[0, 1, 2, 3]), vec![0, 1, 2, 0, 2, 3]);
        assert!(strip_to_list(&[0, 1]).is_empty());
    }

    #[test]
    fn generated_normals_point_out_of_a_ccw_triangle() {
        let mesh = Mesh::with_generated_normals("t", vec![Vec3::ZERO, Vec3::X, Vec3::Z], vec![0, 2, 1]);
        for n in &mesh.normals {
            assert!((*n - Vec3::Y).length() < 1e-6, "{n}");
        }
    }

    #[test]
    fn validation_names_the_bad_index() {
        let mesh = Mesh { name: "m".into(), positions: vec![Vec3::ZERO; 3], normals: vec![Vec3::Y; 3], indices: vec![0, 1, 7] };
        let err = mesh.validate(Path::new("f.obj")).unwrap_err().to_string();
        assert!(err.contains("f.obj") && err.contains("index 7") && err.contains("3 vertices"), "{err}");
    }

    #[test]
    fn validation_rejects_nan() {
        let mesh =
            Mesh { name: "m".into(), positions: vec![Vec3::ZERO, Vec3::NAN, Vec3::X], normals: vec![Vec3::Y; 3], indices: vec![0, 1, 2] };
        assert!(matches!(mesh.validate(Path::new("f")), Err(SceneError::NonFiniteVertex { vertex: 1, .. })));
    }
}
