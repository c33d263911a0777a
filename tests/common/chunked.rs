//! What the streaming tests (`tests/stream.rs`, `tests/serve_stream.rs`,
//! `bindings/c/tests/stream.rs`) share: a sound cut into chunks, each with the marks of its span,
//! as a realtime voice sends them; and the time of a sync point in a feedback log.
#![allow(dead_code)]

use std::ops::Range;

use bml_realizer::language::feedback::Feedback;

/// `samples` samples at `rate` cut into `n` chunks: each chunk's sample range and the marks
/// `lines` (time s, line) that fall in it, joined by line breaks (the last chunk takes any
/// later ones).
pub fn chunks(
    samples: usize,
    rate: u32,
    lines: &[(f64, String)],
    n: usize,
) -> Vec<(Range<usize>, String)> {
    let size = samples.div_ceil(n);
    let rate = f64::from(rate);
    (0..n)
        .map(|i| {
            let (a, b) = (i * size, ((i + 1) * size).min(samples));
            let marks: Vec<&str> = (lines.iter())
                .filter(|l| l.0 >= a as f64 / rate && (l.0 < b as f64 / rate || b == samples))
                .map(|l| l.1.as_str())
                .collect();
            (a..b, marks.join("\n"))
        })
        .collect()
}

/// The global time of `behaviour`'s `sync` in `log`.
pub fn sync_time(log: &[Feedback], behaviour: &str, sync: &str) -> Option<f64> {
    log.iter().find_map(|f| match f {
        Feedback::SyncPointProgress(p) if p.behaviour == behaviour && p.sync == sync => {
            Some(p.global_time)
        }
        _ => None,
    })
}
