//! The unit tests of `xml`.

use super::*;

/// Every event of `src` as a short string, or the error as `!offset message`.
fn events(src: &str) -> Vec<String> {
    let mut t = Reader::new(src, &Limits::default());
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
                let ns = t.resolve(tag.qname, false);
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
        events("<?xml version=\"1.0\"?><!DOCTYPE a [<!ENTITY x \"}\">]><a>1&lt;2&#x41;&#66;<!-- c --><![CDATA[<&>]]>\r\nz</a>"),
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
    assert_eq!(events("<a><!-- -> - ->--><b/></a>")[1], "<b/ Ok(None)@18");
}

#[test]
fn namespaces_follow_the_element_scope() {
    let ev =
        events(r#"<a xmlns="urn:d" xmlns:p="urn:p"><p:b xmlns:p="urn:q"/><p:c/><d xmlns=""/></a>"#);
    assert_eq!(
        ev[0],
        r#"<a xmlns=urn:d@3,xmlns:p=urn:p@17Ok(Some("urn:d"))@0"#
    );
    assert!(ev[1].ends_with(r#"Ok(Some("urn:q"))@33"#), "{}", ev[1]);
    assert!(ev[2].ends_with(r#"Ok(Some("urn:p"))@55"#), "{}", ev[2]);
    assert!(ev[3].ends_with("Ok(None)@61"), "{}", ev[3]);
    let mut t = Reader::new(r#"<a xmlns:p="urn:p"><b/></a>"#, &Limits::default());
    t.next().unwrap();
    assert_eq!(t.resolve("p:x", true), Ok(Some("urn:p")));
    assert_eq!(t.resolve("x", true), Ok(None));
    assert_eq!(t.resolve("q:x", false), Err(()));
    assert_eq!(t.scope(), [("p".to_string(), "urn:p".to_string())]);
    let mark = t.level();
    t.next().unwrap();
    assert!(!t.bound_since(mark, "p"));
}

#[test]
fn attribute_values_are_resolved_only_when_they_hold_references() {
    let src = r#"<a x="plain" y='a&amp;b&lt;' z="&quot;" w="'"/>"#;
    let mut t = Reader::new(src, &Limits::default());
    assert!(matches!(t.next(), Ok(Event::Start(_))));
    let got: Vec<(&str, String, bool)> = t
        .attrs()
        .iter()
        .map(|a| {
            let v = a.value().unwrap();
            let borrowed = matches!(v, Cow::Borrowed(_));
            (a.key, v.into_owned(), borrowed)
        })
        .collect();
    assert_eq!(
        got,
        [
            ("x", "plain".to_string(), true),
            ("y", "a&b<".to_string(), false),
            ("z", "\"".to_string(), false),
            ("w", "'".to_string(), true),
        ]
    );
    // a bad reference is found when the value is asked for, at its offset
    let mut t = Reader::new("<a x='1&bogus;'/>", &Limits::default());
    assert!(matches!(t.next(), Ok(Event::Start(_))));
    assert_eq!(t.attrs()[0].value().unwrap_err().offset, 7);
    let mut t = Reader::new("<a x='&#1;'/>", &Limits::default());
    assert!(matches!(t.next(), Ok(Event::Start(_))));
    assert!(t.attrs()[0].value().unwrap_err().message.contains("U+0001"));
}

#[test]
fn malformed_input_is_reported_where_it_is() {
    for (src, offset, words) in [
        ("<a><b></a>", 6, "expected `</b>`"),
        ("</a>", 0, "does not match"),
        ("<a x=1/>", 5, "not in quotes"),
        ("<a x/>", 4, "has no value"),
        ("<a x='1'y='2'/>", 8, "separated by white space"),
        ("<a x='<'/>", 6, "'<' in the value"),
        ("<a x='1", 0, "not closed"),
        ("<a", 0, "not closed"),
        ("<a>&b</a>", 3, ""),
        ("<a>&#1;</a>", 3, "U+0001"),
        ("<a>&#xD800;</a>", 3, "not a valid character reference"),
        ("<a>&nbsp;</a>", 3, "unknown entity"),
        ("<a><!-- x</a>", 3, "comment not closed"),
        ("<a><!-- x -- y --></a>", 10, "--"),
        ("<a>x ]]> y</a>", 5, "']]>' in text"),
        ("<1a/>", 0, "not a valid qualified name"),
        ("<p:/x/>", 0, "not a valid qualified name"),
        ("<xmlns:x/>", 0, "reserved"),
        ("<a xmlns:p='1' xmlns:p='2'/>", 15, "appears twice"),
        ("<a xmlns:p=''/>", 3, "cannot undeclare"),
        ("<a xmlns:p='urn:a\nb'/>", 17, "U+000A"),
        ("<a xmlns='urn:a b'/>", 15, "U+0020"),
        ("<a x:y:z='1'/>", 3, "not a valid qualified name"),
        ("<a/ >", 0, "not a valid qualified name"),
        ("<!x>", 0, ""),
        ("<?xml version='1.0' encoding='latin1'?><a/>", 0, "UTF-8"),
        ("<?xml version='2.0'?><a/>", 0, "not 1.0"),
        ("<a/><?xml version='1.0'?>", 4, "only open"),
        ("<a/><!DOCTYPE a>", 4, "DOCTYPE"),
        ("<!DOCTYPE a [<!ENTITY x '>'>]><a/>", 0, "not supported"),
        ("<!DOCTYPE a [<!ENTITY x \">\">]><a/>", 0, "not supported"),
    ] {
        let ev = events(src);
        let last = ev.last().unwrap();
        assert!(
            last.starts_with(&format!("!{offset} ")) && last.contains(words),
            "{src}: {last}"
        );
    }
}

#[test]
fn limits_stop_deep_nesting_and_long_attribute_lists() {
    let limits = Limits {
        depth: 3,
        attributes: 2,
        ..Limits::default()
    };
    let read = |src: &str| {
        let mut t = Reader::new(src, &limits);
        loop {
            match t.next() {
                Ok(Event::Eof) => return None,
                Ok(_) => {}
                Err(e) => return Some((e.offset, e.problem)),
            }
        }
    };
    assert_eq!(read("<a><b><c/></b></a>"), None);
    assert_eq!(read("<a><b><c><d/></c></b></a>"), None);
    assert_eq!(
        read("<a><b><c><d></d></c></b></a>"),
        Some((9, Problem::Limit))
    );
    assert_eq!(read("<a x='1' y='2'/>"), None);
    assert_eq!(read("<a x='1' y='2' z='3'/>"), Some((15, Problem::Limit)));
    assert_eq!(
        read("<a xmlns:p='1' xmlns:q='2'><b xmlns:r='3'/></a>"),
        Some((27, Problem::Limit))
    );
}

#[test]
fn reading_goes_on_after_a_content_error_but_not_after_broken_markup() {
    let mut t = Reader::new(
        "<a><b x='&bogus;' y='<'/>&nope;<c/></a>",
        &Limits::default(),
    );
    let mut kinds = Vec::new();
    loop {
        match t.next() {
            Ok(Event::Eof) => break,
            Ok(Event::Start(tag)) => kinds.push(tag.qname.to_string()),
            Ok(_) => {}
            Err(e) => kinds.push(format!("{:?}", e.problem)),
        }
    }
    assert_eq!(kinds, ["a", "Content", "Content", "c"]);
    let mut t = Reader::new("<a></b>", &Limits::default());
    t.next().unwrap();
    assert_eq!(t.next().unwrap_err().problem, Problem::Broken);
    let mut t = Reader::new("<a><!-- x", &Limits::default());
    t.next().unwrap();
    assert_eq!(t.next().unwrap_err().problem, Problem::Unclosed);
}
