//! A metronome voice: each word lasts its estimated syllables × 0.2 s (groups of vowels; a silent
//! final `e` does not count), with 0.15 s after `,;:` and 0.3 s after `.!?` — also after the last
//! word. Its timing can be worked out by hand, which is what schedule tests and hosts that want
//! predictable speech use it for; each syllable is spoken as one open vowel (`AH`).

use super::{Phone, Tts, Utterance, Word};
use crate::language::bml::TextPart;

/// Seconds per syllable.
pub const SYLLABLE: f64 = 0.2;
/// Pause after `,`, `;` or `:`.
pub const COMMA_PAUSE: f64 = 0.15;
/// Pause after `.`, `!` or `?`.
pub const SENTENCE_PAUSE: f64 = 0.3;

/// The metronome voice.
#[derive(Debug, Clone, Copy, Default)]
pub struct Syllables;

/// Syllables of a word, estimated as groups of vowels (a silent final `e` after a consonant
/// does not count in a word of three letters or more); at least one for any word with a letter or
/// digit, none for punctuation.
pub fn syllables(word: &str) -> usize {
    let (mut groups, mut letters, mut any) = (0, 0, false);
    let (mut prev_vowel, mut e_end) = (false, false);
    for c in word.chars() {
        if c.is_alphabetic() {
            let c = c.to_ascii_lowercase();
            let vowel = matches!(c, 'a' | 'e' | 'i' | 'o' | 'u' | 'y');
            if vowel && !prev_vowel {
                groups += 1;
            }
            e_end = c == 'e' && !prev_vowel;
            prev_vowel = vowel;
            letters += 1;
            any = true;
        } else if c.is_numeric() {
            any = true;
        }
    }
    let silent_e = letters > 2 && e_end && groups > 1;
    if any {
        (groups - usize::from(silent_e)).max(1)
    } else {
        0
    }
}

/// The pause after a word ending in `last`.
fn pause_after(last: char) -> f64 {
    match last {
        '.' | '!' | '?' => SENTENCE_PAUSE,
        ',' | ';' | ':' => COMMA_PAUSE,
        _ => 0.0,
    }
}

impl Tts for Syllables {
    fn name(&self) -> &'static str {
        "syllables"
    }

    fn speak(&self, text: &[TextPart]) -> Result<Utterance, String> {
        let mut u = Utterance::default();
        let mut t = 0.0;
        for part in text {
            match part {
                TextPart::Sync(id) => u.syncs.push((id.clone(), t)),
                TextPart::Text(text) => {
                    for w in text.split_whitespace() {
                        let start = t;
                        for _ in 0..syllables(w) {
                            u.phones.push(Phone {
                                symbol: "AH",
                                start: t,
                                end: t + SYLLABLE,
                            });
                            t += SYLLABLE;
                        }
                        if t > start {
                            u.words.push(Word {
                                text: w.to_string(),
                                start,
                                end: t,
                            });
                        }
                        let pause = pause_after(w.chars().last().unwrap_or(' '));
                        if pause > 0.0 {
                            u.phones.push(Phone {
                                symbol: "pau",
                                start: t,
                                end: t + pause,
                            });
                            t += pause;
                        }
                    }
                }
            }
        }
        if t == 0.0 {
            t = SYLLABLE;
            u.phones.push(Phone {
                symbol: "pau",
                start: 0.0,
                end: t,
            });
            for s in &mut u.syncs {
                s.1 = 0.0;
            }
        }
        u.end = t;
        Ok(u)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn syllable_estimates() {
        for (w, n) in [
            ("Hey", 1),
            ("want?", 1),
            ("Welcome", 2),
            ("gentlemen!", 3),
            ("make", 1),
            (",", 0),
            ("16", 1),
        ] {
            assert_eq!(syllables(w), n, "{w}");
        }
    }

    #[test]
    fn words_take_their_syllables_and_punctuation_its_pause() {
        let text = [TextPart::Text("Welcome! I am Griet,".into())];
        let u = Syllables.speak(&text).unwrap();
        // Welcome(2)! I(1) am(1) Griet(1), = 5 syllables, a sentence and a comma pause
        assert!((u.end - (1.0 + 0.3 + 0.15)).abs() < 1e-12);
        assert_eq!(u.words.len(), 4);
    }
}
