//! The glTF document: parsed to a [`serde_json::Value`] first, then each element
//! that ssm reads deserialized on its own into the `gltf` crate's document
//! model (`gltf::json`, the gltf-json crate) when it is first used.
//!
//! Deserializing the whole document as one `gltf::json::Root` would refuse a
//! file for an error in any part of it, materials and animations included;
//! here an error in a part ssm never reads cannot stop a file, and an error in
//! a part it reads names the element (as `accessor 3: missing field ...`).
//! Where gltf-json's serde model departs from glTF 2.0, the element is checked
//! or completed before gltf-json sees it: gltf-json reads every index and
//! enumeration as a `u64` cut to `u32` (2³² + 1 would silently name element 1:
//! refused here), requires a field that glTF makes optional (a scene's
//! `nodes`) and defaults one that glTF requires (a buffer's `byteLength`).

use std::cell::RefCell;
use std::collections::HashMap;
use std::rc::Rc;

use gltf::json::{Accessor, Buffer, Camera, Index, Mesh, Node, Scene, buffer};
use serde::Deserialize;
use serde::de::DeserializeOwned;
use serde_json::{Map, Value};

/// A kind of top-level element, with what gltf-json's serde model needs around it.
pub(super) trait Element: DeserializeOwned {
    /// The element's name in messages, as glTF spells it (`bufferView`).
    const KIND: &'static str;
    /// The array of the root that holds these elements.
    const ARRAY: &'static str;
    /// Fields that glTF 2.0 requires but gltf-json would default.
    const REQUIRED: &'static [&'static str] = &[];
    /// Array fields that glTF 2.0 makes optional but gltf-json requires: absent means empty.
    const OPTIONAL_ARRAYS: &'static [&'static str] = &[];
}

impl Element for Accessor {
    const KIND: &'static str = "accessor";
    const ARRAY: &'static str = "accessors";
}

impl Element for buffer::View {
    const KIND: &'static str = "bufferView";
    const ARRAY: &'static str = "bufferViews";
}

impl Element for Buffer {
    const KIND: &'static str = "buffer";
    const ARRAY: &'static str = "buffers";
    const REQUIRED: &'static [&'static str] = &["byteLength"];
}

impl Element for Mesh {
    const KIND: &'static str = "mesh";
    const ARRAY: &'static str = "meshes";
}

impl Element for Node {
    const KIND: &'static str = "node";
    const ARRAY: &'static str = "nodes";
}

impl Element for Scene {
    const KIND: &'static str = "scene";
    const ARRAY: &'static str = "scenes";
    const OPTIONAL_ARRAYS: &'static [&'static str] = &["nodes"];
}

impl Element for Camera {
    const KIND: &'static str = "camera";
    const ARRAY: &'static str = "cameras";
}

/// Fields that hold an index or an enumeration code, which gltf-json reads as a `u64` cut to
/// `u32`. Under `attributes` and in arrays (`children`, a scene's `nodes`) every member is one.
const U32_FIELDS: &[&str] =
    &["bufferView", "buffer", "componentType", "mode", "indices", "attributes", "mesh", "camera", "children", "nodes"];

/// The first number under one of [`U32_FIELDS`] that does not fit in a `u32`, with its field.
/// `extras` (anything at all) is not searched.
fn oversized_index(value: &Value) -> Option<(String, u64)> {
    let too_big = |v: &Value| v.as_u64().filter(|&n| n > u64::from(u32::MAX));
    match value {
        Value::Object(map) => map.iter().filter(|(key, _)| *key != "extras").find_map(|(key, member)| {
            if U32_FIELDS.contains(&key.as_str()) {
                let found = match member {
                    Value::Array(items) => items.iter().find_map(too_big),
                    Value::Object(map) if key == "attributes" => map.values().find_map(too_big),
                    other => too_big(other),
                };
                if let Some(n) = found {
                    return Some((key.clone(), n));
                }
            }
            oversized_index(member)
        }),
        Value::Array(items) => items.iter().find_map(oversized_index),
        _ => None,
    }
}

/// Deserializes one element into its gltf-json type, after the check above.
fn deserialize<T: DeserializeOwned>(value: &Value) -> Result<T, String> {
    if let Some((field, n)) = oversized_index(value) {
        return Err(format!("`{field}` {n} is not a valid index or code"));
    }
    T::deserialize(value).map_err(|e| e.to_string())
}

/// One array of the root, its elements deserialized on first use.
pub(super) struct Table<'a, T> {
    values: &'a [Value],
    parsed: RefCell<HashMap<usize, Rc<T>>>,
}

impl<'a, T: Element> Table<'a, T> {
    /// The root's array for `T`; an absent one is empty.
    pub(super) fn new(root: &'a Map<String, Value>) -> Result<Self, String> {
        let values = match root.get(T::ARRAY) {
            None => &[][..],
            Some(Value::Array(values)) => values.as_slice(),
            Some(other) => return Err(format!("`{}` is {}, not an array", T::ARRAY, kind_of(other))),
        };
        Ok(Self { values, parsed: RefCell::new(HashMap::new()) })
    }

