//! The BML writer: [`Block`] → BML 1.0 XML text, such that parsing the text gives the block back.

use std::fmt::Write as _;

use super::model::*;
use super::syncref::fmt_seconds;

/// Fixed prefixes for namespaces the writer knows.
const KNOWN_PREFIXES: &[(&str, &str)] = &[
    ("bmla", NS_BMLA),
    ("bmlt", NS_BMLT),
    ("bmlce", NS_CORE_EXT),
    ("bmlis", "http://www.asap-project.org/bmlis"),
];

/// The `xml:` namespace, bound by definition and never declared.
const XML_NS: &str = "http://www.w3.org/XML/1998/namespace";

struct Writer {
    out: String,
    prefixes: Vec<(String, String)>, // (prefix, uri)
}

/// Writes a block as BML 1.0 XML (one behaviour per line).
pub fn write(block: &Block) -> String {
    let mut w = Writer {
        out: String::with_capacity(256 + 128 * block.behaviours.len()),
        prefixes: KNOWN_PREFIXES
            .iter()
            .map(|(p, u)| (p.to_string(), u.to_string()))
            .collect(),
    };
    w.collect_namespaces(block);
    w.block(block);
    w.out
}

/// Declares the namespaces raw content relies on, on the element that wraps it.
fn xmlns(out: &mut String, namespaces: &[(String, String)]) {
    for (p, u) in namespaces {
        let _ = write!(out, " xmlns:{p}=\"{}\"", namespace_name(u));
    }
}

/// A namespace name for a declaration: as it is (the parser accepts no namespace name with a
/// reference, and none it accepts needs one inside double quotes), escaped only if it holds
/// what a double-quoted value cannot (a block built in code may).
fn namespace_name(u: &str) -> std::borrow::Cow<'_, str> {
    if u.contains(['&', '<', '"']) {
        escape(u)
    } else {
        u.into()
    }
}

fn num(v: f64) -> String {
    let mut s = String::new();
    let _ = fmt_seconds(&mut s, v);
    s
}

impl Writer {
    fn collect_namespaces(&mut self, block: &Block) {
        let mut uris: Vec<&str> = block.foreign_attrs.iter().map(|a| a.ns.as_str()).collect();
        for b in &block.behaviours {
            uris.extend(b.foreign_attrs.iter().map(|a| a.ns.as_str()));
            if let BehaviourKind::Unknown(u) = &b.kind {
                uris.extend(u.attrs.iter().map(|a| a.ns.as_str()));
            }
        }
        for uri in uris {
            if !uri.is_empty() && uri != XML_NS && !self.prefixes.iter().any(|(_, u)| u == uri) {
                let p = format!("ns{}", self.prefixes.len() - KNOWN_PREFIXES.len() + 1);
                self.prefixes.push((p, uri.to_string()));
            }
        }
    }

    fn prefix(&self, uri: &str) -> &str {
        if uri == XML_NS {
            return "xml";
        }
        self.prefixes
            .iter()
            .find(|(_, u)| u == uri)
            .map_or("", |(p, _)| p.as_str())
    }

    fn attr(&mut self, name: &str, value: &str) {
        let _ = write!(self.out, " {name}=\"{}\"", escape(value));
    }

    fn foreign(&mut self, attrs: &[ForeignAttr]) {
        for a in attrs {
            let name = if a.ns.is_empty() {
                a.name.clone()
            } else {
                format!("{}:{}", self.prefix(&a.ns), a.name)
            };
            self.attr(&name, &a.value);
        }
    }

    fn list(&mut self, name: &str, ids: &[String]) {
        if !ids.is_empty() {
            self.attr(name, &ids.join(","));
        }
    }

