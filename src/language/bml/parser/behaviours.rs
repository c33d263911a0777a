//! Behaviour elements: their ids, sync attributes, children (descriptions, stances, poses,
//! trajectories, parameters, animation content) and the ones the standard requires.

use super::*;

impl<'i> Parser<'i> {
    /// A behaviour's `id`: present, not empty, without ':'.
    pub(super) fn behaviour_id(&mut self, attrs: &mut Attrs<'i>, el: &El<'i>) -> Option<Id> {
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
    pub(super) fn extension_behaviour(
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
        let syncs = self.sync_attrs(
            &mut attrs,
            crate::language::bml::kinds::ALL_STANDARD_SYNCS,
            on,
        );
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
    pub(super) fn behaviour(
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

    pub(super) fn sync_attrs(
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
    pub(super) fn face_lexeme_child(
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
    pub(super) fn behaviour_children(
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
    pub(super) fn only_one(
        &mut self,
        seen: &mut bool,
        c: &El<'i>,
        name: &str,
        on: &dyn fmt::Display,
    ) {
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
    pub(super) fn description_child(
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
    pub(super) fn stance_child(&mut self, c: &mut El<'i>, post: &mut Posture) -> Result<(), Fatal> {
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
    pub(super) fn pose_child(&mut self, c: &mut El<'i>, post: &mut Posture) -> Result<(), Fatal> {
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
    pub(super) fn trajectory_child(
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
    pub(super) fn parameter_child(
        &mut self,
        c: &mut El<'i>,
        params: &mut Vec<Param>,
    ) -> Result<(), Fatal> {
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
    pub(super) fn animation_content(&mut self, c: &El<'i>, a: &mut Animation) -> Result<(), Fatal> {
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
    pub(super) fn unknown_child(
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
    pub(super) fn missing_children(
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
}
