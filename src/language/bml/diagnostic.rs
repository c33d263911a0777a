//! Diagnostics for BML input: source positions, severities, the stable diagnostic codes and the
//! error type returned when a block cannot be accepted.

use std::fmt;

/// A position in the source text: 1-based line and column (column counted in characters).
///
/// Positions are metadata: two model values that differ only in where they were read from compare
/// equal, so that `parse(write(block)) == block` holds although the writer lays text out anew.
#[derive(Debug, Clone, Copy, Default, Eq)]
pub struct Pos {
    /// 1-based line number (0 when unknown).
    pub line: u32,
    /// 1-based column number in characters (0 when unknown).
    pub col: u32,
}

impl PartialEq for Pos {
    fn eq(&self, _other: &Self) -> bool {
        true
    }
}

impl fmt::Display for Pos {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}:{}", self.line, self.col)
    }
}

/// Maps byte offsets in a source text to line:column positions.
#[derive(Debug, Clone)]
pub struct LineIndex {
    starts: Vec<usize>,
    /// Per line, the offset of its first byte outside ASCII (or of its end): columns before it
    /// are byte counts, so a long line does not make every position cost its length. Empty when
    /// the whole text is ASCII.
    ascii_until: Vec<usize>,
}

impl LineIndex {
    /// Index the line starts of `src`.
    pub fn new(src: &str) -> Self {
        Self::scan(src).0
    }

    /// The index of `src` and, found in the same pass over the text, the offset of its first
    /// C0 control character other than tab, line feed and carriage return (XML 1.0 forbids
    /// them).
    pub(crate) fn scan(src: &str) -> (Self, Option<usize>) {
        let bytes = src.as_bytes();
        let mut starts = vec![0];
        let mut forbidden = None;
        for (at, &b) in bytes.iter().enumerate() {
            match b {
                b'\n' => starts.push(at + 1),
                b'\t' | b'\r' => {}
                0..=0x1f => {
                    forbidden.get_or_insert(at);
                }
                _ => {}
            }
        }
        // an ASCII text (nearly every block) needs no second table: columns are byte counts
        let ascii_until = if src.is_ascii() {
            Vec::new()
        } else {
            let ends = starts.iter().skip(1).copied().chain([src.len()]);
            starts
                .iter()
                .zip(ends)
                .map(|(&s, e)| {
                    bytes[s..e]
                        .iter()
                        .position(|b| !b.is_ascii())
                        .map_or(e, |p| s + p)
                })
                .collect()
        };
        let index = LineIndex {
            starts,
            ascii_until,
        };
        (index, forbidden)
    }

    /// The position of byte offset `offset` in `src` (the text this index was built from).
    pub fn pos(&self, src: &str, offset: usize) -> Pos {
        let offset = offset.min(src.len());
        let line = self.starts.partition_point(|&s| s <= offset) - 1;
        let start = self.starts[line];
        let ascii = if self.ascii_until.is_empty() {
            offset // an ASCII text
        } else {
            self.ascii_until.get(line).copied().unwrap_or(start)
        };
        let col = if offset <= ascii {
            offset - start
        } else {
            (ascii - start)
                + src
                    .get(ascii..offset)
                    .map_or(offset - ascii, |s| s.chars().count())
        };
        Pos {
            line: line as u32 + 1,
            col: col as u32 + 1,
        }
    }
}

/// How serious a diagnostic is.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub enum Severity {
    /// The input is still accepted; something is unsupported or suspicious.
    Warning,
    /// The input is invalid; the block is rejected.
    Error,
}

