//! Sync references (`6`, `beh:sync`, `beh:sync+o`, `block:beh:sync-o`, `anticipators:id:sync+o`):
//! the typed form, a strict whitespace-tolerant parser with precise errors, and the canonical text.

use std::fmt;

use super::diagnostic::Code;
use super::id::Id;

/// The reserved first part of an anticipator reference (`anticipators:ID:SYNC`).
pub const ANTICIPATORS: &str = "anticipators";

/// What a sync reference points at.
#[derive(Debug, Clone, PartialEq)]
pub enum SyncRef {
    /// An offset in seconds from the start of the block.
    Time(f64),
    /// A sync point plus an offset in seconds: time(point) + offset.
    Point {
        /// The sync point referred to.
        point: SyncPoint,
        /// Offset in seconds added to the sync point's time.
        offset: f64,
    },
}

/// A named sync point: of a behaviour in this block, of a behaviour in another block, or of an
/// anticipator.
#[derive(Debug, Clone, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum SyncPoint {
    /// `beh:sync` — a behaviour of the same block.
    Local {
        /// Behaviour id.
        behaviour: Id,
        /// Sync point id.
        sync: Id,
    },
    /// `block:beh:sync` — a behaviour of another block (BMLA/BMLT external reference).
    External {
        /// Block id.
        block: Id,
        /// Behaviour id.
        behaviour: Id,
        /// Sync point id.
        sync: Id,
    },
    /// `anticipators:id:sync` — a predicted time of an anticipator.
    Anticipator {
        /// Anticipator id.
        anticipator: Id,
        /// Sync id of the anticipator.
        sync: Id,
    },
}

impl SyncPoint {
    /// A local sync point `behaviour:sync`.
    pub fn local(behaviour: &str, sync: &str) -> Self {
        SyncPoint::Local {
            behaviour: Id::new(behaviour),
            sync: Id::new(sync),
        }
    }

    /// The sync id part.
    pub fn sync(&self) -> &str {
        match self {
            SyncPoint::Local { sync, .. }
            | SyncPoint::External { sync, .. }
            | SyncPoint::Anticipator { sync, .. } => sync,
        }
    }
}

impl fmt::Display for SyncPoint {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            SyncPoint::Local { behaviour, sync } => write!(f, "{behaviour}:{sync}"),
            SyncPoint::External {
                block,
                behaviour,
                sync,
            } => write!(f, "{block}:{behaviour}:{sync}"),
            SyncPoint::Anticipator { anticipator, sync } => {
                write!(f, "{ANTICIPATORS}:{anticipator}:{sync}")
            }
        }
    }
}

/// Writes a number of seconds in the shortest form that reads back to the same `f64`.
pub(crate) fn fmt_seconds(f: &mut impl fmt::Write, v: f64) -> fmt::Result {
    if v == v.trunc() && v.abs() < 1e15 {
        write!(f, "{}", v as i64)
    } else {
        write!(f, "{v}")
    }
}

impl fmt::Display for SyncRef {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            SyncRef::Time(t) => fmt_seconds(f, *t),
            SyncRef::Point { point, offset } => {
                write!(f, "{point}")?;
                if *offset > 0.0 {
                    f.write_str("+")?;
                    fmt_seconds(f, *offset)
                } else if *offset < 0.0 {
                    f.write_str("-")?;
                    fmt_seconds(f, -*offset)
                } else {
                    Ok(())
                }
            }
        }
    }
}

/// Why a sync reference could not be parsed.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct SyncRefError {
    /// [`Code::EmptySyncRef`], [`Code::MalformedOffset`] or [`Code::MalformedSyncRef`].
    pub code: Code,
    /// What is wrong, for people.
    pub message: String,
}

fn err(code: Code, message: String) -> SyncRefError {
    SyncRefError { code, message }
}

/// Parses a decimal number of seconds: optional sign, digits with an optional fraction and an
/// optional exponent. Rejects `inf`, `NaN`, hex and empty text.
pub(crate) fn parse_seconds(s: &str) -> Option<f64> {
    let s = s.trim_ascii();
    let body = s.strip_prefix(['+', '-']).unwrap_or(s).as_bytes();
    // mantissa: digits with at most one point, at least one digit
    let (mut digits, mut points, mut i) = (0, 0, 0);
    while let Some(&c) = body.get(i) {
        match c {
            b'0'..=b'9' => digits += 1,
            b'.' => points += 1,
            _ => break,
        }
        i += 1;
    }
    if digits == 0 || points > 1 {
        return None;
    }
    // optional exponent: e or E, an optional sign, at least one digit
    if i < body.len() {
        if !matches!(body[i], b'e' | b'E') {
            return None;
        }
        let exp = &body[i + 1..];
        let exp = exp
            .strip_prefix(b"+")
            .or(exp.strip_prefix(b"-"))
            .unwrap_or(exp);
        if exp.is_empty() || !exp.iter().all(u8::is_ascii_digit) {
            return None;
        }
    }
    s.parse::<f64>().ok().filter(|v| v.is_finite())
}

