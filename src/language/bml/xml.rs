//! The XML layer under the BML parser and the stream splitter: quick-xml's namespace reader over
//! a `&str`, turned into start, end and text events that carry byte offsets, plus the checks of
//! XML 1.0 + Namespaces that quick-xml leaves to its user: qualified names, white space between
//! attributes, `<` in attribute values, `]]>` in text, references (to known entities and allowed
//! characters), the XML declaration (version 1.x, UTF-8), undeclaring a prefix, and the limits
//! on nesting depth and attributes per element. Names, values and text are borrowed from the
//! input where nothing needs resolving.

use std::borrow::Cow;

use quick_xml::escape::{resolve_predefined_entity, unescape_with, EscapeError};
use quick_xml::events::attributes::AttrError;
use quick_xml::events::{BytesDecl, BytesRef, BytesStart, Event as XmlEvent};
use quick_xml::name::{PrefixDeclaration, QName, ResolveResult};
use quick_xml::NsReader;

use super::limits::Limits;
use crate::language::xmlname::{is_forbidden_char, is_ncname, split_qname};

/// What kind of problem an [`XmlError`] is, which decides whether reading can go on.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Problem {
    /// The markup is broken where quick-xml reads it: reading cannot go on.
    Broken,
    /// The input ends inside a tag, comment, CDATA section or declaration: more text may
    /// complete it.
    Unclosed,
    /// A tag or text is read but breaks a rule checked here (a name, a value, a reference):
    /// the structure is intact and reading can go on.
    Content,
    /// The input passes one of the limits (the XML itself may be fine); reading can go on.
    Limit,
}

/// A well-formedness error: where it is (byte offset) and what is wrong.
#[derive(Debug, Clone, PartialEq, Eq)]
pub(crate) struct XmlError {
    /// Byte offset of the offending construct.
    pub offset: usize,
    /// What is wrong, in a sentence without the position.
    pub message: String,
    /// What kind of problem it is.
    pub problem: Problem,
}

fn content<T>(offset: usize, message: impl Into<String>) -> Result<T, XmlError> {
    Err(XmlError {
        offset,
        message: message.into(),
        problem: Problem::Content,
    })
}

fn over_limit<T>(offset: usize, message: String) -> Result<T, XmlError> {
    Err(XmlError {
        offset,
        message,
        problem: Problem::Limit,
    })
}

/// One attribute of a start tag, as written (namespace declarations included).
#[derive(Debug, Clone, Copy)]
pub(crate) struct Attr<'i> {
    /// The qualified name (`prefix:local` or `local`).
    pub key: &'i str,
    /// Byte offset of the name.
    pub offset: usize,
    /// The value between the quotes, references not yet resolved (see [`Attr::value`]).
    pub raw: &'i str,
    /// Byte offset of the value's first character.
    pub value_offset: usize,
}

impl<'i> Attr<'i> {
    /// The value with its references resolved (borrowed when it has none).
    pub fn value(&self) -> Result<Cow<'i, str>, XmlError> {
        unescape(self.raw, self.value_offset)
    }

    /// The prefix a namespace declaration binds: `Some("")` for `xmlns`, `Some(p)` for
    /// `xmlns:p`, `None` for an ordinary attribute.
    pub fn declares(&self) -> Option<&'i str> {
        match self.key.strip_prefix("xmlns") {
            Some("") => Some(""),
            Some(rest) => rest.strip_prefix(':'),
            None => None,
        }
    }
}

/// A start tag (or an empty-element tag).
#[derive(Debug, Clone, Copy)]
pub(crate) struct Tag<'i> {
    /// The qualified name.
    pub qname: &'i str,
    /// Whether it is an empty-element tag (`<x/>`).
    pub empty: bool,
    /// Byte offset of the `<`.
    pub offset: usize,
    /// Byte offset just after the `>`.
    pub end: usize,
}

/// What the reader reads.
#[derive(Debug, Clone)]
pub(crate) enum Event<'i> {
    /// A start or empty-element tag; its attributes are in [`Reader::attrs`] until the next
    /// call to [`Reader::next`], and its namespace declarations are in scope.
    Start(Tag<'i>),
    /// An end tag (quick-xml checked that it closes the open element).
    End {
        /// Byte offset of the `</`.
        offset: usize,
        /// Byte offset just after the `>`.
        after: usize,
    },
    /// Character data (a run of text, a reference or a CDATA section), with references
    /// resolved and line ends normalised to `\n`. Adjacent pieces are separate events.
    Text {
        /// The characters.
        text: Cow<'i, str>,
        /// Byte offset of the first one in the source.
        offset: usize,
    },
    /// The end of the input.
    Eof,
}

