//! Wavefront OBJ: our own statement-level parser.
//!
//! Why not `tobj`: ssm needs positions, normals and faces only, and tobj 4
//! refuses or misreads what real exporters write: `usemtl` with an empty name
//! (Blender 2.6x, 3ds Max), lines that are not UTF-8 (3ds Max writes names in
//! the local code page), a UTF-8 byte-order mark (the first vertex is silently
//! dropped), `vt` with one coordinate, vertex colours on some vertices only,
//! MSVC's `-1.#IND` for NaN normals, and `l` polylines, which it reads as
//! faces. Rewriting the text so that tobj accepts it would be longer than this
//! parser, which works on bytes and skips every statement that does not shape
//! the geometry: materials (`mtllib`, `usemtl`), texture coordinates, smoothing
//! groups, lines, points, free-form curves and surfaces, and whatever it does
//! not know.
//!
//! Each `o` or `g` statement starts a new mesh named by it. Faces may use
//! negative (relative) indices and refer to vertices defined later. Polygons
//! are triangulated by [`crate::polygon::triangulate`].

use std::borrow::Cow;
use std::collections::HashMap;
use std::path::Path;

use glam::{Mat4, Vec3};

use super::{LoadedModel, Placement, malformed};
use crate::error::{Result, SceneError};
use crate::mesh::{Mesh, generate_normals};
use crate::polygon::triangulate;

/// No normal index on a face corner.
const NO_NORMAL: usize = usize::MAX;

/// One `o`/`g` section: its name and its polygons, as (position, normal) corners in file-wide indices.
#[derive(Default)]
struct Object {
    name: String,
    corners: Vec<(usize, usize)>,
    /// Corner count of each polygon, in order.
    sizes: Vec<usize>,
    /// The line of each polygon, for messages.
    lines: Vec<usize>,
}

pub(super) fn load(path: &Path, bytes: &[u8]) -> Result<LoadedModel> {
    if bytes.starts_with(&[0xFF, 0xFE]) || bytes.starts_with(&[0xFE, 0xFF]) {
        return Err(SceneError::Unsupported {
            file: path.into(),
            what: "UTF-16 text".into(),
            hint: "save the OBJ file as UTF-8 or ASCII".into(),
        });
    }
    let bytes = bytes.strip_prefix(b"\xEF\xBB\xBF").unwrap_or(bytes);
    let mut positions: Vec<Vec3> = Vec::new();
    let mut normals: Vec<Vec3> = Vec::new();
    let mut objects: Vec<Object> = vec![Object::default()];
    let mut free_form = false;

    for (line_number, line) in lines(bytes) {
        let error = |message: String| malformed(path, "OBJ", format!("line {line_number}: {message}"));
        let mut words = line.split(|b| b.is_ascii_whitespace()).filter(|w| !w.is_empty());
        let Some(keyword) = words.next() else {
            continue;
        };
        match keyword {
            b"v" => positions.push(vector(&mut words, false).map_err(|e| error(format!("`v` statement: {e}")))?),
            b"vn" => normals.push(vector(&mut words, true).map_err(|e| error(format!("`vn` statement: {e}")))?),
            b"f" | b"fo" => {
                let object = objects.last_mut().unwrap_or_else(|| unreachable!("there is always an object"));
                let start = object.corners.len();
                for word in words {
                    let corner = face_corner(word, positions.len(), normals.len()).map_err(&error)?;
                    object.corners.push(corner);
                }
                let size = object.corners.len() - start;
                if size < 3 {
                    // A face of one or two corners is a point or a line: it casts no shadow.
                    object.corners.truncate(start);
                } else {
                    object.sizes.push(size);
                    object.lines.push(line_number);
                }
            }
            b"o" | b"g" => {
                let name = String::from_utf8_lossy(trim(&line[keyword.len()..])).into_owned();
                match objects.last_mut() {
                    Some(object) if object.sizes.is_empty() => object.name = name,
                    _ => objects.push(Object { name, ..Object::default() }),
                }
            }
            b"curv" | b"curv2" | b"surf" => free_form = true,
            // Everything else is either not geometry (materials, texture coordinates, smoothing
            // groups, display attributes), casts no shadow (`l`, `p`), or is unknown: skipped.
            _ => {}
        }
    }

    let mut loaded = LoadedModel::default();
    for (index, object) in objects.into_iter().enumerate() {
        if object.sizes.is_empty() {
            continue;
        }
        let name = if object.name.is_empty() { format!("object-{index}") } else { object.name };
        let mesh = build_mesh(path, name.clone(), &object.corners, &object.sizes, &object.lines, &positions, &normals)?;
        loaded.meshes.push(mesh);
        loaded.placements.push(Placement { mesh: loaded.meshes.len() - 1, transform: Mat4::IDENTITY, node_name: name });
    }
    if free_form {
        if loaded.meshes.is_empty() {
            return Err(SceneError::Unsupported {
                file: path.into(),
                what: "free-form geometry (OBJ `curv` and `surf`)".into(),
                hint: "the file has no polygonal faces; export it as polygons".into(),
            });
        }
        eprintln!("warning: {}: free-form curves and surfaces were skipped; only polygonal faces are loaded", path.display());
    }
    Ok(loaded)
}

