//! Several avatars in one glTF scene (`bmlr run --gltf` of several characters): each
//! character's avatar document (its own JSON and buffer, with its animation) merged into one.
//! Every index is offset by the items of its kind that came before; the buffers become the one
//! binary chunk; each character's scene hangs under a node named after the character; the
//! realized motions become one animation, the first, so that every character plays together in
//! a viewer that plays one animation (the avatars' files' own animations are kept after it).
//! Extensions of the whole document (VRM's humanoid, expressions, spring bones, a light list)
//! describe one avatar and are dropped, with node extensions that point into them; material and
//! texture extensions are kept.

use serde_json::{json, Map, Value};

use super::export::hang_roots;
use crate::character::body::gltf::glb;

/// The kinds of top-level items whose indices are offset.
const KINDS: [&str; 10] = [
    "nodes",
    "meshes",
    "skins",
    "accessors",
    "bufferViews",
    "materials",
    "textures",
    "images",
    "samplers",
    "cameras",
];

/// Adds `by` to the index at `v`, if there is one.
fn shift(v: Option<&mut Value>, by: usize) {
    if let Some(v) = v {
        if let Some(i) = v.as_u64() {
            *v = json!(i as usize + by);
        }
    }
}

/// Offsets every texture index in a material (any `…Texture` object's `index`, also inside its
/// extensions).
fn shift_textures(v: &mut Value, by: usize) {
    match v {
        Value::Object(o) => {
            for (k, x) in o.iter_mut() {
                if k.ends_with("Texture") {
                    shift(x.get_mut("index"), by);
                }
                shift_textures(x, by);
            }
        }
        Value::Array(a) => a.iter_mut().for_each(|x| shift_textures(x, by)),
        _ => {}
    }
}

/// One character's avatar document merged into `out`.
struct Merge {
    out: Map<String, Value>,
    bin: Vec<u8>,
    roots: Vec<usize>,
    channels: Vec<Value>,
    samplers: Vec<Value>,
    /// The avatars' files' own animations.
    own: Vec<Value>,
    used: Vec<String>,
    required: Vec<String>,
}

impl Merge {
    fn len(&self, kind: &str) -> usize {
        self.out
            .get(kind)
            .and_then(Value::as_array)
            .map_or(0, Vec::len)
    }

