//! The XML 1.0 + Namespaces tokenizer under the BML parser: start, end and text events over a
//! `&str`, with names, attribute values and text borrowed from the input, character and entity
//! references resolved, and the namespace scope kept on a stack. It checks well-formedness
//! (names, tag nesting, quoting, references, declarations) and reports each problem at its byte
//! offset. Made for short BML blocks: no allocation for a tag, its attributes or plain text.

use std::borrow::Cow;

use crate::xmlname::{is_forbidden_char, is_ncname, split_qname};

/// The namespace bound to the prefix `xml`.
pub(crate) const XML_URI: &str = "http://www.w3.org/XML/1998/namespace";
/// The namespace of `xmlns` declarations; no element or attribute may be in it.
pub(crate) const XMLNS_URI: &str = "http://www.w3.org/2000/xmlns/";

/// A well-formedness error: where it is (byte offset) and what is wrong.
#[derive(Debug, Clone, PartialEq, Eq)]
pub(crate) struct XmlError {
    /// Byte offset of the offending construct.
    pub offset: usize,
    /// What is wrong, in a sentence without the position.
    pub message: String,
    /// The input passes one of the limits (the XML itself may be fine).
    pub limit: bool,
}

fn err<T>(offset: usize, message: impl Into<String>) -> Result<T, XmlError> {
    Err(XmlError {
        offset,
        message: message.into(),
        limit: false,
    })
}

/// An error for input that passes a limit.
fn over_limit<T>(offset: usize, message: String) -> Result<T, XmlError> {
    Err(XmlError {
        offset,
        message,
        limit: true,
    })
}

/// One attribute of a start tag, as written (namespace declarations included).
#[derive(Debug, Clone, Copy)]
pub(crate) struct Attr<'i> {
    /// The qualified name (`prefix:local` or `local`).
    pub key: &'i str,
    /// Byte offset of the name.
    pub offset: usize,
    /// The value between the quotes, references not yet resolved (see [`unescape`]).
    pub raw: &'i str,
    /// Byte offset of the value's first character.
    pub value_offset: usize,
    /// Whether the value holds a reference (`&`), so that [`Attr::value`] must resolve it.
    pub references: bool,
}

impl<'i> Attr<'i> {
    /// The value with its references resolved (borrowed when it has none).
    pub fn value(&self) -> Result<Cow<'i, str>, XmlError> {
        if self.references {
            unescape(self.raw, self.value_offset)
        } else {
            Ok(Cow::Borrowed(self.raw))
        }
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

/// What the tokenizer reads.
#[derive(Debug, Clone)]
pub(crate) enum Event<'i> {
    /// A start or empty-element tag; its attributes are in [`Tokenizer::attrs`] until the next
    /// call to [`Tokenizer::next`], and its namespace declarations are in scope.
    Start(Tag<'i>),
    /// An end tag (already checked to close the open element).
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

/// An open element: its name, and the length of the binding list before its declarations.
struct Open<'i> {
    qname: &'i str,
    bindings: usize,
}

/// A tokenizer's lists, emptied, for building another one (see [`Tokenizer::take_lists`]): the
/// parser keeps them between blocks, so parsing one small block after another allocates no
/// scratch space.
#[derive(Default)]
pub(crate) struct Lists {
    open: Vec<Open<'static>>,
    bindings: Vec<(&'static str, Cow<'static, str>)>,
    attrs: Vec<Attr<'static>>,
}

impl Lists {
    /// The longest of the lists.
    pub fn longest(&self) -> usize {
        self.open
            .capacity()
            .max(self.bindings.capacity())
            .max(self.attrs.capacity())
    }
}

/// `v` emptied and retyped (here: only its lifetime), keeping its allocation: collecting a
/// by-value iterator into elements of the same size and alignment reuses the buffer.
pub(crate) fn recycle<T, U>(mut v: Vec<T>) -> Vec<U> {
    v.clear();
    v.into_iter()
        .map(|_| unreachable!("the list is empty"))
        .collect()
}

/// The tokenizer: a cursor over the input plus the open elements and namespace bindings.
pub(crate) struct Tokenizer<'i> {
    src: &'i str,
    pos: usize,
    open: Vec<Open<'i>>,
    /// (prefix, namespace) in declaration order; `""` is the default namespace, and an empty
    /// namespace undeclares it.
    bindings: Vec<(&'i str, Cow<'i, str>)>,
    /// The attributes of the last start tag.
    attrs: Vec<Attr<'i>>,
    /// The last event was an empty-element tag: its scope ends before the next event.
    close_empty: Option<usize>,
    /// Most attributes per element, and most namespace declarations in scope (a longer list
    /// is an error: every attribute is checked against the others).
    max_attributes: usize,
    /// Deepest nesting of open elements.
    max_depth: usize,
}

