//! A speech that brings its own sound (`bmlt:audiofile` on a `<speech>`, with `bmlt:marks`):
//! its utterance made from the sound, the text and the marks, not from a TTS. The speech runs
//! from the sound's first sample to its last. The text's words are matched to the marks' words
//! in order (letters and digits compared without case; a word the marks lack, or the marks'
//! word the text lacks, is skipped); an inline sync falls on the start of the marked word after
//! it, or at the end, and a Polly `ssml` mark of the sync's name wins. The lips follow Polly's
//! viseme marks where there are any; else each word's phones as the built-in TTS says them,
//! spread over the word's marked span (text words without a mark placed between their
//! neighbours); else, with a text but no word marks, the text's phones timed to the sound by
//! [`listen::align`]; else, with no text, phones heard in the sound itself
//! ([`listen::phones_of_sound`]: the jaw follows its loudness).

use std::sync::Arc;

use super::builtin::Builtin;
use super::listen;
use super::marks::Marks;
use super::{Audio, Phone, Tts, Utterance, Word};
use crate::language::bml::TextPart;

/// Longest a Polly viseme holds the mouth before it falls silent (seconds): a viseme lasts to
/// the next mark, which after a pause may be long.
const LONGEST_VISEME: f64 = 0.3;

/// The utterance of `text` said by the sound `audio`, timed by `marks` if any, and warnings
/// (marks past the sound's end, words of the text the marks lack).
pub fn utterance(
    text: &[TextPart],
    audio: Arc<Audio>,
    marks: Option<&Marks>,
) -> (Utterance, Vec<String>) {
    let length = audio.samples.len() as f64 / f64::from(audio.rate.max(1));
    let mut warnings = Vec::new();
    // what the built-in TTS makes of the text: its words, phones and syncs in its own time
    let mut said = Builtin.speak(text).unwrap_or_default();
    let mut marks = marks.cloned();
    if let Some(m) = marks.as_mut() {
        cut_to(m, length, &mut warnings);
        if said.words.is_empty() && !m.words.is_empty() {
            // no text: the marks' words are what is said
            let words: Vec<&str> = m.words.iter().map(|w| w.text.as_str()).collect();
            said = Builtin
                .speak(&[TextPart::Text(words.join(" "))])
                .unwrap_or_default();
        }
    }
    let spoken_words = said.words.len();
    let marked = marks.as_ref().filter(|m| !m.words.is_empty());
    // knots from the TTS's time to the sound's
    let knots = match marked {
        Some(m) if spoken_words > 0 => {
            let (knots, matched) = knots_from_words(&said.words, &m.words);
            if matched < spoken_words {
                warnings.push(format!(
                    "{} of the text's {spoken_words} words are not in the marks; they are placed between their neighbours",
                    spoken_words - matched
                ));
            }
            knots
        }
        _ if spoken_words > 0 && length <= listen::MAX_ALIGNED => {
            listen::align(&said.phones, &listen::frames(&audio))
        }
        _ => Vec::new(),
    };
    let words: Vec<Word> = if spoken_words > 0 && !knots.is_empty() {
        (said.words.iter())
            .map(|w| Word {
                text: w.text.clone(),
                start: listen::warp_time(&knots, w.start).clamp(0.0, length),
                end: listen::warp_time(&knots, w.end).clamp(0.0, length),
            })
            .collect()
    } else {
        marked.map(|m| m.words.clone()).unwrap_or_default()
    };
    let visemes = marks.as_ref().map(|m| m.visemes.as_slice()).unwrap_or(&[]);
    let phones = if !visemes.is_empty() {
        phones_of_visemes(visemes, length)
    } else if !knots.is_empty() {
        (said.phones.iter())
            .map(|p| Phone {
                symbol: p.symbol,
                start: listen::warp_time(&knots, p.start).clamp(0.0, length),
                end: listen::warp_time(&knots, p.end).clamp(0.0, length),
            })
            .filter(|p| p.end > p.start)
            .collect()
    } else {
        listen::phones_of_sound(&listen::frames(&audio))
    };
    let mut syncs: Vec<_> = (said.syncs.iter())
        .map(|(id, t)| {
            let named = marks
                .as_ref()
                .and_then(|m| m.named.iter().find(|(n, _)| n == id.as_str()));
            let at = match named {
                Some((_, at)) => *at,
                None if *t >= said.end - 1e-9 || knots.is_empty() => length,
                None => listen::warp_time(&knots, *t).clamp(0.0, length),
            };
            (id.clone(), at)
        })
        .collect();
    // inline syncs keep their text order
    for i in 1..syncs.len() {
        syncs[i].1 = syncs[i].1.max(syncs[i - 1].1);
    }
    let utterance = Utterance {
        phones,
        words,
        syncs,
        end: length,
        audio: Some(audio),
    };
    (utterance, warnings)
}

