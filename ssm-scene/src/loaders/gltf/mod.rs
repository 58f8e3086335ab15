//! glTF 2.0: `.gltf` (buffers in external files or data URIs) and `.glb`.
//!
//! The document model is the `gltf` crate's (`gltf::json`: accessors, buffer
//! views, buffers, meshes, nodes, scenes and cameras, with its enumerations of
//! component types, accessor types, primitive modes and attribute semantics
//! and its `Checked` values). But the file is not read through `gltf::Gltf`
//! nor as one `gltf::json::Root`: that refuses a whole file for an error in a
//! part that shadows never use (a material, an animation) or for any
//! `extensionsRequired` entry it does not implement (even material ones), and
//! gives glTF 1.0 a serde message; and gltf-json's validation is not run
//! either: it indexes the accessors with a primitive's POSITION unchecked (a
//! panic, `fuzz/regressions/gltf/`). So the JSON is parsed to a
//! `serde_json::Value`, checked for its version and required extensions, and
//! each element ssm reads is deserialized on its own when first used
//! ([`json`]); every index is checked where it is used. The GLB container is split here, not by `gltf::Glb`, which
//! subtracts the header's size from the declared length unchecked (a panic
//! under overflow checks) and refuses the unknown chunks that the
//! specification says to skip. Buffers are read and accessors decoded here,
//! not by `gltf::import` and its accessor reader, with every index, offset and
//! length checked and the total size capped: that reader asserts (panics) on
//! some malformed strides and counts.
//!
//! Decoded: `KHR_mesh_quantization` (integer positions and normals),
//! `EXT_meshopt_compression` and `KHR_meshopt_compression` ([`meshopt`]),
//! sparse accessors, triangle strips and fans. Required extensions that only
//! concern materials, textures or lights are ignored; any other required
//! extension, Draco included, is refused by name.

mod json;
mod meshopt;

use std::collections::HashMap;
use std::io::Read;
use std::path::{Path, PathBuf};
use std::rc::Rc;

use glam::{Mat4, Quat, Vec3};
use gltf::json::accessor::{ComponentType, GenericComponentType, IndexComponentType, Type};
use gltf::json::mesh::{Mode, Semantic};
use gltf::json::validation::Checked;
use gltf::json::{Accessor, Buffer, Camera as CameraDef, Mesh as MeshDef, Node, Scene, buffer};
use serde::Deserialize;
use serde_json::{Map, Value};

use self::json::Table;
use self::meshopt::Meshopt;
use super::{LoadedModel, Placement, malformed};
use crate::camera::Camera;
use crate::error::{Result, SceneError};
use crate::mesh::{Mesh, check_indices, fan_to_list, generate_normals, strip_to_list};

/// Extensions whose data this loader decodes.
const DECODED_EXTENSIONS: &[&str] = &["KHR_mesh_quantization", meshopt::EXTENSIONS[0], meshopt::EXTENSIONS[1]];
/// Prefixes of extensions that change only materials, textures, lights or metadata: safe to ignore for shadows.
const IGNORED_EXTENSION_PREFIXES: &[&str] = &[
    "KHR_materials_",
    "KHR_texture_",
    "EXT_texture_",
    "MSFT_texture_",
    "KHR_lights_",
    "EXT_lights_",
    "KHR_xmp",
    "EXT_materials_",
    "ADOBE_materials_",
];
const DRACO: &str = "KHR_draco_mesh_compression";
/// Primitives may share accessors, and an accessor without a buffer view (all zeros but
/// its sparse values) takes no bytes: so that no small file expands into gigabytes, the
/// elements read from all accessors may total this many, plus [`ELEMENTS_PER_BYTE`] per
/// byte of the file and of the buffers it loads. Real files stay far below.
const FREE_ELEMENTS: u64 = 1 << 22;
/// See [`FREE_ELEMENTS`].
const ELEMENTS_PER_BYTE: u64 = 64;
/// A node hierarchy that shares children (not allowed, but tolerated) may expand to at most this many placements.
const MAX_PLACEMENTS: usize = 1 << 20;

const GLB_JSON: u32 = 0x4E4F_534A;
const GLB_BIN: u32 = 0x004E_4942;

fn unsupported(path: &Path, what: impl Into<String>, hint: impl Into<String>) -> SceneError {
    SceneError::Unsupported { file: path.into(), what: what.into(), hint: hint.into() }
}

fn gltf_1(path: &Path) -> SceneError {
    unsupported(path, "glTF 1.0", "convert the file to glTF 2.0 (for example with `npx gltf-pipeline -i old.gltf -o new.gltf`)")
}

fn u32_at(bytes: &[u8], at: usize) -> Option<u32> {
    bytes.get(at..at + 4).map(|b| u32::from_le_bytes([b[0], b[1], b[2], b[3]]))
}