impl<'i> Tokenizer<'i> {
    /// A tokenizer at the start of `src` that uses `lists` (new ones, or from
    /// [`Self::take_lists`]).
    pub fn with_lists(src: &'i str, lists: Lists) -> Self {
        Tokenizer {
            src,
            pos: 0,
            open: recycle(lists.open),
            bindings: recycle(lists.bindings),
            attrs: recycle(lists.attrs),
            close_empty: None,
            max_attributes: usize::MAX,
            max_depth: usize::MAX,
        }
    }

    /// The same tokenizer refusing elements with more than `attributes` attributes (or more
    /// namespace declarations in scope) and nesting deeper than `depth`.
    pub fn limited(mut self, attributes: usize, depth: usize) -> Self {
        self.max_attributes = attributes;
        self.max_depth = depth;
        self
    }

    /// The lists, emptied, for the next tokenizer (this one is done with them; taken through
    /// a reference, so that the tokenizer itself is not copied).
    pub fn take_lists(&mut self) -> Lists {
        Lists {
            open: recycle(std::mem::take(&mut self.open)),
            bindings: recycle(std::mem::take(&mut self.bindings)),
            attrs: recycle(std::mem::take(&mut self.attrs)),
        }
    }

    /// The attributes of the last start tag, in source order.
    pub fn attrs(&self) -> &[Attr<'i>] {
        &self.attrs
    }

    /// The namespace a prefix is bound to here (`None` for no prefix: the default namespace);
    /// `Ok(None)` when there is none, `Err(())` for a prefix that is not declared.
    pub fn resolve(&self, prefix: Option<&str>) -> Result<Option<&str>, ()> {
        let p = prefix.unwrap_or("");
        match p {
            "xml" => return Ok(Some(XML_URI)),
            "xmlns" => return Ok(Some(XMLNS_URI)),
            _ => {}
        }
        match self.bindings.iter().rev().find(|b| b.0 == p) {
            Some((_, uri)) if uri.is_empty() => Ok(None),
            Some((_, uri)) => Ok(Some(uri)),
            None if p.is_empty() => Ok(None),
            None => Err(()),
        }
    }

    /// How many namespace bindings are in scope (a mark for [`Self::bound_since`]).
    pub fn bindings_len(&self) -> usize {
        self.bindings.len()
    }

    /// Whether `prefix` is bound by a declaration made after `mark` that is still in scope.
    pub fn bound_since(&self, mark: usize, prefix: &str) -> bool {
        self.bindings
            .get(mark..)
            .is_some_and(|b| b.iter().any(|(p, _)| *p == prefix))
    }

    /// The prefixed bindings in scope (innermost first for each prefix), `xml` excluded.
    pub fn scope(&self) -> Vec<(String, String)> {
        let mut out: Vec<(String, String)> = Vec::new();
        for (p, uri) in self.bindings.iter().rev() {
            if !p.is_empty() && *p != "xml" && !out.iter().any(|(q, _)| q == p) {
                out.push((p.to_string(), uri.to_string()));
            }
        }
        out
    }

