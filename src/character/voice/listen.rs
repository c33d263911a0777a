//! Listening to a sound: what the lips need from a recording that comes without phone timings.
//! The sound is cut into 10 ms frames, each with its loudness (RMS in decibels, 0 at 40 dB
//! below the loudest frame, 1 at the loudest) and its hiss (zero crossings a second, 0 below
//! 1 500, 1 above 4 000: s, sh, f and th hiss, vowels and nasals do not). From those:
//! - [`phones_of_sound`] gives phones straight from the frames (silence, hiss, loud open vowels,
//!   quieter half-open ones, quiet voiced consonants), for a sound with no text at all;
//! - [`align`] times a text's phones (as the built-in TTS says them) to the sound by dynamic
//!   time warping: each phone expects a loudness and a hiss (a vowel loud and smooth, a stop's
//!   closure silent, a fricative hissing), and the cheapest monotone match of the expected
//!   frames to the heard ones (within a band around the diagonal) gives, for each moment of the
//!   TTS's time, the sound's time. Written here because the matching is a small dynamic
//!   programme over two short feature tracks; no crate does forced alignment without a model.

use super::{Audio, Phone};

/// Frames a second.
pub const FRAME_RATE: f64 = 100.0;

/// A frame's loudness and hiss, both 0 to 1.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Heard {
    /// Loudness: 0 at 40 dB below the loudest frame (or quieter), 1 at the loudest.
    pub loud: f32,
    /// Hiss: 0 at 1 500 zero crossings a second or fewer, 1 at 4 000 or more.
    pub hiss: f32,
}

/// The sound's frames (10 ms hop, 20 ms window).
pub fn frames(audio: &Audio) -> Vec<Heard> {
    let rate = f64::from(audio.rate.max(1));
    let hop = (rate / FRAME_RATE).round().max(1.0) as usize;
    let n = audio.samples.len().div_ceil(hop);
    let mut db = Vec::with_capacity(n);
    let mut hiss = Vec::with_capacity(n);
    for f in 0..n {
        let a = (f * hop).saturating_sub(hop / 2);
        let w = &audio.samples[a..(a + 2 * hop).min(audio.samples.len())];
        let energy = w.iter().map(|&s| f64::from(s).powi(2)).sum::<f64>() / w.len().max(1) as f64;
        db.push(10.0 * (energy + 1.0).log10());
        let crossings = w.windows(2).filter(|p| (p[0] < 0) != (p[1] < 0)).count();
        let per_second = crossings as f64 * rate / w.len().max(1) as f64;
        hiss.push(((per_second - 1500.0) / 2500.0).clamp(0.0, 1.0) as f32);
    }
    let top = db.iter().copied().fold(f64::MIN, f64::max);
    (db.iter().zip(hiss))
        .map(|(&d, h)| {
            let loud = ((d - (top - 40.0)) / 40.0).clamp(0.0, 1.0) as f32;
            // silence does not hiss, whatever its crossings
            Heard {
                loud,
                hiss: if loud < 0.2 { 0.0 } else { h },
            }
        })
        .collect()
}

/// How loud and how hissing phone `symbol` is expected to sound.
fn expected(symbol: &str) -> Heard {
    let (loud, hiss) = match symbol {
        "pau" => (0.0, 0.0),
        "P" | "B" | "T" | "D" | "K" | "G" => (0.3, 0.0),
        "S" | "Z" | "SH" | "ZH" | "CH" | "JH" => (0.55, 1.0),
        "F" | "TH" | "HH" => (0.4, 0.6),
        "V" | "DH" => (0.5, 0.3),
        "M" | "N" | "NG" => (0.65, 0.0),
        "L" | "R" | "W" | "Y" => (0.75, 0.0),
        _ => (0.9, 0.0), // vowels
    };
    Heard { loud, hiss }
}

