//! Sync references in attributes and `<constraint>` elements (synchronize, before, after),
//! with their sync and offset syntax checked here.

use super::*;

impl<'i> Parser<'i> {
    pub(super) fn sync_ref(&mut self, a: &RawAttr<'i>, on: &dyn fmt::Display) -> Option<SyncRef> {
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
    pub(super) fn constraint(
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
    pub(super) fn constraint_item(
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
    pub(super) fn constraint_sync(
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
}