    fn bytes(&self) -> &'i [u8] {
        self.src.as_bytes()
    }

    /// Reads the next event.
    pub fn next(&mut self) -> Result<Event<'i>, XmlError> {
        if let Some(mark) = self.close_empty.take() {
            self.bindings.truncate(mark);
        }
        loop {
            let b = self.bytes();
            let start = self.pos;
            if start >= b.len() {
                return Ok(Event::Eof);
            }
            match b[start] {
                b'<' => match b.get(start + 1) {
                    Some(b'/') => return self.end_tag(start),
                    Some(b'!') => {
                        if let Some(text) = self.bang(start)? {
                            return Ok(Event::Text {
                                text: Cow::Borrowed(text),
                                offset: start,
                            });
                        }
                    }
                    Some(b'?') => self.skip_to(start, "?>", "processing instruction")?,
                    _ => return self.start_tag(start),
                },
                b'&' => {
                    let (c, next) = reference(self.src, start)?;
                    self.pos = next;
                    return Ok(Event::Text {
                        text: c,
                        offset: start,
                    });
                }
                _ => {
                    let end = find_near(&b[start..], [b'<', b'&']).map_or(b.len(), |i| start + i);
                    self.pos = end;
                    let s = &self.src[start..end];
                    let text = if find_near(s.as_bytes(), [b'\r']).is_some() {
                        Cow::Owned(s.replace("\r\n", "\n").replace('\r', "\n"))
                    } else {
                        Cow::Borrowed(s)
                    };
                    return Ok(Event::Text {
                        text,
                        offset: start,
                    });
                }
            }
        }
    }

    /// Skips past `close`, or fails with an unclosed `what`.
    fn skip_to(&mut self, start: usize, close: &str, what: &str) -> Result<(), XmlError> {
        match find(&self.bytes()[start + 2..], close.as_bytes()) {
            Some(i) => {
                self.pos = start + 2 + i + close.len();
                Ok(())
            }
            None => err(start, format!("the {what} is never closed")),
        }
    }

    /// `<!`: a comment or a DOCTYPE (skipped) or a CDATA section (its text).
    fn bang(&mut self, start: usize) -> Result<Option<&'i str>, XmlError> {
        let rest = &self.src[start..];
        if let Some(body) = rest.strip_prefix("<!--") {
            match find(body.as_bytes(), b"-->") {
                Some(i) => self.pos = start + 4 + i + 3,
                None => return err(start, "the comment is never closed"),
            }
            Ok(None)
        } else if let Some(body) = rest.strip_prefix("<![CDATA[") {
            match find(body.as_bytes(), b"]]>") {
                Some(i) => {
                    self.pos = start + 9 + i + 3;
                    Ok(Some(&body[..i]))
                }
                None => err(start, "the CDATA section is never closed"),
            }
        } else if rest.starts_with("<!DOCTYPE") {
            // the internal subset may contain '>' inside brackets and quotes
            let (mut depth, mut quote) = (0usize, None);
            for (i, &c) in rest.as_bytes().iter().enumerate().skip(9) {
                match (quote, c) {
                    (Some(q), _) if c == q => quote = None,
                    (Some(_), _) => {}
                    (None, b'"' | b'\'') => quote = Some(c),
                    (None, b'[') => depth += 1,
                    (None, b']') => depth = depth.saturating_sub(1),
                    (None, b'>') if depth == 0 => {
                        self.pos = start + i + 1;
                        return Ok(None);
                    }
                    _ => {}
                }
            }
            err(start, "the DOCTYPE declaration is never closed")
        } else {
            err(
                start,
                "'<!' starts neither a comment, a CDATA section nor a DOCTYPE",
            )
        }
    }

    /// Scans a name from `at` up to whitespace, `/`, `>`, `=`, `<` or the end; with whether it
    /// is a qualified name (`NCName` or `NCName:NCName`).
    fn name_at(&self, at: usize) -> (&'i str, bool) {
        let b = self.bytes();
        // the common case in one pass: ASCII letters, digits, '_', '-', '.' and at most one ':'
        // not at either end, starting with a letter or '_'
        let mut i = at;
        // plain name characters (nearly every byte of every name) in a tight loop first
        while i < b.len() && NAME_CLASS[usize::from(b[i])] == NAME_CHAR {
            i += 1;
        }
        let mut colon = None;
        let mut ascii = true;
        while i < b.len() {
            match NAME_CLASS[usize::from(b[i])] {
                NAME_CHAR => {}
                NAME_END => break,
                COLON if colon.is_none() => colon = Some(i),
                _ => ascii = false,
            }
            i += 1;
        }
        let name = &self.src[at..i];
        let starts = |j: usize| j < i && (b[j].is_ascii_alphabetic() || b[j] == b'_');
        let valid = if ascii {
            match colon {
                Some(c) => starts(at) && starts(c + 1),
                None => starts(at),
            }
        } else {
            is_qname(name)
        };
        (name, valid)
    }

    fn skip_space(&mut self) {
        let b = self.bytes();
        while self.pos < b.len() && matches!(b[self.pos], b' ' | b'\t' | b'\n' | b'\r') {
            self.pos += 1;
        }
    }

    fn start_tag(&mut self, start: usize) -> Result<Event<'i>, XmlError> {
        let (qname, valid) = self.name_at(start + 1);
        if !valid {
            return err(start, format!("<{qname}> is not a valid qualified name"));
        }
        if qname.starts_with("xmlns:") {
            return err(
                start,
                format!("<{qname}>: the prefix xmlns is reserved for namespace declarations"),
            );
        }
        self.pos = start + 1 + qname.len();
        self.attrs.clear();
        let mark = self.bindings.len();
        let b = self.bytes();
        let empty = loop {
            let before = self.pos;
            self.skip_space();
            match b.get(self.pos) {
                None => return err(start, format!("the tag <{qname}> is never closed")),
                Some(b'>') => {
                    self.pos += 1;
                    break false;
                }
                Some(b'/') => {
                    if b.get(self.pos + 1) == Some(&b'>') {
                        self.pos += 2;
                        break true;
                    }
                    return err(
                        self.pos,
                        format!("'/' in the tag <{qname}> is not followed by '>'"),
                    );
                }
                Some(_) if before == self.pos => {
                    return err(
                        self.pos,
                        format!("attributes of <{qname}> must be separated by white space"),
                    )
                }
                Some(_) if self.attrs.len() >= self.max_attributes => {
                    return over_limit(
                        self.pos,
                        format!(
                            "<{qname}> has more than {} attributes (the limit; --max-attributes)",
                            self.max_attributes
                        ),
                    )
                }
                Some(_) => self.attribute(qname)?,
            }
        };
        // namespace declarations take effect for the element and its attributes
        for i in 0..self.attrs.len() {
            let a = self.attrs[i];
            if let Some(prefix) = a.declares() {
                if self.bindings[mark..].iter().any(|(p, _)| *p == prefix) {
                    return err(
                        a.offset,
                        format!("attribute '{}' appears twice on <{qname}>", a.key),
                    );
                }
                let uri = a.value().map_err(|e| XmlError {
                    offset: a.offset,
                    message: format!(
                        "namespace declaration has a bad character or entity reference: {}",
                        e.message
                    ),
                    limit: false,
                })?;
                if !prefix.is_empty() && uri.is_empty() {
                    return err(
                        a.offset,
                        format!("'{}' cannot undeclare a prefix (XML 1.0 namespaces)", a.key),
                    );
                }
                if matches!(prefix, "xml" | "xmlns") && uri != XML_URI {
                    return err(a.offset, format!("the prefix {prefix} cannot be declared"));
                }
                if self.bindings.len() >= self.max_attributes {
                    return over_limit(
                        a.offset,
                        format!(
                            "more than {} namespace declarations in scope (the limit; --max-attributes)",
                            self.max_attributes
                        ),
                    );
                }
                self.bindings.push((prefix, uri));
            }
        }
        let end = self.pos;
        if !empty && self.open.len() + 1 > self.max_depth {
            return over_limit(
                start,
                format!(
                    "<{qname}> is nested deeper than {} elements (the limit; --max-depth)",
                    self.max_depth
                ),
            );
        }
        if empty {
            self.close_empty = Some(mark);
        } else {
            self.open.push(Open {
                qname,
                bindings: mark,
            });
        }
        Ok(Event::Start(Tag {
            qname,
            empty,
            offset: start,
            end,
        }))
    }

    /// One `name = "value"` at the cursor.
    fn attribute(&mut self, tag: &str) -> Result<(), XmlError> {
        let b = self.bytes();
        let offset = self.pos;
        let (key, valid) = self.name_at(offset);
        if !valid {
            return err(
                offset,
                format!("attribute '{key}' of <{tag}> is not a valid qualified name"),
            );
        }
        self.pos += key.len();
        self.skip_space();
        if b.get(self.pos) != Some(&b'=') {
            return err(offset, format!("attribute '{key}' of <{tag}> has no value"));
        }
        self.pos += 1;
        self.skip_space();
        let quote = match b.get(self.pos) {
            Some(&q @ (b'"' | b'\'')) => q,
            _ => {
                return err(
                    self.pos,
                    format!("the value of attribute '{key}' of <{tag}> is not in quotes"),
                )
            }
        };
        let value_offset = self.pos + 1;
        // one search for the closing quote, a '<' (not allowed) or a reference
        let (mut end, mut references) = (value_offset, false);
        loop {
            match find_near(&b[end..], [quote, b'<', b'&']).map(|i| end + i) {
                None => {
                    return err(
                        offset,
                        format!("the value of attribute '{key}' of <{tag}> is never closed"),
                    )
                }
                Some(i) if b[i] == quote => {
                    end = i;
                    break;
                }
                Some(i) if b[i] == b'<' => {
                    return err(i, format!("'<' in the value of attribute '{key}'"))
                }
                Some(i) => {
                    references = true;
                    end = i + 1;
                }
            }
        }
        self.pos = end + 1;
        self.attrs.push(Attr {
            key,
            offset,
            raw: &self.src[value_offset..end],
            value_offset,
            references,
        });
        Ok(())
    }

    fn end_tag(&mut self, start: usize) -> Result<Event<'i>, XmlError> {
        let (qname, _) = self.name_at(start + 2);
        self.pos = start + 2 + qname.len();
        self.skip_space();
        if self.bytes().get(self.pos) != Some(&b'>') {
            return err(
                start,
                format!("the end tag </{qname}> is not closed by '>'"),
            );
        }
        self.pos += 1;
        match self.open.pop() {
            Some(o) if o.qname == qname => {
                self.bindings.truncate(o.bindings);
                Ok(Event::End {
                    offset: start,
                    after: self.pos,
                })
            }
            Some(o) => err(
                start,
                format!(
                    "end tag </{qname}> does not match the start tag <{}>",
                    o.qname
                ),
            ),
            None => err(start, format!("end tag </{qname}> without a start tag")),
        }
    }
}

