//! XML name rules (the NCName production of Namespaces in XML), shared by the BML parser and the
//! feedback codecs.

/// Whether `c` is outside XML 1.0's `Char` production (C0 controls but tab, LF, CR; U+FFFE, U+FFFF),
/// i.e. may appear in an XML document neither literally nor as a character reference.
pub(crate) fn is_forbidden_char(c: char) -> bool {
    ((c as u32) < 0x20 && !matches!(c, '\t' | '\n' | '\r')) || c == '\u{FFFE}' || c == '\u{FFFF}'
}

/// Splits a qualified name `prefix:local` at its first colon (`None` for an unprefixed name).
pub(crate) fn split_qname(q: &str) -> (Option<&str>, &str) {
    match q.split_once(':') {
        Some((prefix, local)) => (Some(prefix), local),
        None => (None, q),
    }
}

/// Whether `s` is an XML name without colons (the NCName production of Namespaces in XML).
pub(crate) fn is_ncname(s: &str) -> bool {
    // fast path: ASCII letters, digits, '_', '-', '.'
    let b = s.as_bytes();
    if !b.is_empty()
        && (b[0].is_ascii_alphabetic() || b[0] == b'_')
        && b.iter()
            .all(|c| c.is_ascii_alphanumeric() || matches!(c, b'_' | b'-' | b'.'))
    {
        return true;
    }
    fn start(c: char) -> bool {
        matches!(c, 'A'..='Z' | '_' | 'a'..='z' | '\u{C0}'..='\u{D6}' | '\u{D8}'..='\u{F6}'
            | '\u{F8}'..='\u{2FF}' | '\u{370}'..='\u{37D}' | '\u{37F}'..='\u{1FFF}'
            | '\u{200C}'..='\u{200D}' | '\u{2070}'..='\u{218F}' | '\u{2C00}'..='\u{2FEF}'
            | '\u{3001}'..='\u{D7FF}' | '\u{F900}'..='\u{FDCF}' | '\u{FDF0}'..='\u{FFFD}'
            | '\u{10000}'..='\u{EFFFF}')
    }
    fn rest(c: char) -> bool {
        start(c)
            || matches!(c, '-' | '.' | '0'..='9' | '\u{B7}' | '\u{300}'..='\u{36F}' | '\u{203F}'..='\u{2040}')
    }
    let mut chars = s.chars();
    chars.next().is_some_and(start) && chars.all(rest)
}

#[cfg(test)]
mod tests {
    use super::is_ncname;

    #[test]
    fn qualified_names_split_at_their_first_colon() {
        use super::split_qname;
        assert_eq!(split_qname("bmlt:keyframe"), (Some("bmlt"), "keyframe"));
        assert_eq!(split_qname("speech"), (None, "speech"));
        assert_eq!(split_qname(":x"), (Some(""), "x"));
        assert_eq!(split_qname("a:b:c"), (Some("a"), "b:c"));
    }

    #[test]
    fn ncnames() {
        for ok in ["a", "_x", "g1", "stroke-start", "a.b", "é", "x\u{B7}y"] {
            assert!(is_ncname(ok), "{ok}");
        }
        for bad in ["", "1a", "-a", "a:b", "s'tart", "a b", "/x", ".a"] {
            assert!(!is_ncname(bad), "{bad}");
        }
    }
}