fn check_id(part: &str, what: &str, text: &str) -> Result<Id, SyncRefError> {
    if part.is_empty() {
        return Err(err(
            Code::MalformedSyncRef,
            format!("sync reference '{text}' has an empty {what}"),
        ));
    }
    if part.bytes().any(|b| b.is_ascii_whitespace()) {
        return Err(err(
            Code::MalformedSyncRef,
            format!("sync reference '{text}': {what} '{part}' contains whitespace"),
        ));
    }
    Ok(Id::new(part))
}

impl SyncRef {
    /// Parses a sync reference. Whitespace around parts, the sign and the offset is ignored.
    ///
    /// The last part is a sync id optionally followed by `+o` or `-o`; sync ids therefore cannot
    /// contain `+` or `-`. A first part `anticipators` makes a three-part reference an anticipator
    /// reference.
    pub fn parse(text: &str) -> Result<SyncRef, SyncRefError> {
        let t = text.trim_ascii();
        if t.is_empty() {
            return Err(err(
                Code::EmptySyncRef,
                "empty sync reference: expected a time in seconds or behaviour:sync".into(),
            ));
        }
        let parts: Vec<&str> = t.split(':').map(str::trim_ascii).collect();
        if let Some(point) = stroke_iteration(&parts, t)? {
            return Ok(point);
        }
        if parts.len() > 3 {
            return Err(err(
                Code::MalformedSyncRef,
                format!(
                    "sync reference '{t}' has {} parts; expected behaviour:sync, block:behaviour:sync, anticipators:id:sync or [block:]behaviour:stroke:N",
                    parts.len()
                ),
            ));
        }
        let first = parts[0];
        let point = match (parts.get(1).copied(), parts.get(2).copied()) {
            (None, _) => {
                return parse_seconds(t).map(SyncRef::Time).ok_or_else(|| {
                    err(
                        Code::MalformedSyncRef,
                        format!("sync reference '{t}' is neither a number of seconds nor of the form behaviour:sync"),
                    )
                })
            }
            (Some(last), None) => {
                let (sync, offset) = sync_and_offset(last, t)?;
                (local_point(first, sync, t)?, offset)
            }
            (Some(middle), Some(last)) => {
                let (sync, offset) = sync_and_offset(last, t)?;
                (three_part_point(first, middle, sync, t)?, offset)
            }
        };
        Ok(SyncRef::Point {
            point: point.0,
            offset: point.1,
        })
    }
}

/// Said after "has no sync point 'stroke:N'".
pub const STROKE_ITERATION_HINT: &str =
    " (stroke:N is the stroke of repetition N, counted from 0, of a <head> whose repetition is above N)";

/// The name of the `n`th stroke of a repeated behaviour, counted from 0: `stroke` for the
/// first, `stroke:N` for the others (the sync points a head with `repetition` > 1 has).
pub fn stroke_name(n: u32) -> Id {
    if n == 0 {
        Id::new_static("stroke")
    } else {
        Id::new(format!("stroke:{n}"))
    }
}

/// The iteration of a sync name `stroke:N` (`stroke` is iteration 0); `None` for other names.
pub fn stroke_iteration_of(sync: &str) -> Option<u32> {
    if sync == "stroke" {
        return Some(0);
    }
    let n = sync.strip_prefix("stroke:")?;
    n.bytes()
        .all(|b| b.is_ascii_digit())
        .then(|| n.parse().ok())?
}

/// `[block:]behaviour:stroke:N[±o]`: the stroke of repetition N (from 0) of a repeated
/// behaviour, as OpenBMLParser reads a sync reference with an iteration (the behaviour's sync
/// point `stroke:N`; `stroke:0` is `stroke`). `None` when `parts` are not of this form.
fn stroke_iteration(parts: &[&str], t: &str) -> Result<Option<SyncRef>, SyncRefError> {
    let (block, behaviour, sync, last) = match parts {
        [b, s, last] if *s == "stroke" => (None, *b, *s, *last),
        [k, b, s, last] => (Some(*k), *b, *s, *last),
        _ => return Ok(None),
    };
    let digits = last
        .find(['+', '-'])
        .map_or(last, |i| last[..i].trim_ascii());
    if digits.is_empty() || !digits.bytes().all(|b| b.is_ascii_digit()) {
        return Ok(None);
    }
    if sync != "stroke" {
        return Err(err(
            Code::MalformedSyncRef,
            format!("sync reference '{t}': an iteration (:{digits}) may follow only 'stroke'"),
        ));
    }
    let n: u32 = digits.parse().map_err(|_| {
        err(
            Code::MalformedSyncRef,
            format!("sync reference '{t}': iteration {digits} is too large"),
        )
    })?;
    let (_, offset) = sync_and_offset(last, t)?;
    let sync = stroke_name(n);
    let behaviour = check_id(behaviour, "behaviour id", t)?;
    let point = match block {
        Some(b) if b == ANTICIPATORS => {
            return Err(err(
                Code::MalformedSyncRef,
                format!("anticipator reference '{t}' needs the form anticipators:ID:SYNC"),
            ))
        }
        Some(b) => SyncPoint::External {
            block: check_id(b, "block id", t)?,
            behaviour,
            sync,
        },
        None => SyncPoint::Local { behaviour, sync },
    };
    Ok(Some(SyncRef::Point { point, offset }))
}