/// Welds the corners of one object into a mesh: one vertex per distinct (position, normal) pair.
fn build_mesh(
    path: &Path,
    name: String,
    corners: &[(usize, usize)],
    sizes: &[usize],
    lines: &[usize],
    positions: &[Vec3],
    normals: &[Vec3],
) -> Result<Mesh> {
    let mut local: HashMap<(usize, usize), u32> = HashMap::new();
    let mut mesh_positions = Vec::new();
    let mut mesh_normals: Vec<Option<Vec3>> = Vec::new();
    let mut polygon = Vec::new();
    let mut indices = Vec::with_capacity(corners.len());
    let mut start = 0;
    for (&size, &line) in sizes.iter().zip(lines) {
        polygon.clear();
        for &(v, n) in &corners[start..start + size] {
            // Indices are checked only now, so that a face may refer to a vertex defined after it.
            if v >= positions.len() {
                return Err(malformed(
                    path,
                    "OBJ",
                    format!("line {line}: vertex index {} is out of range: the file has {} vertices", v as u64 + 1, positions.len()),
                ));
            }
            // A normal index past the file's normals (some exporters write `v//vn` without any `vn`)
            // costs only that normal: it is computed instead.
            let n = if n < normals.len() { n } else { NO_NORMAL };
            let next = u32::try_from(mesh_positions.len())
                .map_err(|_| malformed(path, "OBJ", format!("object `{name}` has more than 2^32 vertices")))?;
            let vertex = *local.entry((v, n)).or_insert_with(|| {
                mesh_positions.push(positions[v]);
                mesh_normals.push(normals.get(n).and_then(|n| n.try_normalize()));
                next
            });
            polygon.push(vertex);
        }
        triangulate(&mesh_positions, &polygon, &mut indices);
        start += size;
    }
    // A vertex without a usable normal in the file gets a generated one.
    let normals = if mesh_normals.iter().all(Option::is_some) {
        mesh_normals.into_iter().flatten().collect()
    } else {
        let generated = generate_normals(&mesh_positions, &indices);
        mesh_normals.into_iter().zip(generated).map(|(file, generated)| file.unwrap_or(generated)).collect()
    };
    Ok(Mesh { name, positions: mesh_positions, normals, indices })
}

/// Three numbers; what follows (a `w`, vertex colours) is ignored. `lenient`
/// reads MSVC's `1.#IND`/`1.#QNAN`/`1.#INF` as NaN, for normals that the
/// exporter could not compute.
fn vector<'a>(words: &mut impl Iterator<Item = &'a [u8]>, lenient: bool) -> std::result::Result<Vec3, String> {
    let mut xyz = [0.0f32; 3];
    for (k, value) in xyz.iter_mut().enumerate() {
        let Some(word) = words.next() else {
            return Err(format!("expected 3 numbers, found {k}"));
        };
        *value = number(word, lenient)?;
    }
    Ok(Vec3::from_array(xyz))
}

fn number(word: &[u8], lenient: bool) -> std::result::Result<f32, String> {
    let text = std::str::from_utf8(word).map_err(|_| format!("`{}` is not a number", String::from_utf8_lossy(word)))?;
    match text.parse::<f32>() {
        Ok(value) => Ok(value),
        Err(_) if lenient && text.contains(".#") => Ok(f32::NAN),
        Err(_) if text.contains(".#") => Err(format!("`{text}` is not a number (the exporter wrote a NaN or an infinity)")),
        Err(_) => Err(format!("`{text}` is not a number")),
    }
}

/// One face corner, `v`, `v/vt`, `v//vn` or `v/vt/vn`, as 0-based (position, normal) indices.
/// Positive indices are checked later (they may refer forwards); relative ones are resolved here.
fn face_corner(word: &[u8], positions: usize, normals: usize) -> std::result::Result<(usize, usize), String> {
    let mut parts = word.split(|&b| b == b'/');
    let position = parts.next().unwrap_or_default();
    let _texture = parts.next();
    let normal = parts.next().filter(|n| !n.is_empty());
    let text = String::from_utf8_lossy(word);
    let v = index(position, positions).map_err(|problem| format!("face corner `{text}`: {problem}"))?;
    let n = match normal {
        Some(normal) => index(normal, normals).map_err(|problem| format!("face corner `{text}`: normal {problem}"))?,
        None => NO_NORMAL,
    };
    Ok((v, n))
}