/// Splits a `.glb` into its JSON and binary chunks; anything else is returned as JSON text.
fn split_glb<'a>(path: &Path, bytes: &'a [u8]) -> Result<(&'a [u8], Option<&'a [u8]>)> {
    if !bytes.starts_with(b"glTF") {
        return Ok((bytes, None));
    }
    let (Some(version), Some(length)) = (u32_at(bytes, 4), u32_at(bytes, 8)) else {
        return Err(malformed(path, "glTF", "the binary header is truncated"));
    };
    match version {
        2 => {}
        // Binary glTF 1.0 (KHR_binary_glTF).
        1 => return Err(gltf_1(path)),
        _ => return Err(malformed(path, "glTF", format!("unknown binary container version {version}"))),
    }
    let length = length as usize;
    if length < 12 || length > bytes.len() {
        return Err(malformed(path, "glTF", format!("the binary header declares {length} bytes but the file has {}", bytes.len())));
    }
    let bytes = &bytes[..length];
    let (mut json, mut bin) = (None, None);
    let mut at = 12;
    while at < length {
        let (Some(chunk_length), Some(kind)) = (u32_at(bytes, at), u32_at(bytes, at + 4)) else {
            return Err(malformed(path, "glTF", format!("chunk header at byte {at} is truncated")));
        };
        let start = at + 8;
        let Some(chunk) = bytes.get(start..start + chunk_length as usize) else {
            return Err(malformed(
                path,
                "glTF",
                format!("chunk at byte {at} declares {chunk_length} bytes but only {} remain", length - start),
            ));
        };
        match kind {
            GLB_JSON if json.is_none() && at == 12 => json = Some(chunk),
            GLB_BIN if bin.is_none() && json.is_some() => bin = Some(chunk),
            // Unknown chunks are skipped, as the specification asks.
            _ => {}
        }
        at = start + chunk_length as usize;
    }
    let json = json.ok_or_else(|| malformed(path, "glTF", "the first chunk of the binary file is not JSON"))?;
    Ok((json, bin))
}

/// True for a glTF 1.0 (or older) document: by its `asset.version`, or, without one, by its
/// dictionaries where glTF 2.0 has arrays.
fn is_gltf_1(value: &Value) -> bool {
    let version = value.pointer("/asset/version").map(|v| v.as_str().map_or_else(|| v.to_string(), str::to_owned));
    match version {
        Some(v) => v.starts_with('1') || v.starts_with('0'),
        None => {
            ["meshes", "nodes", "accessors", "bufferViews", "buffers", "scenes"].iter().any(|k| value.get(k).is_some_and(|v| v.is_object()))
        }
    }
}

/// The document's root object, once its version and required extensions are known to be read here.
fn parse_document(path: &Path, json: &[u8]) -> Result<Map<String, Value>> {
    let json = json.strip_prefix(b"\xEF\xBB\xBF").unwrap_or(json);
    let value: Value = serde_json::from_slice(json).map_err(|e| malformed(path, "glTF", e))?;
    if is_gltf_1(&value) {
        return Err(gltf_1(path));
    }
    if let Some(version) = value.pointer("/asset/version") {
        let version = version.as_str().map_or_else(|| version.to_string(), str::to_owned);
        if !version.starts_with("2.") && version != "2" {
            return Err(unsupported(path, format!("glTF version {version}"), "ssm reads glTF 2.0"));
        }
    }
    let Value::Object(root) = value else {
        return Err(malformed(path, "glTF", format!("the document is {}, not a JSON object", json::kind_of(&value))));
    };
    for extension in json::extensions_required(&root).map_err(|e| malformed(path, "glTF", e))? {
        if DECODED_EXTENSIONS.contains(&extension.as_str()) || IGNORED_EXTENSION_PREFIXES.iter().any(|p| extension.starts_with(p)) {
            continue;
        }
        if extension == DRACO {
            return Err(draco(path));
        }
        return Err(unsupported(
            path,
            format!("the glTF extension {extension}, which the file requires,"),
            "ssm decodes KHR_mesh_quantization and EXT_meshopt_compression; re-export the model without that extension",
        ));
    }
    Ok(root)
}

fn draco(path: &Path) -> SceneError {
    unsupported(
        path,
        format!("Draco mesh compression (the glTF extension {DRACO})"),
        "ssm has no Draco decoder; re-export the model without Draco compression",
    )
}

/// Decodes base64 (standard or URL-safe alphabet, padding optional, whitespace ignored).
fn base64(text: &[u8]) -> Option<Vec<u8>> {
    let mut out = Vec::with_capacity(text.len() / 4 * 3);
    let (mut bits, mut count) = (0u32, 0);
    for &c in text {
        let value = match c {
            b'A'..=b'Z' => c - b'A',
            b'a'..=b'z' => c - b'a' + 26,
            b'0'..=b'9' => c - b'0' + 52,
            b'+' | b'-' => 62,
            b'/' | b'_' => 63,
            b'=' => break,
            c if c.is_ascii_whitespace() => continue,
            _ => return None,
        };
        bits = (bits << 6) | u32::from(value);
        count += 1;
        if count == 4 {
            out.extend_from_slice(&[(bits >> 16) as u8, (bits >> 8) as u8, bits as u8]);
            (bits, count) = (0, 0);
        }
    }
    match count {
        0 => {}
        2 => out.push((bits >> 4) as u8),
        3 => out.extend_from_slice(&[(bits >> 10) as u8, (bits >> 2) as u8]),
        _ => return None,
    }
    Some(out)
}