/// The last part of reference `t`: a sync id optionally followed by `+o` or `-o` seconds.
fn sync_and_offset(last: &str, t: &str) -> Result<(Id, f64), SyncRefError> {
    let Some(i) = last.find(['+', '-']) else {
        return Ok((check_id(last, "sync id", t)?, 0.0));
    };
    let sign = if last.as_bytes()[i] == b'-' {
        -1.0
    } else {
        1.0
    };
    let num = last[i + 1..].trim_ascii();
    if num.starts_with(['+', '-']) {
        return Err(err(
            Code::MalformedOffset,
            format!("sync reference '{t}' has a doubled sign in its offset"),
        ));
    }
    let v = parse_seconds(num).ok_or_else(|| {
        err(
            Code::MalformedOffset,
            if num.is_empty() {
                format!("sync reference '{t}' has a sign but no offset after it")
            } else {
                format!("sync reference '{t}' has offset '{num}', which is not a number of seconds")
            },
        )
    })?;
    Ok((check_id(last[..i].trim_ascii(), "sync id", t)?, sign * v))
}

/// `behaviour:sync` in the block itself.
fn local_point(behaviour: &str, sync: Id, t: &str) -> Result<SyncPoint, SyncRefError> {
    if behaviour == ANTICIPATORS {
        return Err(err(
            Code::MalformedSyncRef,
            format!("anticipator reference '{t}' needs the form anticipators:ID:SYNC"),
        ));
    }
    Ok(SyncPoint::Local {
        behaviour: check_id(behaviour, "behaviour id", t)?,
        sync,
    })
}

