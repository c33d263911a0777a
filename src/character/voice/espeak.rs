//! The espeak-ng TTS (Debian package `espeak-ng`), run as a program: `espeak-ng -v VOICE --ipa
//! --sep=_ -w FILE` reads the text on its input, writes its sound and prints the phonemes it
//! said, in IPA, word by word. espeak-ng is GPL-3, so the realizer runs the program and never
//! links its library. The program does not print when each phoneme is said: the phonemes, each
//! given the inherent length of the realizer phone it looks like (vowels scaled by their
//! stress), are timed to the sound it made
//! by [`listen::align`] (dynamic time warping of expected against heard loudness and hiss). As
//! with flite, the text between two inline syncs is said in one call, so every sync falls on a
//! boundary of the sound itself; each piece's silence before and after is cut. Lips follow every
//! language espeak-ng speaks through its IPA (`voice::ipa`).

use std::io::Write;
use std::path::PathBuf;
use std::process::{Command, Stdio};
use std::sync::atomic::{AtomicU64, Ordering};

use super::{builtin, ipa, listen, Audio, Phone, Tts, Utterance};
use crate::language::bml::TextPart;

/// What a missing program is told.
pub const MISSING: &str = "the espeak-ng TTS is not installed: install the Debian package 'espeak-ng' (apt-get install espeak-ng), or use --tts builtin";

/// The voice espeak-ng speaks with when none is named.
pub const DEFAULT_VOICE: &str = "en";

/// How long a voice name may be.
const NAME_LENGTH: usize = 32;

/// An espeak-ng voice or language name (`en`, `de`, `pt-br`, `en-gb-x-rp`): ASCII letters,
/// digits, `-`, `_` and `+`, at most 32 of them. A small copyable value, so that a speech
/// timing stays `Copy`.
#[derive(Clone, Copy, PartialEq, Eq)]
pub struct VoiceName {
    bytes: [u8; NAME_LENGTH],
    len: u8,
}

impl VoiceName {
    /// The name `s`, or why it is not one.
    pub fn new(s: &str) -> Result<VoiceName, String> {
        let ok = |c: u8| c.is_ascii_alphanumeric() || matches!(c, b'-' | b'_' | b'+');
        if s.is_empty() || s.len() > NAME_LENGTH || !s.bytes().all(ok) {
            return Err(format!(
                "{s:?} is not an espeak-ng voice name (letters, digits, - _ +, at most {NAME_LENGTH})"
            ));
        }
        let mut bytes = [0; NAME_LENGTH];
        bytes[..s.len()].copy_from_slice(s.as_bytes());
        Ok(VoiceName {
            bytes,
            len: s.len() as u8,
        })
    }

    /// The name.
    pub fn as_str(&self) -> &str {
        std::str::from_utf8(&self.bytes[..usize::from(self.len)]).unwrap_or(DEFAULT_VOICE)
    }
}

impl Default for VoiceName {
    fn default() -> Self {
        VoiceName::new(DEFAULT_VOICE).unwrap_or(VoiceName {
            bytes: [0; NAME_LENGTH],
            len: 0,
        })
    }
}

impl std::fmt::Debug for VoiceName {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "{:?}", self.as_str())
    }
}

/// espeak-ng with one of its voices.
#[derive(Debug, Clone)]
pub struct Espeak {
    program: PathBuf,
    voice: VoiceName,
}

impl Espeak {
    /// espeak-ng (on the PATH) speaking with `voice`.
    pub fn new(voice: VoiceName) -> Espeak {
        Espeak {
            program: PathBuf::from("espeak-ng"),
            voice,
        }
    }

    /// Whether the program runs and has the voice (its version line, or why not).
    pub fn check(&self) -> Result<String, String> {
        let out = Command::new(&self.program)
            .arg("--version")
            .output()
            .map_err(|_| MISSING.to_string())?;
        if !self.has_voice() {
            return Err(format!(
                "espeak-ng has no voice '{}' (espeak-ng --voices lists them)",
                self.voice.as_str()
            ));
        }
        Ok(String::from_utf8_lossy(&out.stdout).trim().to_string())
    }

    /// Whether espeak-ng can speak with this voice (it says one word with it).
    pub fn has_voice(&self) -> bool {
        Command::new(&self.program)
            .args(["-q", "-v", self.voice.as_str(), "a"])
            .stderr(Stdio::null())
            .status()
            .is_ok_and(|s| s.success())
    }

