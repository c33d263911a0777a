//! Speech text with its inline syncs, and the readers of attribute values (required
//! strings, numbers, enumerations) that report a bad value at its place.

use super::*;

impl<'i> Parser<'i> {
    pub(super) fn speech_text(
        &mut self,
        el: &El<'i>,
        out: &mut Vec<TextPart>,
    ) -> Result<(), Fatal> {
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

    pub(super) fn req_str(
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

    pub(super) fn opt_f64(&mut self, attrs: &mut Attrs<'i>, name: &str) -> Option<f64> {
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
    pub(super) fn opt_u32(&mut self, attrs: &mut Attrs<'i>, name: &str, max: u32) -> Option<u32> {
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

    pub(super) fn opt_enum<T>(
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
    pub(super) fn req_enum<T>(
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