/// The phones of a sound with no text: runs of frames of one kind (silence, hiss, open vowel,
/// half-open vowel, quiet voiced sound), runs shorter than 30 ms joined to the one before.
pub fn phones_of_sound(heard: &[Heard]) -> Vec<Phone> {
    let kind = |h: &Heard| match (h.loud, h.hiss) {
        (l, _) if l < 0.25 => "pau",
        (_, s) if s > 0.5 => "S",
        (l, _) if l > 0.75 => "AA",
        (l, _) if l > 0.55 => "EH",
        _ => "N",
    };
    let step = 1.0 / FRAME_RATE;
    let mut phones: Vec<Phone> = Vec::new();
    for (i, h) in heard.iter().enumerate() {
        let (symbol, t) = (kind(h), i as f64 * step);
        match phones.last_mut() {
            Some(p) if p.symbol == symbol || p.end - p.start < 0.03 - 1e-9 => {
                p.end = t + step;
            }
            _ => phones.push(Phone {
                symbol,
                start: t,
                end: t + step,
            }),
        }
    }
    phones
}

/// How long a sound [`align`] times, at most (seconds): the match is quadratic in its frames.
pub const MAX_ALIGNED: f64 = 600.0;

/// Knots (TTS time, sound time), increasing in both, that time `phones` (the TTS's, from 0)
/// to the sound heard as `heard`: the speech is taken to run from the first loud frame to the
/// last. Empty when there is nothing to match.
pub fn align(phones: &[Phone], heard: &[Heard]) -> Vec<(f64, f64)> {
    let step = 1.0 / FRAME_RATE;
    let first = heard.iter().position(|h| h.loud >= 0.25);
    let last = heard.iter().rposition(|h| h.loud >= 0.25);
    let (Some(first), Some(last), Some(end)) = (first, last, phones.last().map(|p| p.end)) else {
        return Vec::new();
    };
    let heard = &heard[first..=last];
    let n = ((end * FRAME_RATE).ceil() as usize).max(1);
    let mut want = Vec::with_capacity(n);
    let mut k = 0;
    for i in 0..n {
        let t = (i as f64 + 0.5) * step;
        while k + 1 < phones.len() && phones[k].end <= t {
            k += 1;
        }
        want.push(expected(phones[k].symbol));
    }
    let path = warp(&want, heard);
    // each TTS frame's mean sound frame, made strictly increasing
    let mut sum = vec![(0.0f64, 0u32); n];
    for &(i, j) in &path {
        sum[i].0 += j as f64;
        sum[i].1 += 1;
    }
    let mut knots: Vec<(f64, f64)> = vec![(0.0, first as f64 * step)];
    for (i, &(s, c)) in sum.iter().enumerate() {
        let t = (i as f64 + 0.5) * step;
        let at = (first as f64 + s / f64::from(c.max(1)) + 0.5) * step;
        if knots.last().is_some_and(|&(_, a)| at > a + 1e-9) {
            knots.push((t, at));
        }
    }
    knots.push((end, (last + 1) as f64 * step));
    knots.dedup_by(|b, a| b.1 <= a.1 + 1e-9);
    knots
}

/// The cheapest monotone path matching `want` (rows) to `heard` (columns), start to end
/// corner, within a band around the diagonal; steps right, down and diagonal, the straight
/// ones a little dearer so that the path does not dawdle.
fn warp(want: &[Heard], heard: &[Heard]) -> Vec<(usize, usize)> {
    let (n, m) = (want.len(), heard.len());
    let band = (n.max(m) / 4).max(50);
    let centre = |i: usize| i * m / n;
    let range = |i: usize| {
        let c = centre(i);
        (c.saturating_sub(band), (c + band + 1).min(m))
    };
    let cost = |i: usize, j: usize| {
        let (a, b) = (want[i], heard[j]);
        (a.loud - b.loud).abs() + 0.5 * (a.hiss - b.hiss).abs()
    };
    const STRAIGHT: f32 = 0.05;
    // per row: its column range, the running costs and where each came from (0 diagonal,
    // 1 from above, 2 from the left)
    let mut rows: Vec<(usize, Vec<f32>, Vec<u8>)> = Vec::with_capacity(n);
    for i in 0..n {
        let (lo, hi) = range(i);
        let mut total = vec![f32::INFINITY; hi - lo];
        let mut from = vec![0u8; hi - lo];
        for j in lo..hi {
            let here = cost(i, j);
            let up = |dj: usize| -> f32 {
                let Some((plo, ptotal, _)) = i.checked_sub(1).map(|p| &rows[p]) else {
                    return f32::INFINITY;
                };
                match j.checked_sub(dj) {
                    Some(c) if c >= *plo && c - plo < ptotal.len() => ptotal[c - plo],
                    _ => f32::INFINITY,
                }
            };
            let left = if j > lo {
                total[j - lo - 1]
            } else {
                f32::INFINITY
            };
            let options = [up(1), up(0) + STRAIGHT, left + STRAIGHT];
            let (best, which) = if i == 0 && j == 0 {
                (0.0, 0)
            } else {
                (options.iter().enumerate()).fold((f32::INFINITY, 0u8), |acc, (k, &v)| {
                    if v < acc.0 {
                        (v, k as u8)
                    } else {
                        acc
                    }
                })
            };
            total[j - lo] = best + here;
            from[j - lo] = which;
        }
        rows.push((lo, total, from));
    }
    let mut path = Vec::with_capacity(n + m);
    let (mut i, mut j) = (n - 1, m - 1);
    loop {
        path.push((i, j));
        if i == 0 && j == 0 {
            break;
        }
        let (lo, _, from) = &rows[i];
        let Some(&which) = j.checked_sub(*lo).and_then(|k| from.get(k)) else {
            break;
        };
        match which {
            0 if i > 0 && j > 0 => {
                i -= 1;
                j -= 1;
            }
            1 if i > 0 => i -= 1,
            _ if j > 0 => j -= 1,
            _ => i -= 1,
        }
    }
    path.reverse();
    path
}