/// Undoes a URI's `%XX` escapes (glTF URIs are RFC 3986 references).
fn percent_decode(uri: &str) -> String {
    let bytes = uri.as_bytes();
    let mut out = Vec::with_capacity(bytes.len());
    let mut k = 0;
    while k < bytes.len() {
        let hex = |b: u8| (b as char).to_digit(16);
        if bytes[k] == b'%'
            && let (Some(h), Some(l)) = (bytes.get(k + 1).and_then(|&b| hex(b)), bytes.get(k + 2).and_then(|&b| hex(b)))
        {
            out.push((h * 16 + l) as u8);
            k += 3;
        } else {
            out.push(bytes[k]);
            k += 1;
        }
    }
    String::from_utf8(out).unwrap_or_else(|_| uri.to_owned())
}

/// The document's elements, deserialized on first use, with its buffers and decoded views.
struct Document<'a> {
    path: &'a Path,
    base: &'a Path,
    blob: Option<&'a [u8]>,
    accessors: Table<'a, Accessor>,
    views: Table<'a, buffer::View>,
    buffer_definitions: Table<'a, Buffer>,
    meshes: Table<'a, MeshDef>,
    nodes: Table<'a, Node>,
    scenes: Table<'a, Scene>,
    cameras: Table<'a, CameraDef>,
    buffers: HashMap<usize, Data<'a>>,
    decoded_views: HashMap<usize, Data<'a>>,
    /// Elements that may still be read (see [`FREE_ELEMENTS`]), and how many that was in all.
    allowance: u64,
    read_limit: u64,
}

/// A buffer's bytes: the GLB's binary chunk, or bytes read or decoded here.
#[derive(Clone)]
enum Data<'a> {
    Blob(&'a [u8]),
    Owned(Rc<Vec<u8>>),
}

impl Data<'_> {
    fn bytes(&self) -> &[u8] {
        match self {
            Self::Blob(bytes) => bytes,
            Self::Owned(bytes) => bytes,
        }
    }
}

/// The bytes of a buffer view: its buffer and the view's range in it.
struct ViewBytes<'a> {
    data: Data<'a>,
    start: usize,
    end: usize,
}

impl ViewBytes<'_> {
    fn bytes(&self) -> &[u8] {
        &self.data.bytes()[self.start..self.end]
    }
}

impl<'a> Document<'a> {
    fn error(&self, message: impl std::fmt::Display) -> SceneError {
        malformed(self.path, "glTF", message)
    }

