//! The built-in TTS (pure Rust, headless, no audio): each word is looked up in a small lexicon
//! of common words (`fixtures/voice/lexicon.txt`) or spelled out by English letter-to-sound rules
//! (digraphs, a silent final `e` that lengthens the vowel before it, soft `c` and `g`, the
//! first vowel stressed and unstressed vowels reduced); then each phone gets a duration: its
//! inherent duration (after Klatt's duration model, 1979) at a running-speech tempo, shortened when the vowel is
//! unstressed, lengthened in the last syllable before a pause (phrase-final lengthening), with
//! pauses after punctuation (`,;:` 0.2 s, `.!?` 0.4 s, between phrases only: a speech ends with
//! its last phone). An inline sync is at the start of the word after it (at the end if none).

use std::collections::HashMap;
use std::sync::LazyLock;

use super::{Phone, Tts, Utterance, Word};
use crate::language::bml::TextPart;

const LEXICON: &str = include_str!("../../../fixtures/voice/lexicon.txt");

/// Pause after `,`, `;` or `:` (seconds).
pub const COMMA_PAUSE: f64 = 0.2;
/// Pause after `.`, `!` or `?`.
pub const SENTENCE_PAUSE: f64 = 0.4;
/// How long an empty speech lasts.
pub const EMPTY: f64 = 0.2;
/// Every phone lasts this share of its inherent duration: Klatt's durations are for careful
/// speech; at 0.85 running speech comes out at about five syllables a second.
pub const TEMPO: f64 = 0.85;
/// Unstressed vowels last this share of their inherent duration.
pub const UNSTRESSED: f64 = 0.65;
/// The last syllable before a pause: its vowel lasts this much longer (consonants after it half
/// as much more).
pub const PHRASE_FINAL: f64 = 1.4;

/// The built-in TTS.
#[derive(Debug, Clone, Copy, Default)]
pub struct Builtin;

/// A phone before timing: symbol and stress (vowels: 0, 1 or 2; consonants: 0).
type Spelled = (&'static str, u8);

/// Every ARPAbet phone with its inherent duration (seconds), vowels first.
const PHONES: &[(&str, f64)] = &[
    ("AA", 0.21),
    ("AE", 0.20),
    ("AH", 0.12),
    ("AO", 0.21),
    ("AW", 0.23),
    ("AY", 0.22),
    ("EH", 0.14),
    ("ER", 0.17),
    ("EY", 0.19),
    ("IH", 0.13),
    ("IY", 0.16),
    ("OW", 0.19),
    ("OY", 0.24),
    ("UH", 0.14),
    ("UW", 0.18),
    ("B", 0.08),
    ("CH", 0.11),
    ("D", 0.07),
    ("DH", 0.05),
    ("F", 0.095),
    ("G", 0.075),
    ("HH", 0.06),
    ("JH", 0.095),
    ("K", 0.08),
    ("L", 0.07),
    ("M", 0.07),
    ("N", 0.06),
    ("NG", 0.08),
    ("P", 0.085),
    ("R", 0.07),
    ("S", 0.1),
    ("SH", 0.1),
    ("T", 0.075),
    ("TH", 0.085),
    ("V", 0.06),
    ("W", 0.07),
    ("Y", 0.065),
    ("Z", 0.075),
    ("ZH", 0.085),
];

/// How many of [`PHONES`] are vowels.
const VOWELS: usize = 15;

/// The phone `symbol` as a `'static` name, and its inherent duration.
fn phone(symbol: &str) -> Option<(&'static str, f64)> {
    PHONES.iter().find(|(p, _)| *p == symbol).copied()
}

/// The `'static` name of ARPAbet phone `symbol` (upper case, no stress digit), if it is one.
pub fn phone_name(symbol: &str) -> Option<&'static str> {
    phone(symbol).map(|p| p.0)
}

/// The inherent duration of ARPAbet phone `symbol` (seconds), if it is one.
pub fn inherent(symbol: &str) -> Option<f64> {
    phone(symbol).map(|p| p.1)
}

/// Whether `symbol` is a vowel.
pub fn is_vowel(symbol: &str) -> bool {
    PHONES[..VOWELS].iter().any(|(p, _)| *p == symbol)
}