/// The reader: quick-xml's namespace reader, the attributes of the last start tag, and the
/// counts the limits need.
pub(crate) struct Reader<'i> {
    src: &'i str,
    xml: NsReader<&'i [u8]>,
    attrs: Vec<Attr<'i>>,
    /// Per open element, the namespace declarations it made.
    declared: Vec<usize>,
    /// The namespace declarations in scope.
    in_scope: usize,
    /// The last event was an empty-element tag that made this many declarations: they go out
    /// of scope before the next event.
    empty_declared: usize,
    /// Whether an element was read (a DOCTYPE may only come before one).
    element_seen: bool,
    max_attributes: usize,
    max_depth: usize,
}

impl<'i> Reader<'i> {
    /// A reader at the start of `src`, refusing elements with more than `limits.attributes`
    /// attributes (or more namespace declarations in scope) and nesting deeper than
    /// `limits.depth`.
    pub fn new(src: &'i str, limits: &Limits) -> Self {
        let mut xml = NsReader::from_str(src);
        xml.config_mut().check_comments = true;
        Reader {
            src,
            xml,
            attrs: Vec::new(),
            declared: Vec::new(),
            in_scope: 0,
            empty_declared: 0,
            element_seen: false,
            max_attributes: limits.attributes,
            max_depth: limits.depth,
        }
    }

    /// The attributes of the last start tag, in source order.
    pub fn attrs(&self) -> &[Attr<'i>] {
        &self.attrs
    }

    /// The namespace of an element name (`attribute` false: an unprefixed name is in the
    /// default namespace) or an attribute name (unprefixed: in none), where the reader is;
    /// `Ok(None)` for no namespace, `Err(())` for a prefix that is not declared.
    pub fn resolve(&self, qname: &str, attribute: bool) -> Result<Option<&str>, ()> {
        let name = QName(qname.as_bytes());
        let resolver = self.xml.resolver();
        let (ns, _) = if attribute {
            resolver.resolve_attribute(name)
        } else {
            resolver.resolve_element(name)
        };
        match ns {
            ResolveResult::Bound(ns) => Ok(std::str::from_utf8(ns.into_inner()).ok()),
            ResolveResult::Unbound => Ok(None),
            ResolveResult::Unknown(_) => Err(()),
        }
    }

    /// How deep the namespace scope is (a mark for [`Self::bound_since`]).
    pub fn level(&self) -> u16 {
        self.xml.resolver().level()
    }

    /// Whether `prefix` is bound by a declaration deeper than `mark` that is still in scope.
    pub fn bound_since(&self, mark: u16, prefix: &str) -> bool {
        let resolver = self.xml.resolver();
        (mark + 1..=resolver.level()).any(|level| {
            resolver
                .bindings_of(level)
                .any(|(p, _)| p == PrefixDeclaration::Named(prefix.as_bytes()))
        })
    }

    /// The prefixed bindings in scope (the innermost for each prefix), `xml` excluded.
    pub fn scope(&self) -> Vec<(String, String)> {
        let text = |b: &[u8]| String::from_utf8_lossy(b).into_owned();
        self.xml
            .resolver()
            .bindings()
            .filter_map(|(p, ns)| match p {
                PrefixDeclaration::Named(p) if p != b"xml" => Some((text(p), text(ns.0))),
                _ => None,
            })
            .collect()
    }

