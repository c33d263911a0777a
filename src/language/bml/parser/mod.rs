//! The streaming BML parser (over the XML reader in `xml.rs`): text → [`Block`], with every
//! problem reported as a [`Diagnostic`] at its line:column. Structure, attribute values and sync
//! reference syntax are checked here; cross-references are checked by `validate.rs`.
//!
//! This file holds the entry points and the reader of tokens and elements; the element families
//! each have a file: the document and block (`document`), constraints and sync references
//! (`constraints`), behaviours and their children (`behaviours`), each behaviour kind's
//! attributes (`kind_builder`), speech text and attribute values (`values`).

use std::borrow::Cow;
use std::fmt;

use super::diagnostic::{BmlError, Code, Diagnostic, LineIndex, Pos};
use super::kinds::{BMLT_BEHAVIOURS, CONTROL_BEHAVIOURS, CORE_BEHAVIOURS};
use super::limits::Limits;
use super::model::*;
use super::syncref::{parse_seconds, SyncRef};
use super::xml::{Event, Problem, Reader, Tag, XmlError};
use crate::language::xmlname::split_qname;

mod behaviours;
mod constraints;
mod document;
mod kind_builder;
mod values;

use kind_builder::KindBuilder;

/// A parsed block together with the warnings found while reading it.
#[derive(Debug, Clone, PartialEq)]
pub struct Parsed {
    /// The block.
    pub block: Block,
    /// Warnings (unsupported extensions, unknown lexemes, ...), in source order.
    pub warnings: Vec<Diagnostic>,
}

/// Parses one `<bml>` block. Returns every diagnostic as an error if any of them is an error.
/// Cross-reference checks are not done here: use [`super::load`] for parse + validation.
pub fn parse(src: &str) -> Result<Parsed, BmlError> {
    let mut block = None;
    let diags = parse_into(src, &mut block, &Limits::default());
    parsed(&mut block, diags)
}

/// The block with its warnings, or every diagnostic (sorted) if any is an error or there is no
/// block. The block is moved once, from the option straight into the result.
pub(crate) fn parsed(
    block: &mut Option<Block>,
    diags: Vec<Diagnostic>,
) -> Result<Parsed, BmlError> {
    match block {
        Some(_) if !diags.iter().any(Diagnostic::is_error) => Ok(Parsed {
            block: block.take().expect("matched"),
            warnings: diags,
        }),
        _ => Err(BmlError(diags)),
    }
}

/// Parses as far as possible: the block (unless the text is not a `<bml>` document at all) and all
/// diagnostics, errors included.
pub fn parse_with_diagnostics(src: &str) -> (Option<Block>, Vec<Diagnostic>) {
    let mut block = None;
    let diags = parse_into(src, &mut block, &Limits::default());
    (block, diags)
}

/// [`parse_with_diagnostics`] with the block written into `block` (which must be `None`): a
/// block is a few hundred bytes, and it is not copied up the parser's return values.
pub(crate) fn parse_into(src: &str, block: &mut Option<Block>, limits: &Limits) -> Vec<Diagnostic> {
    let mut p = Parser::new(src, limits);
    if p.document(block).is_err() {
        *block = None;
    }
    let mut diags = std::mem::take(&mut p.diags);
    diags.sort_by_key(|d| (d.pos.line, d.pos.col));
    diags
}

/// The namespace of an element or attribute, as far as this parser cares.
#[derive(Debug, Clone, PartialEq, Eq)]
enum Ns {
    /// No namespace (unprefixed attribute, or element without a default namespace).
    None,
    /// BML 1.0 core.
    Bml,
    /// BML 1.0 core extensions.
    CoreExt,
    /// BMLA.
    Bmla,
    /// BMLT.
    Bmlt,
    /// Anything else.
    Other(String),
}

impl Ns {
    fn from_uri(uri: &str) -> Ns {
        match uri {
            NS_BML => Ns::Bml,
            NS_CORE_EXT => Ns::CoreExt,
            NS_BMLA => Ns::Bmla,
            NS_BMLT => Ns::Bmlt,
            _ => Ns::Other(uri.to_string()),
        }
    }

