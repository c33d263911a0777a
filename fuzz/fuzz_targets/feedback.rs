//! Fuzz target for the feedback codecs: no line may panic the decoder, and every decoded message
//! must round-trip through both encoders.
#![no_main]

use bml_realizer::language::feedback::{self, Format};
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let Ok(line) = std::str::from_utf8(data) else {
        return;
    };
    if let Ok(fb) = feedback::from_line(line) {
        for f in [Format::Xml, Format::Jsonl] {
            let encoded = f.encode(&fb);
            let back = feedback::from_line(&encoded)
                .unwrap_or_else(|e| panic!("re-encoded feedback does not decode: {e}\n{encoded}"));
            // times are written with millisecond precision, so compare the re-encoded forms
            assert_eq!(f.encode(&back), encoded);
        }
    }
});