/// The marks cut to the sound's `length`, with a warning when any lay past it.
fn cut_to(m: &mut Marks, length: f64, warnings: &mut Vec<String>) {
    let past = m.words.iter().filter(|w| w.start > length + 1e-3).count()
        + m.visemes.iter().filter(|v| v.0 > length + 1e-3).count();
    if past > 0 {
        warnings.push(format!(
            "{past} marks lie past the sound's end ({length:.3} s); they are left out"
        ));
    }
    m.words.retain(|w| w.start <= length + 1e-3);
    m.visemes.retain(|v| v.0 <= length + 1e-3);
    for w in &mut m.words {
        w.start = w.start.min(length);
        w.end = if w.end.is_nan() {
            length
        } else {
            w.end.min(length)
        };
    }
}

/// A word compared: letters and digits, lower case.
fn plain(word: &str) -> String {
    (word.chars())
        .filter(|c| c.is_alphanumeric())
        .flat_map(char::to_lowercase)
        .collect()
}

/// Knots (TTS time, sound time) at the start and end of every text word matched to a marked
/// word (the longest common subsequence of the two word lists; where a word's end and the
/// next one's start are one TTS time, the start), and how many words matched.
fn knots_from_words(spoken: &[Word], marked: &[Word]) -> (Vec<(f64, f64)>, usize) {
    let a: Vec<String> = spoken.iter().map(|w| plain(&w.text)).collect();
    let b: Vec<String> = marked.iter().map(|w| plain(&w.text)).collect();
    let (n, m) = (a.len(), b.len());
    // lcs[i][j]: the longest common subsequence of a[i..] and b[j..]
    let mut lcs = vec![vec![0u32; m + 1]; n + 1];
    for i in (0..n).rev() {
        for j in (0..m).rev() {
            lcs[i][j] = if a[i] == b[j] {
                lcs[i + 1][j + 1] + 1
            } else {
                lcs[i + 1][j].max(lcs[i][j + 1])
            };
        }
    }
    let mut knots: Vec<(f64, f64)> = Vec::new();
    let mut push = |knot: (f64, f64)| match knots.last_mut() {
        Some(last) if knot.0 <= last.0 + 1e-9 => *last = (last.0, knot.1.max(last.1)),
        Some(last) if knot.1 < last.1 => {}
        _ => knots.push(knot),
    };
    let (mut i, mut j, mut matched) = (0, 0, 0);
    while i < n && j < m {
        if a[i] == b[j] {
            push((spoken[i].start, marked[j].start));
            push((spoken[i].end, marked[j].end.max(marked[j].start)));
            matched += 1;
            i += 1;
            j += 1;
        } else if lcs[i + 1][j] >= lcs[i][j + 1] {
            i += 1;
        } else {
            j += 1;
        }
    }
    (knots, matched)
}