    fn block(&mut self, b: &Block) {
        self.out.push_str("<bml");
        self.attr("xmlns", NS_BML);
        for (p, u) in self.prefixes.clone() {
            let _ = write!(self.out, " xmlns:{p}=\"{}\"", namespace_name(&u));
        }
        self.attr("id", &b.id);
        if let Some(c) = &b.character_id {
            self.attr("characterId", c);
        }
        if b.composition != Composition::Merge {
            self.attr("composition", &b.composition.to_bml());
        }
        let e = &b.ext;
        if e.preplan {
            self.attr("bmla:preplan", "true");
        }
        if e.allow_external_refs {
            self.attr("bmla:allowexternalrefs", "true");
        }
        self.list("bmla:onStart", &e.on_start);
        self.list("bmla:interrupt", &e.interrupt);
        self.list("bmla:appendAfter", &e.append_after);
        self.list("bmla:chunkAfter", &e.chunk_after);
        self.list("bmla:chunkBefore", &e.chunk_before);
        self.list("bmla:prependBefore", &e.prepend_before);
        self.foreign(&b.foreign_attrs);
        if b.behaviours.is_empty() && b.constraints.is_empty() {
            self.out.push_str("/>\n");
            return;
        }
        self.out.push_str(">\n");
        let mut in_required = false;
        for beh in &b.behaviours {
            self.required_switch(&mut in_required, beh.required);
            self.behaviour(beh, if in_required { "    " } else { "  " });
        }
        self.required_switch(&mut in_required, false);
        for c in &b.constraints {
            self.required_switch(&mut in_required, c.required);
            self.constraint(c, if in_required { "    " } else { "  " });
        }
        self.required_switch(&mut in_required, false);
        self.out.push_str("</bml>\n");
    }

    fn required_switch(&mut self, state: &mut bool, want: bool) {
        if *state != want {
            self.out.push_str(if want {
                "  <required>\n"
            } else {
                "  </required>\n"
            });
            *state = want;
        }
    }

    fn qname(&self, kind: &BehaviourKind) -> String {
        match kind {
            BehaviourKind::Unknown(_) => kind.element_name().to_string(),
            k if k.namespace() == NS_BML => k.element_name().to_string(),
            k => format!("{}:{}", self.prefix(k.namespace()), k.element_name()),
        }
    }

    fn behaviour(&mut self, b: &Behaviour, indent: &str) {
        let q = self.qname(&b.kind);
        let ext = self.prefix(b.kind.namespace()).to_string();
        let _ = write!(self.out, "{indent}<{q}");
        if let BehaviourKind::Unknown(u) = &b.kind {
            let _ = write!(self.out, " xmlns=\"{}\"", namespace_name(&u.ns));
            xmlns(&mut self.out, &u.namespaces);
        }
        if let BehaviourKind::ProcAnimation(a)
        | BehaviourKind::ProcAnimationGesture(a)
        | BehaviourKind::Keyframe(a) = &b.kind
        {
            xmlns(&mut self.out, &a.namespaces);
        }
        self.attr("id", &b.id);
        self.kind_attrs(&b.kind);
        for s in &b.syncs {
            self.attr(s.sync, &s.value.to_string());
        }
        self.foreign(&b.foreign_attrs);
        let mut body = String::new();
        self.kind_body(&b.kind, &ext, &mut body);
        for d in &b.descriptions {
            body.push_str("<description");
            if let Some(p) = d.priority {
                let _ = write!(body, " priority=\"{p}\"");
            }
            let _ = write!(body, " type=\"{}\"", escape(&d.kind));
            xmlns(&mut body, &d.namespaces);
            let _ = write!(body, ">{}</description>", d.content);
        }
        if body.is_empty() {
            self.out.push_str("/>\n");
        } else {
            let _ = writeln!(self.out, ">{body}</{q}>");
        }
    }

    /// The attributes of a behaviour kind: a BML 1.0 element's or an extension's, each family
    /// one arm per element, the mirror of the parser's kind builder, so that the two compare
    /// side by side.
    fn kind_attrs(&mut self, kind: &BehaviourKind) {
        use BehaviourKind as K;
        match kind {
            K::Speech(_)
            | K::Text(_)
            | K::Gesture(_)
            | K::Pointing(_)
            | K::Head(_)
            | K::HeadDirectionShift { .. }
            | K::Gaze(_)
            | K::GazeShift(_)
            | K::Face(_)
            | K::FaceLexeme(_)
            | K::FaceShift(_)
            | K::FaceFacs(_)
            | K::Posture(_)
            | K::PostureShift(_)
            | K::Locomotion(_)
            | K::Wait(_) => self.core_attrs(kind),
            K::Interrupt(_)
            | K::Activate(_)
            | K::ParameterValueChange(_)
            | K::ProcAnimation(_)
            | K::ProcAnimationGesture(_)
            | K::Keyframe(_)
            | K::Controller(_)
            | K::AudioFile { .. }
            | K::Noise(_)
            | K::FaceMorph(_)
            | K::Transition(_)
            | K::Unknown(_) => self.extension_attrs(kind),
        }
    }

