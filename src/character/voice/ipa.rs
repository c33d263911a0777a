//! International Phonetic Alphabet phonemes as the realizer's phones: one table for every
//! language a voice speaks in IPA (espeak-ng's `--ipa`). Each phoneme becomes the English
//! ARPAbet phone whose mouth looks most like it, so that the lips (`lipsync`) show it through
//! the same visemes: what matters is where the lips and jaw are, not the sound. A phoneme is
//! read by its first letter, with diacritics, length and stress marks dropped; affricates and
//! diphthongs by their first two letters where those differ in shape (t͡ʃ, d͡ʒ, aɪ, aʊ, ɔɪ, eɪ,
//! oʊ, əʊ).

/// The realizer phone of IPA phoneme `ipa` (`pau` for silence, an unknown symbol or nothing).
pub fn phone(ipa: &str) -> &'static str {
    let letters: String = ipa.chars().filter(|c| !is_mark(*c)).collect();
    let mut chars = letters.chars();
    let (Some(first), second) = (chars.next(), chars.next()) else {
        return "pau";
    };
    if let Some(two) = second.and_then(|s| pair(first, s)) {
        return two;
    }
    single(first)
}

/// Marks that do not change a phoneme's mouth: stress, length, ties, diacritics.
fn is_mark(c: char) -> bool {
    matches!(
        c,
        'ˈ' | 'ˌ' | 'ː' | 'ˑ' | '͡' | '‿' | '\'' | ',' | ':' | '_' | '-' | '#'
    ) || ('\u{0300}'..='\u{036f}').contains(&c)
        || ('\u{02b0}'..='\u{02ff}').contains(&c)
}

/// Affricates and diphthongs that a single letter would show wrongly.
fn pair(a: char, b: char) -> Option<&'static str> {
    Some(match (a, b) {
        ('t', 'ʃ') | ('t', 's') => "CH",
        ('d', 'ʒ') | ('d', 'z') => "JH",
        ('a', 'ɪ') | ('a', 'i') => "AY",
        ('a', 'ʊ') | ('a', 'u') => "AW",
        ('ɔ', 'ɪ') | ('ɔ', 'y') => "OY",
        ('e', 'ɪ') | ('e', 'i') => "EY",
        ('o', 'ʊ') | ('ə', 'ʊ') | ('o', 'u') => "OW",
        _ => return None,
    })
}

/// The phone of one IPA letter.
fn single(c: char) -> &'static str {
    match c {
        // lips closed
        'p' | 'b' | 'm' | 'ɓ' | 'ʙ' => "P",
        'ɸ' | 'β' => "B",
        // lips on the teeth
        'f' | 'v' | 'ɱ' | 'ʋ' => "F",
        // tongue between the teeth
        'θ' | 'ð' => "TH",
        // tongue at the ridge
        't' | 'd' | 'ʈ' | 'ɖ' | 'ɗ' | 'ɾ' | 'ɽ' => "T",
        'n' | 'ɳ' | 'l' | 'ɭ' | 'ɬ' | 'ɮ' | 'ʎ' | 'ɲ' => "N",
        's' | 'z' | 'ʂ' | 'ʐ' | 'ɕ' | 'ʑ' => "S",
        'ʃ' | 'ʒ' | 'ç' | 'ʝ' => "SH",
        'ɹ' | 'r' | 'ɻ' | 'ʀ' | 'ʁ' => "R",
        // the back of the mouth: the lips follow the vowels around
        'k' | 'g' | 'ɡ' | 'ŋ' | 'q' | 'ɢ' | 'x' | 'ɣ' | 'χ' | 'ħ' | 'ʕ' | 'ʔ' => "K",
        'h' | 'ɦ' => "HH",
        'j' | 'ɥ' => "Y",
        'w' | 'ʍ' | 'ɰ' => "W",
        // vowels, by openness and rounding
        'a' | 'ɑ' | 'ä' | 'æ' | 'ɶ' | 'ɒ' => "AA",
        'ɐ' | 'ʌ' | 'ə' | 'ɘ' | 'ɚ' => "AH",
        'e' | 'ɛ' | 'ø' | 'œ' | 'ɵ' => "EH",
        'ɜ' | 'ɝ' | 'ɞ' => "ER",
        'i' | 'ɪ' | 'ɨ' | 'y' | 'ʏ' => "IY",
        'o' | 'ɤ' => "OW",
        'ɔ' => "AO",
        'u' | 'ʊ' | 'ɯ' | 'ʉ' => "UW",
        _ => "pau",
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn phonemes_of_several_languages_take_the_mouth_they_show() {
        // espeak-ng's IPA for English, German, French and Spanish words
        for (ipa, phone_) in [
            ("b", "P"),
            ("m", "P"),
            ("ˈaɪ", "AY"),
            ("əʊ", "OW"),
            ("ɑː", "AA"),
            ("t͡ʃ", "CH"),
            ("ʃ", "SH"),
            ("ɾ", "T"),
            ("ʁ", "R"),
            ("ç", "SH"),
            ("y", "IY"),
            ("ø", "EH"),
            ("ɔ̃", "AO"),
            ("ɛ̃", "EH"),
            ("β", "B"),
            ("x", "K"),
            ("", "pau"),
        ] {
            assert_eq!(phone(ipa), phone_, "{ipa}");
        }
    }
}