const NAME_OTHER: u8 = 0;
const NAME_CHAR: u8 = 1;
const NAME_END: u8 = 2;
const COLON: u8 = 3;

/// Bytes in and after a name: ASCII name characters (letters, digits, `_`, `-`, `.`), the
/// bytes that end a name (white space, `/`, `>`, `=`, `<`), the colon, and the rest (checked by
/// the general rule).
static NAME_CLASS: [u8; 256] = {
    let mut t = [NAME_OTHER; 256];
    let mut b = 0;
    while b < 128 {
        let c = b as u8;
        t[b] = match c {
            b' ' | b'\t' | b'\n' | b'\r' | b'/' | b'>' | b'=' | b'<' => NAME_END,
            b':' => COLON,
            b'_' | b'-' | b'.' => NAME_CHAR,
            _ if c.is_ascii_alphanumeric() => NAME_CHAR,
            _ => NAME_OTHER,
        };
        b += 1;
    }
    t
};

/// The first byte of `hay` that is one of `needles`. Matches in a BML document are mostly a few
/// bytes away (the end of an attribute value, the next tag after white space), where a call into
/// `memchr` costs more than the search itself; so the first [`NEAR`] bytes are searched here,
/// eight at a time, and only the rest by `memchr`'s vector search (for one to three needles).
#[inline]
fn find_near<const K: usize>(hay: &[u8], needles: [u8; K]) -> Option<usize> {
    let near = hay.len().min(NEAR);
    let mut words = hay[..near].chunks_exact(8);
    let mut at = 0;
    for w in &mut words {
        let x = u64::from_le_bytes(w.try_into().expect("eight bytes"));
        // a byte equal to a needle is zero after the xor, and zero bytes get their high bit
        // flagged; the lowest flag is exact (a false one only sits above a true one)
        let mut found = 0;
        for n in needles {
            let y = x ^ (ONES * u64::from(n));
            found |= y.wrapping_sub(ONES) & !y & HIGH;
        }
        if found != 0 {
            return Some(at + found.trailing_zeros() as usize / 8);
        }
        at += 8;
    }
    if let Some(i) = words.remainder().iter().position(|b| needles.contains(b)) {
        return Some(at + i);
    }
    if hay.len() <= NEAR {
        return None;
    }
    let far = &hay[NEAR..];
    match *needles.as_slice() {
        [a] => memchr::memchr(a, far),
        [a, b] => memchr::memchr2(a, b, far),
        [a, b, c] => memchr::memchr3(a, b, c, far),
        _ => far.iter().position(|b| needles.contains(b)),
    }
    .map(|i| NEAR + i)
}