/// `anticipators:id:sync` or `block:behaviour:sync`.
fn three_part_point(
    first: &str,
    middle: &str,
    sync: Id,
    t: &str,
) -> Result<SyncPoint, SyncRefError> {
    Ok(if first == ANTICIPATORS {
        SyncPoint::Anticipator {
            anticipator: check_id(middle, "anticipator id", t)?,
            sync,
        }
    } else {
        SyncPoint::External {
            block: check_id(first, "block id", t)?,
            behaviour: check_id(middle, "behaviour id", t)?,
            sync,
        }
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn local(b: &str, s: &str, o: f64) -> SyncRef {
        SyncRef::Point {
            point: SyncPoint::local(b, s),
            offset: o,
        }
    }

    #[test]
    fn seconds_are_decimal_numbers_only() {
        for (text, want) in [
            ("0", Some(0.0)),
            ("+7", Some(7.0)),
            (".5", Some(0.5)),
            ("5.", Some(5.0)),
            (" -1.25 ", Some(-1.25)),
            ("2e3", Some(2000.0)),
            ("1E-2", Some(0.01)),
            ("inf", None),
            ("NaN", None),
            ("0x10", None),
            ("", None),
            ("1.2.3", None),
            ("1e", None),
            ("1e400", None),
            (".", None),
        ] {
            assert_eq!(parse_seconds(text), want, "{text:?}");
        }
    }

    #[test]
    fn parses_every_form_of_a_sync_reference() {
        assert_eq!(SyncRef::parse("6").unwrap(), SyncRef::Time(6.0));
        assert_eq!(SyncRef::parse(" 0.5 ").unwrap(), SyncRef::Time(0.5));
        assert_eq!(
            SyncRef::parse("g1:start").unwrap(),
            local("g1", "start", 0.0)
        );
        assert_eq!(
            SyncRef::parse("g1:end+0.5").unwrap(),
            local("g1", "end", 0.5)
        );
        assert_eq!(
            SyncRef::parse("g1:start-2").unwrap(),
            local("g1", "start", -2.0)
        );
        assert_eq!(
            SyncRef::parse("bml1:speech1:s1+1").unwrap(),
            SyncRef::Point {
                point: SyncPoint::External {
                    block: "bml1".into(),
                    behaviour: "speech1".into(),
                    sync: "s1".into()
                },
                offset: 1.0
            }
        );
        assert_eq!(
            SyncRef::parse("anticipators:speechStopAnticipator:stop+1").unwrap(),
            SyncRef::Point {
                point: SyncPoint::Anticipator {
                    anticipator: "speechStopAnticipator".into(),
                    sync: "stop".into()
                },
                offset: 1.0
            }
        );
        assert_eq!(
            SyncRef::parse("anticipators:ex:squatdown-0.5").unwrap(),
            SyncRef::Point {
                point: SyncPoint::Anticipator {
                    anticipator: "ex".into(),
                    sync: "squatdown".into()
                },
                offset: -0.5
            }
        );
    }

    #[test]
    fn a_stroke_iteration_names_the_stroke_of_that_repetition() {
        assert_eq!(
            SyncRef::parse("h1:stroke:2").unwrap(),
            local("h1", "stroke:2", 0.0)
        );
        assert_eq!(
            SyncRef::parse("h1 : stroke : 02 + 0.5").unwrap(),
            local("h1", "stroke:2", 0.5)
        );
        // the first stroke has no number
        assert_eq!(
            SyncRef::parse("h1:stroke:0").unwrap(),
            local("h1", "stroke", 0.0)
        );
        assert_eq!(
            SyncRef::parse("bml1:h1:stroke:1-1").unwrap(),
            SyncRef::Point {
                point: SyncPoint::External {
                    block: "bml1".into(),
                    behaviour: "h1".into(),
                    sync: "stroke:1".into()
                },
                offset: -1.0
            }
        );
        let code = |s: &str| SyncRef::parse(s).unwrap_err().code;
        // only strokes repeat (as OpenBMLParser reads it)
        assert_eq!(code("b:h1:start:2"), Code::MalformedSyncRef);
        assert_eq!(code("h1:stroke:99999999999"), Code::MalformedSyncRef);
        assert_eq!(code("anticipators:a:stroke:1"), Code::MalformedSyncRef);
        for s in ["h1:stroke:2", "bml1:h1:stroke:1+0.5"] {
            assert_eq!(SyncRef::parse(s).unwrap().to_string(), s);
        }
        assert_eq!(stroke_iteration_of("stroke:3"), Some(3));
        assert_eq!(stroke_iteration_of("stroke"), Some(0));
        assert_eq!(stroke_iteration_of("stroke:x"), None);
        assert_eq!(stroke_iteration_of("strokeEnd"), None);
        assert_eq!(stroke_name(2), "stroke:2");
    }

    #[test]
    fn tolerates_whitespace_around_parts_and_offsets() {
        assert_eq!(
            SyncRef::parse(" g1 : end + 0.5 ").unwrap(),
            local("g1", "end", 0.5)
        );
        assert_eq!(
            SyncRef::parse("g1:end -  2").unwrap(),
            local("g1", "end", -2.0)
        );
    }

    #[test]
    fn malformed_references_get_specific_errors() {
        let code = |s: &str| SyncRef::parse(s).unwrap_err().code;
        assert_eq!(code(""), Code::EmptySyncRef);
        assert_eq!(code("   "), Code::EmptySyncRef);
        assert_eq!(code("s1:start+abc"), Code::MalformedOffset);
        assert_eq!(code("s1:start+"), Code::MalformedOffset);
        assert_eq!(code("s1:start+-1"), Code::MalformedOffset);
        assert_eq!(code("s1:start+inf"), Code::MalformedOffset);
        assert_eq!(code("s1:start+1.2.3"), Code::MalformedOffset);
        assert_eq!(code("abc"), Code::MalformedSyncRef);
        assert_eq!(code("NaN"), Code::MalformedSyncRef);
        assert_eq!(code(":start"), Code::MalformedSyncRef);
        assert_eq!(code("g1:"), Code::MalformedSyncRef);
        assert_eq!(code("a:b:c:d"), Code::MalformedSyncRef);
        assert_eq!(code("anticipators:stop"), Code::MalformedSyncRef);
        assert_eq!(code("g 1:start"), Code::MalformedSyncRef);
        let m = SyncRef::parse("s1:start+abc").unwrap_err().message;
        assert!(m.contains("'abc'"), "{m}");
    }

    #[test]
    fn display_is_canonical_and_reparses() {
        for s in [
            "6",
            "0.25",
            "g1:end+0.5",
            "g1:start-2",
            "b:g:s",
            "anticipators:a:s+1.5",
        ] {
            let r = SyncRef::parse(s).unwrap();
            assert_eq!(r.to_string(), s);
            assert_eq!(SyncRef::parse(&r.to_string()).unwrap(), r);
        }
        assert_eq!(SyncRef::parse("g1:end + 0").unwrap().to_string(), "g1:end");
    }
}