    fn add(&mut self, name: &str, mut doc: Value, bin: &[u8]) {
        let base: Vec<(&str, usize)> = KINDS.iter().map(|&k| (k, self.len(k))).collect();
        let at = |k: &str| base.iter().find(|b| b.0 == k).map_or(0, |b| b.1);
        let bin_base = self.bin.len();
        self.bin.extend_from_slice(bin);
        while !self.bin.len().is_multiple_of(4) {
            self.bin.push(0);
        }
        let items = |kind: &str, doc: &mut Value| -> Vec<Value> {
            doc.get_mut(kind)
                .and_then(Value::as_array_mut)
                .map(std::mem::take)
                .unwrap_or_default()
        };
        let (nodes, meshes, skins) = (at("nodes"), at("meshes"), at("skins"));
        let (accessors, views, materials) = (at("accessors"), at("bufferViews"), at("materials"));
        let (textures, images, samplers) = (at("textures"), at("images"), at("samplers"));
        for mut n in items("nodes", &mut doc) {
            for c in n
                .get_mut("children")
                .and_then(Value::as_array_mut)
                .into_iter()
                .flatten()
            {
                shift(Some(c), nodes);
            }
            shift(n.get_mut("mesh"), meshes);
            shift(n.get_mut("skin"), skins);
            shift(n.get_mut("camera"), at("cameras"));
            if let Some(o) = n.as_object_mut() {
                o.remove("extensions");
            }
            self.push("nodes", n);
        }
        for mut m in items("meshes", &mut doc) {
            for p in m
                .get_mut("primitives")
                .and_then(Value::as_array_mut)
                .into_iter()
                .flatten()
            {
                for a in p
                    .get_mut("attributes")
                    .and_then(Value::as_object_mut)
                    .into_iter()
                    .flatten()
                {
                    shift(Some(a.1), accessors);
                }
                for t in p
                    .get_mut("targets")
                    .and_then(Value::as_array_mut)
                    .into_iter()
                    .flatten()
                {
                    for a in t.as_object_mut().into_iter().flatten() {
                        shift(Some(a.1), accessors);
                    }
                }
                shift(p.get_mut("indices"), accessors);
                shift(p.get_mut("material"), materials);
                if let Some(o) = p.as_object_mut() {
                    o.remove("extensions");
                }
            }
            self.push("meshes", m);
        }
        for mut s in items("skins", &mut doc) {
            shift(s.get_mut("inverseBindMatrices"), accessors);
            shift(s.get_mut("skeleton"), nodes);
            for j in s
                .get_mut("joints")
                .and_then(Value::as_array_mut)
                .into_iter()
                .flatten()
            {
                shift(Some(j), nodes);
            }
            self.push("skins", s);
        }
        for mut a in items("accessors", &mut doc) {
            shift(a.get_mut("bufferView"), views);
            if let Some(sparse) = a.get_mut("sparse") {
                shift(sparse.pointer_mut("/indices/bufferView"), views);
                shift(sparse.pointer_mut("/values/bufferView"), views);
            }
            self.push("accessors", a);
        }
        for mut v in items("bufferViews", &mut doc) {
            v["buffer"] = json!(0);
            let offset = v.get("byteOffset").and_then(Value::as_u64).unwrap_or(0) as usize;
            v["byteOffset"] = json!(offset + bin_base);
            self.push("bufferViews", v);
        }
        for mut m in items("materials", &mut doc) {
            shift_textures(&mut m, textures);
            self.push("materials", m);
        }
        for mut t in items("textures", &mut doc) {
            shift(t.get_mut("sampler"), samplers);
            shift(t.get_mut("source"), images);
            for e in t
                .get_mut("extensions")
                .and_then(Value::as_object_mut)
                .into_iter()
                .flatten()
            {
                shift(e.1.get_mut("source"), images);
            }
            self.push("textures", t);
        }
        for mut i in items("images", &mut doc) {
            shift(i.get_mut("bufferView"), views);
            self.push("images", i);
        }
        for kind in ["samplers", "cameras"] {
            for x in items(kind, &mut doc) {
                self.push(kind, x);
            }
        }
        for (k, a) in items("animations", &mut doc).into_iter().enumerate() {
            // the realized motion (the export puts it first, named after the character) joins
            // the scene's one animation; the file's own stay animations of their own
            let realized = k == 0 && a["name"] == name;
            let (mut samplers, mut channels) = (Vec::new(), Vec::new());
            let first = if realized { self.samplers.len() } else { 0 };
            for mut s in a["samplers"].as_array().cloned().unwrap_or_default() {
                shift(s.get_mut("input"), accessors);
                shift(s.get_mut("output"), accessors);
                samplers.push(s);
            }
            for mut c in a["channels"].as_array().cloned().unwrap_or_default() {
                shift(c.get_mut("sampler"), first);
                shift(c.pointer_mut("/target/node"), nodes);
                channels.push(c);
            }
            if realized {
                self.samplers.extend(samplers);
                self.channels.extend(channels);
            } else {
                let mut own = a;
                own["samplers"] = Value::Array(samplers);
                own["channels"] = Value::Array(channels);
                self.own.push(own);
            }
        }
        // the character's node over its scene's roots, skinned meshes apart
        let scene = doc["scene"].as_u64().unwrap_or(0) as usize;
        let roots: Vec<usize> = (doc["scenes"][scene]["nodes"]
            .as_array()
            .into_iter()
            .flatten())
        .filter_map(|n| Some(n.as_u64()? as usize + nodes))
        .collect();
        let all = self.out.entry("nodes").or_insert_with(|| json!([]));
        if let Some(all) = all.as_array_mut() {
            self.roots
                .extend(hang_roots(all, &roots, json!({"name": name})));
        }
        for (key, list) in [
            ("extensionsUsed", &mut self.used),
            ("extensionsRequired", &mut self.required),
        ] {
            for e in doc[key]
                .as_array()
                .into_iter()
                .flatten()
                .filter_map(Value::as_str)
            {
                if !list.iter().any(|x| x == e) {
                    list.push(e.to_string());
                }
            }
        }
    }

