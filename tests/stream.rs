//! A speech whose sound streams in (`bmlt:stream`, `Realizer::open_stream`): espeak-ng's
//! sentence (`fixtures/voice/espeak-bob.wav`) pushed in 10 chunks, each with its Polly speech
//! marks (written from espeak-ng's own word and phoneme reports), must move the lips as the
//! whole file with the whole marks does (within one frame), end with its sound, carry a nod
//! tied to its end along, and stop sound and lips within one frame of an interrupt.

#[path = "common/chunked.rs"]
mod chunked;
#[path = "common/espeak_report.rs"]
mod espeak_report;

use chunked::sync_time;

use std::sync::{Arc, Mutex};

use bml_realizer::character::face::VISEMES;
use bml_realizer::language::feedback::Feedback;
use bml_realizer::realizer::Realizer;

const NS: &str = r#"xmlns="http://www.bml-initiative.org/bml/bml-1.0" xmlns:bmlt="http://hmi.ewi.utwente.nl/bmlt" xmlns:bmla="http://www.asap-project.org/bmla""#;
const FPS: f64 = 60.0;
const TEXT: &str =
    "Bob may bring a big map to the market, maybe. Please buy more apples and pears.";

fn fixture(name: &str) -> String {
    format!("{}/fixtures/voice/{name}", env!("CARGO_MANIFEST_DIR"))
}

/// Polly speech marks of the fixture, each line with its time (seconds).
fn polly_lines() -> Vec<(f64, String)> {
    espeak_report::polly_lines(&espeak_report::fixture())
}