/// Phones from Polly's viseme marks: each from its mark to the next (at most
/// [`LONGEST_VISEME`], then silence), the last to the sound's end.
fn phones_of_visemes(visemes: &[(f64, &'static str)], length: f64) -> Vec<Phone> {
    let mut phones = Vec::with_capacity(visemes.len() + 1);
    for (k, &(start, symbol)) in visemes.iter().enumerate() {
        let next = visemes.get(k + 1).map_or(length, |v| v.0);
        let end = next.min(start + LONGEST_VISEME);
        if end > start {
            phones.push(Phone { symbol, start, end });
        }
        if next > end + 1e-9 {
            phones.push(Phone {
                symbol: "pau",
                start: end,
                end: next,
            });
        }
    }
    // one silence, not several in a row
    phones.dedup_by(|b, a| {
        let both = a.symbol == "pau" && b.symbol == "pau";
        if both {
            a.end = b.end;
        }
        both
    });
    phones
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::language::bml::Id;

    fn silence(seconds: f64) -> Arc<Audio> {
        Arc::new(Audio {
            rate: 8000,
            samples: vec![0; (seconds * 8000.0) as usize],
        })
    }

    fn word(text: &str, start: f64, end: f64) -> Word {
        Word {
            text: text.into(),
            start,
            end,
        }
    }

    #[test]
    fn syncs_fall_on_the_marked_words_and_the_speech_lasts_as_the_sound() {
        let text = vec![
            TextPart::Text("Hello, ".into()),
            TextPart::Sync(Id::new_static("s1")),
            TextPart::Text("big world".into()),
            TextPart::Sync(Id::new_static("s2")),
        ];
        let marks = Marks {
            words: vec![
                word("Hello", 0.1, 0.4),
                word("big", 0.62, 0.8),
                word("world", 0.85, 1.3),
            ],
            ..Marks::default()
        };
        let (u, warnings) = utterance(&text, silence(1.5), Some(&marks));
        assert!(warnings.is_empty(), "{warnings:?}");
        assert_eq!(u.end, 1.5);
        assert_eq!(u.syncs[0].1, 0.62);
        assert_eq!(
            u.syncs[1].1, 1.5,
            "a sync after the last word is at the end"
        );
        let b = u.phones.iter().find(|p| p.symbol == "B").unwrap();
        assert!(b.start >= 0.62 && b.end <= 0.8, "{b:?}");
    }

    #[test]
    fn words_the_marks_lack_are_placed_between_and_marks_past_the_end_are_warned() {
        let text = vec![
            TextPart::Text("one two ".into()),
            TextPart::Sync(Id::new_static("s")),
            TextPart::Text("three".into()),
        ];
        let marks = Marks {
            words: vec![
                word("one", 0.0, 0.3),
                word("three", 0.8, 1.0),
                word("x", 2.5, 2.6),
            ],
            ..Marks::default()
        };
        let (u, warnings) = utterance(&text, silence(1.2), Some(&marks));
        assert_eq!(warnings.len(), 2, "{warnings:?}");
        assert!(warnings[0].contains("past the sound's end"));
        assert!(warnings[1].starts_with("1 of the text's 3 words"));
        assert_eq!(u.syncs[0].1, 0.8);
        assert!(u.words[1].start >= 0.3 && u.words[1].end <= 0.8);
    }

    #[test]
    fn polly_visemes_drive_the_lips_and_named_marks_the_syncs() {
        let text = vec![
            TextPart::Text("Mama".into()),
            TextPart::Sync(Id::new_static("m")),
        ];
        let marks = Marks {
            words: vec![word("Mama", 0.0, f64::NAN)],
            visemes: vec![
                (0.0, "P"),
                (0.1, "AA"),
                (0.25, "P"),
                (0.35, "AA"),
                (1.5, "pau"),
            ],
            named: vec![("m".into(), 0.25)],
            ..Marks::default()
        };
        let (u, _) = utterance(&text, silence(2.0), Some(&marks));
        let symbols: Vec<_> = u.phones.iter().map(|p| p.symbol).collect();
        assert_eq!(symbols, ["P", "AA", "P", "AA", "pau"]);
        assert_eq!(u.phones[3].end, 0.35 + LONGEST_VISEME);
        assert_eq!(u.syncs[0].1, 0.25);
    }
}
