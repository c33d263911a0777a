//! Comparing two feedback logs (`bmlr diff`): messages are aligned by identity (kind + id, the
//! n-th occurrence with the n-th), times are compared within a tolerance in a way that two runs of
//! the same BML agree on — sync points by their block-relative `time`, block progress relative to
//! the log's first block start (so a different clock origin is no difference), predictions by
//! their predicted length — wall-clock posix times are ignored, and the order of sync points
//! within each block is checked.

use std::collections::HashMap;
use std::fmt;

use super::{from_line, Feedback, FeedbackError};

/// A log read from text, each message with its line number.
#[derive(Debug, Clone, PartialEq)]
pub struct Log {
    /// (line number from 1, message).
    pub messages: Vec<(usize, Feedback)>,
}

/// A line that is not feedback.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[error("line {line}: {error}")]
pub struct LogError {
    /// Line number from 1.
    pub line: usize,
    /// What is wrong.
    pub error: FeedbackError,
}

impl Log {
    /// Reads a log in XML or JSON lines (per line: JSON if it starts with `{`); blank lines are
    /// skipped.
    pub fn parse(text: &str) -> Result<Log, LogError> {
        let mut messages = Vec::new();
        for (i, line) in text.lines().enumerate() {
            if line.trim().is_empty() {
                continue;
            }
            let fb = from_line(line).map_err(|error| LogError { line: i + 1, error })?;
            messages.push((i + 1, fb));
        }
        Ok(Log { messages })
    }
}

/// What a message is, for alignment: kind and id (and character, if any).
fn identity(fb: &Feedback) -> String {
    let character = fb.character_id();
    let id = kind_and_id(fb);
    match character {
        Some(c) => format!("{id} (character {c})"),
        None => id,
    }
}

fn kind_and_id(fb: &Feedback) -> String {
    match fb {
        Feedback::BlockProgress(p) => format!("blockProgress {}:{}", p.block, p.sync),
        Feedback::SyncPointProgress(p) => {
            format!("syncPointProgress {}:{}:{}", p.block, p.behaviour, p.sync)
        }
        Feedback::Prediction(p) => {
            let b = p.blocks.first();
            format!(
                "predictionFeedback {} {}",
                b.map_or("", |b| b.id.as_str()),
                b.and_then(|b| b.status).map_or("", |s| s.as_str())
            )
        }
        Feedback::Warning(w) => format!("warningFeedback {} {}", w.id, w.kind.as_str()),
        Feedback::World(w) => w.kind().to_string(),
    }
}

/// One difference between log A and log B.
#[derive(Debug, Clone, PartialEq)]
pub enum Difference {
    /// In A, not in B.
    Missing {
        /// Kind and id.
        what: String,
        /// Line in A.
        line: usize,
    },
    /// In B, not in A.
    Extra {
        /// Kind and id.
        what: String,
        /// Line in B.
        line: usize,
    },
    /// In both, at times further apart than the tolerance.
    Moved {
        /// Kind and id.
        what: String,
        /// Which time is compared (`time`, `globalTime from the first block start`, …).
        measure: &'static str,
        /// The time in A.
        a: f64,
        /// The time in B.
        b: f64,
        /// Lines in A and B.
        lines: (usize, usize),
    },
    /// Two sync points of a block come in the opposite order.
    Reordered {
        /// The one A has first.
        first: String,
        /// The one A has second (B has it first).
        second: String,
        /// Lines in B of the two.
        lines: (usize, usize),
    },
}

impl fmt::Display for Difference {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Difference::Missing { what, line } => write!(f, "missing in B: {what} (A:{line})"),
            Difference::Extra { what, line } => write!(f, "extra in B: {what} (B:{line})"),
            Difference::Moved {
                what,
                measure,
                a,
                b,
                lines,
            } => write!(
                f,
                "moved: {what}: {measure} {a:.3} -> {b:.3} ({:+.3} s) (A:{}, B:{})",
                b - a,
                lines.0,
                lines.1
            ),
            Difference::Reordered {
                first,
                second,
                lines,
            } => write!(
                f,
                "reordered: B has {second} (B:{}) before {first} (B:{}); A has them the other way round",
                lines.1, lines.0
            ),
        }
    }
}

/// The time of a message that runs of the same BML should agree on, and what it is.
fn measure(fb: &Feedback, origin: f64) -> Option<(&'static str, f64)> {
    match fb {
        Feedback::SyncPointProgress(p) => Some(("time", p.time)),
        Feedback::BlockProgress(p) => Some((
            "globalTime from the first block start",
            p.global_time - origin,
        )),
        Feedback::Prediction(p) => {
            let b = p.blocks.first()?;
            Some(("predicted length", b.global_end? - b.global_start?))
        }
        Feedback::Warning(_) | Feedback::World(_) => None,
    }
}

/// The global time of the log's first block start (0 if none).
fn origin(log: &Log) -> f64 {
    log.messages
        .iter()
        .find_map(|(_, f)| match f {
            Feedback::BlockProgress(p) if p.sync == "start" => Some(p.global_time),
            _ => None,
        })
        .unwrap_or(0.0)
}

