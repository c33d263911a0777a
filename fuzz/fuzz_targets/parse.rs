//! Fuzz target for the BML parser: no input may panic, and every accepted block must survive a
//! write → parse round trip unchanged.
#![no_main]

use bml_realizer::language::bml;
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let Ok(text) = std::str::from_utf8(data) else {
        return;
    };
    let (block, _) = bml::check(text);
    if let Ok(parsed) = bml::parse(text) {
        let written = bml::write(&parsed.block);
        let again = bml::parse(&written)
            .unwrap_or_else(|e| panic!("written block does not parse: {e}\n{written}"));
        assert_eq!(
            again.block, parsed.block,
            "round trip changed the block:\n{written}"
        );
        let _ = bml::extract(&again.block);
    }
    drop(block);
});
