//! What espeak-ng's own library reported while it spoke (`tests/peers/espeak_events.py`): the
//! text, its words and phonemes with their times, the sound's length; and Polly's viseme for
//! each IPA phoneme, to write the marks a cloud voice would send for that sound. Shared by
//! `tests/own_sound.rs`, `tests/stream.rs` and `tests/espeak.rs`.
#![allow(dead_code)]

use serde_json::Value;

/// A report read.
pub struct Report {
    /// The text said.
    pub text: String,
    /// Each word: (text, start s, character offset in the text).
    pub words: Vec<(String, f64, usize)>,
    /// Each phoneme: (IPA, start s, end s: the next phoneme's start); silence has no IPA.
    pub phonemes: Vec<(String, f64, f64)>,
    /// The sound's length (s).
    pub length: f64,
}

/// The report in `json` (what the helper script writes).
pub fn read(json: &str) -> Report {
    let json: Value = serde_json::from_str(json).unwrap();
    let text = json["text"].as_str().unwrap().to_string();
    let chars: Vec<char> = text.chars().collect();
    let length = json["samples"].as_f64().unwrap() / json["rate"].as_f64().unwrap();
    let events = json["events"].as_array().unwrap();
    let seconds = |e: &Value| e["ms"].as_f64().unwrap() / 1000.0;
    let mut words = Vec::new();
    for e in events.iter().filter(|e| e["type"] == "word") {
        let at = e["start"].as_u64().unwrap() as usize;
        let n = e["length"].as_u64().unwrap() as usize;
        let word: String = chars[at..(at + n).min(chars.len())].iter().collect();
        if !word.is_empty() {
            words.push((word, seconds(e), at));
        }
    }
    let said: Vec<&Value> = events.iter().filter(|e| e["type"] == "phoneme").collect();
    let phonemes = (said.windows(2))
        .map(|w| {
            (
                w[0]["ipa"].as_str().unwrap().to_string(),
                seconds(w[0]),
                seconds(w[1]),
            )
        })
        .collect();
    Report {
        text,
        words,
        phonemes,
        length,
    }
}

/// The fixture's report (`fixtures/voice/espeak-bob.events.json`).
pub fn fixture() -> Report {
    let path = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/fixtures/voice/espeak-bob.events.json"
    );
    read(&std::fs::read_to_string(path).unwrap())
}

/// Polly's viseme for an IPA phoneme (Amazon Polly's English viseme table).
pub fn polly_viseme(ipa: &str) -> &'static str {
    let c = ipa.chars().find(|c| !matches!(c, 'ˈ' | 'ˌ' | 'ː'));
    match (c, ipa) {
        (None, _) => "sil",
        (_, "aɪ" | "aʊ") => "a",
        (Some('b' | 'p' | 'm'), _) => "p",
        (Some('t' | 'd' | 'n'), _) => "t",
        (Some('k' | 'ɡ' | 'g' | 'ŋ' | 'h'), _) => "k",
        (Some('f' | 'v'), _) => "f",
        (Some('θ' | 'ð'), _) => "T",
        (Some('s' | 'z'), _) => "s",
        (Some('ʃ' | 'ʒ'), _) => "S",
        (Some('ɹ' | 'r'), _) => "r",
        (Some('l'), _) => "t",
        (Some('j' | 'i' | 'ɪ'), _) => "i",
        (Some('w' | 'u' | 'ʊ'), _) => "u",
        (Some('a' | 'ɑ' | 'æ' | 'ɒ'), _) => "a",
        (Some('ə' | 'ɐ' | 'ʌ'), _) => "@",
        (Some('e' | 'ɛ'), _) => "e",
        (Some('ɜ'), _) => "E",
        (Some('o'), _) => "o",
        (Some('ɔ'), _) => "O",
        _ => "sil",
    }
}

/// Polly speech marks of `report` (its words and its phonemes' visemes), each line with its
/// time (s), in time order.
pub fn polly_lines(report: &Report) -> Vec<(f64, String)> {
    let mut marks: Vec<(f64, String)> = Vec::new();
    for (word, start, at) in &report.words {
        let ms = (start * 1000.0).round();
        let end = at + word.chars().count();
        marks.push((
            *start,
            format!(r#"{{"time":{ms},"type":"word","start":{at},"end":{end},"value":"{word}"}}"#),
        ));
    }
    for (ipa, start, _) in &report.phonemes {
        let ms = (start * 1000.0).round();
        let v = polly_viseme(ipa);
        marks.push((
            *start + 1e-6,
            format!(r#"{{"time":{ms},"type":"viseme","value":"{v}"}}"#),
        ));
    }
    marks.sort_by(|a, b| a.0.total_cmp(&b.0));
    marks
}