/// (viseme, jawOpen) a frame.
type Lips = (Option<&'static str>, f32);

fn lips(r: &mut Realizer, t: f64) -> (Lips, usize) {
    let f = r.tick(t);
    let p = &f.poses[0];
    (
        (
            p.face.viseme.map(|v| VISEMES[v]),
            p.face.morphs.get("jawOpen"),
        ),
        p.sounds.len(),
    )
}

fn listen(r: &mut Realizer) -> Arc<Mutex<Vec<Feedback>>> {
    let log = Arc::new(Mutex::new(Vec::new()));
    let sink = log.clone();
    r.add_listener(Box::new(move |f: &Feedback| {
        sink.lock().unwrap().push(f.clone())
    }));
    log
}

#[test]
fn a_streamed_speech_moves_the_lips_as_its_whole_file_and_ends_with_its_sound() {
    let audio =
        bml_realizer::character::sound::read_wav(std::path::Path::new(&fixture("espeak-bob.wav")))
            .unwrap();
    let length = audio.samples.len() as f64 / f64::from(audio.rate);
    let lines = polly_lines();
    // the whole file with the whole marks, from 0
    let dir = std::env::temp_dir().join(format!("bmlr-stream-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let marks = dir.join("whole.marks");
    let all: Vec<&str> = lines.iter().map(|l| l.1.as_str()).collect();
    std::fs::write(&marks, all.join("\n")).unwrap();
    let mut whole = Realizer::new().with_idle(false);
    whole
        .perform_bml(&format!(
            r#"<bml {NS} id="w"><speech id="s" bmlt:audiofile="{}" bmlt:marks="{}"><text>{TEXT}</text></speech></bml>"#,
            fixture("espeak-bob.wav"),
            marks.display()
        ))
        .unwrap();
    let frames = (length * FPS) as usize + 1;
    let reference: Vec<Lips> = (0..frames)
        .map(|i| lips(&mut whole, i as f64 / FPS).0)
        .collect();
    // the stream: ten chunks, one every 0.2 s from 0.5 s (each 0.47 s of sound: ahead of it)
    let mut r = Realizer::new().with_idle(false);
    let log = listen(&mut r);
    let stream = r.open_stream(None, "reply");
    r.perform_bml(&format!(
        r#"<bml {NS} id="b"><speech id="s" bmlt:stream="reply" start="anticipators:reply:start" end="anticipators:reply:end"><text>{TEXT}</text></speech><head id="n" lexeme="NOD" start="s:end"/></bml>"#
    ))
    .unwrap();
    let chunks = chunked::chunks(audio.samples.len(), audio.rate, &lines, 10);
    let mut pushed = 0;
    let mut streamed = Vec::new();
    let mut started = None;
    for i in 0..((length + 2.5) * FPS) as usize {
        let t = i as f64 / FPS;
        while pushed < 10 && t >= 0.5 + 0.2 * pushed as f64 {
            let (span, marks) = &chunks[pushed];
            stream
                .push(&audio.samples[span.clone()], audio.rate, Some(marks))
                .unwrap();
            pushed += 1;
            if pushed == 10 {
                stream.end();
            }
        }
        let (l, _) = lips(&mut r, t);
        if started.is_none() {
            started = sync_time(&log.lock().unwrap(), "s", "start");
        }
        if let Some(s) = started {
            streamed.push((t - s, l));
        }
    }
    let start = started.expect("the streamed speech starts");
    // pushed between the frames at 29/60 and 30/60 s: it starts at the later one (starting at
    // the earlier would put its first frame of sound in the past)
    assert!(
        (start - 0.5).abs() < 1e-9,
        "it starts at {start}, the first frame after its first chunk came (0.5)"
    );
    // the same lips, frame by frame, within one frame
    let mut worst = 0usize;
    let compared: Vec<_> = (streamed.iter())
        .filter(|(at, _)| *at >= 0.0 && *at < length - 1.0 / FPS)
        .collect();
    let open = compared.iter().filter(|(_, l)| l.1 > 0.2).count();
    eprintln!("{} frames compared, the jaw open in {open}", compared.len());
    assert!(compared.len() > 250 && open > 50);
    for (at, l) in compared {
        let i = (at * FPS).round() as usize;
        let near = |k: usize| {
            reference
                .get(k)
                .is_some_and(|x| x.0 == l.0 && (x.1 - l.1).abs() < 0.05)
        };
        if !(near(i) || near(i + 1) || i.checked_sub(1).is_some_and(near)) {
            worst += 1;
            eprintln!("at {at:.3}: streamed {l:?}, whole {:?}", reference.get(i));
        }
    }
    assert_eq!(
        worst, 0,
        "{worst} frames whose lips differ from the whole file's"
    );
    let log = log.lock().unwrap();
    let end = sync_time(&log, "s", "end").expect("the speech ends");
    assert!(
        (end - (start + length)).abs() <= 1.5 / FPS,
        "it ends at {end:.3}, its sound at {:.3}",
        start + length
    );
    // the block's end was predicted, then revised as the chunks came
    let ends: Vec<f64> = (log.iter())
        .filter_map(|f| match f {
            Feedback::Prediction(p) => p.blocks.first()?.global_end,
            _ => None,
        })
        .filter(|e| *e < 100.0)
        .collect();
    eprintln!("the block's end predicted at {ends:.3?}");
    assert!(ends.len() >= 9, "{ends:?}");
    let nod_end = sync_time(&log, "n", "end").expect("the nod ends");
    assert!(
        (ends.last().unwrap() - nod_end).abs() < 1e-6,
        "the last prediction {ends:?} against the block's real end {nod_end}"
    );
    let nod = sync_time(&log, "n", "start").expect("the nod starts");
    assert!(
        (nod - end).abs() < 1e-6,
        "the nod at {nod}, the speech's end at {end}"
    );
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn an_interrupt_stops_a_stream_s_sound_and_lips_within_a_frame() {
    let audio =
        bml_realizer::character::sound::read_wav(std::path::Path::new(&fixture("espeak-bob.wav")))
            .unwrap();
    let mut r = Realizer::new().with_idle(false);
    let log = listen(&mut r);
    let stream = r.open_stream(None, "reply");
    r.perform_bml(&format!(
        r#"<bml {NS} id="b"><speech id="s" bmlt:stream="reply" start="anticipators:reply:start" end="anticipators:reply:end"><text>{TEXT}</text></speech></bml>"#
    ))
    .unwrap();
    stream
        .push(&audio.samples[..audio.samples.len() / 2], audio.rate, None)
        .unwrap();
    let mut talking = 0;
    for i in 0..60 {
        let (l, sounds) = lips(&mut r, f64::from(i) / FPS);
        talking += usize::from(l.1 > 0.1 && sounds == 1);
    }
    assert!(talking > 10, "it speaks ({talking} frames)");
    r.perform_bml(&format!(
        r#"<bml {NS} id="i"><bmla:interrupt id="x" target="b" start="0"/></bml>"#
    ))
    .unwrap();
    let (l, sounds) = lips(&mut r, 61.0 / FPS);
    assert_eq!(sounds, 0, "the sound stops at once");
    assert!(l.1 < 0.05, "the jaw closes at once: {}", l.1);
    let log = log.lock().unwrap();
    let end = sync_time(&log, "s", "end").expect("the speech ends");
    assert!(
        end <= 61.0 / FPS + 1e-9,
        "its end is reported at the interrupt: {end}"
    );
}

#[test]
fn a_streamed_speech_s_inline_syncs_land_on_their_words_as_the_marks_come() {
    let audio =
        bml_realizer::character::sound::read_wav(std::path::Path::new(&fixture("espeak-bob.wav")))
            .unwrap();
    let length = audio.samples.len() as f64 / f64::from(audio.rate);
    let report = espeak_report::fixture();
    let word = |w: &str| {
        (report.words.iter())
            .find(|x| x.0 == w)
            .map(|x| x.1)
            .unwrap()
    };
    let lines = polly_lines();
    let mut r = Realizer::new().with_idle(false);
    let log = listen(&mut r);
    let stream = r.open_stream(None, "reply");
    // syncs before "map" (in the first chunks), "Please" (past the middle) and "pears" (the
    // last word: in the last chunk); a beat's stroke on the second, a nod on the third
    r.perform_bml(&format!(
        r#"<bml {NS} id="b"><speech id="s" bmlt:stream="reply" start="anticipators:reply:start" end="anticipators:reply:end"><text>Bob may bring a big <sync id="m"/>map to the market, maybe. <sync id="p"/>Please buy more apples and <sync id="e"/>pears.</text></speech><gesture id="g" lexeme="BEAT" stroke="s:p"/><head id="n" lexeme="NOD" start="s:e"/></bml>"#
    ))
    .unwrap();
    let chunks = chunked::chunks(audio.samples.len(), audio.rate, &lines, 10);
    let mut pushed = 0;
    for i in 0..((length + 2.5) * FPS) as usize {
        let t = i as f64 / FPS;
        while pushed < 10 && t >= 0.5 + 0.2 * pushed as f64 {
            let (span, marks) = &chunks[pushed];
            (stream.push(&audio.samples[span.clone()], audio.rate, Some(marks))).unwrap();
            pushed += 1;
            if pushed == 10 {
                stream.end();
            }
        }
        r.tick(t);
    }
    let log = log.lock().unwrap();
    let warnings: Vec<_> = (log.iter())
        .filter(|f| matches!(f, Feedback::Warning(_)))
        .collect();
    assert!(warnings.is_empty(), "{warnings:?}");
    let start = sync_time(&log, "s", "start").expect("the speech starts");
    for (sync, w) in [("m", "map"), ("p", "Please"), ("e", "pears")] {
        let at = sync_time(&log, "s", sync).expect("the sync passes");
        let truth = start + word(w);
        eprintln!(
            "s:{sync} at {:.3} s into the speech, '{w}' at {:.3}",
            at - start,
            word(w)
        );
        assert!(
            (at - truth).abs() <= 0.020,
            "s:{sync} at {at:.3}, the word '{w}' starts at {truth:.3}"
        );
    }
    let stroke = sync_time(&log, "g", "stroke").expect("the beat strikes");
    let p = sync_time(&log, "s", "p").unwrap();
    assert!(
        (stroke - p).abs() < 1e-6,
        "the stroke at {stroke}, s:p at {p}"
    );
    let nod = sync_time(&log, "n", "start").expect("the nod starts");
    let e = sync_time(&log, "s", "e").unwrap();
    assert!((nod - e).abs() < 1e-6, "the nod at {nod}, s:e at {e}");
}
