//! Streaming through the C ABI as a C host calls it (`bmlr_open_stream`, `bmlr_push_audio`,
//! `bmlr_end_audio`): espeak-ng's sentence (`fixtures/voice/espeak-bob.wav`, with Polly speech
//! marks written from espeak-ng's own word and phoneme reports) pushed in 10 chunks moves the
//! face as the whole file with the whole marks does, within one frame; the feedback tells the
//! speech's start, its end predicted and revised, and its end with the sound; an interrupt
//! mid-stream stops sound and lips in the next frame; wrong calls are a status and a sentence.

#[path = "../../../tests/common/chunked.rs"]
mod chunked;
#[path = "../../../tests/common/espeak_report.rs"]
mod espeak_report;

use std::ffi::{c_char, CStr, CString};
use std::ptr::{null, null_mut};

use bml_realizer::language::feedback::Feedback;
use bmlr::*;
use chunked::sync_time;

const NS: &str = r#"xmlns="http://www.bml-initiative.org/bml/bml-1.0" xmlns:bmlt="http://hmi.ewi.utwente.nl/bmlt" xmlns:bmla="http://www.asap-project.org/bmla""#;
const FPS: f64 = 60.0;
const TEXT: &str =
    "Bob may bring a big map to the market, maybe. Please buy more apples and pears.";
const MORPHS: usize = 52;

fn root(path: &str) -> String {
    format!("{}/../../{path}", env!("CARGO_MANIFEST_DIR"))
}

fn last_error() -> String {
    // SAFETY: bmlr_last_error returns a NUL-terminated string valid until the next call
    unsafe { CStr::from_ptr(bmlr_last_error()) }
        .to_string_lossy()
        .into_owned()
}

fn ok(s: bmlr_status) {
    assert_eq!(s, bmlr_status::BMLR_OK, "{}", last_error());
}

fn c(s: &str) -> CString {
    CString::new(s).unwrap()
}