/// A byte of 1 in every lane of a word read eight bytes at a time (this search, and the line
/// index's scan).
pub(super) const ONES: u64 = 0x0101_0101_0101_0101;
/// The high bit of every lane of such a word.
pub(super) const HIGH: u64 = 0x8080_8080_8080_8080;

/// How many bytes [`find_near`] searches itself.
const NEAR: usize = 64;

/// The first occurrence of `needle` (a short closing delimiter) in `haystack`: a search for its
/// first byte, then a comparison (no searcher to build for a comment of a few hundred bytes).
fn find(haystack: &[u8], needle: &[u8]) -> Option<usize> {
    let mut from = 0;
    while let Some(i) = memchr::memchr(needle[0], &haystack[from..]) {
        let at = from + i;
        if haystack[at..].starts_with(needle) {
            return Some(at);
        }
        from = at + 1;
    }
    None
}

/// Whether `q` is `NCName` or `NCName:NCName`.
fn is_qname(q: &str) -> bool {
    match split_qname(q) {
        (Some(p), l) => is_ncname(p) && is_ncname(l),
        (None, l) => is_ncname(l),
    }
}

/// The character or entity reference starting at the `&` at `at` in `src`, and the offset just
/// after its `;`.
fn reference(src: &str, at: usize) -> Result<(Cow<'static, str>, usize), XmlError> {
    let rest = &src[at + 1..];
    let Some(semi) = rest.bytes().take(32).position(|c| c == b';') else {
        return err(
            at,
            "'&' does not start a reference (write &amp; for an ampersand)",
        );
    };
    let name = &rest[..semi];
    let after = at + 1 + semi + 1;
    let c = match name {
        "lt" => "<",
        "gt" => ">",
        "amp" => "&",
        "apos" => "'",
        "quot" => "\"",
        _ => {
            let code = if let Some(hex) = name.strip_prefix("#x") {
                u32::from_str_radix(hex, 16)
                    .ok()
                    .filter(|_| !hex.starts_with('+'))
            } else if let Some(dec) = name.strip_prefix('#') {
                dec.parse::<u32>().ok().filter(|_| !dec.starts_with('+'))
            } else {
                return err(at, format!("unknown entity '&{name};'"));
            };
            return match code.and_then(char::from_u32) {
                Some(c) if is_forbidden_char(c) => err(
                    at,
                    format!(
                        "character reference to U+{:04X}, which XML does not allow",
                        c as u32
                    ),
                ),
                Some(c) => Ok((Cow::Owned(c.to_string()), after)),
                None => err(at, format!("'&{name};' is not a valid character reference")),
            };
        }
    };
    Ok((Cow::Borrowed(c), after))
}

