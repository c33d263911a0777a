//! Saying a text piece by piece, as the voices that run a program do (flite, espeak-ng): the
//! text between two inline syncs is said in one call, so every sync falls on a boundary of the
//! sound itself; the pieces' phones and samples are joined in order, each piece a "word" of the
//! utterance. An empty text is a short silence, as with the built-in TTS.

use std::sync::Arc;

use super::{builtin, Audio, Phone, Utterance, Word};
use crate::language::bml::TextPart;

/// The utterance of `text`, each piece between syncs said by `say` (its phones from 0, its
/// samples, their rate); `rate` is the sound's rate if nothing is said.
pub(super) fn say_in_pieces(
    text: &[TextPart],
    mut rate: u32,
    mut say: impl FnMut(&str) -> Result<(Vec<Phone>, Audio), String>,
) -> Result<Utterance, String> {
    let mut u = Utterance::default();
    let mut samples = Vec::new();
    let mut t = 0.0;
    let mut piece = String::new();
    let mut flush = |piece: &mut String, u: &mut Utterance, t: &mut f64, samples: &mut Vec<i16>| {
        let words = piece.trim().to_string();
        piece.clear();
        if !words.chars().any(char::is_alphanumeric) {
            return Ok::<(), String>(());
        }
        let (phones, audio) = say(&words)?;
        rate = audio.rate;
        let length = audio.samples.len() as f64 / f64::from(audio.rate.max(1));
        u.phones.extend(phones.into_iter().map(|p| Phone {
            start: p.start + *t,
            end: p.end + *t,
            ..p
        }));
        samples.extend(audio.samples);
        u.words.push(Word {
            text: words,
            start: *t,
            end: *t + length,
        });
        *t += length;
        Ok(())
    };
    for part in text {
        match part {
            TextPart::Text(s) => piece.push_str(s),
            TextPart::Sync(id) => {
                flush(&mut piece, &mut u, &mut t, &mut samples)?;
                u.syncs.push((id.clone(), t));
            }
        }
    }
    flush(&mut piece, &mut u, &mut t, &mut samples)?;
    if t == 0.0 {
        t = builtin::EMPTY;
        samples = vec![0; (t * f64::from(rate)) as usize];
        u.phones.push(Phone {
            symbol: "pau",
            start: 0.0,
            end: t,
        });
    }
    u.end = t;
    u.audio = Some(Arc::new(Audio { rate, samples }));
    Ok(u)
}