    /// Reads the next event. After an error of [`Problem::Content`] or [`Problem::Limit`] the
    /// next call goes on after the construct that had it.
    pub fn next(&mut self) -> Result<Event<'i>, XmlError> {
        self.in_scope -= std::mem::take(&mut self.empty_declared);
        loop {
            let at = self.xml.buffer_position() as usize;
            let event = self.xml.read_event().map_err(|e| self.broken(e))?;
            let after = self.xml.buffer_position() as usize;
            return match event {
                XmlEvent::Start(tag) => self.start_tag(&tag, at, after, false),
                XmlEvent::Empty(tag) => self.start_tag(&tag, at, after, true),
                XmlEvent::End(_) => {
                    self.in_scope -= self.declared.pop().unwrap_or(0);
                    Ok(Event::End { offset: at, after })
                }
                XmlEvent::Text(t) => {
                    let text = t.xml10_content().map_err(|e| self.broken(e.into()))?;
                    self.text(text, at)
                }
                XmlEvent::CData(t) => {
                    let text = t.xml10_content().map_err(|e| self.broken(e.into()))?;
                    Ok(Event::Text { text, offset: at })
                }
                XmlEvent::GeneralRef(r) => reference(&r, at),
                XmlEvent::Decl(d) => {
                    declaration(&d, at)?;
                    continue;
                }
                XmlEvent::PI(pi) => {
                    if pi.target().eq_ignore_ascii_case(b"xml") {
                        return content(at, "the processing instruction target 'xml' is reserved (an XML declaration goes at the very start)");
                    }
                    continue;
                }
                XmlEvent::DocType(_) if self.element_seen => {
                    content(at, "a DOCTYPE declaration after the first element")
                }
                XmlEvent::DocType(d) if open_quote(&d) => Err(XmlError {
                    offset: at,
                    message: "a '>' inside a quoted literal of a DOCTYPE's internal subset is not supported (BML needs no DTD)".into(),
                    problem: Problem::Broken,
                }),
                XmlEvent::DocType(_) | XmlEvent::Comment(_) => continue,
                XmlEvent::Eof => Ok(Event::Eof),
            };
        }
    }

    /// A quick-xml error as an [`XmlError`] at the position quick-xml gives for it.
    fn broken(&self, e: quick_xml::Error) -> XmlError {
        let problem = match e {
            quick_xml::Error::Syntax(_) => Problem::Unclosed,
            _ => Problem::Broken,
        };
        let message = match e {
            quick_xml::Error::Syntax(s) => s.to_string(),
            quick_xml::Error::IllFormed(e) => e.to_string(),
            other => other.to_string(),
        };
        XmlError {
            offset: self.xml.error_position() as usize,
            message,
            problem,
        }
    }

    /// Character data outside a CDATA section: `]]>` may not appear in it.
    fn text(&self, text: Cow<'i, str>, at: usize) -> Result<Event<'i>, XmlError> {
        if let Some(i) = text.find("]]>") {
            // line-end normalisation only shortens the text after a '\r'; the raw text says
            let raw = self.src.get(at..).and_then(|s| s.find("]]>")).unwrap_or(i);
            return content(at + raw, "']]>' in text (it may only end a CDATA section)");
        }
        Ok(Event::Text { text, offset: at })
    }

    /// Byte offset of `part`, a slice of the input, in it.
    fn offset_of(&self, part: &[u8]) -> usize {
        (part.as_ptr() as usize).wrapping_sub(self.src.as_ptr() as usize)
    }

    /// The input text at `part` (a slice of it), with its offset.
    fn text_at(&self, part: &[u8]) -> (&'i str, usize) {
        let at = self.offset_of(part);
        (self.src.get(at..at + part.len()).unwrap_or(""), at)
    }

    /// A start or empty-element tag: its scope and attributes recorded first (so that reading
    /// can go on after a content error), then its name and attributes checked.
    fn start_tag(
        &mut self,
        tag: &BytesStart<'i>,
        at: usize,
        after: usize,
        empty: bool,
    ) -> Result<Event<'i>, XmlError> {
        self.element_seen = true;
        let (qname, _) = self.text_at(tag.name().as_ref());
        let (declared, unread) = self.read_attributes(tag, qname);
        self.in_scope += declared;
        if empty {
            self.empty_declared = declared;
        } else {
            self.declared.push(declared);
        }
        if !empty && self.declared.len() > self.max_depth {
            let message = format!(
                "<{qname}> is nested deeper than {} elements (the limit; --max-depth)",
                self.max_depth
            );
            return over_limit(at, message);
        }
        if self.in_scope > self.max_attributes {
            let message = format!(
                "more than {} namespace declarations in scope (the limit; --max-attributes)",
                self.max_attributes
            );
            return over_limit(at, message);
        }
        if let Some(e) = unread {
            return Err(e);
        }
        if !is_qname(qname) {
            return content(at, format!("<{qname}> is not a valid qualified name"));
        }
        if qname.starts_with("xmlns:") {
            let message =
                format!("<{qname}>: the prefix xmlns is reserved for namespace declarations");
            return content(at, message);
        }
        for a in &self.attrs {
            check_attribute(self.src, a, qname)?;
        }
        Ok(Event::Start(Tag {
            qname,
            empty,
            offset: at,
            end: after,
        }))
    }

    /// Reads the attributes of `tag` into [`Self::attrs`]: how many of them declare a
    /// namespace, and why the rest could not be read (the list cannot be parsed, or it is too
    /// long).
    fn read_attributes(&mut self, tag: &BytesStart<'i>, qname: &str) -> (usize, Option<XmlError>) {
        self.attrs.clear();
        let base = self.offset_of(tag.as_ref());
        let mut declared = 0;
        for a in tag.attributes() {
            let a = match a {
                Ok(a) => a,
                Err(e) => return (declared, Some(attr_error(&e, base, qname))),
            };
            let (key, offset) = self.text_at(a.key.as_ref());
            if self.attrs.len() == self.max_attributes {
                let message = format!(
                    "<{qname}> has more than {} attributes (the limit; --max-attributes)",
                    self.max_attributes
                );
                return (declared, over_limit::<()>(offset, message).err());
            }
            let (raw, value_offset) = self.text_at(&a.value);
            let attr = Attr {
                key,
                offset,
                raw,
                value_offset,
            };
            declared += usize::from(attr.declares().is_some());
            self.attrs.push(attr);
        }
        (declared, None)
    }
}