    fn buffer(&mut self, index: usize) -> Result<Data<'a>> {
        if let Some(data) = self.buffers.get(&index) {
            return Ok(data.clone());
        }
        let buffer = self.buffer_definitions.get(index).map_err(|e| self.error(e))?;
        let byte_length = buffer.byte_length.0;
        let data = match (buffer.uri.as_deref(), self.blob) {
            (None, Some(blob)) if index == 0 => Data::Blob(blob),
            (None, _) => return Err(self.error(format!("buffer {index} has no `uri` and is not the binary chunk of a .glb"))),
            (Some(uri), _) if uri.starts_with("data:") => {
                let encoded = uri.split_once(";base64,").map(|(_, data)| data).ok_or_else(|| {
                    self.error(format!("buffer {index}: the data URI is not base64 (`{}...`)", uri.chars().take(40).collect::<String>()))
                })?;
                Data::Owned(Rc::new(
                    base64(encoded.as_bytes()).ok_or_else(|| self.error(format!("buffer {index}: the data URI is not valid base64")))?,
                ))
            }
            (Some(uri), _) if uri.contains("://") => {
                return Err(self.error(format!("buffer {index} refers to `{uri}`: only files beside the model are read")));
            }
            (Some(uri), _) => Data::Owned(Rc::new(self.read_file(index, uri, byte_length)?)),
        };
        let length = data.bytes().len();
        if (length as u64) < byte_length {
            return Err(self.error(format!("buffer {index} holds {length} bytes but declares byteLength {byte_length}")));
        }
        if !matches!(data, Data::Blob(_)) {
            self.allowance = self.allowance.saturating_add(ELEMENTS_PER_BYTE.saturating_mul(length as u64));
            self.read_limit = self.read_limit.saturating_add(ELEMENTS_PER_BYTE.saturating_mul(length as u64));
        }
        self.buffers.insert(index, data.clone());
        Ok(data)
    }

    /// Reads at most `length` bytes of the file a buffer refers to.
    fn read_file(&self, index: usize, uri: &str, length: u64) -> Result<Vec<u8>> {
        let decoded = self.base.join(percent_decode(uri));
        // Some exporters write spaces and other characters unescaped: try the URI as written too.
        let file: PathBuf = if !decoded.exists() && self.base.join(uri).exists() { self.base.join(uri) } else { decoded };
        let missing = |source: std::io::Error| SceneError::MissingReference {
            file: self.path.into(),
            element: format!("buffer {index}"),
            referenced: file.clone(),
            source,
        };
        let metadata = std::fs::metadata(&file).map_err(missing)?;
        if !metadata.is_file() {
            return Err(missing(std::io::Error::new(std::io::ErrorKind::InvalidInput, "not a regular file")));
        }
        let mut data = Vec::with_capacity(length.min(metadata.len()) as usize);
        std::fs::File::open(&file).and_then(|f| f.take(length).read_to_end(&mut data)).map_err(missing)?;
        Ok(data)
    }

    /// The view's compression extension, if it has one: its name and its object.
    fn meshopt(&self, index: usize, view: &buffer::View) -> Result<Option<(&'static str, Meshopt)>> {
        let Some(extensions) = &view.extensions else {
            return Ok(None);
        };
        let Some((name, value)) = meshopt::EXTENSIONS.iter().find_map(|name| extensions.others.get(*name).map(|value| (*name, value)))
        else {
            return Ok(None);
        };
        let extension = Meshopt::deserialize(value).map_err(|e| self.error(format!("bufferView {index}: {name}: {e}")))?;
        Ok(Some((name, extension)))
    }

    fn view(&mut self, index: usize) -> Result<ViewBytes<'a>> {
        if let Some(data) = self.decoded_views.get(&index) {
            return Ok(ViewBytes { end: data.bytes().len(), data: data.clone(), start: 0 });
        }
        let view = self.views.get(index).map_err(|e| self.error(e))?;
        if let Some((name, extension)) = self.meshopt(index, &view)? {
            let buffer = extension.buffer.value();
            let source = self.buffer(buffer)?;
            let source = source.bytes();
            let range =
                extension.byte_offset.checked_add(extension.byte_length).filter(|&end| end <= source.len() as u64).ok_or_else(|| {
                    self.error(format!("bufferView {index}: its compressed bytes lie outside buffer {buffer} ({} bytes)", source.len()))
                })?;
            let compressed = &source[extension.byte_offset as usize..range as usize];
            let data = meshopt::decode(&extension, compressed)
                .map_err(|e| self.error(format!("bufferView {index} ({name}, {} mode): {e}", extension.mode)))?;
            let data = Data::Owned(Rc::new(data));
            self.decoded_views.insert(index, data.clone());
            return Ok(ViewBytes { end: data.bytes().len(), data, start: 0 });
        }
        let data = self.buffer(view.buffer.value())?;
        let length = data.bytes().len();
        let (offset, byte_length) = (view.byte_offset.map_or(0, |o| o.0), view.byte_length.0);
        let end = offset.checked_add(byte_length).filter(|&end| end <= length as u64).ok_or_else(|| {
            self.error(format!(
                "bufferView {index} (bytes {offset}..+{byte_length}) lies outside buffer {} ({length} bytes)",
                view.buffer.value()
            ))
        })?;
        Ok(ViewBytes { start: offset as usize, end: end as usize, data })
    }

    /// The accessor's elements, each as `components` numbers (normalised integers mapped to
    /// [-1, 1] or [0, 1]), sparse substitutions applied. It must be of type `expected`;
    /// `what` names it in messages.
    fn read(&mut self, index: usize, expected: Type, what: &str) -> Result<Vec<f64>> {
        let path = self.path;
        let accessor = self.accessors.get(index).map_err(|e| self.error(format!("{what}: {e}")))?;
        let at = |message: String| malformed(path, "glTF", format!("{what}: accessor {index}: {message}"));
        if accessor.type_ != Checked::Valid(expected) {
            return Err(at(format!("type {} is not {}", self.accessors.shown(index, "/type"), type_name(expected))));
        }
        let components = expected.multiplicity();
        let Checked::Valid(GenericComponentType(component_type)) = accessor.component_type else {
            return Err(at(format!("componentType {} is not valid", self.accessors.shown(index, "/componentType"))));
        };
        let component = component_type.size();
        let element = components * component;
        let count = accessor.count.0;
        if count > self.allowance {
            return Err(at(format!(
                "its {count} elements would take the file past {} elements read in all, more than a file of its size can hold",
                self.read_limit
            )));
        }
        self.allowance -= count;
        let byte_offset = accessor.byte_offset.map_or(0, |o| o.0);
        let mut values: Vec<f64>;
        match accessor.buffer_view.map(|v| v.value()) {
            Some(view_index) => {
                let view = self.view(view_index)?;
                let declared_stride = self.views.get(view_index).ok().and_then(|v| v.byte_stride).map(|s| s.0 as u64);
                let stride = declared_stride.unwrap_or(element as u64);
                if stride < element as u64 {
                    return Err(at(format!(
                        "byteStride {stride} of bufferView {view_index} is smaller than one element ({element} bytes)"
                    )));
                }
                let bytes = view.bytes();
                let needed = if count == 0 {
                    Some(0)
                } else {
                    (count - 1).checked_mul(stride).and_then(|n| n.checked_add(byte_offset)).and_then(|n| n.checked_add(element as u64))
                };
                if needed.is_none_or(|n| n > bytes.len() as u64) {
                    return Err(at(format!(
                        "{count} elements of {element} bytes from byte {byte_offset} with stride {stride} do not fit in bufferView {view_index} ({} bytes)",
                        bytes.len()
                    )));
                }
                values = Vec::with_capacity(count as usize * components);
                for k in 0..count as usize {
                    let start = byte_offset as usize + k * stride as usize;
                    for c in 0..components {
                        let at = start + c * component;
                        values.push(decode_component(&bytes[at..at + component], component_type, accessor.normalized));
                    }
                }
            }
            None if accessor.sparse.is_none() => {
                return Err(at("it has neither a bufferView nor sparse values".into()));
            }
            None => values = vec![0.0; count as usize * components],
        }
        if let Some(sparse) = &accessor.sparse {
            let sparse_count = sparse.count.0;
            if sparse_count > count {
                return Err(at(format!("{sparse_count} sparse values for {count} elements")));
            }
            let Checked::Valid(IndexComponentType(index_type)) = sparse.indices.component_type else {
                return Err(at(format!(
                    "sparse componentType {} is not valid: sparse indices are unsigned bytes, shorts or ints",
                    self.accessors.shown(index, "/sparse/indices/componentType")
                )));
            };
            let indices =
                self.read_plain(sparse.indices.buffer_view.value(), sparse.indices.byte_offset.0, sparse_count, 1, index_type, false, &at)?;
            let replacements = self.read_plain(
                sparse.values.buffer_view.value(),
                sparse.values.byte_offset.0,
                sparse_count,
                components,
                component_type,
                accessor.normalized,
                &at,
            )?;
            for (k, &target) in indices.iter().enumerate() {
                if target >= count as f64 {
                    return Err(at(format!("sparse index {target} is out of range: the accessor has {count} elements")));
                }
                let target = target as usize;
                values[target * components..(target + 1) * components].copy_from_slice(&replacements[k * components..(k + 1) * components]);
            }
        }
        Ok(values)
    }

    /// Tightly packed elements (sparse indices and values).
    #[allow(clippy::too_many_arguments)]
    fn read_plain(
        &mut self,
        view_index: usize,
        offset: u64,
        count: u64,
        components: usize,
        component_type: ComponentType,
        normalized: bool,
        at: &dyn Fn(String) -> SceneError,
    ) -> Result<Vec<f64>> {
        let component = component_type.size();
        let view = self.view(view_index)?;
        let bytes = view.bytes();
        let size = (components * component) as u64;
        if count.checked_mul(size).and_then(|n| n.checked_add(offset)).is_none_or(|end| end > bytes.len() as u64) {
            return Err(at(format!("{count} sparse elements do not fit in bufferView {view_index} ({} bytes)", bytes.len())));
        }
        let bytes = &bytes[offset as usize..(offset + count * size) as usize];
        Ok(bytes.chunks_exact(component).map(|c| decode_component(c, component_type, normalized)).collect())
    }
}

