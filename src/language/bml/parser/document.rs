//! The document and its block: the `<bml>` element, its attributes, and each child in
//! turn (behaviours, constraints, extensions); attributes no one reads are kept as foreign.

use super::*;

impl<'i> Parser<'i> {
    /// Reads the document; `out` gets the block when the root is `<bml>` (only partly filled if
    /// a fatal error stops the parse, which the caller discards then).
    pub(super) fn document(&mut self, out: &mut Option<Block>) -> Result<(), Fatal> {
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

    pub(super) fn bool_attr(&mut self, a: &RawAttr<'i>) -> bool {
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
    pub(super) fn block(&mut self, mut el: El<'i>, block: &mut Block) -> Result<(), Fatal> {
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
    pub(super) fn leftover_attrs(
        &mut self,
        attrs: Attrs<'i>,
        on: &dyn fmt::Display,
    ) -> Vec<ForeignAttr> {
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

    pub(super) fn block_child(
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
}
