//! A realizer described by options as JSON, for hosts that speak neither Rust nor the command
//! line (the C ABI, Python): `{"world": {…the world file's object…}, "tts": "builtin" |
//! "flite", "idle": true, "character": "ID", "fps": 60}`; every key may be left out (the
//! defaults of `bmlr run`). `fps` is for hosts that step the realizer frame by frame instead
//! of ticking it at times of their own. Unknown keys are refused, naming them, so that a typo does not silently change
//! nothing.

use serde_json::Value;

use super::Realizer;
use crate::planning::timing::{SpeechTiming, Voice};

/// The realizer `options` (JSON, or empty for the defaults) describe and the frame rate they
/// ask for (60 when they do not), or a sentence saying what is wrong with them.
pub fn from_options(options: &str) -> Result<(Realizer, f64), String> {
    let bad = |what: String| format!("options: {what}");
    let options: Value = if options.trim().is_empty() {
        Value::Object(Default::default())
    } else {
        serde_json::from_str(options).map_err(|e| bad(format!("not JSON: {e}")))?
    };
    let Value::Object(o) = options else {
        return Err(bad("not a JSON object".into()));
    };
    if let Some(k) = o
        .keys()
        .find(|k| !["world", "tts", "idle", "character", "fps"].contains(&k.as_str()))
    {
        return Err(bad(format!(
            "unknown option '{k}' (known: world, tts, idle, character, fps)"
        )));
    }
    let fps = match o.get("fps") {
        None => 60.0,
        Some(v) => v
            .as_f64()
            .filter(|f| f.is_finite() && *f > 0.0 && *f <= 10_000.0)
            .ok_or_else(|| {
                bad("fps is a number of frames a second above 0, at most 10 000".into())
            })?,
    };
    let mut realizer = Realizer::new();
    match o.get("tts").map(|v| v.as_str()) {
        None | Some(Some("builtin")) => {}
        Some(Some("flite")) => {
            crate::character::voice::flite::Flite::default()
                .check()
                .map_err(|e| bad(format!("tts flite: {e}")))?;
            realizer = realizer.with_speech_timing(SpeechTiming {
                voice: Voice::Flite,
                ..SpeechTiming::default()
            });
        }
        Some(_) => return Err(bad("tts is \"builtin\" or \"flite\"".into())),
    }
    match o.get("idle") {
        None => {}
        Some(Value::Bool(on)) => realizer = realizer.with_idle(*on),
        Some(_) => return Err(bad("idle is true or false".into())),
    }
    match o.get("character") {
        None | Some(Value::Null) => {}
        Some(Value::String(id)) => realizer = realizer.with_default_character(Some(id.clone())),
        Some(_) => return Err(bad("character is a string".into())),
    }
    if let Some(world) = o.get("world") {
        let (world, _) = crate::world::World::from_json(&world.to_string())
            .map_err(|e| bad(format!("world: {e}")))?;
        *realizer.world_mut() = world;
    }
    Ok((realizer, fps))
}
