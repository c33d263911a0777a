//! The flite TTS (CMU Flite, Debian package `flite`, a BSD-style licence), run as a program:
//! `flite -psdur -t TEXT -o FILE.wav` gives its phones with their end times and the sound. The
//! text between two inline syncs is said in one call, so every sync falls on a boundary flite
//! itself chose (the end of one call's speech, the start of the next); the silence flite puts
//! before and after each piece is cut, so the speech starts with its first phone and ends with
//! its last, and the pieces' sound is joined sample by sample. Word times are not known inside
//! a piece (flite does not print them): `words` lists the pieces.

use std::path::PathBuf;
use std::process::Command;
use std::sync::atomic::{AtomicU64, Ordering};

use super::{Audio, Phone, Tts, Utterance};
use crate::language::bml::TextPart;

/// The flite program (looked up on the PATH).
#[derive(Debug, Clone)]
pub struct Flite {
    program: PathBuf,
}

impl Default for Flite {
    fn default() -> Self {
        Flite {
            program: PathBuf::from("flite"),
        }
    }
}

/// What a missing program is told.
pub const MISSING: &str = "the flite TTS is not installed: install the Debian package 'flite' (apt-get install flite), or use --tts builtin";

/// One piece said by flite: its phones (from 0, silence cut) and its samples.
struct Piece {
    phones: Vec<Phone>,
    samples: Vec<i16>,
    rate: u32,
}

/// A fresh temporary file name for one call's sound.
fn scratch() -> PathBuf {
    static NEXT: AtomicU64 = AtomicU64::new(0);
    let n = NEXT.fetch_add(1, Ordering::Relaxed);
    std::env::temp_dir().join(format!("bmlr-flite-{}-{n}.wav", std::process::id()))
}

/// Our name for a flite phone (flite's are lower-case ARPAbet with `ax` for the schwa).
fn symbol(flite: &str) -> &'static str {
    let upper = match flite {
        "ax" => "AH".to_string(),
        "dx" => "D".to_string(),
        "pau" | "h#" | "brth" => return "pau",
        p => p.to_ascii_uppercase(),
    };
    super::builtin::phone_name(&upper).unwrap_or("AH")
}

impl Flite {
    /// Flite at `program`.
    pub fn at(program: impl Into<PathBuf>) -> Flite {
        Flite {
            program: program.into(),
        }
    }

    /// Whether the program runs (its version, or the error for a missing one).
    pub fn check(&self) -> Result<String, String> {
        let out = Command::new(&self.program)
            .arg("--version")
            .output()
            .map_err(|_| MISSING.to_string())?;
        Ok(String::from_utf8_lossy(&out.stdout).trim().to_string())
    }

    /// Says `text` (one piece).
    fn piece(&self, text: &str) -> Result<Piece, String> {
        let wav = scratch();
        let out = Command::new(&self.program)
            .args(["-psdur", "-t", text, "-o"])
            .arg(&wav)
            .output()
            .map_err(|_| MISSING.to_string())?;
        if !out.status.success() {
            let _ = std::fs::remove_file(&wav);
            return Err(format!(
                "flite failed on {text:?}: {}",
                String::from_utf8_lossy(&out.stderr).trim()
            ));
        }
        let read = hound::WavReader::open(&wav).map_err(|e| format!("flite's sound: {e}"));
        let _ = std::fs::remove_file(&wav);
        let mut reader = read?;
        let rate = reader.spec().sample_rate;
        let samples: Vec<i16> = reader.samples::<i16>().filter_map(Result::ok).collect();
        let mut phones = Vec::new();
        let mut start = 0.0;
        for seg in String::from_utf8_lossy(&out.stdout).split_whitespace() {
            let Some((name, end)) = seg.split_once(':') else {
                continue;
            };
            let Ok(end) = end.parse::<f64>() else {
                continue;
            };
            phones.push(Phone {
                symbol: symbol(name),
                start,
                end,
            });
            start = end;
        }
        Ok(cut_silence(Piece {
            phones,
            samples,
            rate,
        }))
    }
}

/// The piece without the pauses at its ends (phones shifted to start at 0, samples cut to match).
fn cut_silence(mut p: Piece) -> Piece {
    let lead = (p.phones.first())
        .filter(|f| f.symbol == "pau")
        .map_or(0.0, |f| f.end);
    let tail = (p.phones.last())
        .filter(|l| l.symbol == "pau")
        .map(|l| l.start);
    p.phones.retain(|ph| {
        !(ph.symbol == "pau"
            && (ph.start < lead + 1e-9 || tail.is_some_and(|t| ph.start >= t - 1e-9)))
    });
    let end = tail.unwrap_or(p.phones.last().map_or(lead, |l| l.end));
    for ph in &mut p.phones {
        ph.start -= lead;
        ph.end -= lead;
    }
    let at = |t: f64| ((t * f64::from(p.rate)).round() as usize).min(p.samples.len());
    let (a, b) = (at(lead), at(end));
    p.samples = p.samples[a..b.max(a)].to_vec();
    p
}

impl Tts for Flite {
    fn name(&self) -> &'static str {
        "flite"
    }

    fn speak(&self, text: &[TextPart]) -> Result<Utterance, String> {
        super::pieces::say_in_pieces(text, 8000, |words| {
            let p = self.piece(words)?;
            Ok((
                p.phones,
                Audio {
                    rate: p.rate,
                    samples: p.samples,
                },
            ))
        })
    }
}