    fn uri(&self) -> &str {
        match self {
            Ns::None => "",
            Ns::Bml => NS_BML,
            Ns::CoreExt => NS_CORE_EXT,
            Ns::Bmla => NS_BMLA,
            Ns::Bmlt => NS_BMLT,
            Ns::Other(u) => u,
        }
    }

    /// Core BML elements may be written without a namespace.
    fn is_core(&self) -> bool {
        matches!(self, Ns::None | Ns::Bml)
    }

    fn is_ext(&self) -> bool {
        matches!(self, Ns::Bmla | Ns::Bmlt)
    }
}

/// Text borrowed from the source where possible.
type Str<'i> = Cow<'i, str>;

#[derive(Debug, Clone)]
struct RawAttr<'i> {
    ns: Ns,
    name: &'i str,
    value: Str<'i>,
    offset: usize,
}

#[derive(Debug)]
struct El<'i> {
    ns: Ns,
    name: &'i str,
    qname: &'i str,
    /// Namespace prefixes used by the tag (element and attribute names).
    prefixes: Vec<&'i str>,
    /// Attributes (xmlns declarations excluded); `Option` so that they can be taken one by one.
    attrs: Vec<Option<RawAttr<'i>>>,
    empty: bool,
    offset: usize,
    inner_start: usize,
}

#[derive(Debug)]
enum Tok<'i> {
    Start(El<'i>),
    End { offset: usize, after: usize },
    Text { text: Str<'i>, offset: usize },
    Eof,
}

/// What [`Parser::skip`] passed over.
struct Skipped<'i> {
    /// The raw XML between the start and end tags.
    content: String,
    /// Offset just after the end tag.
    after: usize,
    /// Namespace prefixes used by the tags inside.
    prefixes: Vec<&'i str>,
}

/// Fatal XML error: parsing stops.
struct Fatal;

struct Parser<'i> {
    src: &'i str,
    tok: Reader<'i>,
    lines: LineIndex,
    /// Offset of the first control character XML forbids (found while indexing the lines).
    forbidden: Option<usize>,
    diags: Vec<Diagnostic>,
    pending: Option<Tok<'i>>,
    limits: Limits,
}

/// Remaining attributes of an element, taken one by one by name.
struct Attrs<'i> {
    items: Vec<Option<RawAttr<'i>>>,
}

impl<'i> Attrs<'i> {
    fn new(items: Vec<Option<RawAttr<'i>>>) -> Self {
        Attrs { items }
    }

    fn take(&mut self, name: &str) -> Option<RawAttr<'i>> {
        self.items
            .iter_mut()
            .find(|a| matches!(a, Some(a) if a.ns == Ns::None && a.name == name))
            .and_then(Option::take)
    }

    fn take_ext(&mut self, names: &[&str]) -> Option<RawAttr<'i>> {
        self.items
            .iter_mut()
            .find(|a| matches!(a, Some(a) if a.ns.is_ext() && names.contains(&a.name)))
            .and_then(Option::take)
    }

    fn rest(self) -> impl Iterator<Item = RawAttr<'i>> {
        self.items.into_iter().flatten()
    }
}

impl<'i> Parser<'i> {
    fn new(src: &'i str, limits: &Limits) -> Self {
        // A byte-order mark is not content; offsets are relative to the rest.
        let src = src.strip_prefix('\u{feff}').unwrap_or(src);
        let (lines, forbidden) = LineIndex::scan(src);
        Parser {
            src,
            tok: Reader::new(src, limits),
            lines,
            forbidden,
            diags: Vec::new(),
            pending: None,
            limits: *limits,
        }
    }

    fn pos(&self, offset: usize) -> Pos {
        self.lines.pos(self.src, offset)
    }

    fn error(&mut self, code: Code, offset: usize, msg: impl Into<String>) {
        let pos = self.pos(offset);
        self.diags.push(Diagnostic::error(code, pos, msg));
    }

    fn warn(&mut self, code: Code, offset: usize, msg: impl Into<String>) {
        let pos = self.pos(offset);
        self.diags.push(Diagnostic::warning(code, pos, msg));
    }

    fn xml_error(&mut self, e: XmlError) -> Fatal {
        if e.problem == Problem::Limit {
            self.error(Code::LimitExceeded, e.offset, e.message);
        } else {
            let message = format!("not well-formed XML: {}", e.message);
            self.error(Code::NotXml, e.offset, message);
        }
        Fatal
    }

