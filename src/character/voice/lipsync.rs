//! Lip sync: each phone is shown as one of the 15 visemes, and neighbouring phones blend by
//! coarticulation after Cohen and Massaro (1993): every phone has a *dominance* over the mouth
//! that peaks at its centre and decays exponentially with distance in time, and the mouth at any
//! moment is the dominance-weighted mean of the visemes of the phones around it. Lips that must
//! close (p, b, m) and lips on the teeth (f, v) dominate strongly and briefly, so they reach
//! their shape whatever the neighbours are; vowels dominate their own span; `h` barely at all (it
//! takes the shape of the vowels around it); pauses close the mouth (`sil`).

use super::Phone;
use crate::character::face::VISEMES;

/// The viseme (an index into [`VISEMES`]) of ARPAbet phone `symbol`.
pub fn viseme(symbol: &str) -> usize {
    let name = match symbol {
        "P" | "B" | "M" => "PP",
        "F" | "V" => "FF",
        "TH" | "DH" => "TH",
        "T" | "D" => "DD",
        "K" | "G" | "NG" | "HH" => "kk",
        "CH" | "JH" | "SH" | "ZH" => "CH",
        "S" | "Z" => "SS",
        "N" | "L" => "nn",
        "R" | "ER" => "RR",
        "AA" | "AE" | "AH" | "AY" | "AW" => "aa",
        "EH" | "EY" => "E",
        "IH" | "IY" | "Y" => "ih",
        "AO" | "OW" | "OY" => "oh",
        "UH" | "UW" | "W" => "ou",
        _ => "sil",
    };
    VISEMES.iter().position(|v| *v == name).unwrap_or(0)
}

/// A phone's dominance: its peak, how fast it decays (the time constant, as a share of the
/// phone's duration, at least 15 ms for a vowel and 35 ms for the rest), and the exponent of the distance (Cohen and Massaro's
/// `c`). Vowels peak sharply (`c` = 1: the jaw opens most at their centre); consonants and
/// pauses are rounded (`c` = 2), so that two consonants in a row hold the mouth together
/// rather than letting it open between them.
fn dominance(symbol: &str) -> (f64, f64, i32) {
    match symbol {
        "P" | "B" | "M" | "F" | "V" => (4.0, 0.45, 2),
        "HH" => (0.1, 0.4, 2),
        "pau" => (1.0, 0.4, 2),
        s if super::builtin::is_vowel(s) => (1.0, 0.3, 1),
        _ => (0.6, 0.45, 2),
    }
}

/// How far from a phone its dominance still counts (seconds).
const REACH: f64 = 0.35;

/// The dominance of the mouth's rest (`sil`) at every moment: a phone's shape shows fully only
/// near its centre, so the jaw opens most at the middle of a vowel, not over a flat plateau.
const REST: f64 = 0.1;

/// The viseme weights (summing to 1) at time `t` of an utterance with `phones` (in order;
/// times as in the phones).
pub fn weights(phones: &[Phone], t: f64) -> [f32; 15] {
    let mut w = [0.0f64; 15];
    w[0] = REST;
    let from = phones.partition_point(|p| p.end < t - REACH);
    let mut total = REST;
    for p in phones[from..].iter().take_while(|p| p.start <= t + REACH) {
        let (peak, share, c) = dominance(p.symbol);
        let tau = (share * (p.end - p.start)).max(if c == 1 { 0.015 } else { 0.035 });
        let d = peak * (-((t - p.centre()).abs() / tau).powi(c)).exp();
        w[viseme(p.symbol)] += d;
        total += d;
    }
    w.map(|x| (x / total) as f32)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_phone_has_a_viseme_and_pauses_are_silent() {
        assert_eq!(VISEMES[viseme("P")], "PP");
        assert_eq!(VISEMES[viseme("AA")], "aa");
        assert_eq!(VISEMES[viseme("pau")], "sil");
        let p = |symbol, start, end| Phone { symbol, start, end };
        let phones = [p("AA", 0.0, 0.2), p("M", 0.2, 0.27), p("AA", 0.27, 0.47)];
        let at_m = weights(&phones, 0.235);
        assert!(at_m[viseme("M")] > 0.8, "the lips close on m: {at_m:?}");
        let sum: f32 = at_m.iter().sum();
        assert!((sum - 1.0).abs() < 1e-5);
        assert!(weights(&phones, 0.1)[viseme("AA")] > 0.9);
    }
}
