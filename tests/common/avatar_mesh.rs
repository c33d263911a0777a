//! A skinned mesh added to a test avatar, written in each of the ways the glTF 2.0
//! specification allows and exporters use: a morph target whose accessor has no `bufferView`
//! (zeros), a sparse accessor without a base view, joints and weights as normalized 8- and
//! 16-bit integers, positions quantized to 16-bit integers (`KHR_mesh_quantization`), two
//! primitives of which only one has moving targets, and the buffers given as a `.gltf` with a
//! `data:` URI or with two `.bin` files beside it. A small triangle on the left upper arm,
//! skinned to the arm and the hips, with a `jawOpen` target.

#![allow(dead_code)]

use base64::Engine as _;
use glam::{Mat4, Vec3};
use serde_json::{json, Value};

/// How the mesh is written (see the module documentation).
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Case {
    /// The morph target's POSITION accessor has no bufferView.
    NoBufferView,
    /// The morph target is sparse, without a base bufferView.
    SparseNoBase,
    /// JOINTS_0 and WEIGHTS_0 as normalized unsigned bytes.
    WeightsU8,
    /// JOINTS_0 and WEIGHTS_0 as normalized unsigned shorts.
    WeightsU16,
    /// POSITION as 16-bit integers (millimetres), KHR_mesh_quantization required.
    Quantized,
    /// Two primitives; the second's targets are all zeros (accessors without bufferView).
    TwoPrimitives,
}

/// Every case.
pub const CASES: [Case; 6] = [
    Case::NoBufferView,
    Case::SparseNoBase,
    Case::WeightsU8,
    Case::WeightsU16,
    Case::Quantized,
    Case::TwoPrimitives,
];

/// A binary buffer being laid out, with its views and accessors.
struct Bin {
    bytes: Vec<u8>,
    views: Vec<Value>,
    accessors: Vec<Value>,
}

impl Bin {
    /// A view of `data` (aligned to 4 bytes), with `stride` when given.
    fn view(&mut self, data: &[u8], stride: Option<usize>) -> usize {
        self.bytes.resize(self.bytes.len().next_multiple_of(4), 0);
        let mut v = json!({"buffer": 0, "byteOffset": self.bytes.len(), "byteLength": data.len()});
        if let Some(s) = stride {
            v["byteStride"] = json!(s);
        }
        self.bytes.extend_from_slice(data);
        self.views.push(v);
        self.views.len() - 1
    }

    fn accessor(&mut self, a: Value) -> usize {
        self.accessors.push(a);
        self.accessors.len() - 1
    }
}

fn floats(v: &[f32]) -> Vec<u8> {
    v.iter().flat_map(|f| f.to_le_bytes()).collect()
}