/// Resolves the references in an attribute value (`raw` starts at byte `offset` of the source);
/// borrowed when there are none.
fn unescape(raw: &str, offset: usize) -> Result<Cow<'_, str>, XmlError> {
    let Some(first) = raw.bytes().position(|c| c == b'&') else {
        return Ok(Cow::Borrowed(raw));
    };
    let mut out = String::with_capacity(raw.len());
    out.push_str(&raw[..first]);
    let mut i = first;
    while i < raw.len() {
        if raw.as_bytes()[i] == b'&' {
            let (c, next) = reference(raw, i).map_err(|e| XmlError {
                offset: offset + e.offset,
                message: e.message,
                limit: false,
            })?;
            out.push_str(&c);
            i = next;
        } else {
            let end = memchr::memchr(b'&', &raw.as_bytes()[i..]).map_or(raw.len(), |j| i + j);
            out.push_str(&raw[i..end]);
            i = end;
        }
    }
    Ok(Cow::Owned(out))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The short search finds the same first match as `memchr` for every length around its
    /// word and near-window edges, with needles and other bytes at every place.
    #[test]
    fn short_search_agrees_with_memchr() {
        let mut rng = crate::testrand::XorShift(0x2545_f491_4f6c_dd1d);
        for len in 0..150 {
            for _ in 0..40 {
                let hay: Vec<u8> = (0..len)
                    .map(|_| {
                        let seed = rng.next_u64();
                        // mostly ordinary bytes, sometimes a needle, a zero or a high byte
                        match seed % 40 {
                            0 => b'"',
                            1 => b'<',
                            2 => b'&',
                            3 => 0,
                            4 => 0xFF,
                            5 => b'"' - 1,
                            _ => b'a' + (seed % 26) as u8,
                        }
                    })
                    .collect();
                let three = super::find_near(&hay, [b'"', b'<', b'&']);
                assert_eq!(three, memchr::memchr3(b'"', b'<', b'&', &hay), "{hay:?}");
                let one = super::find_near(&hay, [0u8]);
                assert_eq!(one, memchr::memchr(0, &hay), "{hay:?}");
                let two = super::find_near(&hay, [b'<', 0xFF]);
                assert_eq!(two, memchr::memchr2(b'<', 0xFF, &hay), "{hay:?}");
            }
        }
    }

    /// The kept lists are reused, not reallocated: `recycle` keeps the buffer.
    #[test]
    fn recycle_keeps_the_allocation() {
        let mut v: Vec<Open<'_>> = Vec::with_capacity(8);
        v.push(Open {
            qname: "bml",
            bindings: 0,
        });
        let (ptr, cap) = (v.as_ptr() as usize, v.capacity());
        let w: Vec<Open<'static>> = recycle(v);
        assert!(w.is_empty());
        assert_eq!((w.as_ptr() as usize, w.capacity()), (ptr, cap));
    }

    /// Every event of `src` as a short string, or the error as `!offset message`.
    fn events(src: &str) -> Vec<String> {
        let mut t = Tokenizer::with_lists(src, Lists::default());
        let mut out = Vec::new();
        loop {
            match t.next() {
                Ok(Event::Eof) => return out,
                Ok(Event::Start(tag)) => {
                    let attrs: Vec<String> = t
                        .attrs()
                        .iter()
                        .map(|a| format!("{}={}@{}", a.key, a.raw, a.offset))
                        .collect();
                    let ns = t.resolve(split_qname(tag.qname).0);
                    out.push(format!(
                        "<{}{} {}{:?}@{}",
                        tag.qname,
                        if tag.empty { "/" } else { "" },
                        attrs.join(","),
                        ns,
                        tag.offset
                    ));
                }
                Ok(Event::End { offset, after }) => out.push(format!("/{offset}-{after}")),
                Ok(Event::Text { text, offset }) => out.push(format!("'{text}'@{offset}")),
                Err(e) => {
                    out.push(format!("!{} {}", e.offset, e.message));
                    return out;
                }
            }
        }
    }

    #[test]
    fn tags_attributes_text_and_offsets() {
        assert_eq!(
            events(r#"<a x = "1" y='2'>hi<b/></a>"#),
            [
                "<a x=1@3,y=2@11Ok(None)@0",
                "'hi'@17",
                "<b/ Ok(None)@19",
                "/23-27"
            ]
        );
    }

    #[test]
    fn references_cdata_comments_and_line_ends() {
        assert_eq!(
            events("<?xml version=\"1.0\"?><!DOCTYPE a [<!ENTITY x \">\">]><a>1&lt;2&#x41;&#66;<!-- c --><![CDATA[<&>]]>\r\nz</a>"),
            [
                "<a Ok(None)@51",
                "'1'@54",
                "'<'@55",
                "'2'@59",
                "'A'@60",
                "'B'@66",
                "'<&>'@81",
                "'\nz'@96",
                "/99-103"
            ]
        );
        assert_eq!(unescape("a&amp;b&quot;", 10).unwrap(), "a&b\"");
        assert_eq!(unescape("a&bogus;", 10).unwrap_err().offset, 11);
    }

    #[test]
    fn closing_delimiters_are_found_after_partial_matches() {
        assert_eq!(find(b"a - b -- c --->", b"-->"), Some(12));
        assert_eq!(find(b"x]]]>", b"]]>"), Some(2));
        assert_eq!(find(b"no end -- here", b"-->"), None);
        assert_eq!(find(b"ends with --", b"-->"), None);
        assert_eq!(find(b"", b"?>"), None);
        assert_eq!(events("<a><!-- - -- ---><b/></a>")[1], "<b/ Ok(None)@17");
    }

    #[test]
    fn namespaces_follow_the_element_scope() {
        let ev = events(
            r#"<a xmlns="urn:d" xmlns:p="urn:p"><p:b xmlns:p="urn:q"/><p:c/><d xmlns=""/></a>"#,
        );
        assert_eq!(
            ev[0],
            r#"<a xmlns=urn:d@3,xmlns:p=urn:p@17Ok(Some("urn:d"))@0"#
        );
        assert!(ev[1].ends_with(r#"Ok(Some("urn:q"))@33"#), "{}", ev[1]);
        assert!(ev[2].ends_with(r#"Ok(Some("urn:p"))@55"#), "{}", ev[2]);
        assert!(ev[3].ends_with("Ok(None)@61"), "{}", ev[3]);
        let mut t = Tokenizer::with_lists(r#"<a xmlns:p="urn:p&amp;x"><b/></a>"#, Lists::default());
        t.next().unwrap();
        assert_eq!(t.resolve(Some("p")), Ok(Some("urn:p&x")));
        assert_eq!(t.resolve(Some("q")), Err(()));
        assert_eq!(t.scope(), [("p".to_string(), "urn:p&x".to_string())]);
    }

    #[test]
    fn attribute_values_are_resolved_only_when_they_hold_references() {
        let src = r#"<a x="plain" y='a&amp;b&lt;' z="&quot;" w="'"/>"#;
        let mut t = Tokenizer::with_lists(src, Lists::default());
        assert!(matches!(t.next(), Ok(Event::Start(_))));
        let got: Vec<(&str, bool, String, bool)> = t
            .attrs()
            .iter()
            .map(|a| {
                let v = a.value().unwrap();
                let borrowed = matches!(v, Cow::Borrowed(_));
                (a.key, a.references, v.into_owned(), borrowed)
            })
            .collect();
        assert_eq!(
            got,
            [
                ("x", false, "plain".to_string(), true),
                ("y", true, "a&b<".to_string(), false),
                ("z", true, "\"".to_string(), false),
                ("w", false, "'".to_string(), true),
            ]
        );
        // a bad reference is found when the value is asked for, at its offset
        let mut t = Tokenizer::with_lists("<a x='1&bogus;'/>", Lists::default());
        assert!(matches!(t.next(), Ok(Event::Start(_))));
        assert_eq!(t.attrs()[0].value().unwrap_err().offset, 7);
        // a '<' after a reference, and a value left open after one, are still found
        for (src, offset, words) in [
            ("<a x='&amp;<'/>", 11, "'<' in the value"),
            ("<a x='&amp;", 3, "never closed"),
        ] {
            let last = events(src).pop().unwrap();
            assert!(
                last.starts_with(&format!("!{offset} ")) && last.contains(words),
                "{src}: {last}"
            );
        }
    }

    #[test]
    fn malformed_input_is_reported_where_it_is() {
        for (src, offset, words) in [
            ("<a><b></a>", 6, "does not match the start tag <b>"),
            ("</a>", 0, "without a start tag"),
            ("<a x=1/>", 5, "not in quotes"),
            ("<a x/>", 3, "has no value"),
            ("<a x='1'y='2'/>", 8, "separated by white space"),
            ("<a x='<'/>", 6, "'<' in the value"),
            ("<a x='1", 3, "never closed"),
            ("<a", 0, "never closed"),
            ("<a>&b</a>", 3, "does not start a reference"),
            ("<a>&#1;</a>", 3, "U+0001"),
            ("<a>&#xD800;</a>", 3, "not a valid character reference"),
            ("<a><!-- x</a>", 3, "comment is never closed"),
            ("<1a/>", 0, "not a valid qualified name"),
            ("<p:/x/>", 0, "not a valid qualified name"),
            ("<xmlns:x/>", 0, "reserved"),
            ("<a xmlns:p='1' xmlns:p='2'/>", 15, "appears twice"),
            ("<a xmlns:p=''/>", 3, "cannot undeclare"),
            ("<a x:y:z='1'/>", 3, "not a valid qualified name"),
            ("<a/ >", 2, "not followed by '>'"),
            ("<!x>", 0, "neither a comment"),
        ] {
            let ev = events(src);
            let last = ev.last().unwrap();
            assert!(
                last.starts_with(&format!("!{offset} ")) && last.contains(words),
                "{src}: {last}"
            );
        }
    }
}