    pub(super) fn len(&self) -> usize {
        self.values.len()
    }

    pub(super) fn is_empty(&self) -> bool {
        self.values.is_empty()
    }

    /// Element `index`, or a message naming it (`accessor 3 does not exist: ...`, `accessor 3: ...`).
    pub(super) fn get(&self, index: usize) -> Result<Rc<T>, String> {
        if let Some(parsed) = self.parsed.borrow().get(&index) {
            return Ok(Rc::clone(parsed));
        }
        let Some(value) = self.values.get(index) else {
            return Err(format!("{} {index} does not exist: the file has {}", T::KIND, self.values.len()));
        };
        let at = |message: String| format!("{} {index}: {message}", T::KIND);
        let object = value.as_object().ok_or_else(|| at(format!("it is {}, not an object", kind_of(value))))?;
        if let Some(field) = T::REQUIRED.iter().find(|f| !object.contains_key(**f)) {
            return Err(at(format!("missing field `{field}`")));
        }
        let parsed: T = if T::OPTIONAL_ARRAYS.iter().all(|f| object.contains_key(*f)) {
            deserialize(value)
        } else {
            let mut object = object.clone();
            for field in T::OPTIONAL_ARRAYS {
                object.entry(*field).or_insert_with(|| Value::Array(Vec::new()));
            }
            deserialize(&Value::Object(object))
        }
        .map_err(at)?;
        let parsed = Rc::new(parsed);
        self.parsed.borrow_mut().insert(index, Rc::clone(&parsed));
        Ok(parsed)
    }

    /// The JSON text of a field of element `index` (a JSON pointer into it), for messages about
    /// values that gltf-json reads as `Checked::Invalid`; unquoted if it is a string.
    pub(super) fn shown(&self, index: usize, pointer: &str) -> String {
        match self.values.get(index).and_then(|v| v.pointer(pointer)) {
            Some(Value::String(s)) => s.clone(),
            Some(other) => other.to_string(),
            None => "(none)".into(),
        }
    }
}

/// The root's `scene`, as gltf-json's index type.
pub(super) fn default_scene(root: &Map<String, Value>) -> Result<Option<Index<Scene>>, String> {
    let Some(value) = root.get("scene") else {
        return Ok(None);
    };
    if let Some(n) = value.as_u64().filter(|&n| n > u64::from(u32::MAX)) {
        return Err(format!("`scene` {n} is not a valid index"));
    }
    Option::<Index<Scene>>::deserialize(value).map_err(|e| format!("`scene`: {e}"))
}

/// The root's `extensionsRequired`.
pub(super) fn extensions_required(root: &Map<String, Value>) -> Result<Vec<String>, String> {
    match root.get("extensionsRequired") {
        None => Ok(Vec::new()),
        Some(value) => Vec::<String>::deserialize(value).map_err(|e| format!("`extensionsRequired`: {e}")),
    }
}

/// What a JSON value is, for messages.
pub(super) fn kind_of(value: &Value) -> &'static str {
    match value {
        Value::Null => "null",
        Value::Bool(_) => "a boolean",
        Value::Number(_) => "a number",
        Value::String(_) => "a string",
        Value::Array(_) => "an array",
        Value::Object(_) => "an object",
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn root(text: &str) -> Map<String, Value> {
        serde_json::from_str(text).unwrap_or_default()
    }

    #[test]
    fn an_index_past_u32_is_refused_not_cut() {
        let root = root(r#"{"nodes": [{"mesh": 4294967296}, {"children": [1, 4294967297]}, {"mesh": 0, "extras": {"mesh": 4294967296}}]}"#);
        let nodes = Table::<Node>::new(&root).unwrap_or_else(|e| panic!("{e}"));
        assert_eq!(nodes.get(0).err().as_deref(), Some("node 0: `mesh` 4294967296 is not a valid index or code"));
        assert_eq!(nodes.get(1).err().as_deref(), Some("node 1: `children` 4294967297 is not a valid index or code"));
        assert!(nodes.get(2).is_ok(), "extras may hold anything");
        assert_eq!(nodes.get(3).err().as_deref(), Some("node 3 does not exist: the file has 3"));
    }

    #[test]
    fn optional_and_required_fields_follow_gltf_not_gltf_json() {
        let root = root(r#"{"scenes": [{}], "buffers": [{"uri": "a.bin"}]}"#);
        let scenes = Table::<Scene>::new(&root).unwrap_or_else(|e| panic!("{e}"));
        assert!(scenes.get(0).is_ok_and(|s| s.nodes.is_empty()));
        let buffers = Table::<Buffer>::new(&root).unwrap_or_else(|e| panic!("{e}"));
        assert_eq!(buffers.get(0).err().as_deref(), Some("buffer 0: missing field `byteLength`"));
    }
}