/// `json` (an avatar without meshes, skin 0 its skeleton, its rest transforms `rest`, one per
/// node) with the mesh of `case` added; the binary buffer beside it.
pub fn with_mesh(mut json: Value, rest: &[Mat4], case: Case) -> (Value, Vec<u8>) {
    let mut bin = Bin {
        bytes: Vec::new(),
        views: Vec::new(),
        accessors: Vec::new(),
    };
    let joints: Vec<usize> = (json["skins"][0]["joints"].as_array().unwrap().iter())
        .map(|j| j.as_u64().unwrap() as usize)
        .collect();
    let named = |suffix: &str| {
        let n = json["nodes"].as_array().unwrap();
        let vrm = match suffix {
            "LeftArm" => "J_leftUpperArm",
            _ => "J_hips",
        };
        let name = |i: usize| n[i]["name"].as_str().unwrap_or("");
        let node = (0..n.len()).find(|&i| name(i).ends_with(suffix) || name(i) == vrm);
        joints.iter().position(|&j| Some(j) == node).unwrap()
    };
    // (Mixamo's names, or VRM's J_ names)
    let (arm, hips) = (named("LeftArm"), named("Hips"));
    // the triangle, in the world at rest (metres)
    let at = rest[joints[arm]].w_axis.truncate();
    let corners = [
        at,
        at + Vec3::new(0.1, 0.0, 0.0),
        at + Vec3::new(0.0, -0.1, 0.0),
    ];
    // (quantized: millimetres as 16-bit integers, the thousandth folded into the bind matrices)
    let unit = if case == Case::Quantized { 0.001 } else { 1.0 };
    let ibm: Vec<f32> = (joints.iter())
        .flat_map(|&j| (rest[j].inverse() * Mat4::from_scale(Vec3::splat(unit))).to_cols_array())
        .collect();
    let ibm_view = bin.view(&floats(&ibm), None);
    let ibm = bin.accessor(json!({"bufferView": ibm_view, "componentType": 5126, "count": joints.len(), "type": "MAT4"}));
    let (lo, hi) = (
        corners.iter().fold(Vec3::MAX, |a, &b| a.min(b)),
        corners.iter().fold(Vec3::MIN, |a, &b| a.max(b)),
    );
    let position = if case == Case::Quantized {
        let mm: Vec<[i16; 3]> = (corners.iter())
            .map(|c| (*c * 1000.0).round().to_array().map(|v| v as i16))
            .collect();
        // (6 bytes a vertex, padded to 8: vertex attributes are aligned to 4)
        let data: Vec<u8> = (mm.iter())
            .flat_map(|p| {
                p.iter()
                    .flat_map(|v| v.to_le_bytes())
                    .chain([0, 0])
                    .collect::<Vec<u8>>()
            })
            .collect();
        let view = bin.view(&data, Some(8));
        let (lo, hi) = (
            [0, 1, 2].map(|k| mm.iter().map(|p| p[k]).min().unwrap()),
            [0, 1, 2].map(|k| mm.iter().map(|p| p[k]).max().unwrap()),
        );
        bin.accessor(json!({"bufferView": view, "componentType": 5122, "count": 3, "type": "VEC3", "min": lo, "max": hi}))
    } else {
        let view = bin.view(
            &floats(
                &corners
                    .iter()
                    .flat_map(|c| c.to_array())
                    .collect::<Vec<f32>>(),
            ),
            None,
        );
        bin.accessor(json!({"bufferView": view, "componentType": 5126, "count": 3, "type": "VEC3", "min": lo.to_array(), "max": hi.to_array()}))
    };
    let (j, w) = ([arm as u16, hips as u16, 0, 0], [0.75f32, 0.25, 0.0, 0.0]);
    let (joints_acc, weights_acc) = match case {
        Case::WeightsU8 => {
            let jd: Vec<u8> = (0..3).flat_map(|_| j.map(|x| x as u8)).collect();
            let wd: Vec<u8> = (0..3).flat_map(|_| [191u8, 64, 0, 0]).collect();
            let (jv, wv) = (bin.view(&jd, None), bin.view(&wd, None));
            (
                bin.accessor(json!({"bufferView": jv, "componentType": 5121, "count": 3, "type": "VEC4"})),
                bin.accessor(json!({"bufferView": wv, "componentType": 5121, "normalized": true, "count": 3, "type": "VEC4"})),
            )
        }
        Case::WeightsU16 => {
            let jd: Vec<u8> = (0..3)
                .flat_map(|_| j.map(u16::to_le_bytes))
                .flatten()
                .collect();
            let wd: Vec<u8> = (0..3)
                .flat_map(|_| [49151u16, 16384, 0, 0].map(u16::to_le_bytes))
                .flatten()
                .collect();
            let (jv, wv) = (bin.view(&jd, None), bin.view(&wd, None));
            (
                bin.accessor(json!({"bufferView": jv, "componentType": 5123, "count": 3, "type": "VEC4"})),
                bin.accessor(json!({"bufferView": wv, "componentType": 5123, "normalized": true, "count": 3, "type": "VEC4"})),
            )
        }
        _ => {
            let jd: Vec<u8> = (0..3)
                .flat_map(|_| j.map(u16::to_le_bytes))
                .flatten()
                .collect();
            let wv_data = floats(&(0..3).flat_map(|_| w).collect::<Vec<f32>>());
            let (jv, wv) = (bin.view(&jd, None), bin.view(&wv_data, None));
            (
                bin.accessor(
                    json!({"bufferView": jv, "componentType": 5123, "count": 3, "type": "VEC4"}),
                ),
                bin.accessor(
                    json!({"bufferView": wv, "componentType": 5126, "count": 3, "type": "VEC4"}),
                ),
            )
        }
    };
    let zeros = json!({"componentType": 5126, "count": 3, "type": "VEC3", "min": [0.0, 0.0, 0.0], "max": [0.0, 0.0, 0.0]});
    let target = match case {
        Case::Quantized | Case::WeightsU8 | Case::WeightsU16 => None,
        Case::SparseNoBase => {
            // the third corner moves down 2 cm, the others stay (zeros)
            let iv = bin.view(&[2u8, 0, 0, 0][..1], None);
            let vv = bin.view(&floats(&[0.0, -0.02, 0.0]), None);
            Some(
                bin.accessor(json!({"componentType": 5126, "count": 3, "type": "VEC3",
                "min": [0.0, -0.02, 0.0], "max": [0.0, 0.0, 0.0],
                "sparse": {"count": 1, "indices": {"bufferView": iv, "componentType": 5121},
                           "values": {"bufferView": vv}}})),
            )
        }
        Case::NoBufferView | Case::TwoPrimitives => Some(bin.accessor(zeros.clone())),
    };
    let mut primitive = json!({"attributes": {"POSITION": position, "JOINTS_0": joints_acc, "WEIGHTS_0": weights_acc}});
    let mut mesh = json!({"name": "arm patch", "primitives": []});
    if let Some(t) = target {
        primitive["targets"] = json!([{"POSITION": t}]);
        mesh["weights"] = json!([0.0]);
        mesh["extras"] = json!({"targetNames": ["jawOpen"]});
    }
    let mut primitives = vec![primitive.clone()];
    if case == Case::TwoPrimitives {
        // a second patch whose target does not move it
        let z = bin.accessor(zeros);
        primitive["targets"] = json!([{"POSITION": z}]);
        primitives.push(primitive);
    }
    mesh["primitives"] = json!(primitives);
    json["meshes"] = json!([mesh]);
    json["skins"][0]["inverseBindMatrices"] = json!(ibm);
    let nodes = json["nodes"].as_array_mut().unwrap();
    nodes.push(json!({"name": "body", "mesh": 0, "skin": 0}));
    let body = nodes.len() - 1;
    let scene = json["scenes"][0]["nodes"].as_array_mut().unwrap();
    scene.push(json!(body));
    if case == Case::Quantized {
        json["extensionsUsed"] = json!(["KHR_mesh_quantization"]);
        json["extensionsRequired"] = json!(["KHR_mesh_quantization"]);
    }
    bin.bytes.resize(bin.bytes.len().next_multiple_of(4), 0);
    json["bufferViews"] = json!(bin.views);
    json["accessors"] = json!(bin.accessors);
    json["buffers"] = json!([{"byteLength": bin.bytes.len()}]);
    (json, bin.bytes)
}