/// The lexicon: word → phones.
fn lexicon() -> &'static HashMap<&'static str, Vec<Spelled>> {
    static WORDS: LazyLock<HashMap<&'static str, Vec<Spelled>>> = LazyLock::new(|| {
        let mut words = HashMap::new();
        for line in LEXICON
            .lines()
            .filter(|l| !l.starts_with('#') && !l.trim().is_empty())
        {
            let mut parts = line.split_whitespace();
            let Some(word) = parts.next() else { continue };
            let phones = parts
                .map(|p| {
                    let (name, stress) = match p.char_indices().last() {
                        Some((i, c)) if c.is_ascii_digit() => (&p[..i], c as u8 - b'0'),
                        _ => (p, 0),
                    };
                    let (name, _) =
                        phone(name).unwrap_or_else(|| panic!("lexicon: '{p}' in '{word}'"));
                    (name, stress)
                })
                .collect();
            words.insert(word, phones);
        }
        words
    });
    &WORDS
}

/// The digits as words.
const DIGITS: [&str; 10] = [
    "zero", "one", "two", "three", "four", "five", "six", "seven", "eight", "nine",
];

/// The phones of `word` (lower case letters and digits only).
pub fn pronounce(word: &str) -> Vec<Spelled> {
    if let Some(p) = lexicon().get(word) {
        return p.clone();
    }
    if word.chars().all(|c| c.is_ascii_digit()) {
        return (word.chars())
            .flat_map(|d| pronounce(DIGITS[(d as u8 - b'0') as usize]))
            .collect();
    }
    let letters: Vec<u8> = word.bytes().filter(u8::is_ascii_lowercase).collect();
    stress(letter_to_sound(&letters))
}

fn vowel_letter(c: u8) -> bool {
    matches!(c, b'a' | b'e' | b'i' | b'o' | b'u')
}

/// Phones of a spelling by rule (stress not yet given: all vowels 1).
fn letter_to_sound(w: &[u8]) -> Vec<&'static str> {
    let mut out: Vec<&'static str> = Vec::new();
    let mut i = 0;
    let at = |k: usize| w.get(k).copied().unwrap_or(0);
    let starts = |k: usize, s: &str| w.get(k..).is_some_and(|r| r.starts_with(s.as_bytes()));
    while i < w.len() {
        let c = w[i];
        let next = at(i + 1);
        // a vowel, one consonant and a final e: the vowel says its name, the e is silent
        let magic = vowel_letter(c)
            && next != 0
            && !vowel_letter(next)
            && next != b'r'
            && at(i + 2) == b'e'
            && i + 3 == w.len();
        let (phones, len): (&[&'static str], usize) = if starts(i, "tion") {
            (&["SH", "AH", "N"], 4)
        } else if starts(i, "sion") {
            (&["ZH", "AH", "N"], 4)
        } else if starts(i, "igh") {
            (&["AY"], 3)
        } else if starts(i, "ough") || starts(i, "augh") {
            (&["AO"], 4)
        } else if starts(i, "tch") {
            (&["CH"], 3)
        } else if starts(i, "dge") {
            (&["JH"], 3)
        } else if magic {
            let long: &[&'static str] = match c {
                b'a' => &["EY"],
                b'e' => &["IY"],
                b'i' => &["AY"],
                b'o' => &["OW"],
                _ => &["UW"],
            };
            out.extend_from_slice(long);
            out.extend(consonant(next, 0));
            i += 3;
            continue;
        } else if let Some(d) = digraph(&w[i..], i == 0, i + 2 == w.len()) {
            d
        } else if c == b'e' && i + 1 == w.len() && i > 1 {
            (&[], 1) // a silent final e
        } else if c == b'y' {
            let only = !w.iter().any(|&x| vowel_letter(x));
            match (i, i + 1 == w.len()) {
                (0, _) => (&["Y"], 1),
                (_, true) if only => (&["AY"], 1),
                (_, true) => (&["IY"], 1),
                _ => (&["IH"], 1),
            }
        } else if vowel_letter(c) {
            let short: &[&'static str] = match c {
                b'a' => &["AE"],
                b'e' => &["EH"],
                b'i' => &["IH"],
                b'o' => &["AA"],
                _ => &["AH"],
            };
            (short, 1)
        } else if c == next {
            (&[], 1) // a doubled consonant is one
        } else {
            out.extend(consonant(c, next));
            i += 1;
            continue;
        };
        out.extend_from_slice(phones);
        i += len;
    }
    out
}

