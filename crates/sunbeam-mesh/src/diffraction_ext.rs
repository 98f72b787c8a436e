//! The vendor glTF extension `SUNBEAM_materials_diffraction` (docs/ENGINES.md):
//! on a material, it names the response map (and the term pack) that render the
//! diffraction colour, with the numbers a shader needs. It is listed in
//! `extensionsUsed` only, never in `extensionsRequired`, so viewers that do not
//! know it draw the material's base colour.

use crate::gltf::Document;
use serde_json::{json, Map, Value};

/// The extension's name.
pub const EXTENSION: &str = "SUNBEAM_materials_diffraction";

/// Put `ext` on every material of `doc` (creating one, with `base_color` as its
/// base colour, for primitives that have none) and list the extension as used.
/// Returns how many materials carry it.
pub fn attach(doc: &mut Document, ext: &Value, base_color: [f64; 3]) -> usize {
    let mut untextured = Vec::new();
    if let Some(meshes) = doc.json.get("meshes").and_then(Value::as_array) {
        for (mi, m) in meshes.iter().enumerate() {
            for (pi, p) in m
                .get("primitives")
                .and_then(Value::as_array)
                .map(Vec::as_slice)
                .unwrap_or_default()
                .iter()
                .enumerate()
            {
                if p.get("material").is_none() {
                    untextured.push((mi, pi));
                }
            }
        }
    }
    if !untextured.is_empty() {
        let mats = doc.json_array_mut("materials");
        let idx = mats.len();
        mats.push(json!({
            "name": "sunbeam-diffraction",
            "pbrMetallicRoughness": {
                "baseColorFactor": [base_color[0], base_color[1], base_color[2], 1.0],
                "metallicFactor": 0.0,
                "roughnessFactor": 0.5
            }
        }));
        for (mi, pi) in untextured {
            doc.json["meshes"][mi]["primitives"][pi]["material"] = json!(idx);
        }
    }
    let mut n = 0;
    for m in doc.json_array_mut("materials").iter_mut() {
        if let Some(o) = m.as_object_mut() {
            let exts = o
                .entry("extensions")
                .or_insert_with(|| Value::Object(Map::new()));
            if let Some(e) = exts.as_object_mut() {
                e.insert(EXTENSION.to_string(), ext.clone());
                n += 1;
            }
        }
    }
    let used = doc.json_array_mut("extensionsUsed");
    if !used.iter().any(|v| v == EXTENSION) {
        used.push(json!(EXTENSION));
    }
    n
}
