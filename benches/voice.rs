//! Criterion bench `voice`: the built-in TTS saying a sentence (phones, durations, syncs), the lip
//! sync of one frame, and — when Debian's `flite` is installed — the latency from `perform_bml`
//! of a one-sentence speech to its PENDING prediction with `--tts flite` (flite runs as a
//! program, so this is mostly process start-up).
//!
//! A speech's own sound: parsing Polly speech marks of a 30 s utterance and planning its lips
//! from them (`voice/marks-30s`), hearing 30 s of sound with no text (`voice/listen-30s`) and
//! timing a 30 s text to its sound without marks (`voice/align-30s`).
//!
//! Run: `cargo bench --bench voice`

use std::hint::black_box;

use bml_realizer::character::voice::{builtin::Builtin, lipsync, Tts};
use bml_realizer::language::bml::{Id, TextPart};
use bml_realizer::planning::timing::{SpeechTiming, Voice};
use bml_realizer::realizer::Realizer;
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
    own_sound(c);
    let flite = bml_realizer::character::voice::flite::Flite::default();
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

/// 30 s of espeak-ng's sentence (the fixture, repeated) and its text.
fn thirty_seconds() -> (
    std::sync::Arc<bml_realizer::character::voice::Audio>,
    String,
) {
    let path = concat!(env!("CARGO_MANIFEST_DIR"), "/fixtures/voice/espeak-bob.wav");
    let one = bml_realizer::character::sound::read_wav(std::path::Path::new(path)).unwrap();
    let mut samples = Vec::new();
    while samples.len() < 30 * one.rate as usize {
        samples.extend(&one.samples);
    }
    samples.truncate(30 * one.rate as usize);
    let sentence =
        "Bob may bring a big map to the market, maybe. Please buy more apples and pears. ";
    let audio = bml_realizer::character::voice::Audio {
        rate: one.rate,
        samples,
    };
    (std::sync::Arc::new(audio), sentence.repeat(7))
}

fn own_sound(c: &mut Criterion) {
    use bml_realizer::character::voice::{listen, marks, recorded};
    let (audio, text) = thirty_seconds();
    // Polly marks: a word every 0.35 s, a viseme every 70 ms
    let words: Vec<&str> = text.split_whitespace().collect();
    let mut lines = String::new();
    for k in 0..(30.0 / 0.35) as usize {
        let w = words[k % words.len()];
        lines += &format!(
            "{{\"time\":{},\"type\":\"word\",\"start\":0,\"end\":1,\"value\":\"{w}\"}}\n",
            k * 350
        );
        for v in 0..5 {
            let viseme = ["p", "a", "t", "@", "s"][v];
            lines += &format!(
                "{{\"time\":{},\"type\":\"viseme\",\"value\":\"{viseme}\"}}\n",
                k * 350 + v * 70
            );
        }
    }
    let parts = vec![TextPart::Text(text.clone())];
    c.bench_function("voice/marks-30s", |b| {
        b.iter(|| {
            let m = marks::parse(black_box(&lines), "bench.marks").unwrap();
            black_box(recorded::utterance(&parts, audio.clone(), Some(&m)))
        })
    });
    c.bench_function("voice/listen-30s", |b| {
        b.iter(|| black_box(listen::phones_of_sound(&listen::frames(black_box(&audio)))))
    });
    c.bench_function("voice/align-30s", |b| {
        b.iter(|| black_box(recorded::utterance(&parts, audio.clone(), None)))
    });
}

criterion_group! {
    name = benches;
    config = Criterion::default().sample_size(20);
    targets = voice
}
criterion_main!(benches);