    fn push(&mut self, kind: &str, item: Value) {
        let list = self.out.entry(kind).or_insert_with(|| json!([]));
        if let Some(l) = list.as_array_mut() {
            l.push(item);
        }
    }
}

/// Every extension name used by an `extensions` object in `v`.
fn extensions_in(v: &Value, out: &mut Vec<String>) {
    match v {
        Value::Object(o) => {
            for (k, x) in o {
                if k == "extensions" {
                    out.extend(x.as_object().into_iter().flatten().map(|e| e.0.clone()));
                }
                extensions_in(x, out);
            }
        }
        Value::Array(a) => a.iter().for_each(|x| extensions_in(x, out)),
        _ => {}
    }
}

/// One GLB holding every `(character name, avatar document, its binary buffer)` of `parts`,
/// their animations as one animation named `animation`.
pub fn scene_glb(parts: Vec<(String, Value, Vec<u8>)>, animation: &str) -> Vec<u8> {
    let mut m = Merge {
        out: Map::new(),
        bin: Vec::new(),
        roots: Vec::new(),
        channels: Vec::new(),
        samplers: Vec::new(),
        own: Vec::new(),
        used: Vec::new(),
        required: Vec::new(),
    };
    for (name, doc, bin) in parts {
        m.add(&name, doc, &bin);
    }
    let mut out = m.out;
    out.insert(
        "asset".into(),
        json!({"version": "2.0", "generator": concat!("bml-realizer ", env!("CARGO_PKG_VERSION"))}),
    );
    out.insert("scene".into(), json!(0));
    out.insert("scenes".into(), json!([{"nodes": m.roots}]));
    let mut animations = m.own;
    if !m.channels.is_empty() {
        let realized = json!({"name": animation, "samplers": m.samplers, "channels": m.channels});
        animations.insert(0, realized);
    }
    if !animations.is_empty() {
        out.insert("animations".into(), Value::Array(animations));
    }
    if !m.bin.is_empty() {
        out.insert("buffers".into(), json!([{"byteLength": m.bin.len()}]));
    }
    let mut json = Value::Object(out);
    let mut present = Vec::new();
    extensions_in(&json, &mut present);
    for (key, list) in [
        ("extensionsUsed", m.used),
        ("extensionsRequired", m.required),
    ] {
        let kept: Vec<String> = list.into_iter().filter(|e| present.contains(e)).collect();
        if !kept.is_empty() {
            json[key] = json!(kept);
        }
    }
    let text = serde_json::to_vec(&json).expect("a JSON value serialises");
    glb(&text, m.bin)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A document with one skinned, textured mesh and the realized animation of its one joint
    /// (named `name`, as the export names it), then the file's own animation of it.
    fn part(name: &str) -> (Value, Vec<u8>) {
        let doc = json!({
            "asset": {"version": "2.0"},
            "extensionsUsed": ["VRMC_vrm", "KHR_materials_unlit"],
            "extensions": {"VRMC_vrm": {"humanoid": {"humanBones": {"hips": {"node": 0}}}}},
            "scene": 0,
            "scenes": [{"nodes": [0, 1]}],
            "nodes": [{"name": "hips"}, {"name": "body", "mesh": 0, "skin": 0}],
            "meshes": [{"primitives": [{"attributes": {"POSITION": 0}, "material": 0,
                                        "targets": [{"POSITION": 1}]}]}],
            "materials": [{"pbrMetallicRoughness": {"baseColorTexture": {"index": 0}},
                           "extensions": {"KHR_materials_unlit": {}}}],
            "textures": [{"source": 0, "sampler": 0}],
            "samplers": [{}],
            "images": [{"bufferView": 1, "mimeType": "image/png"}],
            "skins": [{"joints": [0], "inverseBindMatrices": 2}],
            "accessors": [{"bufferView": 0}, {"bufferView": 0}, {"bufferView": 0}],
            "bufferViews": [{"buffer": 0, "byteOffset": 0, "byteLength": 4},
                            {"buffer": 0, "byteOffset": 4, "byteLength": 2}],
            "buffers": [{"byteLength": 6}],
            "animations": [
                {"name": name, "samplers": [{"input": 0, "output": 1}],
                 "channels": [{"sampler": 0, "target": {"node": 0, "path": "rotation"}}]},
                {"name": "Walk", "samplers": [{"input": 0, "output": 2}],
                 "channels": [{"sampler": 0, "target": {"node": 0, "path": "rotation"}}]}],
        });
        (doc, vec![1, 2, 3, 4, 5, 6])
    }

    #[test]
    fn two_documents_merge_with_every_index_offset() {
        let (a, bin_a) = part("A");
        let (b, bin_b) = part("B");
        let glb = scene_glb(vec![("A".into(), a, bin_a), ("B".into(), b, bin_b)], "bml");
        let len = u32::from_le_bytes(glb[12..16].try_into().unwrap()) as usize;
        let doc: Value = serde_json::from_slice(&glb[20..20 + len]).unwrap();
        // nodes: A's two, A, B's two, B
        assert_eq!(doc["nodes"][2], json!({"name": "A", "children": [0]}));
        assert_eq!(doc["nodes"][4]["mesh"], 1);
        assert_eq!(doc["nodes"][4]["skin"], 1);
        assert_eq!(doc["nodes"][5], json!({"name": "B", "children": [3]}));
        // skinned meshes at the scene's root, beside the characters' nodes
        assert_eq!(doc["scenes"][0]["nodes"], json!([1, 2, 4, 5]));
        let p = &doc["meshes"][1]["primitives"][0];
        assert_eq!(p["attributes"]["POSITION"], 3);
        assert_eq!(p["targets"][0]["POSITION"], 4);
        assert_eq!(p["material"], 1);
        let m = &doc["materials"][1];
        assert_eq!(m["pbrMetallicRoughness"]["baseColorTexture"]["index"], 1);
        assert_eq!(doc["textures"][1], json!({"source": 1, "sampler": 1}));
        assert_eq!(doc["images"][1]["bufferView"], 3);
        assert_eq!(
            doc["skins"][1],
            json!({"joints": [3], "inverseBindMatrices": 5})
        );
        // B's buffer after A's, padded to 4 bytes
        assert_eq!(doc["bufferViews"][2]["byteOffset"], 8);
        assert_eq!(doc["bufferViews"][3]["byteOffset"], 12);
        assert_eq!(doc["buffers"], json!([{"byteLength": 16}]));
        // the realized motions, first and as one: B's channel on B's joint with B's sampler
        let anim = &doc["animations"][0];
        assert_eq!(anim["channels"][1]["sampler"], 1);
        assert_eq!(anim["channels"][1]["target"]["node"], 3);
        assert_eq!(anim["samplers"][1], json!({"input": 3, "output": 4}));
        assert_eq!(anim["channels"].as_array().unwrap().len(), 2);
        // the files' own animations after it, each on its own, A's then B's
        let own = &doc["animations"][2];
        assert_eq!(own["name"], "Walk");
        assert_eq!(own["channels"][0]["sampler"], 0);
        assert_eq!(own["channels"][0]["target"]["node"], 3);
        assert_eq!(own["samplers"][0], json!({"input": 3, "output": 5}));
        assert_eq!(doc["animations"].as_array().unwrap().len(), 3);
        // VRM's document extension dropped, the material's kept
        assert!(doc.get("extensions").is_none());
        assert_eq!(doc["extensionsUsed"], json!(["KHR_materials_unlit"]));
    }
}
