//! Fuzz target for what arrives from a broker: bytes on a STOMP connection (cut into pieces
//! where the input says) through the frame decoder, and a payload on an ipaaca topic (a
//! message, an IU event in MessagePack). No input may panic them; a frame the decoder takes
//! must be written back by `Frame::encode` and read again as the same frame.
#![no_main]

use bml_realizer::ports::broker::ipaaca::{iu, Ipaaca};
use bml_realizer::ports::broker::stomp::frame::{Decoded, Decoder};
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    // the first byte cuts the stream into pieces of 1 to 256 bytes
    let Some((&cut, bytes)) = data.split_first() else {
        return;
    };
    let mut decoder = Decoder::default();
    for piece in bytes.chunks(usize::from(cut) + 1) {
        decoder.push(piece);
        loop {
            match decoder.take() {
                Ok(Some(Decoded::Frame(f))) => {
                    let mut again = Decoder::default();
                    again.push(&f.encode());
                    match again.take() {
                        Ok(Some(Decoded::Frame(g))) => assert_eq!(f, g),
                        other => panic!("{f:?} written back reads as {other:?}"),
                    }
                }
                Ok(Some(Decoded::HeartBeat)) => {}
                Ok(None) | Err(_) => break,
            }
        }
    }
    let _ = iu::read_event(bytes);
    let ipaaca = Ipaaca::new(&["default".to_string()], "fuzz").expect("a channel");
    for topic in [
        "default/bml/M",
        "default/realizerRequest/IU/u1",
        "default/other/M",
    ] {
        let _ = ipaaca.read(topic, bytes);
    }
});