/// A realizer without idle motion, with `block` performed after `before` (streams opened).
fn realizer(before: &[&str], block: &str) -> *mut bmlr_realizer {
    let mut r = null_mut();
    // SAFETY: valid arguments throughout
    unsafe {
        ok(bmlr_new(c(r#"{"idle": false}"#).as_ptr(), &mut r));
        for name in before {
            ok(bmlr_open_stream(r, null(), c(name).as_ptr()));
        }
        ok(bmlr_perform(r, c(block).as_ptr()));
    }
    r
}

/// Ticks to `t`: the face's weights; the feedback lines it sends, decoded, go to `log`.
fn tick(r: *mut bmlr_realizer, t: f64, log: &mut Vec<Feedback>) -> Vec<f32> {
    let mut w = vec![0.0f32; MORPHS];
    let mut buf = vec![0 as c_char; 1 << 16];
    // SAFETY: a live realizer, buffers of their lengths
    unsafe {
        ok(bmlr_tick(r, t));
        ok(bmlr_morphs(r, null(), w.as_mut_ptr(), w.len()));
        loop {
            let mut len = 0;
            ok(bmlr_next_feedback(r, buf.as_mut_ptr(), buf.len(), &mut len));
            if len == 0 {
                break;
            }
            let line = CStr::from_ptr(buf.as_ptr()).to_string_lossy();
            log.push(bml_realizer::language::feedback::from_json(&line).unwrap());
        }
    }
    w
}

/// Whether the audio events show a sound playing now (started and not stopped).
fn playing(r: *mut bmlr_realizer, sounding: &mut bool) -> bool {
    let mut buf = vec![0 as c_char; 4096];
    loop {
        let mut len = 0;
        // SAFETY: a live realizer, a buffer of its length
        ok(unsafe { bmlr_next_audio_event(r, buf.as_mut_ptr(), buf.len(), &mut len) });
        if len == 0 {
            return *sounding;
        }
        // SAFETY: NUL-terminated by the library
        let line = unsafe { CStr::from_ptr(buf.as_ptr()) }.to_string_lossy();
        *sounding = line.contains("audio-start");
    }
}

#[test]
fn a_c_host_streams_a_speech_that_moves_as_its_whole_file() {
    let wav = root("fixtures/voice/espeak-bob.wav");
    let audio = bml_realizer::character::sound::read_wav(std::path::Path::new(&wav)).unwrap();
    let length = audio.samples.len() as f64 / f64::from(audio.rate);
    let report = std::fs::read_to_string(root("fixtures/voice/espeak-bob.events.json")).unwrap();
    let lines = espeak_report::polly_lines(&espeak_report::read(&report));
    let dir = std::env::temp_dir().join(format!("bmlr-c-stream-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let marks = dir.join("whole.marks");
    let all: Vec<&str> = lines.iter().map(|l| l.1.as_str()).collect();
    std::fs::write(&marks, all.join("\n")).unwrap();
    let whole = realizer(
        &[],
        &format!(
            r#"<bml {NS} id="w"><speech id="s" bmlt:audiofile="{wav}" bmlt:marks="{}"><text>{TEXT}</text></speech></bml>"#,
            marks.display()
        ),
    );
    let frames = (length * FPS) as usize + 1;
    let mut ignored = Vec::new();
    let reference: Vec<Vec<f32>> = (0..frames)
        .map(|i| tick(whole, i as f64 / FPS, &mut ignored))
        .collect();
    let r = realizer(
        &["reply"],
        &format!(
            r#"<bml {NS} id="b"><speech id="s" bmlt:stream="reply" start="anticipators:reply:start" end="anticipators:reply:end"><text>{TEXT}</text></speech><head id="n" lexeme="NOD" start="s:end"/></bml>"#
        ),
    );
    // ten chunks, one every 0.2 s from 0.5 s, each with its marks
    let chunks = chunked::chunks(audio.samples.len(), audio.rate, &lines, 10);
    let (mut pushed, mut log, mut streamed) = (0, Vec::new(), Vec::new());
    for i in 0..((length + 2.5) * FPS) as usize {
        let t = i as f64 / FPS;
        while pushed < 10 && t >= 0.5 + 0.2 * pushed as f64 {
            let (span, marks) = &chunks[pushed];
            let pcm = &audio.samples[span.clone()];
            let m = c(marks);
            // SAFETY: a live realizer, `pcm.len()` samples, NUL-terminated strings
            unsafe {
                ok(bmlr_push_audio(
                    r,
                    c"reply".as_ptr(),
                    pcm.as_ptr(),
                    pcm.len(),
                    audio.rate,
                    m.as_ptr(),
                ));
                if pushed == 9 {
                    ok(bmlr_end_audio(r, c"reply".as_ptr()));
                }
            }
            pushed += 1;
        }
        streamed.push((t, tick(r, t, &mut log)));
    }
    let start = sync_time(&log, "s", "start").expect("the streamed speech starts");
    assert!(
        (start - 0.5).abs() < 1e-3,
        "it starts at {start}, the first frame after its first chunk came (0.5)"
    );
    let mut differ = 0;
    let mut open = 0;
    for (t, w) in streamed
        .iter()
        .filter(|(t, _)| *t >= start && *t < start + length - 1.0 / FPS)
    {
        let k = ((t - start) * FPS).round() as usize;
        let near = |k: usize| {
            reference
                .get(k)
                .is_some_and(|x| x.iter().zip(w).all(|(a, b)| (a - b).abs() < 0.05))
        };
        open += usize::from(w[24..].iter().any(|&v| v > 0.2));
        if !(near(k) || near(k + 1) || k.checked_sub(1).is_some_and(near)) {
            differ += 1;
            let worst = |x: &Vec<f32>| {
                (x.iter().zip(w).enumerate())
                    .map(|(i, (a, b))| (i, (a - b).abs()))
                    .fold((0, 0.0f32), |m, d| if d.1 > m.1 { d } else { m })
            };
            eprintln!(
                "at {t:.3}: the worst morph ({}) against frames k-1, k, k+1: {:?}",
                bml_realizer::character::face::ARKIT[35],
                [k.wrapping_sub(1), k, k + 1].map(|k| reference.get(k).map(worst))
            );
        }
    }
    assert!(open > 50, "the face moves in {open} frames");
    assert_eq!(
        differ, 0,
        "{differ} frames whose face differs from the whole file's"
    );
    let end = sync_time(&log, "s", "end").expect("the speech ends");
    assert!(
        (end - (start + length)).abs() <= 1.5 / FPS,
        "it ends at {end}"
    );
    let predictions = log
        .iter()
        .filter(|f| matches!(f, Feedback::Prediction(_)))
        .count();
    assert!(predictions >= 9, "{predictions} predictions");
    let nod = sync_time(&log, "n", "start").expect("the nod starts");
    assert!(
        (nod - end).abs() < 1e-6,
        "the nod at {nod}, the speech's end at {end}"
    );
    // SAFETY: live realizers, freed once
    unsafe {
        ok(bmlr_free(r));
        ok(bmlr_free(whole));
    }
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn an_interrupt_mid_stream_stops_sound_and_lips_in_one_frame() {
    let wav = root("fixtures/voice/espeak-bob.wav");
    let audio = bml_realizer::character::sound::read_wav(std::path::Path::new(&wav)).unwrap();
    let r = realizer(
        &["reply"],
        &format!(
            r#"<bml {NS} id="b"><speech id="s" bmlt:stream="reply" start="anticipators:reply:start" end="anticipators:reply:end"><text>{TEXT}</text></speech></bml>"#
        ),
    );
    let half = &audio.samples[..audio.samples.len() / 2];
    // SAFETY: a live realizer, `half.len()` samples
    ok(unsafe {
        bmlr_push_audio(
            r,
            c"reply".as_ptr(),
            half.as_ptr(),
            half.len(),
            audio.rate,
            null(),
        )
    });
    let (mut log, mut sounding, mut talking) = (Vec::new(), false, 0);
    for i in 0..60 {
        let w = tick(r, f64::from(i) / FPS, &mut log);
        talking += usize::from(w.iter().any(|&v| v > 0.1) && playing(r, &mut sounding));
    }
    assert!(talking > 10, "it speaks ({talking} frames)");
    let stop = c(&format!(
        r#"<bml {NS} id="i"><bmla:interrupt id="x" target="b" start="0"/></bml>"#
    ));
    // SAFETY: a live realizer, a NUL-terminated block
    ok(unsafe { bmlr_perform(r, stop.as_ptr()) });
    let w = tick(r, 61.0 / FPS, &mut log);
    assert!(!playing(r, &mut sounding), "the sound stops at once");
    let jaw = w.iter().cloned().fold(0.0f32, f32::max);
    assert!(jaw < 0.05, "the face is at rest at once: {jaw}");
    let end = sync_time(&log, "s", "end").expect("the speech's end is reported");
    assert!(end <= 61.0 / FPS + 1e-9, "at the interrupt: {end}");
    // SAFETY: a live realizer
    ok(unsafe { bmlr_free(r) });
}

#[test]
fn wrong_stream_calls_are_a_status_and_a_sentence() {
    let r = realizer(
        &["reply"],
        &format!(r#"<bml {NS} id="b"><gaze id="g" target="camera"/></bml>"#),
    );
    let pcm = [0i16; 100];
    // SAFETY: every pointer is valid or NULL on purpose
    unsafe {
        let s = bmlr_push_audio(r, c"other".as_ptr(), pcm.as_ptr(), 100, 16000, null());
        assert_eq!(s, bmlr_status::BMLR_ERR_STREAM);
        assert!(
            last_error().contains("no stream 'other' is open"),
            "{}",
            last_error()
        );
        assert_eq!(
            bmlr_end_audio(r, c"other".as_ptr()),
            bmlr_status::BMLR_ERR_STREAM
        );
        assert_eq!(
            bmlr_open_stream(r, null(), c"".as_ptr()),
            bmlr_status::BMLR_ERR_STREAM
        );
        assert_eq!(
            bmlr_open_stream(r, null(), null()),
            bmlr_status::BMLR_ERR_NULL
        );
        assert_eq!(
            bmlr_push_audio(r, c"reply".as_ptr(), null(), 10, 16000, null()),
            bmlr_status::BMLR_ERR_NULL
        );
        ok(bmlr_push_audio(
            r,
            c"reply".as_ptr(),
            pcm.as_ptr(),
            100,
            16000,
            null(),
        ));
        let s = bmlr_push_audio(r, c"reply".as_ptr(), pcm.as_ptr(), 100, 22050, null());
        assert_eq!(s, bmlr_status::BMLR_ERR_STREAM);
        assert!(
            last_error().contains("22050 Hz after chunks at 16000 Hz"),
            "{}",
            last_error()
        );
        let s = bmlr_push_audio(
            r,
            c"reply".as_ptr(),
            pcm.as_ptr(),
            100,
            16000,
            c"{not marks".as_ptr(),
        );
        assert_eq!(s, bmlr_status::BMLR_ERR_STREAM);
        assert!(last_error().contains("line 1"), "{}", last_error());
        ok(bmlr_end_audio(r, c"reply".as_ptr()));
        let s = bmlr_push_audio(r, c"reply".as_ptr(), pcm.as_ptr(), 100, 16000, null());
        assert_eq!(s, bmlr_status::BMLR_ERR_STREAM);
        assert!(last_error().contains("has ended"), "{}", last_error());
        ok(bmlr_free(r));
    }
}