/// The rules an attribute must keep that quick-xml does not check.
fn check_attribute(src: &str, a: &Attr<'_>, tag: &str) -> Result<(), XmlError> {
    let key = a.key;
    if !preceded_by_space(src, a.offset) {
        return content(
            a.offset,
            format!("attributes of <{tag}> must be separated by white space"),
        );
    }
    if !is_qname(key) {
        let message = format!("attribute '{key}' of <{tag}> is not a valid qualified name");
        return content(a.offset, message);
    }
    if let Some(i) = a.raw.find('<') {
        return content(
            a.value_offset + i,
            format!("'<' in the value of attribute '{key}'"),
        );
    }
    match a.declares() {
        Some(prefix) if !prefix.is_empty() && a.raw.is_empty() => content(
            a.offset,
            format!("'{key}' cannot undeclare a prefix (XML 1.0 namespaces)"),
        ),
        Some(_) if a.raw.contains('&') => content(
            a.value_offset,
            format!("the namespace name of '{key}' holds a reference, which this reader does not resolve"),
        ),
        Some(_) => match a.raw.char_indices().find(|&(_, c)| not_in_uri(c)) {
            Some((i, c)) => content(
                a.value_offset + i,
                format!(
                    "the namespace name of '{key}' holds U+{:04X}, which no URI reference may hold",
                    c as u32
                ),
            ),
            None => Ok(()),
        },
        None => Ok(()),
    }
}

/// Whether `c` may appear in no URI reference (nor IRI): white space, controls and the ASCII
/// characters RFC 3986 leaves out. A namespace name is a URI reference.
fn not_in_uri(c: char) -> bool {
    c.is_whitespace()
        || c.is_control()
        || matches!(c, '"' | '<' | '>' | '\\' | '^' | '`' | '{' | '|' | '}')
}

/// Whether the byte before `at` is XML white space.
fn preceded_by_space(src: &str, at: usize) -> bool {
    at.checked_sub(1)
        .and_then(|i| src.as_bytes().get(i))
        .is_some_and(|b| matches!(b, b' ' | b'\t' | b'\n' | b'\r'))
}

/// An attribute list quick-xml cannot read, as an error in the words of this parser.
fn attr_error(e: &AttrError, base: usize, tag: &str) -> XmlError {
    let (at, message) = match *e {
        AttrError::ExpectedEq(p) => (p, format!("an attribute of <{tag}> has no value")),
        AttrError::ExpectedValue(p) => (p, format!("'=' in <{tag}> is not followed by a value")),
        AttrError::UnquotedValue(p) => (
            p,
            format!("the value of an attribute of <{tag}> is not in quotes"),
        ),
        AttrError::ExpectedQuote(p, _) => (
            p,
            format!("the value of an attribute of <{tag}> is never closed"),
        ),
        AttrError::Duplicated(p, _) => (p, format!("an attribute appears twice on <{tag}>")),
    };
    XmlError {
        offset: base + at,
        message,
        problem: Problem::Content,
    }
}