/// Every difference between `a` and `b`, times compared within `tolerance` seconds.
pub fn diff(a: &Log, b: &Log, tolerance: f64) -> Vec<Difference> {
    let (oa, ob) = (origin(a), origin(b));
    // identity + occurrence → index in b
    let mut in_b: HashMap<(String, usize), usize> = HashMap::new();
    let mut seen: HashMap<String, usize> = HashMap::new();
    for (i, (_, fb)) in b.messages.iter().enumerate() {
        let id = identity(fb);
        let n = seen.entry(id.clone()).or_insert(0);
        in_b.insert((id, *n), i);
        *n += 1;
    }
    let mut out = Vec::new();
    let mut matched = vec![false; b.messages.len()];
    // (block, position in a, position in b, identity) of matched sync points, for the order check
    let mut syncs: Vec<(String, usize, usize, String)> = Vec::new();
    let mut seen_a: HashMap<String, usize> = HashMap::new();
    for (ia, (line_a, fa)) in a.messages.iter().enumerate() {
        let id = identity(fa);
        let n = seen_a.entry(id.clone()).or_insert(0);
        let key = (id.clone(), *n);
        *n += 1;
        let Some(&ib) = in_b.get(&key) else {
            out.push(Difference::Missing {
                what: id,
                line: *line_a,
            });
            continue;
        };
        matched[ib] = true;
        let (line_b, fb) = &b.messages[ib];
        if let (Some((m, ta)), Some((_, tb))) = (measure(fa, oa), measure(fb, ob)) {
            if (ta - tb).abs() > tolerance + 1e-9 {
                out.push(Difference::Moved {
                    what: id.clone(),
                    measure: m,
                    a: ta,
                    b: tb,
                    lines: (*line_a, *line_b),
                });
            }
        }
        if let Feedback::SyncPointProgress(p) = fa {
            syncs.push((p.block.to_string(), ia, ib, id));
        }
    }
    for (ib, (line, fb)) in b.messages.iter().enumerate() {
        if !matched[ib] {
            out.push(Difference::Extra {
                what: identity(fb),
                line: *line,
            });
        }
    }
    // per block: matched sync points must come in the same order in both logs
    let mut by_block: HashMap<&str, Vec<&(String, usize, usize, String)>> = HashMap::new();
    for s in &syncs {
        by_block.entry(s.0.as_str()).or_default().push(s);
    }
    let mut blocks: Vec<&&str> = by_block.keys().collect();
    blocks.sort();
    for block in blocks {
        let list = &by_block[*block];
        // in A order; report each pair that B has the other way round (adjacent in A)
        for w in list.windows(2) {
            let (x, y) = (w[0], w[1]);
            if y.2 < x.2 {
                out.push(Difference::Reordered {
                    first: x.3.clone(),
                    second: y.3.clone(),
                    lines: (b.messages[x.2].0, b.messages[y.2].0),
                });
            }
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    const NS: &str = r#"xmlns="http://www.bml-initiative.org/bml/bml-1.0""#;

    fn log(lines: &[String]) -> Log {
        Log::parse(&lines.join("\n")).unwrap()
    }

    fn run(offset: f64, jitter: f64, swap: bool, drop_relax: bool) -> Log {
        let mut l = vec![format!(
            r#"<blockProgress {NS} id="b:start" globalTime="{}"/>"#,
            offset
        )];
        let mut syncs = vec![
            ("start", 0.0),
            ("stroke", 0.5),
            ("relax", 0.8),
            ("end", 1.0),
        ];
        if swap {
            syncs.swap(1, 2);
        }
        for (s, t) in syncs {
            if drop_relax && s == "relax" {
                continue;
            }
            let t = t + jitter;
            l.push(format!(
                r#"<syncPointProgress {NS} id="b:g:{s}" time="{t}" globalTime="{}"/>"#,
                offset + t
            ));
        }
        l.push(format!(
            r#"<blockProgress {NS} id="b:end" globalTime="{}"/>"#,
            offset + 1.0 + jitter
        ));
        log(&l)
    }

    #[test]
    fn the_same_run_on_another_clock_with_jitter_is_no_difference() {
        assert_eq!(
            diff(
                &run(0.0, 0.0, false, false),
                &run(0.0, 0.0, false, false),
                0.1
            ),
            []
        );
        assert_eq!(
            diff(
                &run(0.0, 0.0, false, false),
                &run(5.0, 0.05, false, false),
                0.1
            ),
            []
        );
        let d = diff(
            &run(0.0, 0.0, false, false),
            &run(0.0, 0.2, false, false),
            0.1,
        );
        assert_eq!(d.len(), 5, "{d:?}"); // four syncs and the end moved
        assert!(d[0]
            .to_string()
            .starts_with("moved: syncPointProgress b:g:start: time 0.000 -> 0.200 (+0.200 s)"));
    }

    #[test]
    fn missing_extra_and_reordered_syncs_are_reported() {
        let d = diff(
            &run(0.0, 0.0, false, false),
            &run(0.0, 0.0, false, true),
            0.1,
        );
        assert_eq!(
            d,
            [Difference::Missing {
                what: "syncPointProgress b:g:relax".into(),
                line: 4
            }]
        );
        let d = diff(
            &run(0.0, 0.0, false, true),
            &run(0.0, 0.0, false, false),
            0.1,
        );
        assert!(
            matches!(&d[..], [Difference::Extra { line: 4, .. }]),
            "{d:?}"
        );
        let d = diff(
            &run(0.0, 0.0, false, false),
            &run(0.0, 0.0, true, false),
            0.5,
        );
        assert_eq!(
            d,
            [Difference::Reordered {
                first: "syncPointProgress b:g:stroke".into(),
                second: "syncPointProgress b:g:relax".into(),
                lines: (4, 3),
            }]
        );
    }

    #[test]
    fn a_bad_line_is_reported_with_its_number() {
        let e = Log::parse("\n<blockProgress").unwrap_err();
        assert_eq!(e.line, 2);
    }
}