    /// The attributes of BML 1.0's own behaviours.
    fn core_attrs(&mut self, kind: &BehaviourKind) {
        match kind {
            BehaviourKind::Speech(_) | BehaviourKind::Text(_) => {}
            BehaviourKind::Gesture(g) => {
                self.attr("lexeme", &g.lexeme);
                if let Some(m) = g.mode {
                    self.attr("mode", m.as_str());
                }
            }
            BehaviourKind::Pointing(p) => {
                self.attr("target", &p.target);
                if let Some(m) = p.mode {
                    self.attr("mode", m.as_str());
                }
            }
            BehaviourKind::Head(h) => {
                self.attr("lexeme", &h.lexeme);
                if let Some(r) = h.repetition {
                    self.attr("repetition", &r.to_string());
                }
                self.opt_num("amount", h.amount);
            }
            BehaviourKind::HeadDirectionShift { target } => self.attr("target", target),
            BehaviourKind::Gaze(g) | BehaviourKind::GazeShift(g) => {
                self.attr("target", &g.target);
                if let Some(i) = g.influence {
                    self.attr("influence", i.as_str());
                }
                self.opt_num("offsetAngle", g.offset_angle);
                if let Some(d) = g.offset_direction {
                    self.attr("offsetDirection", d.as_str());
                }
            }
            BehaviourKind::Face(f) => {
                self.opt_attr("lexeme", &f.lexeme);
                if let Some(au) = f.au {
                    self.attr("au", &au.to_string());
                }
                if let Some(s) = f.side {
                    self.attr("side", s.as_str());
                }
                self.opt_num("amount", f.amount);
            }
            BehaviourKind::FaceLexeme(f) | BehaviourKind::FaceShift(f) => {
                self.attr("lexeme", &f.lexeme);
                self.opt_num("amount", f.amount);
            }
            BehaviourKind::FaceFacs(f) => {
                self.attr("au", &f.au.to_string());
                if let Some(s) = f.side {
                    self.attr("side", s.as_str());
                }
                self.opt_num("amount", f.amount);
            }
            BehaviourKind::Posture(_) | BehaviourKind::PostureShift(_) => {}
            BehaviourKind::Locomotion(l) => {
                self.attr("target", &l.target);
                self.opt_attr("manner", &l.manner);
            }
            BehaviourKind::Wait(w) => self.opt_num("max-wait", w.max_wait),
            _ => {}
        }
    }

    /// The attributes of the BMLA and BMLT extensions' behaviours.
    fn extension_attrs(&mut self, kind: &BehaviourKind) {
        match kind {
            BehaviourKind::Interrupt(i) => {
                self.attr("target", &i.target);
                self.list("include", &i.include);
                self.list("exclude", &i.exclude);
            }
            BehaviourKind::Activate(a) => self.attr("target", &a.target),
            BehaviourKind::ParameterValueChange(p) => {
                let target = match &p.target_block {
                    Some(b) => format!("{b}:{}", p.target_behaviour),
                    None => p.target_behaviour.clone(),
                };
                self.attr("target", &target);
                self.attr("paramId", &p.param_id);
            }
            BehaviourKind::ProcAnimation(a)
            | BehaviourKind::ProcAnimationGesture(a)
            | BehaviourKind::Keyframe(a) => {
                self.opt_attr("name", &a.name);
                self.opt_attr("fileName", &a.file_name);
            }
            BehaviourKind::Controller(c) => {
                self.attr("class", &c.class);
                self.opt_attr("name", &c.name);
            }
            BehaviourKind::AudioFile { file_name } => self.attr("fileName", file_name),
            BehaviourKind::Noise(n) => {
                self.attr("joint", &n.joint);
                self.attr("type", &n.kind);
            }
            BehaviourKind::FaceMorph(f) => {
                self.attr("targetname", &f.target_name);
                self.opt_num("intensity", f.intensity);
            }
            BehaviourKind::Transition(t) => self.attr("class", &t.class),
            BehaviourKind::Unknown(u) => {
                self.foreign(&u.attrs);
            }
            _ => {}
        }
    }

    /// `name="v"` where there is a value.
    fn opt_attr(&mut self, name: &str, v: &Option<String>) {
        if let Some(v) = v {
            self.attr(name, v);
        }
    }

    /// `name="v"` (a number) where there is a value.
    fn opt_num(&mut self, name: &str, v: Option<f64>) {
        if let Some(v) = v {
            self.attr(name, &num(v));
        }
    }

