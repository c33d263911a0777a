//! An avatar's buffers gathered into one, as a GLB holds them: the GLB's own BIN chunk, buffers
//! given as `data:` URIs (base64) and buffers in files beside a `.gltf`, laid one after the other
//! (each at a multiple of 4 bytes) with every buffer view's `buffer` and `byteOffset` moved to
//! match; images given by `uri` (a file beside, or `data:`) are taken into the buffer too. The
//! avatar is then written back as one self-contained GLB with the animation added.

use std::path::Path;

use base64::Engine as _;
use serde_json::{json, Value};

/// Where a buffer's bytes come from.
pub enum First {
    /// A GLB: buffer 0 without a `uri` is its BIN chunk.
    Glb(Vec<u8>),
    /// A `.gltf` in this directory (files named by `uri` are read from it).
    Beside(std::path::PathBuf),
}

/// The bytes of a `data:` URI (base64; others are refused with the reason).
fn data_uri(uri: &str) -> Result<Vec<u8>, String> {
    let (head, data) = uri.split_once(',').ok_or("a data: URI without ','")?;
    if !head.ends_with(";base64") {
        return Err("a data: URI that is not base64".into());
    }
    base64::engine::general_purpose::STANDARD
        .decode(data.trim())
        .map_err(|e| format!("a data: URI whose base64 is broken ({e})"))
}

/// The bytes of buffer `i` of the document.
fn bytes(i: usize, buffer: &Value, first: &mut First) -> Result<Vec<u8>, String> {
    let uri = buffer["uri"].as_str();
    let mut b = match (uri, &mut *first) {
        (None, First::Glb(bin)) if i == 0 => std::mem::take(bin),
        (None, _) => return Err(format!("buffers[{i}] has no uri and is not the GLB's own")),
        (Some(u), _) if u.starts_with("data:") => {
            data_uri(u).map_err(|e| format!("buffers[{i}]: {e}"))?
        }
        (Some(u), First::Beside(dir)) => {
            let name = percent_decoded(u);
            if Path::new(&name).is_absolute() || name.contains("..") || name.contains("://") {
                return Err(format!("buffers[{i}]: '{u}' is not a file beside the avatar"));
            }
            let path = dir.join(&name);
            std::fs::read(&path).map_err(|e| format!("buffers[{i}] {}: {e}", path.display()))?
        }
        (Some(u), First::Glb(_)) => {
            return Err(format!(
                "buffers[{i}] is the file '{u}' (read the avatar from its path, with the file beside it)"
            ))
        }
    };
    let length = buffer["byteLength"].as_u64().unwrap_or(0) as usize;
    if b.len() < length {
        return Err(format!(
            "buffers[{i}] holds {} bytes, fewer than its byteLength {length}",
            b.len()
        ));
    }
    if length > 0 {
        b.truncate(length);
    }
    Ok(b)
}

/// `%20` and the like in a URI, decoded.
fn percent_decoded(uri: &str) -> String {
    let b = uri.as_bytes();
    let mut out = Vec::with_capacity(b.len());
    let mut i = 0;
    while i < b.len() {
        let hex = b
            .get(i + 1..i + 3)
            .and_then(|h| std::str::from_utf8(h).ok());
        match (b[i], hex.and_then(|h| u8::from_str_radix(h, 16).ok())) {
            (b'%', Some(v)) => {
                out.push(v);
                i += 3;
            }
            (c, _) => {
                out.push(c);
                i += 1;
            }
        }
    }
    String::from_utf8_lossy(&out).into_owned()
}

/// Every buffer of `json` in one, the views moved to match; `json` then has one buffer.
pub fn gather(json: &mut Value, mut first: First) -> Result<Vec<u8>, String> {
    let buffers = json["buffers"].as_array().cloned().unwrap_or_default();
    if buffers.is_empty() && json["images"].as_array().is_none_or(|i| i.is_empty()) {
        return Ok(match first {
            First::Glb(bin) => bin,
            First::Beside(_) => Vec::new(),
        });
    }
    let mut bin = Vec::new();
    let mut starts = Vec::with_capacity(buffers.len());
    for (i, b) in buffers.iter().enumerate() {
        bin.resize(bin.len().next_multiple_of(4), 0);
        let b = bytes(i, b, &mut first)?;
        starts.push((bin.len(), b.len()));
        bin.extend(b);
    }
    let views = json["bufferViews"].as_array_mut();
    for (k, v) in views.into_iter().flatten().enumerate() {
        let b = (v["buffer"].as_u64().map(|b| b as usize))
            .filter(|&b| b < starts.len())
            .ok_or_else(|| format!("bufferViews[{k}].buffer is not one of the buffers"))?;
        let (start, len) = starts[b];
        let within = v["byteOffset"].as_u64().unwrap_or(0) as usize;
        let end = within.saturating_add(v["byteLength"].as_u64().unwrap_or(0) as usize);
        if end > len {
            return Err(format!(
                "bufferViews[{k}] ends at byte {end} of buffer {b}, which holds {len}"
            ));
        }
        let offset = start + within;
        v["buffer"] = json!(0);
        v["byteOffset"] = json!(offset);
    }
    embed_images(json, &mut bin, &first)?;
    json["buffers"] = json!([{"byteLength": bin.len()}]);
    Ok(bin)
}

/// Images given by `uri` taken into `bin` (a view each, with their MIME type).
fn embed_images(json: &mut Value, bin: &mut Vec<u8>, first: &First) -> Result<(), String> {
    let images = json["images"].as_array().cloned().unwrap_or_default();
    for (i, image) in images.iter().enumerate() {
        let Some(uri) = image["uri"].as_str() else {
            continue;
        };
        let (bytes, mime) = if let Some(rest) = uri.strip_prefix("data:") {
            let mime = rest.split([';', ',']).next().unwrap_or("").to_string();
            (
                data_uri(uri).map_err(|e| format!("images[{i}]: {e}"))?,
                mime,
            )
        } else {
            let First::Beside(dir) = first else {
                return Err(format!(
                    "images[{i}] is the file '{uri}' (read the avatar from its path, with the file beside it)"
                ));
            };
            let name = percent_decoded(uri);
            if Path::new(&name).is_absolute() || name.contains("..") || name.contains("://") {
                return Err(format!(
                    "images[{i}]: '{uri}' is not a file beside the avatar"
                ));
            }
            let path = dir.join(&name);
            let bytes =
                std::fs::read(&path).map_err(|e| format!("images[{i}] {}: {e}", path.display()))?;
            let lower = name.to_ascii_lowercase();
            let mime = if lower.ends_with(".png") {
                "image/png"
            } else if lower.ends_with(".jpg") || lower.ends_with(".jpeg") {
                "image/jpeg"
            } else {
                image["mimeType"]
                    .as_str()
                    .unwrap_or("application/octet-stream")
            };
            (bytes, mime.to_string())
        };
        bin.resize(bin.len().next_multiple_of(4), 0);
        let views = json["bufferViews"].as_array().map_or(0, Vec::len);
        let view = json!({"buffer": 0, "byteOffset": bin.len(), "byteLength": bytes.len()});
        bin.extend(bytes);
        match json["bufferViews"].as_array_mut() {
            Some(v) => v.push(view),
            None => json["bufferViews"] = json!([view]),
        }
        let image = &mut json["images"][i];
        if let Some(o) = image.as_object_mut() {
            o.remove("uri");
        }
        image["bufferView"] = json!(views);
        image["mimeType"] = json!(mime);
    }
    Ok(())
}