/// An OBJ index (1-based, or negative: relative to the `count` elements defined so far), 0-based.
fn index(word: &[u8], count: usize) -> std::result::Result<usize, String> {
    let text = std::str::from_utf8(word).map_err(|_| "the index is not a number".to_owned())?;
    let value: i64 = text.parse().map_err(|_| format!("index `{text}` is not an integer"))?;
    match value {
        0 => Err("index 0 is invalid (OBJ indices start at 1)".into()),
        v if v > 0 => usize::try_from(v - 1).map_err(|_| format!("index {v} is too large")),
        v => usize::try_from(v.unsigned_abs())
            .ok()
            .and_then(|back| count.checked_sub(back))
            .ok_or_else(|| format!("relative index {v} points before the first of the {count} defined so far")),
    }
}

fn trim(bytes: &[u8]) -> &[u8] {
    let start = bytes.iter().position(|b| !b.is_ascii_whitespace()).unwrap_or(bytes.len());
    let end = bytes.iter().rposition(|b| !b.is_ascii_whitespace()).map_or(start, |e| e + 1);
    &bytes[start..end.max(start)]
}

/// The file's logical lines with their 1-based numbers: split at `\n`, `\r\n` or a lone `\r`
/// (classic Mac OS), joined where a line ends with a `\` continuation, and cut at a `#` that
/// starts a word (a comment; a `#` inside a name is kept).
fn lines(bytes: &[u8]) -> impl Iterator<Item = (usize, Cow<'_, [u8]>)> {
    let mut rest = bytes;
    let mut number = 0;
    std::iter::from_fn(move || {
        if rest.is_empty() {
            return None;
        }
        let first = number + 1;
        let mut joined: Option<Vec<u8>> = None;
        loop {
            number += 1;
            let end = rest.iter().position(|&b| b == b'\n' || b == b'\r').unwrap_or(rest.len());
            let line = strip_comment(&rest[..end]);
            let skip = match rest.get(end) {
                Some(b'\r') if rest.get(end + 1) == Some(&b'\n') => 2,
                Some(_) => 1,
                None => 0,
            };
            rest = &rest[end + skip..];
            if let Some(body) = trim(line).strip_suffix(b"\\")
                && !rest.is_empty()
            {
                let joined = joined.get_or_insert_with(Vec::new);
                joined.extend_from_slice(body);
                joined.push(b' ');
                continue;
            }
            return Some((
                first,
                match joined {
                    Some(mut joined) => {
                        joined.extend_from_slice(line);
                        Cow::Owned(joined)
                    }
                    None => Cow::Borrowed(line),
                },
            ));
        }
    })
}

/// The line up to a `#` that starts a word.
fn strip_comment(line: &[u8]) -> &[u8] {
    let cut = (0..line.len()).find(|&k| line[k] == b'#' && (k == 0 || line[k - 1].is_ascii_whitespace())).unwrap_or(line.len());
    &line[..cut]
}

#[cfg(test)]
mod tests {
    use super::*;

    fn collect(text: &[u8]) -> Vec<(usize, String)> {
        lines(text).map(|(n, l)| (n, String::from_utf8_lossy(&l).into_owned())).collect()
    }

    #[test]
    fn line_endings_continuations_and_comments() {
        assert_eq!(collect(b"a\nb\r\nc\rd"), vec![(1, "a".into()), (2, "b".into()), (3, "c".into()), (4, "d".into())]);
        assert_eq!(collect(b"a\r\n\r\nb\n"), vec![(1, "a".into()), (2, "".into()), (3, "b".into())]);
        let joined = collect(b"f 1 2 \\\n 3 # tri\nv 1#2");
        assert_eq!(joined.len(), 2);
        assert_eq!((joined[0].0, joined[0].1.split_whitespace().collect::<Vec<_>>()), (1, vec!["f", "1", "2", "3"]));
        assert_eq!(joined[1], (3, "v 1#2".into()));
    }

    #[test]
    fn indices_absolute_and_relative() {
        assert_eq!(index(b"1", 0), Ok(0));
        assert_eq!(index(b"-1", 3), Ok(2));
        assert!(index(b"-4", 3).is_err());
        assert!(index(b"0", 3).is_err());
        assert!(index(b"x", 3).is_err());
        assert_eq!(face_corner(b"3//-1", 5, 2), Ok((2, 1)));
        assert_eq!(face_corner(b"3/7", 5, 0), Ok((2, NO_NORMAL)));
    }
}