/// `json` and `bin` as a `.gltf` whose buffer is a `data:` URI.
pub fn gltf_embedded(json: &Value, bin: &[u8]) -> Vec<u8> {
    let mut json = json.clone();
    let data = base64::engine::general_purpose::STANDARD.encode(bin);
    json["buffers"] = json!([{"byteLength": bin.len(), "uri": format!("data:application/octet-stream;base64,{data}")}]);
    serde_json::to_vec(&json).unwrap()
}

/// `json` and `bin` as a `.gltf` whose bytes are split into two files beside it, `a.bin` (the
/// first half of the views) and `b.bin` (the rest): (the .gltf, [(file name, bytes)]).
pub fn gltf_two_files(json: &Value, bin: &[u8]) -> (Vec<u8>, Vec<(String, Vec<u8>)>) {
    let mut json = json.clone();
    let views = json["bufferViews"].as_array_mut().unwrap();
    let cut = views.len() / 2;
    let split = views[cut]["byteOffset"].as_u64().unwrap() as usize;
    for v in views.iter_mut().skip(cut) {
        v["buffer"] = json!(1);
        v["byteOffset"] = json!(v["byteOffset"].as_u64().unwrap() as usize - split);
    }
    json["buffers"] = json!([
        {"byteLength": split, "uri": "a.bin"},
        {"byteLength": bin.len() - split, "uri": "b%20c.bin"},
    ]);
    let files = vec![
        ("a.bin".to_string(), bin[..split].to_vec()),
        ("b c.bin".to_string(), bin[split..].to_vec()),
    ];
    (serde_json::to_vec(&json).unwrap(), files)
}