    fn kind_body(&self, kind: &BehaviourKind, ext: &str, body: &mut String) {
        let params = |body: &mut String, params: &[Param]| {
            for p in params {
                let _ = write!(
                    body,
                    "<bmlt:parameter name=\"{}\" value=\"{}\"/>",
                    escape(&p.name),
                    escape(&p.value)
                );
            }
        };
        match kind {
            BehaviourKind::Speech(s) | BehaviourKind::Text(s) => {
                let tag = if matches!(kind, BehaviourKind::Text(_)) {
                    "bmlt:text"
                } else {
                    "text"
                };
                let _ = write!(body, "<{tag}>");
                for part in &s.text {
                    match part {
                        TextPart::Text(t) => body.push_str(&escape_text(t)),
                        TextPart::Sync(id) => {
                            let _ = write!(body, "<sync id=\"{}\"/>", escape(id.as_str()));
                        }
                    }
                }
                let _ = write!(body, "</{tag}>");
            }
            BehaviourKind::Posture(p) | BehaviourKind::PostureShift(p) => {
                let _ = write!(body, "<stance type=\"{}\"/>", p.stance.as_str());
                for pose in &p.poses {
                    let _ = write!(
                        body,
                        "<pose part=\"{}\" lexeme=\"{}\"/>",
                        pose.part.as_str(),
                        escape(&pose.lexeme)
                    );
                }
            }
            BehaviourKind::ParameterValueChange(p) => {
                let t = &p.trajectory;
                let _ = write!(body, "<{ext}:trajectory type=\"{}\"", t.kind.as_str());
                if let Some(v) = t.initial_value {
                    let _ = write!(body, " initialValue=\"{}\"", num(v));
                }
                let _ = write!(body, " targetValue=\"{}\"/>", num(t.target_value));
            }
            BehaviourKind::ProcAnimation(a)
            | BehaviourKind::ProcAnimationGesture(a)
            | BehaviourKind::Keyframe(a) => {
                params(body, &a.params);
                body.push_str(&a.content);
            }
            BehaviourKind::Controller(c) => params(body, &c.params),
            BehaviourKind::Noise(n) => params(body, &n.params),
            BehaviourKind::Transition(t) => params(body, &t.params),
            BehaviourKind::Unknown(u) => body.push_str(&u.content),
            _ => {}
        }
    }

    fn constraint(&mut self, c: &ConstraintElement, indent: &str) {
        let _ = write!(self.out, "{indent}<constraint");
        if let Some(id) = &c.id {
            self.attr("id", id);
        }
        self.out.push_str(">\n");
        for item in &c.items {
            let (tag, reference, syncs) = match item {
                ConstraintItem::Synchronize {
                    reference, syncs, ..
                } => ("synchronize", reference.as_ref(), syncs),
                ConstraintItem::Before {
                    reference, syncs, ..
                } => ("before", Some(reference), syncs),
                ConstraintItem::After {
                    reference, syncs, ..
                } => ("after", Some(reference), syncs),
            };
            let _ = write!(self.out, "{indent}  <{tag}");
            if let Some(r) = reference {
                self.attr("ref", &r.to_string());
            }
            self.out.push('>');
            for s in syncs {
                let _ = write!(
                    self.out,
                    "<sync ref=\"{}\"/>",
                    escape(&s.reference.to_string())
                );
            }
            let _ = writeln!(self.out, "</{tag}>");
        }
        let _ = writeln!(self.out, "{indent}</constraint>");
    }
}

/// `s` for an attribute value: the XML specials as entities, and tab, line feed and carriage
/// return as character references (a reader turns them into spaces otherwise).
fn escape(s: &str) -> std::borrow::Cow<'_, str> {
    let escaped = quick_xml::escape::escape(s);
    if !s.contains(['\t', '\n', '\r']) {
        return escaped;
    }
    escaped
        .replace('\t', "&#9;")
        .replace('\n', "&#10;")
        .replace('\r', "&#13;")
        .into()
}

/// `s` for text content: the XML specials as entities, and a carriage return as a character
/// reference (a reader turns a raw one into a line feed).
fn escape_text(s: &str) -> std::borrow::Cow<'_, str> {
    let escaped = quick_xml::escape::escape(s);
    if !s.contains('\r') {
        return escaped;
    }
    escaped.replace('\r', "&#13;").into()
}
