//! Stanford PLY, ASCII and binary (both byte orders): our own reader.
//!
//! Why not `ply-rs-bw`: it stores every vertex and face as a map from
//! property name to value (hundreds of bytes per element), it hangs and then
//! runs out of memory on a header that declares billions of elements without
//! properties, its ASCII grammar refuses numbers such as `1.` and `nan`, and
//! its messages span several lines with a dump of its grammar state. This
//! reader keeps only what shadows need: `x`, `y`, `z` and, if present, `nx`,
//! `ny`, `nz` of `vertex`; the `vertex_indices` (or `vertex_index`) list of
//! `face`; and `tristrips` (strips separated by -1), as old Stanford scans
//! store them. Every other element and property (colours, texture
//! coordinates, confidence, `material`, `edge`...) is read past. Element
//! counts are checked against the bytes left before anything is allocated.

use std::path::Path;

use glam::{Mat4, Vec3};

use super::{LoadedModel, Placement, malformed};
use crate::error::{Result, SceneError};
use crate::mesh::{Mesh, generate_normals, strip_to_list};
use crate::polygon::triangulate;

#[derive(Clone, Copy, Debug, PartialEq)]
enum Scalar {
    I8,
    U8,
    I16,
    U16,
    I32,
    U32,
    F32,
    F64,
}

impl Scalar {
    fn parse(name: &str) -> Option<Self> {
        Some(match name {
            "char" | "int8" => Self::I8,
            "uchar" | "uint8" => Self::U8,
            "short" | "int16" => Self::I16,
            "ushort" | "uint16" => Self::U16,
            "int" | "int32" => Self::I32,
            "uint" | "uint32" => Self::U32,
            "float" | "float32" => Self::F32,
            "double" | "float64" => Self::F64,
            _ => return None,
        })
    }

    fn size(self) -> usize {
        match self {
            Self::I8 | Self::U8 => 1,
            Self::I16 | Self::U16 => 2,
            Self::I32 | Self::U32 | Self::F32 => 4,
            Self::F64 => 8,
        }
    }

    fn is_integer(self) -> bool {
        !matches!(self, Self::F32 | Self::F64)
    }
}

#[derive(Debug)]
enum Kind {
    Scalar(Scalar),
    List { count: Scalar, item: Scalar },
}

#[derive(Debug)]
struct Property {
    name: String,
    kind: Kind,
}

#[derive(Debug)]
struct Element {
    name: String,
    count: u64,
    properties: Vec<Property>,
}

impl Element {
    /// The fewest bytes one entry takes in a binary file.
    fn min_binary_size(&self) -> u64 {
        self.properties
            .iter()
            .map(|p| match p.kind {
                Kind::Scalar(s) => s.size() as u64,
                Kind::List { count, .. } => count.size() as u64,
            })
            .sum()
    }

    fn property(&self, names: &[&str]) -> Option<usize> {
        names.iter().find_map(|name| self.properties.iter().position(|p| p.name == *name))
    }
}

#[derive(Clone, Copy, PartialEq)]
enum Format {
    Ascii,
    Binary { big_endian: bool },
}

/// The payload after the header, read value by value.
struct Payload<'a> {
    bytes: &'a [u8],
    position: usize,
    format: Format,
    /// 1-based line of the next ASCII token, for messages.
    line: usize,
}