/// glTF's name of an accessor type (`VEC3`), as gltf-json writes it.
fn type_name(kind: Type) -> String {
    match serde_json::to_value(kind) {
        Ok(Value::String(name)) => name,
        _ => format!("{kind:?}"),
    }
}

/// One little-endian component; `bytes` has exactly its size.
fn decode_component(bytes: &[u8], component_type: ComponentType, normalized: bool) -> f64 {
    match (component_type, normalized) {
        (ComponentType::I8, false) => f64::from(bytes[0] as i8),
        (ComponentType::I8, true) => (f64::from(bytes[0] as i8) / 127.0).max(-1.0),
        (ComponentType::U8, false) => f64::from(bytes[0]),
        (ComponentType::U8, true) => f64::from(bytes[0]) / 255.0,
        (ComponentType::I16, false) => f64::from(i16::from_le_bytes([bytes[0], bytes[1]])),
        (ComponentType::I16, true) => (f64::from(i16::from_le_bytes([bytes[0], bytes[1]])) / 32767.0).max(-1.0),
        (ComponentType::U16, false) => f64::from(u16::from_le_bytes([bytes[0], bytes[1]])),
        (ComponentType::U16, true) => f64::from(u16::from_le_bytes([bytes[0], bytes[1]])) / 65535.0,
        (ComponentType::U32, false) => f64::from(u32::from_le_bytes([bytes[0], bytes[1], bytes[2], bytes[3]])),
        (ComponentType::U32, true) => f64::from(u32::from_le_bytes([bytes[0], bytes[1], bytes[2], bytes[3]])) / f64::from(u32::MAX),
        (ComponentType::F32, _) => f64::from(f32::from_le_bytes([bytes[0], bytes[1], bytes[2], bytes[3]])),
    }
}

fn to_vec3(values: &[f64]) -> Vec<Vec3> {
    values.chunks_exact(3).map(|v| Vec3::new(v[0] as f32, v[1] as f32, v[2] as f32)).collect()
}

fn local_transform(node: &Node) -> Mat4 {
    if let Some(matrix) = node.matrix {
        return Mat4::from_cols_array(&matrix);
    }
    let rotation = Quat::from_array(node.rotation.map_or([0.0, 0.0, 0.0, 1.0], |q| q.0));
    // Exporters round quaternions: renormalise (a zero or non-finite one stays as it is and fails validation).
    let rotation = if rotation.length() > 0.0 { rotation.normalize() } else { rotation };
    Mat4::from_scale_rotation_translation(
        Vec3::from_array(node.scale.unwrap_or([1.0; 3])),
        rotation,
        Vec3::from_array(node.translation.unwrap_or([0.0; 3])),
    )
}

