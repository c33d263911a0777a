//! Criterion bench `voice`: the built-in TTS saying a sentence (phones, durations, syncs), the lip
//! sync of one frame, and — when Debian's `flite` is installed — the latency from `perform_bml`
//! of a one-sentence speech to its PENDING prediction with `--tts flite` (flite runs as a
//! program, so this is mostly process start-up).
//!
//! Run: `cargo bench --bench voice`

use std::hint::black_box;

use bml_realizer::bml::{Id, TextPart};
use bml_realizer::realizer::Realizer;
use bml_realizer::timing::{SpeechTiming, Voice};
use bml_realizer::voice::{builtin::Builtin, lipsync, Tts};
use criterion::{criterion_group, criterion_main, Criterion};

const SENTENCE: &str =
    "Good morning, I am glad to see you again; shall we take a look at the plans together?";

fn voice(c: &mut Criterion) {
    let text = vec![
        TextPart::Text("Good morning, I am glad to see you again;".into()),
        TextPart::Sync(Id::new_static("s1")),
        TextPart::Text("shall we take a look at the plans together?".into()),
    ];
    c.bench_function("voice/builtin-sentence-17-words", |b| {
        b.iter(|| black_box(Builtin.speak(black_box(&text)).unwrap()))
    });
    let u = Builtin.speak(&text).unwrap();
    let mut t = 0.0;
    c.bench_function("voice/lipsync-one-frame", |b| {
        b.iter(|| {
            t = (t + 1.0 / 60.0) % u.end;
            black_box(lipsync::weights(&u.phones, t))
        })
    });
    let flite = bml_realizer::voice::flite::Flite::default();
    if flite.check().is_err() {
        eprintln!("voice/flite-perform-to-pending: skipped, flite is not installed (apt-get install flite)");
        return;
    }
    let mut n = 0u64;
    let mut r = Realizer::new().with_speech_timing(SpeechTiming {
        voice: Voice::Flite,
        ..SpeechTiming::default()
    });
    c.bench_function("voice/flite-perform-to-pending", |b| {
        b.iter(|| {
            n += 1;
            // a new text each time: the engine remembers texts it has said
            let bml = format!(
                r#"<bml xmlns="http://www.bml-initiative.org/bml/bml-1.0" id="b{n}" composition="REPLACE"><speech id="s"><text>{SENTENCE} Number {n}.</text></speech></bml>"#
            );
            r.perform_bml(&bml).unwrap();
            black_box(r.tick(r.now()))
        })
    });
}

criterion_group! {
    name = benches;
    config = Criterion::default().sample_size(20);
    targets = voice
}
criterion_main!(benches);
