//! The ground truth's on-disk cache: an image is stored under a hash (FNV-1a, 64-bit) of
//! everything that changes it (the scene's triangles, the light, the points, the sampling, the
//! seed and [`REFERENCE_VERSION`]), in the folder [`default_cache_dir`] names unless told
//! another.

use std::path::{Path, PathBuf};
use std::time::Duration;

use ssm_scene::{RectLight, Scene};

use super::prepare::traced_triangles;
use super::{GroundTruth, REFERENCE_VERSION, ReferenceImage, Sampling, SurfacePoint};

/// The ground truth's on-disk cache for one scene: what an image is keyed
/// by beyond its own inputs (the light, the points, the samples and the
/// seed) is the hash of the scene's triangles, with [`REFERENCE_VERSION`].
/// Made without building the BVH, so a viewer can ask whether a view's
/// ground truth is cached without the cost of a tracer.
#[derive(Clone, Copy, Debug)]
pub struct ReferenceCache {
    geometry_hash: u64,
}

impl ReferenceCache {
    /// The cache of `scene`'s ground truth.
    #[must_use]
    pub fn of(scene: &Scene) -> Self {
        let mut hasher = Fnv64::new();
        for corners in traced_triangles(scene) {
            for corner in corners {
                hasher.write_f32s(&corner.to_array());
            }
        }
        Self { geometry_hash: hasher.finish() }
    }

    /// The image [`GroundTruth::trace_cached`] would return, if `cache_dir`
    /// holds it; `None` without tracing anything otherwise (a live viewer
    /// shows the error against the ground truth only where it is cached).
    #[must_use]
    pub fn cached(
        &self,
        light: &RectLight,
        points: &[Option<SurfacePoint>],
        sampling: Sampling,
        seed: u64,
        cache_dir: &Path,
    ) -> Option<ReferenceImage> {
        let bytes = std::fs::read(self.file(light, points, sampling, seed, cache_dir)).ok()?;
        (bytes.len() == points.len() * 8).then(|| {
            let mut values: Vec<f32> = bytes.chunks_exact(4).map(|b| f32::from_le_bytes([b[0], b[1], b[2], b[3]])).collect();
            let noise = values.split_off(points.len());
            ReferenceImage { visibility: values, noise, rays: 0, elapsed: Duration::ZERO, cached: true }
        })
    }

    fn file(&self, light: &RectLight, points: &[Option<SurfacePoint>], sampling: Sampling, seed: u64, cache_dir: &Path) -> PathBuf {
        cache_dir.join(format!("{:016x}.f32", self.key(light, points, sampling, seed)))
    }

    fn key(&self, light: &RectLight, points: &[Option<SurfacePoint>], sampling: Sampling, seed: u64) -> u64 {
        let mut hasher = Fnv64::new();
        hasher.write(&REFERENCE_VERSION.to_le_bytes());
        hasher.write(&self.geometry_hash.to_le_bytes());
        hasher.write_f32s(&[light.centre.x, light.centre.y, light.centre.z, light.u_axis.x, light.u_axis.y, light.u_axis.z]);
        hasher.write_f32s(&[light.v_axis.x, light.v_axis.y, light.v_axis.z, light.half_size.x, light.half_size.y]);
        hasher.write(&sampling.samples_per_axis.to_le_bytes());
        hasher.write(&sampling.refine.to_le_bytes());
        hasher.write(&seed.to_le_bytes());
        hasher.write(&(points.len() as u64).to_le_bytes());
        for point in points {
            match point {
                Some(p) => {
                    hasher.write_f32s(&[p.position.x, p.position.y, p.position.z, p.normal.x, p.normal.y, p.normal.z]);
                    // One byte of flags per point, so that no two point lists hash the same bytes.
                    hasher.write(&[u8::from(p.closed) | (u8::from(p.footprint.is_some()) << 1)]);
                    if let Some(f) = &p.footprint {
                        for v in [f.eye, f.corner, f.across, f.down] {
                            hasher.write_f32s(&v.to_array());
                        }
                    }
                }
                None => hasher.write(&[0xff]),
            }
        }
        hasher.finish()
    }
}

impl GroundTruth {
    /// As [`GroundTruth::trace`], through a cache in `cache_dir` keyed by a hash
    /// of the geometry, the light, the points, the sampling, the seed and
    /// [`REFERENCE_VERSION`]. A cache that cannot be read or written is ignored.
    #[must_use]
    pub fn trace_cached(
        &self,
        light: &RectLight,
        points: &[Option<SurfacePoint>],
        sampling: Sampling,
        seed: u64,
        cache_dir: &Path,
    ) -> ReferenceImage {
        if let Some(image) = self.cache.cached(light, points, sampling, seed, cache_dir) {
            return image;
        }
        let file = self.cache.file(light, points, sampling, seed, cache_dir);
        let image = self.trace(light, points, sampling, seed);
        // The visibility, then the noise.
        let bytes: Vec<u8> = image.visibility.iter().chain(&image.noise).flat_map(|v| v.to_le_bytes()).collect();
        // Write then rename, so that a concurrent reader never sees half a file.
        let partial = file.with_extension(format!("partial{}", std::process::id()));
        if std::fs::create_dir_all(cache_dir).is_ok() && std::fs::write(&partial, bytes).is_ok() {
            let _ = std::fs::rename(&partial, &file);
        }
        image
    }
}

/// The default cache folder: `$SSM_CACHE_DIR/reference`, else
/// `$XDG_CACHE_HOME/ssm/reference`, else `~/.cache/ssm/reference`, else
/// `ssm-cache/reference` under the working folder.
#[must_use]
pub fn default_cache_dir() -> PathBuf {
    if let Some(dir) = std::env::var_os("SSM_CACHE_DIR") {
        return PathBuf::from(dir).join("reference");
    }
    if let Some(dir) = std::env::var_os("XDG_CACHE_HOME") {
        return PathBuf::from(dir).join("ssm/reference");
    }
    if let Some(home) = std::env::var_os("HOME") {
        return PathBuf::from(home).join(".cache/ssm/reference");
    }
    PathBuf::from("ssm-cache/reference")
}

/// FNV-1a, 64-bit: a stable hash (the same on every machine and Rust version) for cache keys.
struct Fnv64(u64);

impl Fnv64 {
    fn new() -> Self {
        Self(0xcbf2_9ce4_8422_2325)
    }

    fn write(&mut self, bytes: &[u8]) {
        for byte in bytes {
            self.0 ^= u64::from(*byte);
            self.0 = self.0.wrapping_mul(0x0100_0000_01b3);
        }
    }

    fn write_f32s(&mut self, values: &[f32]) {
        for value in values {
            self.write(&value.to_le_bytes());
        }
    }

    fn finish(&self) -> u64 {
        self.0
    }
}
