//! The streaming BML parser (over the XML reader in `xml.rs`): text → [`Block`], with every
//! problem reported as a [`Diagnostic`] at its line:column. Structure, attribute values and sync
//! reference syntax are checked here; cross-references are checked by `validate.rs`.

use std::borrow::Cow;
use std::fmt;

use super::diagnostic::{BmlError, Code, Diagnostic, LineIndex, Pos};
use super::kinds::{BMLT_BEHAVIOURS, CONTROL_BEHAVIOURS, CORE_BEHAVIOURS};
use super::limits::Limits;
use super::model::*;
use super::syncref::{parse_seconds, SyncRef};
use super::xml::{Event, Problem, Reader, Tag, XmlError};
use crate::xmlname::split_qname;

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

    /// Reads the document; `out` gets the block when the root is `<bml>` (only partly filled if
    /// a fatal error stops the parse, which the caller discards then).
    fn document(&mut self, out: &mut Option<Block>) -> Result<(), Fatal> {
        // XML 1.0 forbids most C0 control characters anywhere in a document.
        if let Some(at) = self.forbidden {
            let c = self.src.as_bytes()[at];
            self.error(
                Code::NotXml,
                at,
                format!("character U+{c:04X} is not allowed in XML"),
            );
            return Err(Fatal);
        }
        let root = loop {
            match self.next_markup()? {
                Tok::Start(el) => break el,
                Tok::Text { text, offset } if !text.trim_ascii().is_empty() => {
                    self.error(
                        Code::NotXml,
                        offset,
                        "text before the root element; expected <bml>",
                    );
                    return Err(Fatal);
                }
                Tok::Text { .. } => {}
                Tok::End { offset, .. } => {
                    self.error(Code::NotXml, offset, "end tag without a start tag");
                    return Err(Fatal);
                }
                Tok::Eof => {
                    self.error(
                        Code::NotXml,
                        0,
                        "no XML element found; expected a <bml> block",
                    );
                    return Err(Fatal);
                }
            }
        };
        // the root must be in the BML 1.0 namespace (as the schema says); elements inside it
        // without a prefix are in it too
        if root.name != "bml" || !matches!(root.ns, Ns::Bml) {
            let ns = match root.ns {
                Ns::Bml => String::new(),
                Ns::None => format!(" in no namespace (add xmlns=\"{NS_BML}\")"),
                _ => format!(" in namespace {}", root.ns.uri()),
            };
            self.error(
                Code::WrongRoot,
                root.offset,
                format!(
                    "root element is <{}>{ns}; expected <bml> (BML 1.0 block)",
                    root.qname
                ),
            );
            return Ok(());
        }
        self.block(root, out.insert(Block::default()))?;
        loop {
            match self.next_markup()? {
                Tok::Eof => break,
                Tok::Text { text, offset } if !text.trim_ascii().is_empty() => {
                    self.error(
                        Code::NotXml,
                        offset,
                        "text after the end of the <bml> element",
                    );
                    break;
                }
                Tok::Start(el) => {
                    self.error(
                        Code::NotXml,
                        el.offset,
                        format!(
                            "<{}> after the end of the <bml> element: one block per document",
                            el.qname
                        ),
                    );
                    break;
                }
                _ => {}
            }
        }
        Ok(())
    }

    fn bool_attr(&mut self, a: &RawAttr<'i>) -> bool {
        match a.value.trim_ascii().to_ascii_lowercase().as_str() {
            "true" => true,
            "false" => false,
            _ => {
                self.error(
                    Code::InvalidNumber,
                    a.offset,
                    format!(
                        "attribute '{}' is '{}'; expected true or false",
                        a.name, a.value
                    ),
                );
                false
            }
        }
    }

    /// Reads the `<bml>` element `el` into `block` (a default one).
    fn block(&mut self, mut el: El<'i>, block: &mut Block) -> Result<(), Fatal> {
        block.pos = self.pos(el.offset);
        let mut attrs = Attrs::new(std::mem::take(&mut el.attrs));
        match attrs.take("id") {
            Some(a) if !a.value.trim_ascii().is_empty() => {
                block.id = Id::new(a.value.trim_ascii());
                if block.id.contains(':') {
                    self.error(
                        Code::InvalidId,
                        a.offset,
                        format!(
                            "block id '{}' contains ':', so it cannot be referred to",
                            block.id
                        ),
                    );
                }
            }
            Some(a) => self.error(
                Code::MissingBlockId,
                a.offset,
                "the <bml> block has an empty id",
            ),
            None => self.error(
                Code::MissingBlockId,
                el.offset,
                "the <bml> block has no id attribute; every block needs one",
            ),
        }
        block.character_id = attrs.take("characterId").map(|a| a.value.into_owned());
        let composition = attrs.take("composition");
        let scheduling = attrs.take("scheduling");
        if let (Some(_), Some(s)) = (&composition, &scheduling) {
            self.warn(
                Code::UnknownAttribute,
                s.offset,
                "both composition and its draft alias scheduling are given; scheduling is ignored",
            );
        }
        if let Some(a) = composition.or(scheduling) {
            match Composition::parse(&a.value) {
                Some(c) => block.composition = c,
                None => self.error(
                    Code::UnknownComposition,
                    a.offset,
                    format!(
                        "unknown composition '{}'; expected MERGE, APPEND, REPLACE or APPEND-AFTER(block,...)",
                        a.value
                    ),
                ),
            }
        }
        if let Some(a) = attrs.take_ext(&["preplan"]) {
            block.ext.preplan = self.bool_attr(&a);
        }
        if let Some(a) = attrs.take_ext(&["allowexternalrefs", "allowExternalRefs"]) {
            block.ext.allow_external_refs = self.bool_attr(&a);
        }
        let lists: [(&str, &mut Vec<String>); 6] = [
            ("onStart", &mut block.ext.on_start),
            ("interrupt", &mut block.ext.interrupt),
            ("appendAfter", &mut block.ext.append_after),
            ("chunkAfter", &mut block.ext.chunk_after),
            ("chunkBefore", &mut block.ext.chunk_before),
            ("prependBefore", &mut block.ext.prepend_before),
        ];
        for (name, target) in lists {
            if let Some(a) = attrs.take_ext(&[name]) {
                *target = split_id_list(&a.value);
            }
        }
        block.foreign_attrs = self.leftover_attrs(attrs, &"<bml>");

        // kept as long as the block runs: room for two behaviours to start with (most blocks
        // have one or two), growing as usual after that
        let mut behaviours = Vec::with_capacity(2);
        let mut constraints = Vec::new();
        self.children(&el, |p, child| {
            p.block_child(child, false, &mut behaviours, &mut constraints)
        })?;
        block.behaviours = behaviours;
        block.constraints = constraints;
        Ok(())
    }

    /// Reports leftover attributes: unprefixed ones are errors, extension ones warnings (kept).
    fn leftover_attrs(&mut self, attrs: Attrs<'i>, on: &dyn fmt::Display) -> Vec<ForeignAttr> {
        let mut kept = Vec::new();
        let mut items = attrs.items;
        for a in items.drain(..).flatten() {
            if a.ns == Ns::None {
                self.error(
                    Code::UnknownAttribute,
                    a.offset,
                    format!("attribute '{}' is not defined on {on}", a.name),
                );
            } else {
                self.warn(
                    Code::UnsupportedAttribute,
                    a.offset,
                    format!(
                        "extension attribute '{}' (namespace {}) on {on} is not supported and is ignored",
                        a.name,
                        a.ns.uri()
                    ),
                );
                kept.push(ForeignAttr {
                    ns: a.ns.uri().to_string(),
                    name: a.name.to_owned(),
                    value: a.value.into_owned(),
                });
            }
        }
        kept
    }

    fn block_child(
        &mut self,
        child: El<'i>,
        required: bool,
        behaviours: &mut Vec<Behaviour>,
        constraints: &mut Vec<ConstraintElement>,
    ) -> Result<(), Fatal> {
        if child.ns.is_core() && child.name == "constraint" {
            if let Some(c) = self.constraint(child, required)? {
                constraints.push(c);
            }
        } else if child.ns.is_core() && child.name == "required" {
            if required {
                self.error(
                    Code::UnknownElement,
                    child.offset,
                    "<required> cannot be nested in <required>",
                );
                // what is inside is not read as behaviours (nor recursed into)
                self.skip(&child)?;
                return Ok(());
            }
            for a in child.attrs.iter().flatten() {
                self.error(
                    Code::UnknownAttribute,
                    a.offset,
                    format!("attribute '{}' is not defined on <required>", a.name),
                );
            }
            self.children(&child, |p, c| {
                p.block_child(c, true, behaviours, constraints)
            })?;
        } else if behaviours.len() >= self.limits.behaviours {
            self.error(
                Code::LimitExceeded,
                child.offset,
                format!(
                    "the block has more than {} behaviours (the limit; --max-behaviours)",
                    self.limits.behaviours
                ),
            );
            return Err(Fatal);
        } else {
            self.behaviour(child, required, behaviours)?;
        }
        Ok(())
    }

    fn sync_ref(&mut self, a: &RawAttr<'i>, on: &dyn fmt::Display) -> Option<SyncRef> {
        match SyncRef::parse(&a.value) {
            Ok(r) => {
                let t = match &r {
                    SyncRef::Time(t) | SyncRef::Point { offset: t, .. } => *t,
                };
                if t.abs() > self.limits.time {
                    self.error(
                        Code::LimitExceeded,
                        a.offset,
                        format!(
                            "{on}, attribute {}: {t:e} s is further from the block start than the limit of {} s (--max-time)",
                            a.name, self.limits.time
                        ),
                    );
                    return None;
                }
                Some(r)
            }
            Err(e) => {
                self.error(
                    e.code,
                    a.offset,
                    format!("{on}, attribute {}: {}", a.name, e.message),
                );
                None
            }
        }
    }

    /// A `<constraint>` element: its `<synchronize>`, `<before>` and `<after>` items. `None` if
    /// anything in it is wrong (every problem is reported).
    fn constraint(
        &mut self,
        mut el: El<'i>,
        required: bool,
    ) -> Result<Option<ConstraintElement>, Fatal> {
        let mut attrs = Attrs::new(std::mem::take(&mut el.attrs));
        let id = attrs.take("id").map(|a| a.value.into_owned());
        let _ = self.leftover_attrs(attrs, &"<constraint>");
        let mut items = Vec::new();
        let mut ok = true;
        self.children(&el, |p, mut item| {
            items.extend(p.constraint_item(&mut item, &mut ok)?);
            Ok(())
        })?;
        if ok && items.is_empty() {
            self.error(
                Code::InvalidConstraint,
                el.offset,
                "<constraint> is empty; it needs <synchronize>, <before> or <after>",
            );
            ok = false;
        }
        Ok(ok.then(|| ConstraintElement {
            id,
            items,
            required,
            pos: self.pos(el.offset),
        }))
    }

    /// One item of a constraint: `<synchronize ref?>`, `<before ref>` or `<after ref>` with its
    /// `<sync ref>` children. Clears `ok` on any problem.
    fn constraint_item(
        &mut self,
        item: &mut El<'i>,
        ok: &mut bool,
    ) -> Result<Option<ConstraintItem>, Fatal> {
        let kind = match (item.ns.is_core(), item.name) {
            (true, k @ ("synchronize" | "before" | "after")) => k,
            _ => {
                self.error(
                    Code::UnknownElement,
                    item.offset,
                    format!("<{}> is not allowed in <constraint>; expected <synchronize>, <before> or <after>", item.qname),
                );
                self.skip(item)?;
                *ok = false;
                return Ok(None);
            }
        };
        let on = format!("<{kind}>");
        let mut attrs = Attrs::new(std::mem::take(&mut item.attrs));
        let reference = match attrs.take("ref") {
            Some(a) => {
                let r = self.sync_ref(&a, &on);
                *ok &= r.is_some();
                r
            }
            None if kind == "synchronize" => None,
            None => {
                self.error(
                    Code::MissingAttribute,
                    item.offset,
                    format!("{on} needs a ref attribute"),
                );
                *ok = false;
                None
            }
        };
        let _ = self.leftover_attrs(attrs, &on);
        let mut syncs = Vec::new();
        self.children(item, |p, mut s| {
            syncs.extend(p.constraint_sync(&mut s, &on, ok)?);
            Ok(())
        })?;
        let pos = self.pos(item.offset);
        let needed = if reference.is_some() { 1 } else { 2 };
        if *ok && syncs.len() < needed {
            self.error(
                Code::InvalidConstraint,
                item.offset,
                format!(
                    "{on} relates nothing: it needs {} <sync ref> child{}",
                    needed,
                    if needed == 1 { "" } else { "ren" }
                ),
            );
            *ok = false;
        }
        Ok(match (kind, reference) {
            ("before", Some(reference)) => Some(ConstraintItem::Before {
                reference,
                syncs,
                pos,
            }),
            ("after", Some(reference)) => Some(ConstraintItem::After {
                reference,
                syncs,
                pos,
            }),
            ("synchronize", reference) => Some(ConstraintItem::Synchronize {
                reference,
                syncs,
                pos,
            }),
            _ => None, // missing ref: already reported
        })
    }

    /// A `<sync ref>` child of a constraint item (`on`). Clears `ok` on any problem.
    fn constraint_sync(
        &mut self,
        s: &mut El<'i>,
        on: &str,
        ok: &mut bool,
    ) -> Result<Option<ConstraintSync>, Fatal> {
        if !(s.ns.is_core() && s.name == "sync") {
            self.error(
                Code::UnknownElement,
                s.offset,
                format!("<{}> is not allowed in {on}; expected <sync ref>", s.qname),
            );
            *ok = false;
            self.skip(s)?;
            return Ok(None);
        }
        let mut attrs = Attrs::new(std::mem::take(&mut s.attrs));
        let mut sync = None;
        match attrs.take("ref") {
            Some(a) => match self.sync_ref(&a, &"<sync>") {
                Some(r) => {
                    sync = Some(ConstraintSync {
                        reference: r,
                        pos: self.pos(s.offset),
                    })
                }
                None => *ok = false,
            },
            None => {
                self.error(
                    Code::MissingAttribute,
                    s.offset,
                    "<sync> needs a ref attribute",
                );
                *ok = false;
            }
        }
        let _ = self.leftover_attrs(attrs, &"<sync>");
        self.skip(s)?;
        Ok(sync)
    }

    /// A behaviour's `id`: present, not empty, without ':'.
    fn behaviour_id(&mut self, attrs: &mut Attrs<'i>, el: &El<'i>) -> Option<Id> {
        match attrs.take("id") {
            Some(a) if !a.value.trim_ascii().is_empty() => {
                let id = Id::new(a.value.trim_ascii());
                if id.contains(':') {
                    self.error(
                        Code::InvalidId,
                        a.offset,
                        format!("behaviour id '{id}' contains ':', so it cannot be referred to"),
                    );
                }
                Some(id)
            }
            _ => {
                self.error(
                    Code::MissingId,
                    el.offset,
                    format!(
                        "<{}> has no id attribute; every behaviour needs one",
                        el.qname
                    ),
                );
                None
            }
        }
    }

    /// A behaviour of a namespace this parser does not know: kept as written (its attributes and
    /// content), with a warning that nothing realizes it.
    fn extension_behaviour(
        &mut self,
        el: &El<'i>,
        mut attrs: Attrs<'i>,
        on: &On<'_>,
    ) -> Result<(BehaviourKind, Vec<SyncAttr>), Fatal> {
        self.warn(
            Code::UnsupportedExtension,
            el.offset,
            format!("unsupported extension behaviour {on} (namespace {}); it is kept but will not be realized", el.ns.uri()),
        );
        let syncs = self.sync_attrs(&mut attrs, super::kinds::ALL_STANDARD_SYNCS, on);
        let scope = self.scope();
        let Skipped {
            content, prefixes, ..
        } = self.skip(el)?;
        let namespaces = used_prefixes(scope, &prefixes, &[]);
        let kind = BehaviourKind::Unknown(UnknownBehaviour {
            ns: el.ns.uri().to_string(),
            name: el.name.to_string(),
            attrs: attrs
                .rest()
                .map(|a| ForeignAttr {
                    ns: a.ns.uri().to_string(),
                    name: a.name.to_owned(),
                    value: a.value.into_owned(),
                })
                .collect(),
            content,
            namespaces,
        });
        Ok((kind, syncs))
    }

    /// Reads a behaviour element into `out` (nothing is added for one that cannot be kept; the
    /// behaviour is built in its place in the list, not copied up a return value).
    fn behaviour(
        &mut self,
        mut el: El<'i>,
        required: bool,
        out: &mut Vec<Behaviour>,
    ) -> Result<(), Fatal> {
        let core = el.ns.is_core();
        let name = el.name;
        let known = (core && CORE_BEHAVIOURS.contains(&name))
            || (el.ns == Ns::CoreExt && name == "faceFacs")
            || (el.ns.is_ext() && CONTROL_BEHAVIOURS.contains(&name))
            || (el.ns == Ns::Bmlt && BMLT_BEHAVIOURS.contains(&name));
        if !known && core {
            self.error(
                Code::UnknownElement,
                el.offset,
                format!("<{}> is not a BML 1.0 behaviour or block element", el.qname),
            );
            self.skip(&el)?;
            return Ok(());
        }
        let mut attrs = Attrs::new(std::mem::take(&mut el.attrs));
        let id = self.behaviour_id(&mut attrs, &el);
        let qname = el.qname;
        let on = On {
            qname,
            id: id.as_deref(),
        };
        let (kind, syncs, descriptions, foreign_attrs) = if !known {
            let (kind, syncs) = self.extension_behaviour(&el, attrs, &on)?;
            (kind, syncs, Vec::new(), Vec::new())
        } else {
            let mut kb = KindBuilder::new(self, &mut attrs, &on, &el);
            let kind = kb.build();
            let Some(mut kind) = kind else {
                self.skip(&el)?;
                return Ok(());
            };
            let syncs = self.sync_attrs(&mut attrs, kind.standard_syncs(), &on);
            let foreign_attrs = self.leftover_attrs(attrs, &on);
            let descriptions = self.behaviour_children(&el, &mut kind, &on)?;
            (kind, syncs, descriptions, foreign_attrs)
        };
        if let Some(id) = id {
            out.push(Behaviour {
                id,
                kind,
                syncs,
                required,
                descriptions,
                foreign_attrs,
                pos: self.pos(el.offset),
            });
        }
        Ok(())
    }

    fn sync_attrs(
        &mut self,
        attrs: &mut Attrs<'i>,
        names: &[&'static str],
        on: &dyn fmt::Display,
    ) -> Vec<SyncAttr> {
        let sync_name = |a: &RawAttr| {
            (a.ns == Ns::None)
                .then(|| names.iter().find(|n| **n == a.name).copied())
                .flatten()
        };
        // in document order; the list is kept with the behaviour, so it gets its exact size
        // (each attribute's name is looked up once: where the sync attributes are is noted)
        let mut found: smallvec::SmallVec<[(usize, &'static str); 8]> = smallvec::SmallVec::new();
        for (i, slot) in attrs.items.iter().enumerate() {
            if let Some(name) = slot.as_ref().and_then(sync_name) {
                found.push((i, name));
            }
        }
        let mut out = Vec::with_capacity(found.len());
        for &(i, name) in &found {
            let Some(a) = attrs.items[i].take() else {
                continue;
            };
            if let Some(value) = self.sync_ref(&a, on) {
                out.push(SyncAttr {
                    sync: name,
                    value,
                    pos: self.pos(a.offset),
                });
            }
        }
        out
    }

    /// A `<lexeme lexeme amount>` child of `<face>` or `<faceShift>` (the BML 1.0 standard's
    /// child form): its values go into `kind`, unless the behaviour has a lexeme already.
    fn face_lexeme_child(
        &mut self,
        c: &mut El<'i>,
        kind: &mut BehaviourKind,
        on: &dyn fmt::Display,
    ) -> Result<(), Fatal> {
        let mut attrs = Attrs::new(std::mem::take(&mut c.attrs));
        let lexeme = self.req_str(&mut attrs, "lexeme", &"<lexeme>", c.offset);
        let amount = self.opt_f64(&mut attrs, "amount");
        let _ = self.leftover_attrs(attrs, &"<lexeme>");
        let taken = match kind {
            BehaviourKind::Face(f) if f.lexeme.is_none() && f.au.is_none() => {
                f.lexeme = lexeme;
                f.amount = amount.or(f.amount);
                true
            }
            BehaviourKind::FaceShift(f) if f.lexeme.is_empty() => {
                f.lexeme = lexeme.unwrap_or_default();
                f.amount = amount.or(f.amount);
                true
            }
            _ => false,
        };
        if !taken {
            self.error(
                Code::UnknownElement,
                c.offset,
                format!("{on} has its lexeme already; a <lexeme> child is one too many"),
            );
        }
        self.skip(c)?;
        Ok(())
    }

    /// Reads the children of a known behaviour into `kind`; returns its descriptions.
    /// The children of behaviour element `el` (already read as `kind`): descriptions (returned),
    /// and the children each kind has (`<text>`, `<stance>` and `<pose>`, `<lexeme>`,
    /// `<trajectory>`, `<parameter>`, animation content). One arm per child; each reads itself.
    fn behaviour_children(
        &mut self,
        el: &El<'i>,
        kind: &mut BehaviourKind,
        on: &dyn fmt::Display,
    ) -> Result<Vec<Description>, Fatal> {
        let mut descriptions = Vec::new();
        let mut seen = Seen::default();
        self.children(el, |p, mut c| {
            let core = c.ns.is_core();
            match (&mut *kind, c.name) {
                (_, "description") if core => descriptions.push(p.description_child(&mut c, on)?),
                (BehaviourKind::Speech(s) | BehaviourKind::Text(s), "text")
                    if core || c.ns == Ns::Bmlt =>
                {
                    p.only_one(&mut seen.text, &c, "text", on);
                    for a in c.attrs.iter().flatten() {
                        p.error(
                            Code::UnknownAttribute,
                            a.offset,
                            format!("attribute '{}' is not defined on <text>", a.name),
                        );
                    }
                    p.speech_text(&c, &mut s.text)?;
                }
                (BehaviourKind::Posture(post) | BehaviourKind::PostureShift(post), "stance")
                    if core =>
                {
                    p.only_one(&mut seen.stance, &c, "stance", on);
                    p.stance_child(&mut c, post)?;
                }
                (BehaviourKind::Posture(post) | BehaviourKind::PostureShift(post), "pose")
                    if core =>
                {
                    p.pose_child(&mut c, post)?;
                }
                (BehaviourKind::Face(_) | BehaviourKind::FaceShift(_), "lexeme") if core => {
                    p.face_lexeme_child(&mut c, kind, on)?;
                }
                (BehaviourKind::ParameterValueChange(pvc), "trajectory")
                    if c.ns.is_ext() || c.ns == Ns::None =>
                {
                    p.only_one(&mut seen.trajectory, &c, "trajectory", on);
                    p.trajectory_child(&mut c, pvc)?;
                }
                (
                    BehaviourKind::ProcAnimation(Animation { params, .. })
                    | BehaviourKind::ProcAnimationGesture(Animation { params, .. })
                    | BehaviourKind::Keyframe(Animation { params, .. })
                    | BehaviourKind::Controller(Controller { params, .. })
                    | BehaviourKind::Noise(Noise { params, .. })
                    | BehaviourKind::Transition(Transition { params, .. }),
                    "parameter",
                ) if c.ns == Ns::Bmlt || c.ns == Ns::None => p.parameter_child(&mut c, params)?,
                (
                    BehaviourKind::ProcAnimation(a)
                    | BehaviourKind::ProcAnimationGesture(a)
                    | BehaviourKind::Keyframe(a),
                    _,
                ) => p.animation_content(&c, a)?,
                _ => p.unknown_child(&c, core, on)?,
            }
            Ok(())
        })?;
        self.missing_children(el, kind, &seen, on);
        Ok(descriptions)
    }

    /// Reports a second `<name>` child where only one is allowed.
    fn only_one(&mut self, seen: &mut bool, c: &El<'i>, name: &str, on: &dyn fmt::Display) {
        if *seen {
            self.error(
                Code::UnknownElement,
                c.offset,
                format!("{on} has more than one <{name}>"),
            );
        }
        *seen = true;
    }

    /// A `<description priority type>` child: kept as written, with the namespaces it uses.
    fn description_child(
        &mut self,
        c: &mut El<'i>,
        on: &dyn fmt::Display,
    ) -> Result<Description, Fatal> {
        let mut attrs = Attrs::new(std::mem::take(&mut c.attrs));
        let priority =
            attrs
                .take("priority")
                .and_then(|a| match a.value.trim_ascii().parse::<i64>() {
                    Ok(v) => Some(v),
                    Err(_) => {
                        self.error(
                            Code::InvalidNumber,
                            a.offset,
                            format!("description priority '{}' is not an integer", a.value),
                        );
                        None
                    }
                });
        let kind_attr = attrs.take("type");
        if kind_attr.is_none() {
            self.error(
                Code::MissingAttribute,
                c.offset,
                format!("<description> in {on} needs a type attribute"),
            );
        }
        let _ = self.leftover_attrs(attrs, &"<description>");
        let scope = self.scope();
        let Skipped {
            content, prefixes, ..
        } = self.skip(c)?;
        Ok(Description {
            priority,
            kind: kind_attr.map(|a| a.value.into_owned()).unwrap_or_default(),
            namespaces: used_prefixes(scope, &prefixes, &[]),
            content,
            pos: self.pos(c.offset),
        })
    }

    /// A posture's `<stance type>`.
    fn stance_child(&mut self, c: &mut El<'i>, post: &mut Posture) -> Result<(), Fatal> {
        let mut attrs = Attrs::new(std::mem::take(&mut c.attrs));
        if let Some(t) = self.req_enum(
            &mut attrs,
            "type",
            &"<stance>",
            c.offset,
            StanceType::parse,
            StanceType::expected,
        ) {
            post.stance = t;
        }
        let _ = self.leftover_attrs(attrs, &"<stance>");
        self.skip(c)?;
        Ok(())
    }

    /// A posture's `<pose part lexeme>`.
    fn pose_child(&mut self, c: &mut El<'i>, post: &mut Posture) -> Result<(), Fatal> {
        let mut attrs = Attrs::new(std::mem::take(&mut c.attrs));
        let part = self.req_enum(
            &mut attrs,
            "part",
            &"<pose>",
            c.offset,
            PosePart::parse,
            PosePart::expected,
        );
        let lexeme = self.req_str(&mut attrs, "lexeme", &"<pose>", c.offset);
        let _ = self.leftover_attrs(attrs, &"<pose>");
        if let (Some(part), Some(lexeme)) = (part, lexeme) {
            post.poses.push(Pose { part, lexeme });
        }
        self.skip(c)?;
        Ok(())
    }

    /// A parameter value change's `<trajectory type initialValue targetValue>`.
    fn trajectory_child(
        &mut self,
        c: &mut El<'i>,
        pvc: &mut ParameterValueChange,
    ) -> Result<(), Fatal> {
        let mut attrs = Attrs::new(std::mem::take(&mut c.attrs));
        let t = self.req_enum(
            &mut attrs,
            "type",
            &"<trajectory>",
            c.offset,
            TrajectoryType::parse,
            TrajectoryType::expected,
        );
        let initial = self.opt_f64(&mut attrs, "initialValue");
        let target = self.req_str(&mut attrs, "targetValue", &"<trajectory>", c.offset);
        let _ = self.leftover_attrs(attrs, &"<trajectory>");
        if let Some(t) = t {
            pvc.trajectory.kind = t;
        }
        pvc.trajectory.initial_value = initial;
        if let Some(v) = target {
            match parse_seconds(&v) {
                Some(v) => pvc.trajectory.target_value = v,
                None => self.error(
                    Code::InvalidNumber,
                    c.offset,
                    format!("<trajectory> targetValue '{v}' is not a number"),
                ),
            }
        }
        self.skip(c)?;
        Ok(())
    }

    /// A `<parameter name value>` of an animation, controller, noise or transition.
    fn parameter_child(&mut self, c: &mut El<'i>, params: &mut Vec<Param>) -> Result<(), Fatal> {
        let mut attrs = Attrs::new(std::mem::take(&mut c.attrs));
        let name = self.req_str(&mut attrs, "name", &"<parameter>", c.offset);
        let value = self.req_str(&mut attrs, "value", &"<parameter>", c.offset);
        let _ = self.leftover_attrs(attrs, &"<parameter>");
        if let (Some(name), Some(value)) = (name, value) {
            params.push(Param { name, value });
        }
        self.skip(c)?;
        Ok(())
    }

    /// Any other child of an animation: kept as raw content with the namespaces it uses.
    fn animation_content(&mut self, c: &El<'i>, a: &mut Animation) -> Result<(), Fatal> {
        let scope = self.scope();
        let Skipped {
            after,
            mut prefixes,
            ..
        } = self.skip(c)?;
        prefixes.extend(c.prefixes.iter().cloned());
        a.content.push_str(&self.src[c.offset..after]);
        a.namespaces = used_prefixes(scope, &prefixes, &a.namespaces);
        Ok(())
    }

    /// A child the behaviour does not have: an error in the core namespaces, a warning for an
    /// extension; skipped either way.
    fn unknown_child(
        &mut self,
        c: &El<'i>,
        core: bool,
        on: &dyn fmt::Display,
    ) -> Result<(), Fatal> {
        if core {
            self.error(
                Code::UnknownElement,
                c.offset,
                format!("<{}> is not allowed in {on}", c.qname),
            );
        } else {
            self.warn(
                Code::UnsupportedExtension,
                c.offset,
                format!(
                    "extension element <{}> in {on} is not supported and is ignored",
                    c.qname
                ),
            );
        }
        self.skip(c)?;
        Ok(())
    }

    /// Reports the children `kind` needs and did not get.
    fn missing_children(
        &mut self,
        el: &El<'i>,
        kind: &BehaviourKind,
        seen: &Seen,
        on: &dyn fmt::Display,
    ) {
        match kind {
            BehaviourKind::Speech(_) | BehaviourKind::Text(_) if !seen.text => {
                self.error(
                    Code::MissingElement,
                    el.offset,
                    format!("{on} has no <text> child"),
                );
            }
            BehaviourKind::Posture(_) | BehaviourKind::PostureShift(_) if !seen.stance => {
                self.error(
                    Code::MissingElement,
                    el.offset,
                    format!("{on} has no <stance> child"),
                );
            }
            BehaviourKind::Face(Face {
                lexeme: None,
                au: None,
                ..
            }) => self.error(
                Code::MissingAttribute,
                el.offset,
                format!("{on} needs a lexeme or an au attribute, or a <lexeme> child"),
            ),
            BehaviourKind::FaceShift(f) if f.lexeme.is_empty() => self.error(
                Code::MissingAttribute,
                el.offset,
                format!("{on} needs a lexeme attribute or a <lexeme> child"),
            ),
            BehaviourKind::ParameterValueChange(_) if !seen.trajectory => {
                self.error(
                    Code::MissingElement,
                    el.offset,
                    format!("{on} has no <trajectory> child"),
                );
            }
            _ => {}
        }
    }

    fn speech_text(&mut self, el: &El<'i>, out: &mut Vec<TextPart>) -> Result<(), Fatal> {
        if el.empty {
            return Ok(());
        }
        loop {
            match self.next()? {
                Tok::Text { text, .. } => match out.last_mut() {
                    Some(TextPart::Text(t)) => t.push_str(&text),
                    _ => {
                        // the parts are kept with the block: most texts are one part (the
                        // token after it, parked, ends the text); one with syncs has three or
                        // more, and gets room for them at once (no reallocation). Two calls
                        // with constants: a computed amount takes the general, slower path.
                        if out.capacity() == 0 {
                            if matches!(self.pending, Some(Tok::Start(_))) {
                                out.reserve_exact(4);
                            } else {
                                out.reserve_exact(1);
                            }
                        }
                        out.push(TextPart::Text(text.into_owned()))
                    }
                },
                Tok::Start(mut c) => {
                    if c.ns.is_core() && c.name == "sync" {
                        let mut attrs = Attrs::new(std::mem::take(&mut c.attrs));
                        match attrs.take("id") {
                            Some(a) if !a.value.trim_ascii().is_empty() => {
                                out.push(TextPart::Sync(Id::new(a.value.trim_ascii())))
                            }
                            _ => self.error(
                                Code::MissingId,
                                c.offset,
                                "<sync> in speech text has no id",
                            ),
                        }
                        let _ = self.leftover_attrs(attrs, &"<sync>");
                    } else if c.ns.is_core() {
                        self.error(
                            Code::UnknownElement,
                            c.offset,
                            format!(
                                "<{}> is not allowed in speech <text>; only <sync id> is",
                                c.qname
                            ),
                        );
                    } else {
                        self.warn(Code::UnsupportedExtension, c.offset, format!("extension element <{}> in speech text is not supported and is ignored", c.qname));
                    }
                    self.skip(&c)?;
                }
                Tok::End { .. } => return Ok(()),
                Tok::Eof => return Err(self.unexpected_eof(el)),
            }
        }
    }

    fn req_str(
        &mut self,
        attrs: &mut Attrs<'i>,
        name: &str,
        on: &dyn fmt::Display,
        at: usize,
    ) -> Option<String> {
        match attrs.take(name) {
            Some(a) => Some(a.value.into_owned()),
            None => {
                self.error(
                    Code::MissingAttribute,
                    at,
                    format!("{on} needs a {name} attribute"),
                );
                None
            }
        }
    }

    fn opt_f64(&mut self, attrs: &mut Attrs<'i>, name: &str) -> Option<f64> {
        let a = attrs.take(name)?;
        let v = parse_seconds(&a.value);
        if v.is_none() {
            self.error(
                Code::InvalidNumber,
                a.offset,
                format!("attribute '{name}' is '{}'; expected a number", a.value),
            );
        }
        v
    }

    /// An integer attribute from 0 to `max`: above it, a `limit-exceeded` error.
    fn opt_u32(&mut self, attrs: &mut Attrs<'i>, name: &str, max: u32) -> Option<u32> {
        let a = attrs.take(name)?;
        let v = a.value.trim_ascii().parse::<u32>().ok();
        match v {
            None => self.error(
                Code::InvalidNumber,
                a.offset,
                format!(
                    "attribute '{name}' is '{}'; expected a non-negative integer",
                    a.value
                ),
            ),
            Some(n) if n > max => {
                self.error(
                    Code::LimitExceeded,
                    a.offset,
                    format!("attribute '{name}' is {n}, more than the limit of {max}"),
                );
                return None;
            }
            Some(_) => {}
        }
        v
    }

    fn opt_enum<T>(
        &mut self,
        attrs: &mut Attrs<'i>,
        name: &str,
        on: &dyn fmt::Display,
        parse: fn(&str) -> Option<T>,
        expected: fn() -> String,
    ) -> Option<T> {
        let a = attrs.take(name)?;
        let v = parse(a.value.trim_ascii());
        if v.is_none() {
            self.error(
                Code::InvalidEnumValue,
                a.offset,
                format!(
                    "{on}: {name}=\"{}\" is not valid; expected one of {}",
                    a.value,
                    expected()
                ),
            );
        }
        v
    }

    #[allow(clippy::too_many_arguments)]
    fn req_enum<T>(
        &mut self,
        attrs: &mut Attrs<'i>,
        name: &str,
        on: &dyn fmt::Display,
        at: usize,
        parse: fn(&str) -> Option<T>,
        expected: fn() -> String,
    ) -> Option<T> {
        if attrs
            .items
            .iter()
            .flatten()
            .all(|a| !(a.ns == Ns::None && a.name == name))
        {
            self.error(
                Code::MissingAttribute,
                at,
                format!("{on} needs a {name} attribute (one of {})", expected()),
            );
            return None;
        }
        self.opt_enum(attrs, name, on, parse, expected)
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

/// Builds the kind-specific part of a known behaviour from its attributes.
struct KindBuilder<'a, 'i> {
    p: &'a mut Parser<'i>,
    attrs: &'a mut Attrs<'i>,
    on: &'a dyn fmt::Display,
    el: &'a El<'i>,
}

impl<'a, 'i> KindBuilder<'a, 'i> {
    fn new(
        p: &'a mut Parser<'i>,
        attrs: &'a mut Attrs<'i>,
        on: &'a dyn fmt::Display,
        el: &'a El<'i>,
    ) -> Self {
        KindBuilder { p, attrs, on, el }
    }

    fn req(&mut self, name: &str) -> Option<String> {
        self.p.req_str(self.attrs, name, self.on, self.el.offset)
    }
    fn opt(&mut self, name: &str) -> Option<String> {
        self.attrs.take(name).map(|a| a.value.into_owned())
    }
    fn f64(&mut self, name: &str) -> Option<f64> {
        self.p.opt_f64(self.attrs, name)
    }
    fn u32(&mut self, name: &str) -> Option<u32> {
        self.p.opt_u32(self.attrs, name, u32::MAX)
    }
    fn mode(&mut self) -> Option<Mode> {
        self.p
            .opt_enum(self.attrs, "mode", self.on, Mode::parse, Mode::expected)
    }
    fn list(&mut self, name: &str) -> Vec<String> {
        self.opt(name)
            .map(|v| split_id_list(&v))
            .unwrap_or_default()
    }
    fn gaze(&mut self) -> Option<Gaze> {
        let target = self.req("target");
        let influence = self.p.opt_enum(
            self.attrs,
            "influence",
            self.on,
            Influence::parse,
            Influence::expected,
        );
        let offset_angle = self.f64("offsetAngle");
        let offset_direction = self.p.opt_enum(
            self.attrs,
            "offsetDirection",
            self.on,
            OffsetDirection::parse,
            OffsetDirection::expected,
        );
        Some(Gaze {
            target: target?,
            influence,
            offset_angle,
            offset_direction,
        })
    }
    fn face_lexeme(&mut self) -> Option<FaceLexeme> {
        let lexeme = self.req("lexeme");
        let amount = self.f64("amount");
        Some(FaceLexeme {
            lexeme: lexeme?,
            amount,
        })
    }
    fn animation(&mut self) -> Animation {
        let name = self.opt("name");
        let file_name = self.opt("fileName").or_else(|| self.opt("filename"));
        Animation {
            name,
            file_name,
            ..Animation::default()
        }
    }

    /// The behaviour kind of the element being read, from its attributes. Long on purpose: one
    /// arm per BML element, each a few lines, so the whole attribute grammar reads as one table
    /// (and beside `Writer::kind_attrs`, which writes it back).
    fn build(&mut self) -> Option<BehaviourKind> {
        let placeholder_posture = || Posture {
            stance: StanceType::Standing,
            poses: Vec::new(),
        };
        Some(match self.el.name {
            "speech" => BehaviourKind::Speech(Speech::default()),
            "text" => BehaviourKind::Text(Speech::default()),
            "gesture" => {
                let lexeme = self.req("lexeme");
                let mode = self.mode();
                BehaviourKind::Gesture(Gesture {
                    lexeme: lexeme?,
                    mode,
                })
            }
            "pointing" => {
                let target = self.req("target");
                let mode = self.mode();
                BehaviourKind::Pointing(Pointing {
                    target: target?,
                    mode,
                })
            }
            "head" => {
                let lexeme = self.req("lexeme");
                let repetition = self
                    .p
                    .opt_u32(self.attrs, "repetition", super::MAX_REPETITION);
                let amount = self.f64("amount");
                BehaviourKind::Head(Head {
                    lexeme: lexeme?,
                    repetition,
                    amount,
                })
            }
            "headDirectionShift" => BehaviourKind::HeadDirectionShift {
                target: self.req("target")?,
            },
            "gaze" => BehaviourKind::Gaze(self.gaze()?),
            "gazeShift" => BehaviourKind::GazeShift(self.gaze()?),
            "face" => {
                let lexeme = self.opt("lexeme");
                let au = self.u32("au");
                let side =
                    self.p
                        .opt_enum(self.attrs, "side", self.on, Side::parse, Side::expected);
                let amount = self.f64("amount");
                // without lexeme and au, a <lexeme> child must give them (checked after it)
                BehaviourKind::Face(Face {
                    lexeme,
                    au,
                    side,
                    amount,
                })
            }
            "faceLexeme" => BehaviourKind::FaceLexeme(self.face_lexeme()?),
            // the lexeme may come from a <lexeme> child instead (checked after the children)
            "faceShift" => BehaviourKind::FaceShift(FaceLexeme {
                lexeme: self.opt("lexeme").unwrap_or_default(),
                amount: self.f64("amount"),
            }),
            "faceFacs" => {
                let au = match self
                    .attrs
                    .items
                    .iter()
                    .flatten()
                    .any(|a| a.ns == Ns::None && a.name == "au")
                {
                    true => self.u32("au"),
                    false => {
                        self.req("au");
                        None
                    }
                };
                let side =
                    self.p
                        .opt_enum(self.attrs, "side", self.on, Side::parse, Side::expected);
                let amount = self.f64("amount");
                BehaviourKind::FaceFacs(FaceFacs {
                    au: au?,
                    side,
                    amount,
                })
            }
            "posture" => BehaviourKind::Posture(placeholder_posture()),
            "postureShift" => BehaviourKind::PostureShift(placeholder_posture()),
            "locomotion" => {
                let target = self.req("target");
                let manner = self.opt("manner");
                BehaviourKind::Locomotion(Locomotion {
                    target: target?,
                    manner,
                })
            }
            "wait" => BehaviourKind::Wait(Wait {
                max_wait: self.f64("max-wait"),
            }),
            "interrupt" => {
                let target = self.req("target");
                let include = self.list("include");
                let exclude = self.list("exclude");
                BehaviourKind::Interrupt(Interrupt {
                    target: target?,
                    include,
                    exclude,
                })
            }
            "activate" => BehaviourKind::Activate(Activate {
                target: self.req("target")?,
            }),
            "parametervaluechange" => {
                let target = self.req("target");
                let param_id = self.req("paramId");
                let target = target?;
                let (target_block, target_behaviour) = match target.split_once(':') {
                    Some((b, beh)) => (
                        Some(b.trim_ascii().to_string()),
                        beh.trim_ascii().to_string(),
                    ),
                    None => (None, target.trim_ascii().to_string()),
                };
                BehaviourKind::ParameterValueChange(ParameterValueChange {
                    target_block,
                    target_behaviour,
                    param_id: param_id?,
                    trajectory: Trajectory {
                        kind: TrajectoryType::Linear,
                        initial_value: None,
                        target_value: 0.0,
                    },
                })
            }
            "procanimation" => BehaviourKind::ProcAnimation(self.animation()),
            "procanimationgesture" => BehaviourKind::ProcAnimationGesture(self.animation()),
            "keyframe" => BehaviourKind::Keyframe(self.animation()),
            "controller" => {
                let class = self.req("class");
                let name = self.opt("name");
                BehaviourKind::Controller(Controller {
                    class: class?,
                    name,
                    params: Vec::new(),
                })
            }
            "audiofile" => {
                let file = self.opt("fileName").or_else(|| self.opt("filename"));
                match file {
                    Some(file_name) => BehaviourKind::AudioFile { file_name },
                    None => {
                        self.req("fileName");
                        return None;
                    }
                }
            }
            "noise" => {
                let joint = self.req("joint");
                let kind = self.req("type");
                BehaviourKind::Noise(Noise {
                    joint: joint?,
                    kind: kind?,
                    params: Vec::new(),
                })
            }
            "facemorph" => {
                let target_name = self.req("targetname");
                let intensity = self.f64("intensity");
                BehaviourKind::FaceMorph(FaceMorph {
                    target_name: target_name?,
                    intensity,
                })
            }
            "transition" => BehaviourKind::Transition(Transition {
                class: self.req("class")?,
                params: Vec::new(),
            }),
            _ => return None,
        })
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