pub(super) fn load(path: &Path, bytes: &[u8]) -> Result<LoadedModel> {
    let (json, blob) = split_glb(path, bytes)?;
    let root = parse_document(path, json)?;
    let base = path.parent().unwrap_or_else(|| Path::new("."));
    let allowance = FREE_ELEMENTS.saturating_add(ELEMENTS_PER_BYTE.saturating_mul(bytes.len() as u64));
    let error = |message: String| malformed(path, "glTF", message);
    let mut document = Document {
        path,
        base,
        blob,
        accessors: Table::new(&root).map_err(error)?,
        views: Table::new(&root).map_err(error)?,
        buffer_definitions: Table::new(&root).map_err(error)?,
        meshes: Table::new(&root).map_err(error)?,
        nodes: Table::new(&root).map_err(error)?,
        scenes: Table::new(&root).map_err(error)?,
        cameras: Table::new(&root).map_err(error)?,
        buffers: HashMap::new(),
        decoded_views: HashMap::new(),
        allowance,
        read_limit: allowance,
    };
    let default_scene = json::default_scene(&root).map_err(error)?.map(|scene| scene.value());

    let (placements, cameras) = place_nodes(&document, default_scene)?;
    // Only meshes that some node places are decoded; they are numbered in order of first use.
    let mut loaded = LoadedModel { cameras, ..LoadedModel::default() };
    let mut numbering: HashMap<usize, usize> = HashMap::new();
    for (mesh_index, transform, node_name) in placements {
        let mesh = match numbering.get(&mesh_index) {
            Some(&mesh) => mesh,
            None => {
                loaded.meshes.push(read_mesh(&mut document, mesh_index)?);
                numbering.insert(mesh_index, loaded.meshes.len() - 1);
                loaded.meshes.len() - 1
            }
        };
        let node_name = node_name.unwrap_or_else(|| loaded.meshes[mesh].name.clone());
        loaded.placements.push(Placement { mesh, transform, node_name });
    }
    Ok(loaded)
}

/// Placements (glTF mesh index, world transform, node name) and cameras of the default scene.
type Placements = Vec<(usize, Mat4, Option<String>)>;

/// Walks the node hierarchy of `scene` (the root's `scene`, else the first scene, else every
/// node that is nobody's child).
fn place_nodes(document: &Document<'_>, scene: Option<usize>) -> Result<(Placements, Vec<Camera>)> {
    let path = document.path;
    let (nodes, meshes, scenes, cameras_defined) = (&document.nodes, &document.meshes, &document.scenes, &document.cameras);
    let error = |message: String| malformed(path, "glTF", message);
    let mut placements = Vec::new();
    let mut cameras = Vec::new();
    if nodes.is_empty() && scenes.is_empty() {
        // No node at all: every mesh stands where it was modelled.
        for index in 0..meshes.len() {
            placements.push((index, Mat4::IDENTITY, None));
        }
        return Ok((placements, cameras));
    }
    let roots: Vec<usize> = match scene.or(if scenes.is_empty() { None } else { Some(0) }) {
        Some(scene) => scenes.get(scene).map_err(error)?.nodes.iter().map(|n| n.value()).collect(),
        None => {
            // No scene: every node that is nobody's child is a root.
            let mut is_child = vec![false; nodes.len()];
            for index in 0..nodes.len() {
                for child in nodes.get(index).map_err(error)?.children.iter().flatten() {
                    if let Some(flag) = is_child.get_mut(child.value()) {
                        *flag = true;
                    }
                }
            }
            (0..nodes.len()).filter(|&n| !is_child[n]).collect()
        }
    };
    // Depth-first with an explicit stack (no recursion limit to hit). `lineage` holds the current
    // node's ancestors, so a cycle is found, not followed.
    let mut stack: Vec<(usize, Mat4, usize)> = roots.iter().rev().map(|&n| (n, Mat4::IDENTITY, 0)).collect();
    let mut lineage: Vec<usize> = Vec::new();
    let mut on_path = vec![false; nodes.len()];
    let mut visits = 0;
    while let Some((index, parent, depth)) = stack.pop() {
        while lineage.len() > depth {
            if let Some(left) = lineage.pop() {
                on_path[left] = false;
            }
        }
        // `get` succeeds only for an index below `nodes.len()`, the length of `on_path`.
        let node = nodes.get(index).map_err(error)?;
        if on_path[index] {
            return Err(SceneError::NodeCycle { file: path.into(), node: index, name: node.name.clone().unwrap_or_default() });
        }
        visits += 1;
        if visits > MAX_PLACEMENTS {
            return Err(error(format!("the node hierarchy shares children and expands to more than {MAX_PLACEMENTS} nodes")));
        }
        lineage.push(index);
        on_path[index] = true;
        let world = parent * local_transform(&node);
        if let Some(mesh) = node.mesh.map(|m| m.value()) {
            if mesh >= meshes.len() {
                return Err(error(format!("node {index} refers to mesh {mesh}, but the file has {} meshes", meshes.len())));
            }
            placements.push((mesh, world, node.name.clone()));
        }
        if let Some(camera) = node.camera.map(|c| c.value()) {
            if camera >= cameras_defined.len() {
                return Err(error(format!("node {index} refers to camera {camera}, but the file has {}", cameras_defined.len())));
            }
            let definition = cameras_defined.get(camera).map_err(error)?;
            if let Some(perspective) = &definition.perspective {
                let position = world.transform_point3(Vec3::ZERO);
                // glTF cameras look down their local -Z with +Y up.
                let forward = world.transform_vector3(-Vec3::Z).normalize_or(-Vec3::Z);
                let up = world.transform_vector3(Vec3::Y).normalize_or(Vec3::Y);
                let near = perspective.znear;
                cameras.push(Camera {
                    position,
                    target: position + forward,
                    up,
                    fov_y: perspective.yfov,
                    near,
                    far: perspective.zfar.unwrap_or(near * 1.0e4),
                });
            }
        }
        for child in node.children.iter().flatten().rev() {
            stack.push((child.value(), world, depth + 1));
        }
    }
    Ok((placements, cameras))
}