/// Two- and three-letter spellings of one sound: `rest` from here, whether at the start, and
/// whether the two letters end the word.
fn digraph(rest: &[u8], first: bool, last2: bool) -> Option<(&'static [&'static str], usize)> {
    let two = rest.get(..2)?;
    let p: &'static [&'static str] = match two {
        b"ch" => &["CH"],
        b"sh" => &["SH"],
        b"th" => &["TH"],
        b"ph" => &["F"],
        b"wh" => &["W"],
        b"ck" => &["K"],
        b"ng" => &["NG"],
        b"qu" => &["K", "W"],
        b"gh" => &[],
        b"kn" if first => &["N"],
        b"wr" if first => &["R"],
        b"mb" if last2 => &["M"],
        b"ee" | b"ea" => &["IY"],
        b"oo" => &["UW"],
        b"ou" => &["AW"],
        b"ow" if last2 => &["OW"],
        b"ow" => &["AW"],
        b"ai" | b"ay" | b"ei" | b"ey" => &["EY"],
        b"oa" => &["OW"],
        b"oi" | b"oy" => &["OY"],
        b"au" | b"aw" => &["AO"],
        b"ie" if last2 => &["AY"],
        b"ie" => &["IY"],
        b"ew" | b"ue" | b"ui" => &["UW"],
        b"ar" => &["AA", "R"],
        b"or" => &["AO", "R"],
        b"er" | b"ir" | b"ur" => &["ER"],
        _ => return None,
    };
    Some((p, 2))
}

/// The sound of consonant letter `c` before letter `next`.
fn consonant(c: u8, next: u8) -> Vec<&'static str> {
    let soft = matches!(next, b'e' | b'i' | b'y');
    let one = |p: &'static str| vec![p];
    match c {
        b'c' if soft => one("S"),
        b'c' => one("K"),
        b'g' if soft => one("JH"),
        b'g' => one("G"),
        b'x' => vec!["K", "S"],
        b'j' => one("JH"),
        b'h' => one("HH"),
        b'q' => one("K"),
        b'b' => one("B"),
        b'd' => one("D"),
        b'f' => one("F"),
        b'k' => one("K"),
        b'l' => one("L"),
        b'm' => one("M"),
        b'n' => one("N"),
        b'p' => one("P"),
        b'r' => one("R"),
        b's' => one("S"),
        b't' => one("T"),
        b'v' => one("V"),
        b'w' => one("W"),
        b'z' => one("Z"),
        _ => Vec::new(),
    }
}

/// Stress by rule: the first vowel primary; the others unstressed, short vowels reduced to a
/// schwa (AH).
fn stress(phones: Vec<&'static str>) -> Vec<Spelled> {
    let mut seen = false;
    (phones.into_iter())
        .map(|p| {
            if !is_vowel(p) {
                return (p, 0);
            }
            if !seen {
                seen = true;
                return (p, 1);
            }
            let reduced = if matches!(p, "AE" | "EH" | "AA" | "AH") {
                "AH"
            } else {
                p
            };
            (reduced, 0)
        })
        .collect()
}

/// A word of the text: its letters (lower case) and the pause its punctuation asks for.
struct Token {
    text: String,
    pause: f64,
}

/// The words of a run of text.
fn tokens(text: &str) -> Vec<Token> {
    (text.split_whitespace())
        .filter_map(|raw| {
            let word: String = (raw.chars())
                .filter(|c| c.is_alphanumeric())
                .flat_map(char::to_lowercase)
                .collect();
            let pause = match raw.trim_end_matches(['"', '\'', ')']).chars().last() {
                Some('.' | '!' | '?') => SENTENCE_PAUSE,
                Some(',' | ';' | ':') => COMMA_PAUSE,
                _ => 0.0,
            };
            (!word.is_empty() || pause > 0.0).then_some(Token { text: word, pause })
        })
        .collect()
}

/// Adds `word`'s phones at the end of `phones` from `t`; returns the end. The last syllable
/// is lengthened when a pause follows.
fn time_word(spelled: &[Spelled], mut t: f64, before_pause: bool, phones: &mut Vec<Phone>) -> f64 {
    let last_vowel = spelled.iter().rposition(|(p, _)| is_vowel(p));
    for (k, &(p, stress)) in spelled.iter().enumerate() {
        let (symbol, inherent) = phone(p).unwrap_or((p, 0.08));
        let mut d = inherent * TEMPO;
        if is_vowel(symbol) && stress == 0 {
            d *= UNSTRESSED;
        }
        if before_pause && last_vowel.is_some_and(|v| k >= v) {
            d *= if k == last_vowel.unwrap_or(0) {
                PHRASE_FINAL
            } else {
                1.0 + (PHRASE_FINAL - 1.0) / 2.0
            };
        }
        phones.push(Phone {
            symbol,
            start: t,
            end: t + d,
        });
        t += d;
    }
    t
}