impl Payload<'_> {
    fn remaining(&self) -> usize {
        self.bytes.len() - self.position
    }

    fn read(&mut self, scalar: Scalar) -> std::result::Result<f64, String> {
        match self.format {
            Format::Ascii => self.read_ascii(scalar),
            Format::Binary { big_endian } => {
                let size = scalar.size();
                let Some(raw) = self.bytes.get(self.position..self.position + size) else {
                    return Err("the file ends early".into());
                };
                self.position += size;
                let mut b = [0u8; 8];
                b[..size].copy_from_slice(raw);
                if big_endian {
                    b[..size].reverse();
                }
                Ok(match scalar {
                    Scalar::I8 => f64::from(b[0] as i8),
                    Scalar::U8 => f64::from(b[0]),
                    Scalar::I16 => f64::from(i16::from_le_bytes([b[0], b[1]])),
                    Scalar::U16 => f64::from(u16::from_le_bytes([b[0], b[1]])),
                    Scalar::I32 => f64::from(i32::from_le_bytes([b[0], b[1], b[2], b[3]])),
                    Scalar::U32 => f64::from(u32::from_le_bytes([b[0], b[1], b[2], b[3]])),
                    Scalar::F32 => f64::from(f32::from_le_bytes([b[0], b[1], b[2], b[3]])),
                    Scalar::F64 => f64::from_le_bytes(b),
                })
            }
        }
    }

    fn read_ascii(&mut self, scalar: Scalar) -> std::result::Result<f64, String> {
        while let Some(&b) = self.bytes.get(self.position) {
            if !b.is_ascii_whitespace() {
                break;
            }
            // `\n`, `\r\n` and a lone `\r` each end one line.
            let after_cr = b == b'\n' && self.position > 0 && self.bytes[self.position - 1] == b'\r';
            if (b == b'\n' || b == b'\r') && !after_cr {
                self.line += 1;
            }
            self.position += 1;
        }
        let start = self.position;
        while self.bytes.get(self.position).is_some_and(|b| !b.is_ascii_whitespace()) {
            self.position += 1;
        }
        if start == self.position {
            return Err("the file ends early".into());
        }
        let word = String::from_utf8_lossy(&self.bytes[start..self.position]);
        let value: f64 = word.parse().map_err(|_| format!("line {}: `{word}` is not a number", self.line))?;
        if scalar.is_integer() && value.fract() != 0.0 {
            return Err(format!("line {}: `{word}` is not an integer", self.line));
        }
        Ok(value)
    }

    /// A list's length, checked against what is left of the file.
    fn read_count(&mut self, count: Scalar, item: Scalar) -> std::result::Result<usize, String> {
        let n = self.read(count)?;
        if !(0.0..=u32::MAX as f64).contains(&n) {
            return Err(format!("list length {n} is invalid"));
        }
        let n = n as usize;
        let least = match self.format {
            Format::Ascii => n,
            Format::Binary { .. } => n * item.size(),
        };
        if least > self.remaining() {
            return Err(format!("a list of {n} values does not fit in the {} bytes left", self.remaining()));
        }
        Ok(n)
    }
}

struct Header {
    format: Format,
    elements: Vec<Element>,
    /// Where the payload starts.
    end: usize,
}

fn parse_header(path: &Path, bytes: &[u8]) -> Result<Header> {
    let error = |line: usize, message: String| malformed(path, "PLY", format!("header line {line}: {message}"));
    let mut position = 0;
    let mut format = None;
    let mut elements: Vec<Element> = Vec::new();
    let mut line_number = 0;
    loop {
        if position >= bytes.len() {
            return Err(malformed(path, "PLY", "the header has no `end_header` line"));
        }
        line_number += 1;
        let end = bytes[position..].iter().position(|&b| b == b'\n' || b == b'\r').map_or(bytes.len(), |e| position + e);
        let line = String::from_utf8_lossy(&bytes[position..end]);
        position = match bytes.get(end) {
            Some(b'\r') if bytes.get(end + 1) == Some(&b'\n') => end + 2,
            Some(_) => end + 1,
            None => end,
        };
        let words: Vec<&str> = line.split_ascii_whitespace().collect();
        if line_number == 1 {
            if words != ["ply"] {
                return Err(malformed(path, "PLY", "not a PLY file: it does not start with a `ply` line"));
            }
            continue;
        }
        match words.as_slice() {
            [] | ["comment" | "obj_info", ..] => {}
            ["format", encoding, ..] => {
                format = Some(match *encoding {
                    "ascii" => Format::Ascii,
                    "binary_little_endian" => Format::Binary { big_endian: false },
                    "binary_big_endian" => Format::Binary { big_endian: true },
                    other => return Err(error(line_number, format!("unknown format `{other}`"))),
                });
            }
            ["element", name, count] => {
                let count = count.parse().map_err(|_| error(line_number, format!("element count `{count}` is not a number")))?;
                elements.push(Element { name: (*name).to_owned(), count, properties: Vec::new() });
            }
            ["property", rest @ ..] => {
                let Some(element) = elements.last_mut() else {
                    return Err(error(line_number, "a property comes before any element".into()));
                };
                let scalar = |name: &str| Scalar::parse(name).ok_or_else(|| error(line_number, format!("unknown property type `{name}`")));
                let (kind, name) = match rest {
                    ["list", count, item, name] => (Kind::List { count: scalar(count)?, item: scalar(item)? }, name),
                    [ty, name] => (Kind::Scalar(scalar(ty)?), name),
                    _ => return Err(error(line_number, format!("cannot read `{}`", line.trim()))),
                };
                element.properties.push(Property { name: (*name).to_owned(), kind });
            }
            ["end_header"] => break,
            _ => return Err(error(line_number, format!("cannot read `{}`", line.trim()))),
        }
    }
    let format = format.ok_or_else(|| malformed(path, "PLY", "the header has no `format` line"))?;
    Ok(Header { format, elements, end: position })
}

