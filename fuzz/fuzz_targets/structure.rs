//! Fuzz target that reaches the depths a byte-level fuzzer seldom builds: the input chooses a
//! block's shape — how deep elements nest and with which element, how many attributes and
//! namespace declarations a behaviour carries, extreme sync times, and raw text in the middle —
//! and the block is checked, scheduled and cut from a stream. Nothing may panic, and a block over
//! the limits must be refused by a limit, not by running out of stack or time.
#![no_main]

use bml_realizer::language::bml::{self, BlockStream, Code};
use bml_realizer::planning::schedule::{NoExternal, Optimal, SchedulingStrategy};
use bml_realizer::planning::timing::DefaultTimingModels;
use libfuzzer_sys::arbitrary::Unstructured;
use libfuzzer_sys::fuzz_target;

const WRAPPERS: &[&str] = &["required", "x:deep", "constraint", "speech", "description"];
const ATTRIBUTES: &[&str] = &[
    "a{i}=\"1\"",
    "xmlns:p{i}=\"urn:{i}\" p{i}:a=\"1\"",
    "start=\"{t}\"",
    "id=\"dup\"",
];
const TIMES: &[&str] = &[
    "0", "1e-300", "999999", "1e6", "1e7", "1e308", "-1e6", "nan", "1e-9",
];

fn block(u: &mut Unstructured) -> Option<String> {
    let depth = usize::from(u.arbitrary::<u16>().ok()? % 10_000);
    let wrapper = WRAPPERS[u.choose_index(WRAPPERS.len()).ok()?];
    let attributes = usize::from(u.arbitrary::<u16>().ok()? % 20_000);
    let kind = ATTRIBUTES[u.choose_index(ATTRIBUTES.len()).ok()?];
    let time = TIMES[u.choose_index(TIMES.len()).ok()?];
    let raw: &str = u.arbitrary().ok()?;
    let mut attrs = String::new();
    for i in 0..attributes {
        attrs.push(' ');
        attrs.push_str(&kind.replace("{i}", &i.to_string()).replace("{t}", time));
    }
    let open = format!("<{wrapper}>").repeat(depth);
    let close = format!("</{wrapper}>").repeat(depth);
    Some(format!(
        r#"<bml xmlns="http://www.bml-initiative.org/bml/bml-1.0" xmlns:x="urn:x" id="b">{open}<gesture id="g" lexeme="BEAT"{attrs}/>{raw}{close}<head id="h" lexeme="NOD" end="g:end+{time}"/></bml>"#
    ))
}

fuzz_target!(|data: &[u8]| {
    let mut u = Unstructured::new(data);
    let Some(text) = block(&mut u) else { return };
    let (parsed, diags) = bml::check(&text);
    let limits = bml::Limits::default();
    // a block past the limits is refused for them
    if text.len() > limits.block_bytes {
        assert!(diags.iter().any(|d| d.code == Code::LimitExceeded));
    }
    if let Some(block) = parsed.filter(|_| diags.iter().all(|d| !d.is_error())) {
        let _ = Optimal.schedule(&block, &DefaultTimingModels::default(), &NoExternal);
    }
    let mut stream = BlockStream::new();
    stream.push(&text);
    while stream.next_item(true).is_some() {}
});