impl Tts for Builtin {
    fn name(&self) -> &'static str {
        "builtin"
    }

    fn speak(&self, text: &[TextPart]) -> Result<Utterance, String> {
        let mut u = Utterance::default();
        let mut t = 0.0;
        let mut pending_syncs = Vec::new();
        let mut pause = 0.0; // owed before the next word
        for part in text {
            let TextPart::Text(text) = part else {
                if let TextPart::Sync(id) = part {
                    pending_syncs.push(id.clone());
                }
                continue;
            };
            for token in tokens(text) {
                let spelled = pronounce(&token.text);
                if !spelled.is_empty() {
                    if pause > 0.0 && !u.phones.is_empty() {
                        u.phones.push(Phone {
                            symbol: "pau",
                            start: t,
                            end: t + pause,
                        });
                        t += pause;
                    }
                    pause = 0.0;
                    u.syncs.extend(pending_syncs.drain(..).map(|id| (id, t)));
                    let start = t;
                    t = time_word(&spelled, t, token.pause > 0.0, &mut u.phones);
                    u.words.push(Word {
                        text: token.text,
                        start,
                        end: t,
                    });
                }
                pause = pause.max(token.pause);
            }
        }
        if u.phones.is_empty() {
            u.phones.push(Phone {
                symbol: "pau",
                start: 0.0,
                end: EMPTY,
            });
            t = EMPTY;
        }
        u.syncs.extend(pending_syncs.drain(..).map(|id| (id, t)));
        u.end = t;
        Ok(u)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn phones(word: &str) -> String {
        pronounce(word)
            .iter()
            .map(|p| p.0)
            .collect::<Vec<_>>()
            .join(" ")
    }

    #[test]
    fn letter_to_sound_rules_spell_regular_words() {
        assert_eq!(phones("cat"), "K AE T");
        assert_eq!(phones("make"), "M EY K");
        assert_eq!(phones("shine"), "SH AY N");
        assert_eq!(phones("night"), "N AY T");
        assert_eq!(phones("city"), "S IH T IY");
        assert_eq!(phones("ship"), "SH IH P");
        assert_eq!(phones("nation"), "N AE SH AH N");
        assert_eq!(phones("beat"), "B IY T");
        assert_eq!(phones("42"), "F AO R T UW");
        assert_eq!(phones("the"), "DH AH", "from the lexicon");
    }

    #[test]
    fn durations_follow_stress_phrase_ends_and_punctuation() {
        let text = [TextPart::Text("Hello, world. Bye".into())];
        let u = Builtin.speak(&text).unwrap();
        assert_eq!(u.words.len(), 3);
        let pauses: Vec<f64> = (u.phones.iter())
            .filter(|p| p.symbol == "pau")
            .map(|p| p.end - p.start)
            .collect();
        assert_eq!(pauses.len(), 2);
        assert!(
            (pauses[0] - COMMA_PAUSE).abs() < 1e-9 && (pauses[1] - SENTENCE_PAUSE).abs() < 1e-9
        );
        assert_eq!(
            u.end,
            u.phones.last().unwrap().end,
            "ends with its last phone"
        );
        // "hello": the unstressed first vowel is short, the stressed final one lengthened
        let vowels: Vec<&Phone> = u.phones.iter().filter(|p| p.is_vowel()).collect();
        assert!((vowels[0].end - vowels[0].start - 0.12 * TEMPO * UNSTRESSED).abs() < 1e-9);
        assert!((vowels[1].end - vowels[1].start - 0.19 * TEMPO * PHRASE_FINAL).abs() < 1e-9);
        // about four to six syllables a second in running speech
        let text = [TextPart::Text(
            "we think that the people of this city like to walk along the river in the morning"
                .into(),
        )];
        let u = Builtin.speak(&text).unwrap();
        let rate = u.phones.iter().filter(|p| p.is_vowel()).count() as f64 / u.end;
        assert!((4.5..5.5).contains(&rate), "{rate} syllables per second");
    }
}
