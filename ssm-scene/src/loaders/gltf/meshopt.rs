//! `EXT_meshopt_compression` (and its ratified twin `KHR_meshopt_compression`):
//! buffer views compressed by meshoptimizer's codecs, decoded by the `meshopt`
//! crate, which builds the reference C++ decoders (written to be safe on
//! untrusted input). Every precondition that those decoders `assert` is
//! checked here first.
//!
//! gltf-json keeps the extension object as JSON (in `extensions.others` of a
//! `gltf::json::buffer::View`); [`Meshopt`] is its shape.

use gltf::json::{Buffer, Index};
use serde::Deserialize;

/// The extension names, the ratified one last.
pub(super) const EXTENSIONS: [&str; 2] = ["EXT_meshopt_compression", "KHR_meshopt_compression"];

/// A buffer view's `EXT_meshopt_compression` (or `KHR_meshopt_compression`) object.
#[derive(Debug, Deserialize)]
#[serde(rename_all = "camelCase")]
pub(super) struct Meshopt {
    pub buffer: Index<Buffer>,
    #[serde(default)]
    pub byte_offset: u64,
    pub byte_length: u64,
    pub byte_stride: u64,
    pub count: u64,
    pub mode: String,
    #[serde(default)]
    pub filter: Option<String>,
}

/// The decoded view may be at most this many times larger than its compressed bytes.
/// The codecs store at least one byte per triangle or index, and at least two bits
/// per vertex byte channel and block of up to 256 vertices, so no valid data exceeds
/// it; a lying `count` is refused before it is allocated.
const MAX_EXPANSION: u64 = 1024;
/// And never more than this.
const MAX_DECODED: u64 = 1 << 31;

/// Bytes of one vertex, as the decoders want them: a plain array of any size.
#[derive(Clone, Copy)]
struct Vertex<const N: usize>([u8; N]);

impl<const N: usize> Default for Vertex<N> {
    fn default() -> Self {
        Self([0; N])
    }
}

fn vertices<const N: usize>(encoded: &[u8], count: usize) -> Result<Vec<u8>, String> {
    let decoded: Vec<Vertex<N>> =
        meshopt::decode_vertex_buffer(encoded, count).map_err(|e| format!("cannot decode the vertex data: {e}"))?;
    Ok(decoded.into_iter().flat_map(|v| v.0).collect())
}

/// Expands to a `match` on the stride that calls [`vertices`] with it as a constant.
macro_rules! by_stride {
    ($stride:expr, $encoded:expr, $count:expr, [$($n:literal)*]) => {
        match $stride {
            $($n => vertices::<$n>($encoded, $count),)*
            other => Err(format!("byteStride {other} is not a multiple of 4 between 4 and 256")),
        }
    };
}

/// Decodes one compressed buffer view from `source` (the bytes its extension points at).
pub(super) fn decode(extension: &Meshopt, source: &[u8]) -> Result<Vec<u8>, String> {
    let stride = extension.byte_stride;
    let size = extension.count.checked_mul(stride).filter(|&s| s <= MAX_DECODED).ok_or_else(|| {
        format!("{} elements of {stride} bytes is more than the {MAX_DECODED} bytes a view may decode to", extension.count)
    })?;
    if size > MAX_EXPANSION.saturating_mul(source.len() as u64) {
        return Err(format!("{} compressed bytes cannot hold {} elements of {stride} bytes", source.len(), extension.count));
    }
    let count = extension.count as usize;
    let mut data = match extension.mode.as_str() {
        "ATTRIBUTES" => by_stride!(stride, source, count, [
            4 8 12 16 20 24 28 32 36 40 44 48 52 56 60 64 68 72 76 80 84 88 92 96 100 104 108 112 116 120 124 128
            132 136 140 144 148 152 156 160 164 168 172 176 180 184 188 192 196 200 204 208 212 216 220 224 228 232 236 240 244 248 252 256
        ])?,
        "TRIANGLES" if !count.is_multiple_of(3) => return Err(format!("TRIANGLES mode needs a multiple of 3 indices, not {count}")),
        "TRIANGLES" | "INDICES" => {
            let triangles = extension.mode == "TRIANGLES";
            let error = |_| "cannot decode the index data: it is corrupt or truncated".to_owned();
            match (stride, triangles) {
                (2, true) => {
                    meshopt::decode_index_buffer::<u16>(source, count).map_err(error)?.iter().flat_map(|i| i.to_le_bytes()).collect()
                }
                (4, true) => {
                    meshopt::decode_index_buffer::<u32>(source, count).map_err(error)?.iter().flat_map(|i| i.to_le_bytes()).collect()
                }
                (2, false) => {
                    meshopt::decode_index_sequence::<u16>(source, count).map_err(error)?.iter().flat_map(|i| i.to_le_bytes()).collect()
                }
                (4, false) => {
                    meshopt::decode_index_sequence::<u32>(source, count).map_err(error)?.iter().flat_map(|i| i.to_le_bytes()).collect()
                }
                _ => return Err(format!("index byteStride must be 2 or 4, not {stride}")),
            }
        }
        other => return Err(format!("unknown mode `{other}`")),
    };
    match extension.filter.as_deref().unwrap_or("NONE") {
        "NONE" => {}
        _ if extension.mode != "ATTRIBUTES" => return Err("filters apply to ATTRIBUTES only".into()),
        "OCTAHEDRAL" if stride == 4 => {
            let mut values: Vec<[i8; 4]> = data.chunks_exact(4).map(|c| [c[0], c[1], c[2], c[3]].map(|b| b as i8)).collect();
            meshopt::decode_filter_oct(&mut values);
            data = values.iter().flatten().map(|&b| b as u8).collect();
        }
        "OCTAHEDRAL" | "QUATERNION" if stride == 8 => {
            let mut values: Vec<[i16; 4]> =
                data.chunks_exact(8).map(|c| [0, 2, 4, 6].map(|k| i16::from_le_bytes([c[k], c[k + 1]]))).collect();
            if extension.filter.as_deref() == Some("OCTAHEDRAL") {
                meshopt::decode_filter_oct(&mut values);
            } else {
                meshopt::decode_filter_quat(&mut values);
            }
            data = values.iter().flatten().flat_map(|v| v.to_le_bytes()).collect();
        }
        // The exponential filter decodes each 32-bit value on its own.
        "EXPONENTIAL" => {
            let mut values: Vec<[u32; 1]> = data.chunks_exact(4).map(|c| [u32::from_le_bytes([c[0], c[1], c[2], c[3]])]).collect();
            meshopt::decode_filter_exp(&mut values);
            data = values.iter().flatten().flat_map(|v| v.to_le_bytes()).collect();
        }
        other => return Err(format!("filter `{other}` with byteStride {stride} is not supported")),
    }
    Ok(data)
}