    /// Says `text` (one piece): its phones (from its first sound) and its samples.
    fn piece(&self, text: &str) -> Result<(Vec<Phone>, Audio), String> {
        static NEXT: AtomicU64 = AtomicU64::new(0);
        let n = NEXT.fetch_add(1, Ordering::Relaxed);
        let wav = std::env::temp_dir().join(format!("bmlr-espeak-{}-{n}.wav", std::process::id()));
        let mut child = Command::new(&self.program)
            .args(["-v", self.voice.as_str(), "--ipa", "--sep=_", "-w"])
            .arg(&wav)
            .stdin(Stdio::piped())
            .stdout(Stdio::piped())
            .stderr(Stdio::piped())
            .spawn()
            .map_err(|_| MISSING.to_string())?;
        if let Some(mut input) = child.stdin.take() {
            let _ = input.write_all(text.as_bytes());
        }
        let out = child.wait_with_output().map_err(|e| e.to_string())?;
        let read = crate::character::sound::read_wav(&wav);
        let _ = std::fs::remove_file(&wav);
        if !out.status.success() {
            return Err(format!(
                "espeak-ng failed on {text:?}: {}",
                String::from_utf8_lossy(&out.stderr).trim()
            ));
        }
        let audio = read.map_err(|e| format!("espeak-ng's sound: {e}"))?;
        let said = phones_of_ipa(&String::from_utf8_lossy(&out.stdout));
        let heard = listen::frames(&audio);
        let knots = listen::align(&said, &heard);
        let (Some(&(_, from)), Some(&(_, to))) = (knots.first(), knots.last()) else {
            return Ok((
                Vec::new(),
                Audio {
                    rate: audio.rate,
                    samples: Vec::new(),
                },
            ));
        };
        let phones = (said.iter())
            .map(|p| Phone {
                symbol: p.symbol,
                start: (listen::warp_time(&knots, p.start) - from).clamp(0.0, to - from),
                end: (listen::warp_time(&knots, p.end) - from).clamp(0.0, to - from),
            })
            .filter(|p| p.end > p.start)
            .collect();
        let at = |t: f64| ((t * f64::from(audio.rate)).round() as usize).min(audio.samples.len());
        let samples = audio.samples[at(from)..at(to).max(at(from))].to_vec();
        Ok((
            phones,
            Audio {
                rate: audio.rate,
                samples,
            },
        ))
    }
}

/// The phones of espeak-ng's IPA output (`_` between phonemes, spaces between words, a line a
/// clause), each with the inherent length of the realizer phone it looks like, a pause
/// between clauses.
fn phones_of_ipa(text: &str) -> Vec<Phone> {
    let mut phones = Vec::new();
    let mut t = 0.0;
    for (k, line) in text.lines().filter(|l| !l.trim().is_empty()).enumerate() {
        if k > 0 {
            phones.push(Phone {
                symbol: "pau",
                start: t,
                end: t + builtin::COMMA_PAUSE,
            });
            t += builtin::COMMA_PAUSE;
        }
        for phoneme in line.split(['_', ' ']).filter(|p| !p.is_empty()) {
            let symbol = ipa::phone(phoneme);
            if symbol == "pau" {
                continue;
            }
            let length = builtin::inherent(symbol).unwrap_or(0.08) * weight(phoneme, symbol);
            phones.push(Phone {
                symbol,
                start: t,
                end: t + length,
            });
            t += length;
        }
    }
    phones
}

/// How much longer or shorter than its phone's inherent length espeak-ng says `phoneme`: a
/// vowel with primary stress (`ˈ`) longer, an unstressed one (no mark) much shorter, a schwa
/// shortest, a long one (`ː`) longer. Stress-timed languages squeeze their unstressed syllables
/// (German's final schwa lasts a third of a stressed vowel); the warp matches expected to heard
/// loudness, so where the sound is evenly loud the path keeps these proportions.
fn weight(phoneme: &str, symbol: &str) -> f64 {
    if !builtin::is_vowel(symbol) {
        return 1.0;
    }
    let stress = if phoneme.contains('ˈ') {
        1.25
    } else if phoneme.contains('ˌ') {
        1.0
    } else if symbol == "AH" {
        0.45
    } else {
        0.7
    };
    let long = if phoneme.contains('ː') { 1.3 } else { 1.0 };
    stress * long
}

impl Tts for Espeak {
    fn name(&self) -> &'static str {
        "espeak"
    }

    fn speak(&self, text: &[TextPart]) -> Result<Utterance, String> {
        super::pieces::say_in_pieces(text, 22_050, |words| self.piece(words))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn voice_names_are_checked() {
        assert_eq!(VoiceName::new("pt-br").unwrap().as_str(), "pt-br");
        assert_eq!(VoiceName::default().as_str(), "en");
        assert!(VoiceName::new("de; rm -rf").is_err());
        assert!(VoiceName::new("").is_err());
    }

    #[test]
    fn ipa_output_becomes_phones_with_pauses_between_clauses() {
        let phones = phones_of_ipa("h_ˈa_l_oː v_ˈɛ_l_t\nɡ_ˈuː_t\n");
        let symbols: Vec<_> = phones.iter().map(|p| p.symbol).collect();
        assert_eq!(
            symbols,
            ["HH", "AA", "N", "OW", "F", "EH", "N", "T", "pau", "K", "UW", "T"]
        );
        assert!(phones
            .windows(2)
            .all(|w| (w[0].end - w[1].start).abs() < 1e-12));
    }

    #[test]
    fn stress_sets_a_vowel_s_length() {
        // German "Brücke": the stressed y long, the final schwa short; consonants as they are
        let phones = phones_of_ipa("b_ɾ_ˈy_k_ə");
        let length = |i: usize| phones[i].end - phones[i].start;
        assert!(length(2) > 2.0 * length(4), "{phones:?}");
        assert_eq!(length(0), builtin::inherent("P").unwrap());
        let long = phones_of_ipa("ˈiː");
        assert!(long[0].end > 1.6 * builtin::inherent("IY").unwrap());
    }
}