/// One glTF mesh, its triangle primitives concatenated.
fn read_mesh(document: &mut Document<'_>, mesh_index: usize) -> Result<Mesh> {
    let path = document.path;
    let definition = document.meshes.get(mesh_index).map_err(|e| malformed(path, "glTF", e))?;
    let name = definition.name.clone().unwrap_or_else(|| format!("mesh-{mesh_index}"));
    let mut mesh = Mesh { name: name.clone(), ..Mesh::default() };
    let mut normals_complete = true;
    for (primitive_index, primitive) in definition.primitives.iter().enumerate() {
        let what = format!("mesh `{name}` primitive {primitive_index}");
        let mode = match primitive.mode {
            // Points and lines cast no shadows.
            Checked::Valid(Mode::Points | Mode::Lines | Mode::LineLoop | Mode::LineStrip) => continue,
            Checked::Valid(mode) => mode,
            Checked::Invalid => {
                let mode = document.meshes.shown(mesh_index, &format!("/primitives/{primitive_index}/mode"));
                return Err(malformed(path, "glTF", format!("{what}: mode {mode} is not a glTF primitive mode")));
            }
        };
        let Some(position_accessor) = primitive.attributes.get(&Checked::Valid(Semantic::Positions)).map(|a| a.value()) else {
            return Err(malformed(path, "glTF", format!("{what} has no POSITION")));
        };
        if primitive.extensions.as_ref().is_some_and(|e| e.others.contains_key(DRACO))
            && document.accessors.get(position_accessor).is_ok_and(|a| a.buffer_view.is_none() && a.sparse.is_none())
        {
            // Draco-compressed, without the optional uncompressed fallback.
            return Err(draco(path));
        }
        let values = document.read(position_accessor, Type::Vec3, &format!("{what} POSITION"))?;
        let positions = to_vec3(&values);
        let count = positions.len();
        let local: Vec<u32> = match primitive.indices.map(|i| i.value()) {
            Some(accessor) => {
                let unsigned = |a: &Accessor| {
                    matches!(
                        a.component_type,
                        Checked::Valid(GenericComponentType(ComponentType::U8 | ComponentType::U16 | ComponentType::U32))
                    )
                };
                // A missing or malformed accessor is named by `read`.
                if document.accessors.get(accessor).is_ok_and(|a| !unsigned(&a)) {
                    return Err(malformed(path, "glTF", format!("{what}: indices must be unsigned bytes, shorts or ints")));
                }
                let values = document.read(accessor, Type::Scalar, &format!("{what} indices"))?;
                check_indices(path, &name, values.iter().map(|&i| i as u64), count)?;
                values.iter().map(|&i| i as u32).collect()
            }
            None => (0..count as u32).collect(),
        };
        let triangles = match mode {
            Mode::TriangleStrip => strip_to_list(&local),
            Mode::TriangleFan => fan_to_list(&local),
            _ => local.chunks_exact(3).flatten().copied().collect(),
        };
        let base_vertex = mesh.positions.len() as u32;
        match primitive.attributes.get(&Checked::Valid(Semantic::Normals)).map(|a| a.value()) {
            Some(accessor) => {
                let values = document.read(accessor, Type::Vec3, &format!("{what} NORMAL"))?;
                let normals = to_vec3(&values);
                if normals.len() == count {
                    mesh.normals.extend(normals.iter().map(|n| n.normalize_or(Vec3::Y)));
                } else {
                    normals_complete = false;
                }
            }
            None => normals_complete = false,
        }
        mesh.positions.extend(positions);
        mesh.indices.extend(triangles.into_iter().map(|i| i + base_vertex));
    }
    if !normals_complete || mesh.normals.len() != mesh.positions.len() {
        mesh.normals = generate_normals(&mesh.positions, &mesh.indices);
    }
    Ok(mesh)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn base64_round_trips_with_and_without_padding() {
        assert_eq!(base64(b"aGVsbG8=").as_deref(), Some(&b"hello"[..]));
        assert_eq!(base64(b"aGVsbG8").as_deref(), Some(&b"hello"[..]));
        assert_eq!(base64(b"aGVs bG8h").as_deref(), Some(&b"hello!"[..]));
        assert_eq!(base64(b"a"), None);
        assert_eq!(base64(b"a*=="), None);
    }

    #[test]
    fn uris_are_percent_decoded() {
        assert_eq!(percent_decode("my%20model.bin"), "my model.bin");
        assert_eq!(percent_decode("100%.bin"), "100%.bin");
    }

    /// A unit square (two triangles) with its buffer in a data URI, and `extra` members at the root.
    fn square(extra: &str) -> String {
        let mut bytes: Vec<u8> = [[0.0f32, 0.0, 0.0], [1.0, 0.0, 0.0], [1.0, 0.0, 1.0], [0.0, 0.0, 1.0]]
            .iter()
            .flatten()
            .flat_map(|c| c.to_le_bytes())
            .collect();
        bytes.extend([0u16, 2, 1, 0, 3, 2].iter().flat_map(|i| i.to_le_bytes()));
        const ALPHABET: &[u8] = b"ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
        let encoded: String = bytes
            .chunks(3)
            .flat_map(|c| {
                let n = (u32::from(c[0]) << 16) | (u32::from(*c.get(1).unwrap_or(&0)) << 8) | u32::from(*c.get(2).unwrap_or(&0));
                (0..=c.len()).map(move |k| ALPHABET[(n >> (18 - 6 * k)) as usize & 63] as char)
            })
            .collect();
        format!(
            r#"{{"asset": {{"version": "2.0"}}, "scene": 0, "scenes": [{{"nodes": [0]}}],
            "nodes": [{{"name": "square", "mesh": 0}}],
            "meshes": [{{"primitives": [{{"attributes": {{"POSITION": 0}}, "indices": 1, "mode": 4}}]}}],
            "buffers": [{{"uri": "data:application/octet-stream;base64,{encoded}", "byteLength": 60}}],
            "bufferViews": [{{"buffer": 0, "byteLength": 48}}, {{"buffer": 0, "byteOffset": 48, "byteLength": 12}}],
            "accessors": [{{"bufferView": 0, "componentType": 5126, "count": 4, "type": "VEC3"}},
                          {{"bufferView": 1, "componentType": 5123, "count": 6, "type": "SCALAR"}}]{extra}}}"#
        )
    }

    fn outcome(text: &str) -> Result<usize, String> {
        load(Path::new("t.gltf"), text.as_bytes()).map(|m| m.meshes.iter().map(Mesh::triangle_count).sum()).map_err(|e| e.to_string())
    }

    #[test]
    fn parts_that_ssm_never_reads_cannot_stop_a_file() {
        assert_eq!(outcome(&square("")), Ok(2));
        let unread = r#", "materials": [{"pbrMetallicRoughness": 5}], "animations": [{"channels": 7}], "textures": 3,
            "cameras": [{"perspective": "wide"}], "extras": {"mesh": 4294967296}"#;
        let text = square(unread)
            // A node no scene reaches, and accessors no primitive uses.
            .replace(r#"{"name": "square", "mesh": 0}"#, r#"{"name": "square", "mesh": 0}, "not a node""#)
            .replace(r#""type": "SCALAR"}"#, r#""type": "SCALAR"}, {"count": "many"}, {"componentType": 1}"#);
        assert_eq!(outcome(&text), Ok(2));
        // A scene without `nodes` (optional in glTF 2.0, required by gltf-json) is empty.
        assert_eq!(outcome(&square("").replace(r#"{"nodes": [0]}"#, "{}")), Ok(0));
    }

    #[test]
    fn an_error_in_a_part_that_ssm_reads_names_the_element() {
        let fails = |from: &str, to: &str, expected: &str| {
            let text = square("").replacen(from, to, 1);
            assert_ne!(text, square(""), "{from}");
            let message = outcome(&text).err().unwrap_or_default();
            assert!(message.starts_with("t.gltf: invalid glTF file: ") && message.contains(expected), "{to}: {message}");
        };
        fails(r#""componentType": 5126"#, r#""componentType": 5127"#, "primitive 0 POSITION: accessor 0: componentType 5127 is not valid");
        fails(r#""type": "VEC3""#, r#""type": "VEC7""#, "primitive 0 POSITION: accessor 0: type VEC7 is not VEC3");
        fails(r#""type": "SCALAR""#, r#""type": "VEC2""#, "primitive 0 indices: accessor 1: type VEC2 is not SCALAR");
        fails(r#""componentType": 5123"#, r#""componentType": 5122"#, "primitive 0: indices must be unsigned bytes, shorts or ints");
        fails(r#""count": 4,"#, "", "primitive 0 POSITION: accessor 0: missing field `count`");
        fails(r#""mode": 4"#, r#""mode": 9"#, "mesh `mesh-0` primitive 0: mode 9 is not a glTF primitive mode");
        fails(r#""byteLength": 60"#, r#""byteLen": 60"#, "buffer 0: missing field `byteLength`");
        fails(r#"{"buffer": 0, "byteLength": 48}"#, r#"{"buffer": 0}"#, "bufferView 0: missing field `byteLength`");
        fails(r#""nodes": [0]"#, r#""nodes": [3]"#, "node 3 does not exist: the file has 1");
        fails(r#""scene": 0"#, r#""scene": 2"#, "scene 2 does not exist: the file has 1");
        fails(r#""mesh": 0"#, r#""mesh": "square""#, "node 0: invalid type: string \"square\"");
        fails(r#""meshes": ["#, r#""meshes": {}, "x": ["#, "`meshes` is an object, not an array");
        // gltf-json reads indices and codes as u64 cut to u32: 2^32 would be element 0.
        fails(r#""POSITION": 0"#, r#""POSITION": 4294967296"#, "mesh 0: `attributes` 4294967296 is not a valid index or code");
        fails(r#""bufferView": 0"#, r#""bufferView": 4294967296"#, "accessor 0: `bufferView` 4294967296 is not a valid index or code");
        fails(r#""componentType": 5126"#, r#""componentType": 4294972422"#, "accessor 0: `componentType` 4294972422 is not a valid index");
        fails(r#""scene": 0"#, r#""scene": 4294967296"#, "`scene` 4294967296 is not a valid index");
    }
}