    /// Reads the next token, merging adjacent text, character references and CDATA.
    fn next(&mut self) -> Result<Tok<'i>, Fatal> {
        self.token(true)
    }

    /// [`Self::next`] where text that is only white space does not matter (between elements):
    /// such a run of text is passed over, not returned (and the token after it is not parked).
    fn next_markup(&mut self) -> Result<Tok<'i>, Fatal> {
        self.token(false)
    }

    /// The next token; a run of blank text is returned only if `blank_text`.
    fn token(&mut self, blank_text: bool) -> Result<Tok<'i>, Fatal> {
        if let Some(t) = self.pending.take() {
            return Ok(t);
        }
        let mut text: Option<(Str<'i>, usize)> = None;
        loop {
            let tok = match self.tok.next() {
                Ok(Event::Start(tag)) => Tok::Start(self.element(tag)?),
                Ok(Event::End { offset, after }) => Tok::End { offset, after },
                Ok(Event::Eof) => Tok::Eof,
                Ok(Event::Text { text: t, offset }) => {
                    push_text(&mut text, t, offset);
                    continue;
                }
                Err(e) => return Err(self.xml_error(e)),
            };
            return Ok(match text {
                Some((text, _)) if !blank_text && text.trim_ascii().is_empty() => tok,
                Some((text, offset)) => {
                    self.pending = Some(tok);
                    Tok::Text { text, offset }
                }
                None => tok,
            });
        }
    }

    /// The namespace of the element or attribute named `qname` where the reader is; an
    /// undeclared prefix is an error on `what`, at `offset`.
    fn namespace(
        &mut self,
        qname: &str,
        attribute: bool,
        offset: usize,
        what: &dyn fmt::Display,
    ) -> Ns {
        match self.tok.resolve(qname, attribute) {
            Ok(Some(uri)) => Ns::from_uri(uri),
            Ok(None) => Ns::None,
            Err(()) => {
                let prefix = split_qname(qname).0.unwrap_or_default();
                self.error(
                    Code::NotXml,
                    offset,
                    format!("namespace prefix '{prefix}' of {what} is not declared"),
                );
                Ns::Other(prefix.to_string())
            }
        }
    }

    /// Turns a start (or empty-element) tag into an [`El`], resolving its namespaces and its
    /// attributes' while the element's namespace scope is current.
    fn element(&mut self, tag: Tag<'i>) -> Result<El<'i>, Fatal> {
        let qname = tag.qname;
        let (prefix, name) = split_qname(qname);
        let ns = self.namespace(qname, false, tag.offset, &format_args!("<{qname}>"));
        let mut prefixes: Vec<&'i str> = prefix.into_iter().collect();
        let n = self.tok.attrs().len();
        let mut attrs: Vec<Option<RawAttr<'i>>> = Vec::with_capacity(n);
        for i in 0..n {
            let a = self.tok.attrs()[i];
            if a.declares().is_some() {
                continue; // in scope now; the reader checked them
            }
            let (aprefix, aname) = split_qname(a.key);
            let ans = match aprefix {
                None => Ns::None, // unprefixed attributes are in no namespace
                Some(p) => {
                    prefixes.push(p);
                    let what = format_args!("attribute '{}'", a.key);
                    match self.namespace(a.key, true, a.offset, &what) {
                        Ns::Bml => Ns::None,
                        other => other,
                    }
                }
            };
            let value = match a.value() {
                Ok(v) => v,
                Err(e) => {
                    self.error(
                        Code::NotXml,
                        a.offset,
                        format!(
                            "not well-formed XML: attribute '{}' has a bad character or entity reference: {}",
                            a.key, e.message
                        ),
                    );
                    return Err(Fatal);
                }
            };
            if attrs
                .iter()
                .flatten()
                .any(|b| b.ns == ans && b.name == aname)
            {
                self.error(
                    Code::NotXml,
                    a.offset,
                    format!("attribute '{}' appears twice on <{qname}>", a.key),
                );
                return Err(Fatal);
            }
            attrs.push(Some(RawAttr {
                ns: ans,
                name: aname,
                value,
                offset: a.offset,
            }));
        }
        Ok(El {
            ns,
            name,
            qname,
            prefixes,
            attrs,
            empty: tag.empty,
            offset: tag.offset,
            inner_start: tag.end,
        })
    }

    /// The prefixed namespace bindings in scope now (call right after reading a start tag).
    fn scope(&self) -> Vec<(String, String)> {
        self.tok.scope()
    }

    /// Skips the rest of an element whose start tag was just read, returning what it held.
    fn skip(&mut self, el: &El<'i>) -> Result<Skipped<'i>, Fatal> {
        let mut prefixes = Vec::new();
        if el.empty {
            return Ok(Skipped {
                content: String::new(),
                after: el.inner_start,
                prefixes,
            });
        }
        let mut depth = 0usize;
        // prefixes declared inside the content need nothing from outside it
        let mark = self.tok.level();
        loop {
            match self.next_markup()? {
                Tok::Start(e) => {
                    let outer = e
                        .prefixes
                        .into_iter()
                        .filter(|p| !self.tok.bound_since(mark, p));
                    prefixes.extend(outer);
                    if !e.empty {
                        depth += 1;
                    }
                }
                Tok::End { offset, after } => {
                    if depth == 0 {
                        return Ok(Skipped {
                            content: self.src[el.inner_start..offset].to_string(),
                            after,
                            prefixes,
                        });
                    }
                    depth -= 1;
                }
                Tok::Eof => return Err(self.unexpected_eof(el)),
                _ => {}
            }
        }
    }

    fn unexpected_eof(&mut self, el: &El<'i>) -> Fatal {
        self.error(
            Code::NotXml,
            el.offset,
            format!("<{}> is never closed", el.qname),
        );
        Fatal
    }

    /// Iterates the children of `el`: calls `f` for each child element (which must consume it,
    /// e.g. via `skip`), reports non-whitespace text unless `text` handles it.
    fn children(
        &mut self,
        el: &El<'i>,
        mut on_child: impl FnMut(&mut Self, El<'i>) -> Result<(), Fatal>,
    ) -> Result<usize, Fatal> {
        if el.empty {
            return Ok(el.inner_start);
        }
        loop {
            match self.next_markup()? {
                Tok::Start(child) => on_child(self, child)?,
                Tok::End { after, .. } => return Ok(after),
                Tok::Text { text, offset } => {
                    if !text.trim_ascii().is_empty() {
                        let lead = text.len() - text.trim_ascii_start().len();
                        self.error(
                            Code::UnexpectedText,
                            offset + lead,
                            format!(
                                "unexpected text '{}' inside <{}>",
                                abbreviate(text.trim_ascii()),
                                el.qname
                            ),
                        );
                    }
                }
                Tok::Eof => return Err(self.unexpected_eof(el)),
            }
        }
    }
}

/// Names an element in messages, e.g. `<gesture id="g1">`; formatted only when a message is made.
struct On<'a> {
    qname: &'a str,
    id: Option<&'a str>,
}

impl fmt::Display for On<'_> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self.id {
            Some(id) => write!(f, "<{} id=\"{id}\">", self.qname),
            None => write!(f, "<{}>", self.qname),
        }
    }
}

/// The bindings of `scope` whose prefix is in `used`, merged with `known`, sorted by prefix. Raw
/// content keeps these so that the writer can declare them again.
fn used_prefixes(
    scope: Vec<(String, String)>,
    used: &[&str],
    known: &[(String, String)],
) -> Vec<(String, String)> {
    let mut out: Vec<(String, String)> = known.to_vec();
    for (prefix, uri) in scope {
        if used.iter().any(|u| *u == prefix) && !out.iter().any(|(p, _)| *p == prefix) {
            out.push((prefix, uri));
        }
    }
    out.sort();
    out
}

fn push_text<'i>(acc: &mut Option<(Str<'i>, usize)>, s: Str<'i>, offset: usize) {
    match acc {
        Some((t, _)) => t.to_mut().push_str(&s),
        None => *acc = Some((s, offset)),
    }
}

fn abbreviate(s: &str) -> String {
    let mut out: String = s.chars().take(40).collect();
    if s.chars().count() > 40 {
        out.push('…');
    }
    out
}

/// The children of a behaviour that may appear once, as seen so far.
#[derive(Default)]
struct Seen {
    text: bool,
    stance: bool,
    trajectory: bool,
}