/// Stable identifiers of every diagnostic the language layer produces, so that tools and tests can
/// match on the kind of problem rather than on message text.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Code {
    /// The input is not well-formed XML.
    NotXml,
    /// The root element is not `<bml>`.
    WrongRoot,
    /// The `<bml>` element has no `id`.
    MissingBlockId,
    /// A behaviour (or constraint child) lacks its `id`.
    MissingId,
    /// Two behaviours of one block share an id.
    DuplicateId,
    /// A required attribute is absent.
    MissingAttribute,
    /// A required child element is absent (e.g. speech without `<text>`).
    MissingElement,
    /// An id that cannot be referred to (contains `:`, or a sync id with `+`/`-`, ...).
    InvalidId,
    /// An attribute that the element does not define (and that is not in an extension namespace).
    UnknownAttribute,
    /// A BML element in a place where it is not allowed, or unknown in the BML namespace.
    UnknownElement,
    /// Non-whitespace text where only elements are allowed.
    UnexpectedText,
    /// An attribute value outside its enumeration.
    InvalidEnumValue,
    /// An attribute value that should be a number (or boolean) and is not.
    InvalidNumber,
    /// The `composition` value is not one of MERGE, APPEND, REPLACE, APPEND-AFTER(...).
    UnknownComposition,
    /// An empty sync reference.
    EmptySyncRef,
    /// A sync reference with a malformed offset, e.g. `s1:start+abc`.
    MalformedOffset,
    /// A sync reference that is malformed otherwise (empty parts, too many parts, ...).
    MalformedSyncRef,
    /// A sync reference names a behaviour that is not in the block.
    UnknownBehaviour,
    /// A sync reference names a sync point that the referenced behaviour does not have.
    UnknownSyncPoint,
    /// A constraint that can never hold or relates nothing (e.g. two absolute times).
    InvalidConstraint,
    /// A behaviour or element from an extension namespace that this realizer does not support.
    UnsupportedExtension,
    /// An attribute from an extension namespace that this realizer does not interpret.
    UnsupportedAttribute,
    /// A lexeme outside the vocabulary of the BML 1.0 standard (accepted; engines may not know it).
    UnknownLexeme,
    /// Constraints that no timing can satisfy together (a cycle such as `a:start = b:end` with
    /// `b:start = a:end`): the realizer would drop a behaviour or refuse the block.
    ContradictoryConstraints,
    /// The block passes one of its limits (nesting depth, attributes, size, behaviours, time).
    LimitExceeded,
    /// A schedule that squeezes a phase of a behaviour (a gesture's stroke, say) below what a
    /// person can perform: the realizer performs it that fast, with an `INVALID_TIMING` warning.
    SqueezedPhase,
}

impl Code {
    /// A short kebab-case name for the code, used in CLI output.
    pub fn as_str(self) -> &'static str {
        match self {
            Code::NotXml => "not-xml",
            Code::WrongRoot => "wrong-root",
            Code::MissingBlockId => "missing-block-id",
            Code::MissingId => "missing-id",
            Code::DuplicateId => "duplicate-id",
            Code::MissingAttribute => "missing-attribute",
            Code::MissingElement => "missing-element",
            Code::InvalidId => "invalid-id",
            Code::UnknownAttribute => "unknown-attribute",
            Code::UnknownElement => "unknown-element",
            Code::UnexpectedText => "unexpected-text",
            Code::InvalidEnumValue => "invalid-enum-value",
            Code::InvalidNumber => "invalid-number",
            Code::UnknownComposition => "unknown-composition",
            Code::EmptySyncRef => "empty-sync-ref",
            Code::MalformedOffset => "malformed-offset",
            Code::MalformedSyncRef => "malformed-sync-ref",
            Code::UnknownBehaviour => "unknown-behaviour",
            Code::UnknownSyncPoint => "unknown-sync-point",
            Code::InvalidConstraint => "invalid-constraint",
            Code::UnsupportedExtension => "unsupported-extension",
            Code::UnsupportedAttribute => "unsupported-attribute",
            Code::UnknownLexeme => "unknown-lexeme",
            Code::ContradictoryConstraints => "contradictory-constraints",
            Code::LimitExceeded => "limit-exceeded",
            Code::SqueezedPhase => "squeezed-phase",
        }
    }
}

/// One finding about a BML text: what, where and how serious.
#[derive(Debug, Clone, PartialEq)]
pub struct Diagnostic {
    /// Error or warning.
    pub severity: Severity,
    /// What kind of problem.
    pub code: Code,
    /// Where in the source (line:col).
    pub pos: Pos,
    /// A sentence for people.
    pub message: String,
}

impl Diagnostic {
    /// An error diagnostic.
    pub fn error(code: Code, pos: Pos, message: impl Into<String>) -> Self {
        Diagnostic {
            severity: Severity::Error,
            code,
            pos,
            message: message.into(),
        }
    }