/// The XML declaration: only at the very start, version 1.x, and (the input being text in
/// UTF-8) no other encoding.
fn declaration(d: &BytesDecl<'_>, at: usize) -> Result<(), XmlError> {
    if at != 0 {
        return content(at, "the XML declaration may only open the document");
    }
    let version = d.version().map_err(|e| XmlError {
        offset: at,
        message: format!("XML declaration: {e}"),
        problem: Problem::Content,
    })?;
    if !version.starts_with(b"1.") {
        let v = String::from_utf8_lossy(&version);
        return content(at, format!("XML version '{v}' is not 1.0"));
    }
    match d.encoding() {
        Some(Ok(enc)) if !enc.eq_ignore_ascii_case(b"utf-8") => {
            let enc = String::from_utf8_lossy(&enc);
            content(
                at,
                format!("the document declares encoding '{enc}', but BML is read as UTF-8"),
            )
        }
        Some(Err(e)) => content(at, format!("XML declaration: {e}")),
        _ => Ok(()),
    }
}

/// A reference in text (`&name;` or `&#N;`), resolved to the text it stands for.
fn reference<'i>(r: &BytesRef<'i>, at: usize) -> Result<Event<'i>, XmlError> {
    let name = String::from_utf8_lossy(r);
    let text = match r.resolve_char_ref() {
        Ok(Some(c)) if is_forbidden_char(c) => {
            let message = format!(
                "'&{name};' refers to U+{:04X}, which is not allowed in XML",
                c as u32
            );
            return content(at, message);
        }
        Ok(Some(c)) => Cow::Owned(c.to_string()),
        Ok(None) => match resolve_predefined_entity(&name) {
            Some(s) => Cow::Borrowed(s),
            None => return content(at, format!("unknown entity '&{name};'")),
        },
        Err(_) => return content(at, format!("'&{name};' is not a valid character reference")),
    };
    Ok(Event::Text { text, offset: at })
}

/// An attribute value (starting at `offset`) with its references resolved; an unknown entity,
/// a bad character reference or a reference to a character XML forbids is an error at the `&`.
fn unescape(raw: &str, offset: usize) -> Result<Cow<'_, str>, XmlError> {
    if !raw.contains('&') {
        return Ok(Cow::Borrowed(raw));
    }
    let first = offset + raw.find('&').unwrap_or(0);
    let value = unescape_with(raw, resolve_predefined_entity).map_err(|e| {
        let (at, message) = match e {
            EscapeError::UnrecognizedEntity(range, name) => (
                offset + range.start - 1,
                format!("unknown entity '&{name};'"),
            ),
            EscapeError::UnterminatedEntity(range) => (
                offset + range.start,
                "'&' does not start a reference (write &amp;)".to_string(),
            ),
            EscapeError::InvalidCharRef(e) => (first, format!("bad character reference: {e}")),
        };
        XmlError {
            offset: at,
            message,
            problem: Problem::Content,
        }
    })?;
    match value.chars().find(|&c| is_forbidden_char(c)) {
        Some(c) => content(
            first,
            format!(
                "a reference to U+{:04X}, which is not allowed in XML",
                c as u32
            ),
        ),
        None => Ok(value),
    }
}

/// Whether a DOCTYPE, as quick-xml read it, was cut short: quick-xml ends the declaration where
/// its `<` and `>` balance, so a `>` inside a quoted literal ends it early, inside the internal
/// subset's brackets or inside the quotes.
fn open_quote(doctype: &[u8]) -> bool {
    let (mut quote, mut brackets) = (None, 0i32);
    for &b in doctype {
        match (quote, b) {
            (Some(q), _) if b == q => quote = None,
            (Some(_), _) => {}
            (None, b'"' | b'\'') => quote = Some(b),
            (None, b'[') => brackets += 1,
            (None, b']') => brackets -= 1,
            _ => {}
        }
    }
    quote.is_some() || brackets != 0
}

/// Whether `q` is `NCName` or `NCName:NCName`.
fn is_qname(q: &str) -> bool {
    match split_qname(q) {
        (Some(p), l) => is_ncname(p) && is_ncname(l),
        (None, l) => is_ncname(l),
    }
}

#[cfg(test)]
mod tests;
