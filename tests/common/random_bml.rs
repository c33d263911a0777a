//! What the tests that make random blocks share: one behaviour element from its kind and its
//! sync constraints, a sync given twice keeping its first value (BML allows one each).

/// `<KIND id="xB" SYNC="VALUE"…/>` from `kind` (the element name with its fixed attributes),
/// behaviour number `b` and (sync name, value) pairs; a sync named again is left out.
pub fn behaviour<'a>(
    kind: &str,
    b: usize,
    syncs: impl IntoIterator<Item = (&'a str, String)>,
) -> String {
    let mut seen: Vec<&str> = Vec::new();
    let mut attrs = String::new();
    for (sync, value) in syncs {
        if !seen.contains(&sync) {
            seen.push(sync);
            attrs.push_str(&format!(r#" {sync}="{value}""#));
        }
    }
    format!(r#"<{kind} id="x{b}"{attrs}/>"#)
}