    /// A warning diagnostic.
    pub fn warning(code: Code, pos: Pos, message: impl Into<String>) -> Self {
        Diagnostic {
            severity: Severity::Warning,
            code,
            pos,
            message: message.into(),
        }
    }

    /// Whether this is an error.
    pub fn is_error(&self) -> bool {
        self.severity == Severity::Error
    }
}

impl fmt::Display for Diagnostic {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let sev = match self.severity {
            Severity::Error => "error",
            Severity::Warning => "warning",
        };
        write!(
            f,
            "{}: {}[{}]: {}",
            self.pos,
            sev,
            self.code.as_str(),
            self.message
        )
    }
}

/// The error returned when a BML text cannot be accepted: every diagnostic found (at least one is
/// an error), in source order.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[error("{}", render(.0))]
pub struct BmlError(pub Vec<Diagnostic>);

fn render(diags: &[Diagnostic]) -> String {
    diags
        .iter()
        .filter(|d| d.is_error())
        .map(|d| d.to_string())
        .collect::<Vec<_>>()
        .join("\n")
}

impl BmlError {
    /// The error diagnostics only.
    pub fn errors(&self) -> impl Iterator<Item = &Diagnostic> {
        self.0.iter().filter(|d| d.is_error())
    }

    /// The first error (there always is one).
    pub fn first(&self) -> &Diagnostic {
        self.errors().next().unwrap_or(&self.0[0])
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The scan finds every line start, the first forbidden control character, and (through the
    /// columns) character positions on lines with and without text outside ASCII.
    #[test]
    fn the_scan_finds_line_starts_forbidden_characters_and_columns() {
        let pieces = [
            "a", "bc", "\n", "\t", "\r\n", "\u{1}", "\u{1f}", " ", "é", "€", "~", "\u{7f}",
        ];
        let mut rng = crate::testrand::XorShift(0x9e37_79b9_7f4a_7c15);
        for _ in 0..3000 {
            let seed = rng.next_u64();
            let len = (seed % 40) as usize;
            let src: String = (0..len)
                .map(|j| pieces[((seed >> (j % 60)) as usize + j * 7) % pieces.len()])
                .collect();
            let (index, forbidden) = LineIndex::scan(&src);
            let starts: Vec<usize> = [0]
                .into_iter()
                .chain(src.match_indices('\n').map(|(i, _)| i + 1))
                .collect();
            assert_eq!(index.starts, starts, "{src:?}");
            let first = src
                .bytes()
                .position(|b| b < 0x20 && !matches!(b, b'\t' | b'\n' | b'\r'));
            assert_eq!(forbidden, first, "{src:?}");
            assert_eq!(index.ascii_until.is_empty(), src.is_ascii(), "{src:?}");
            for (o, _) in src.char_indices() {
                let line_start = src[..o].rfind('\n').map_or(0, |i| i + 1);
                let col = src[line_start..o].chars().count() as u32 + 1;
                assert_eq!(index.pos(&src, o).col, col, "{src:?} at {o}");
            }
        }
    }

    #[test]
    fn line_index_maps_offsets_to_line_and_char_column() {
        let src = "ab\ncdé f\n\nx";
        let idx = LineIndex::new(src);
        let p = |o| {
            let p = idx.pos(src, o);
            (p.line, p.col)
        };
        assert_eq!(p(0), (1, 1));
        assert_eq!(p(1), (1, 2));
        assert_eq!(p(3), (2, 1));
        // 'f' is after a two-byte character: byte 8, char column 5
        assert_eq!(p(src.find('f').unwrap()), (2, 5));
        assert_eq!(p(src.find('x').unwrap()), (4, 1));
    }

    #[test]
    fn columns_are_characters_at_every_offset_of_mixed_lines() {
        for src in [
            "plain ascii\nline two",
            "é début\nfin ü x\n\n€€ a",
            "ab\r\ncd",
            "ä",
        ] {
            let idx = LineIndex::new(src);
            for (o, _) in src.char_indices().chain([(src.len(), ' ')]) {
                let line_start = src[..o].rfind('\n').map_or(0, |i| i + 1);
                let line = src[..o].matches('\n').count() as u32 + 1;
                let col = src[line_start..o].chars().count() as u32 + 1;
                assert_eq!(idx.pos(src, o), Pos { line, col }, "{src:?} at {o}");
            }
        }
    }
}