pub(super) fn load(path: &Path, bytes: &[u8]) -> Result<LoadedModel> {
    let bytes = bytes.strip_prefix(b"\xEF\xBB\xBF").unwrap_or(bytes);
    let header = parse_header(path, bytes)?;
    let name = path.file_stem().and_then(|s| s.to_str()).unwrap_or("ply").to_owned();
    if !header.elements.iter().any(|e| e.name == "vertex") {
        return Err(malformed(path, "PLY", "no `vertex` element"));
    }
    if !header.elements.iter().any(|e| e.name == "face" || e.name == "tristrips") {
        return Err(malformed(path, "PLY", "no `face` element (point clouds cast no shadows)"));
    }

    let mut payload = Payload { bytes, position: header.end, format: header.format, line: 1 + count_lines(&bytes[..header.end]) };
    let mut positions: Vec<Vec3> = Vec::new();
    let mut file_normals: Vec<Vec3> = Vec::new();
    // Polygons as corner lists (`sizes` gives each one's length) and strips, validated once every vertex is known.
    let mut corners: Vec<i64> = Vec::new();
    let mut sizes: Vec<usize> = Vec::new();
    let mut strips: Vec<i64> = Vec::new();
    for element in &header.elements {
        if element.properties.is_empty() {
            continue;
        }
        if let Format::Binary { .. } = header.format
            && element.count.checked_mul(element.min_binary_size()).is_none_or(|least| least > payload.remaining() as u64)
        {
            return Err(malformed(
                path,
                "PLY",
                format!(
                    "element `{}` declares {} entries of at least {} bytes, but only {} bytes follow the header",
                    element.name,
                    element.count,
                    element.min_binary_size(),
                    payload.remaining()
                ),
            ));
        }
        // Capacity is bounded by the file's size, whatever the header claims.
        let capacity = (element.count as usize).min(payload.remaining());
        let role = match element.name.as_str() {
            "vertex" => {
                let [x, y, z] = ["x", "y", "z"].map(|axis| element.property(&[axis]));
                let (Some(x), Some(y), Some(z)) = (x, y, z) else {
                    return Err(malformed(path, "PLY", "element `vertex` lacks one of the properties `x`, `y` and `z`"));
                };
                positions.reserve(capacity);
                Role::Vertex([x, y, z])
            }
            "face" => match element.property(&["vertex_indices", "vertex_index"]) {
                Some(k) if matches!(element.properties[k].kind, Kind::List { .. }) => Role::Polygons(k),
                Some(_) => return Err(malformed(path, "PLY", "property `vertex_indices` of element `face` is not a list")),
                None => return Err(malformed(path, "PLY", "element `face` has no `vertex_indices` list")),
            },
            "tristrips" => match element.property(&["vertex_indices", "vertex_index"]) {
                Some(k) if matches!(element.properties[k].kind, Kind::List { .. }) => Role::Strips(k),
                _ => return Err(malformed(path, "PLY", "element `tristrips` has no `vertex_indices` list")),
            },
            _ => Role::Skip,
        };
        let normal_keys = ["nx", "ny", "nz"].map(|axis| element.property(&[axis]));
        let mut values = vec![0.0f64; element.properties.len()];
        for entry in 0..element.count {
            let at = |message: String| malformed(path, "PLY", format!("element `{}` entry {entry}: {message}", element.name));
            for (k, property) in element.properties.iter().enumerate() {
                match property.kind {
                    Kind::Scalar(scalar) => values[k] = payload.read(scalar).map_err(at)?,
                    Kind::List { count, item } => {
                        let n = payload.read_count(count, item).map_err(at)?;
                        let target = match role {
                            Role::Polygons(p) if p == k => Some(&mut corners),
                            Role::Strips(p) if p == k => Some(&mut strips),
                            _ => None,
                        };
                        match target {
                            Some(target) => {
                                for _ in 0..n {
                                    target.push(payload.read(item).map_err(at)? as i64);
                                }
                                if matches!(role, Role::Polygons(_)) {
                                    sizes.push(n);
                                } else {
                                    target.push(-1);
                                }
                            }
                            None => {
                                for _ in 0..n {
                                    payload.read(item).map_err(at)?;
                                }
                            }
                        }
                    }
                }
            }
            if let Role::Vertex(coordinates) = role {
                let [x, y, z] = coordinates.map(|k| values[k] as f32);
                positions.push(Vec3::new(x, y, z));
                if let [Some(nx), Some(ny), Some(nz)] = normal_keys {
                    file_normals.push(Vec3::new(values[nx] as f32, values[ny] as f32, values[nz] as f32));
                }
            }
        }
    }

    let count = positions.len();
    let check = |index: i64, position: usize| -> Result<u32> {
        u32::try_from(index).ok().filter(|&i| (i as usize) < count).ok_or_else(|| SceneError::InvalidIndex {
            file: path.into(),
            mesh: name.clone(),
            index: index as u64,
            position,
            count,
        })
    };
    let mut indices = Vec::with_capacity(corners.len());
    let mut polygon = Vec::new();
    let mut start = 0;
    for (face, &size) in sizes.iter().enumerate() {
        polygon.clear();
        for &corner in &corners[start..start + size] {
            polygon.push(check(corner, face)?);
        }
        triangulate(&positions, &polygon, &mut indices);
        start += size;
    }
    for (strip_number, strip) in strips.split(|&i| i < 0).enumerate() {
        let strip = strip.iter().map(|&i| check(i, strip_number)).collect::<Result<Vec<u32>>>()?;
        indices.extend(strip_to_list(&strip));
    }
    // File normals are kept where they are usable; the others are generated.
    let normals = if file_normals.len() == count && file_normals.iter().all(|n| n.try_normalize().is_some()) {
        file_normals.iter().map(|n| n.normalize()).collect()
    } else if file_normals.len() == count {
        let generated = generate_normals(&positions, &indices);
        file_normals.iter().zip(generated).map(|(n, g)| n.try_normalize().unwrap_or(g)).collect()
    } else {
        generate_normals(&positions, &indices)
    };
    Ok(LoadedModel {
        meshes: vec![Mesh { name: name.clone(), positions, normals, indices }],
        placements: vec![Placement { mesh: 0, transform: Mat4::IDENTITY, node_name: name }],
        cameras: Vec::new(),
    })
}

/// What the reader keeps of an element.
#[derive(Clone, Copy)]
enum Role {
    /// Vertices, with the positions of the `x`, `y` and `z` properties.
    Vertex([usize; 3]),
    /// Polygons in the list property at this position.
    Polygons(usize),
    /// Triangle strips in the list property at this position.
    Strips(usize),
    Skip,
}

fn count_lines(bytes: &[u8]) -> usize {
    bytes.iter().enumerate().filter(|&(k, &b)| b == b'\n' || (b == b'\r' && bytes.get(k + 1) != Some(&b'\n'))).count()
}