/// The sound time of TTS time `t` through `knots` (linear between them, slope 1 beyond).
pub fn warp_time(knots: &[(f64, f64)], t: f64) -> f64 {
    let k = knots.partition_point(|&(a, _)| a <= t);
    match (k.checked_sub(1).map(|i| knots[i]), knots.get(k)) {
        (Some((a0, b0)), Some(&(a1, b1))) if a1 > a0 => b0 + (b1 - b0) * (t - a0) / (a1 - a0),
        (Some((a0, b0)), _) => b0 + (t - a0),
        (None, Some(&(a1, b1))) => b1 - (a1 - t),
        (None, None) => t,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A sound of loud vowels and silent gaps at the given (start, end) spans.
    fn bursts(spans: &[(f64, f64)], length: f64) -> Audio {
        let rate = 16_000;
        let samples = (0..(length * f64::from(rate)) as usize)
            .map(|i| {
                let t = i as f64 / f64::from(rate);
                let on = spans.iter().any(|&(a, b)| t >= a && t < b);
                if on {
                    (8000.0 * (t * 2.0 * std::f64::consts::PI * 220.0).sin()) as i16
                } else {
                    0
                }
            })
            .collect();
        Audio { rate, samples }
    }

    #[test]
    fn frames_hear_loudness_and_silence() {
        let heard = frames(&bursts(&[(0.2, 0.5)], 1.0));
        assert_eq!(heard.len(), 100);
        assert!(heard[35].loud > 0.9 && heard[35].hiss == 0.0);
        assert!(heard[80].loud < 0.05);
        let phones = phones_of_sound(&heard);
        let loud: Vec<_> = phones.iter().filter(|p| p.symbol != "pau").collect();
        assert_eq!(loud.len(), 1, "{phones:?}");
        assert!((loud[0].start - 0.2).abs() < 0.02 && (loud[0].end - 0.5).abs() < 0.02);
    }

    #[test]
    fn a_text_s_vowels_land_on_the_sound_s_loud_spans() {
        // the TTS says two vowels around a bilabial closure, evenly; the sound has them late
        // and uneven
        let p = |symbol, start, end| Phone { symbol, start, end };
        let phones = [p("AA", 0.0, 0.2), p("P", 0.2, 0.3), p("AA", 0.3, 0.5)];
        let heard = frames(&bursts(&[(0.4, 0.9), (1.0, 1.2)], 1.5));
        let knots = align(&phones, &heard);
        let closure = warp_time(&knots, 0.25);
        assert!((closure - 0.95).abs() < 0.045, "the closure at {closure}");
        assert!((warp_time(&knots, 0.0) - 0.4).abs() < 0.02);
        assert!((warp_time(&knots, 0.5) - 1.2).abs() < 0.02);
    }
}
