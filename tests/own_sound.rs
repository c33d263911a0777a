//! A speech that brings its own sound (`bmlt:audiofile`, `bmlt:marks`), held against what the
//! voice that made the sound reported while it made it: `fixtures/voice/espeak-bob.wav` was
//! synthesized by espeak-ng's own library, which reported every word and phoneme with its time
//! (`espeak-bob.events.json`, written by `tests/peers/espeak_events.py`). From those reports the
//! test writes the marks a cloud voice would send in each of the three forms, and checks that
//! the text's sync points land on the words (20 ms), the lips close on every p, b and m and
//! open on the open vowels within 45 ms of espeak-ng's phonemes (the lag people notice between
//! picture and sound, ITU-R BT.1359), and the speech ends with the sound (50 ms). Without
//! marks, the jaw follows the sound's loudness.

#[path = "common/espeak_report.rs"]
mod espeak_report;

use std::collections::HashMap;
use std::sync::{Arc, Mutex};

use bml_realizer::character::face::VISEMES;
use bml_realizer::language::feedback::Feedback;
use bml_realizer::realizer::Realizer;

const NS: &str = r#"xmlns="http://www.bml-initiative.org/bml/bml-1.0" xmlns:bmlt="http://hmi.ewi.utwente.nl/bmlt""#;
const FPS: f64 = 200.0;

fn fixture(name: &str) -> String {
    format!("{}/fixtures/voice/{name}", env!("CARGO_MANIFEST_DIR"))
}

/// What espeak-ng reported while it made the fixture's sound.
type Truth = espeak_report::Report;

fn truth() -> Truth {
    espeak_report::fixture()
}

impl Truth {
    /// Each word's end: the next word's start, or the pause before it.
    fn word_end(&self, k: usize) -> f64 {
        let next = self.words.get(k + 1).map_or(self.length, |w| w.1);
        let start = self.words[k].1;
        (self.phonemes.iter())
            .find(|p| p.0.is_empty() && p.1 > start + 0.02 && p.1 < next)
            .map_or(next, |p| p.1)
    }

    /// The text with a sync point `w{k}` before every word.
    fn text_with_syncs(&self) -> String {
        let mut out = String::new();
        let mut from = 0;
        let chars: Vec<char> = self.text.chars().collect();
        for (k, w) in self.words.iter().enumerate() {
            out.extend(&chars[from..w.2]);
            out.push_str(&format!(r#"<sync id="w{k}"/>"#));
            from = w.2;
        }
        out.extend(&chars[from..]);
        out
    }

    fn polly(&self) -> String {
        let lines: Vec<String> = espeak_report::polly_lines(self)
            .into_iter()
            .map(|l| l.1)
            .collect();
        lines.join("\n") + "\n"
    }

    fn word_list(&self) -> String {
        let items: Vec<String> = (self.words.iter().enumerate())
            .map(|(k, w)| {
                format!(
                    r#"{{"word": "{}", "start": {:.3}, "end": {:.3}}}"#,
                    w.0,
                    w.1,
                    self.word_end(k)
                )
            })
            .collect();
        format!("[{}]", items.join(",\n"))
    }

    fn webvtt(&self) -> String {
        let stamp = |t: f64| {
            let ms = (t * 1000.0).round() as u64;
            format!(
                "00:{:02}:{:02}.{:03}",
                ms / 60_000,
                ms / 1000 % 60,
                ms % 1000
            )
        };
        let mut out = String::from("WEBVTT\n");
        for (k, w) in self.words.iter().enumerate() {
            out += &format!(
                "\n{}\n{} --> {}\n{}\n",
                k + 1,
                stamp(w.1),
                stamp(self.word_end(k)),
                w.0
            );
        }
        out
    }
}

/// (time, jawOpen, viseme) of a frame.
type Mouth = (f64, f32, Option<&'static str>);

/// What a run shows: the mouth every frame, each sync's time, the warnings.
struct Run {
    mouth: Vec<Mouth>,
    syncs: HashMap<String, f64>,
    warnings: Vec<String>,
}

fn run(attrs: &str, text: &str, until: f64) -> Run {
    let mut r = Realizer::new().with_idle(false);
    let log = Arc::new(Mutex::new(Vec::new()));
    let sink = log.clone();
    r.add_listener(Box::new(move |f: &Feedback| {
        sink.lock().unwrap().push(f.clone())
    }));
    r.perform_bml(&format!(
        r#"<bml {NS} id="b"><speech id="s" {attrs}><text>{text}</text></speech></bml>"#
    ))
    .unwrap();
    let mouth = (0..=(until * FPS) as u32)
        .map(|i| {
            let t = f64::from(i) / FPS;
            let f = r.tick(t);
            let face = &f.poses[0].face;
            (
                t,
                face.morphs.get("jawOpen"),
                face.viseme.map(|v| VISEMES[v]),
            )
        })
        .collect();
    let mut syncs = HashMap::new();
    let mut warnings = Vec::new();
    for f in log.lock().unwrap().iter() {
        match f {
            Feedback::SyncPointProgress(p) if p.behaviour == "s" => {
                syncs.insert(p.sync.to_string(), p.global_time);
            }
            Feedback::Warning(w) => warnings.push(w.text.clone()),
            _ => {}
        }
    }
    Run {
        mouth,
        syncs,
        warnings,
    }
}

/// The worst distance from each phoneme of `kind` to the nearest frame within 45 ms of it
/// that shows it (`shows`), or the phoneme none shows.
fn lips_follow(truth: &Truth, run: &Run) -> Result<(), String> {
    let near = |p: &(String, f64, f64), shows: &dyn Fn(&Mouth) -> bool| {
        (run.mouth.iter()).any(|m| m.0 >= p.1 - 0.045 && m.0 <= p.2 + 0.045 && shows(m))
    };
    let mut missed = Vec::new();
    let mut checked = 0;
    for p in &truth.phonemes {
        let first = p.0.chars().next();
        if matches!(first, Some('p' | 'b' | 'm')) && !near(p, &|m| m.2 == Some("PP")) {
            missed.push(format!("{} at {:.3}: lips not closed", p.0, p.1));
        }
        if matches!(first, Some('a' | 'ɑ' | 'ɒ' | 'æ')) && !near(p, &|m| m.1 > 0.3) {
            missed.push(format!("{} at {:.3}: jaw not open", p.0, p.1));
        }
        checked += usize::from(matches!(
            first,
            Some('p' | 'b' | 'm' | 'a' | 'ɑ' | 'ɒ' | 'æ')
        ));
    }
    eprintln!("{checked} phonemes checked, {} missed", missed.len());
    if missed.is_empty() {
        Ok(())
    } else {
        Err(missed.join("\n"))
    }
}

fn check_with_marks(marks: &str, ext: &str) {
    let truth = truth();
    let dir = std::env::temp_dir().join(format!("bmlr-own-sound-{}-{ext}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let file = dir.join(format!("marks.{ext}"));
    std::fs::write(&file, marks).unwrap();
    let attrs = format!(
        r#"bmlt:audiofile="{}" bmlt:marks="{}""#,
        fixture("espeak-bob.wav"),
        file.display()
    );
    let run = run(&attrs, &truth.text_with_syncs(), truth.length + 0.3);
    assert!(run.warnings.is_empty(), "{:?}", run.warnings);
    let mut worst = 0.0f64;
    for (k, w) in truth.words.iter().enumerate() {
        let at = run.syncs[&format!("w{k}")];
        worst = worst.max((at - w.1).abs());
    }
    eprintln!("{ext}: syncs at worst {worst:.4} s off their words");
    assert!(worst <= 0.020, "{ext}: a sync {worst:.3} s off its word");
    let end = run.syncs["end"];
    assert!(
        (end - truth.length).abs() <= 0.050,
        "{ext}: the speech ends at {end:.3}, the sound at {:.3}",
        truth.length
    );
    if let Err(e) = lips_follow(&truth, &run) {
        panic!("{ext}:\n{e}");
    }
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn polly_speech_marks_time_the_syncs_and_the_lips() {
    check_with_marks(&truth().polly(), "marks");
}

#[test]
fn a_word_list_times_the_syncs_and_the_lips() {
    check_with_marks(&truth().word_list(), "json");
}

#[test]
fn webvtt_word_cues_time_the_syncs_and_the_lips() {
    check_with_marks(&truth().webvtt(), "vtt");
}

/// The correlation of the jaw with the sound's loudness (RMS over each frame's 1/60 s) at 60
/// frames a second over the sound.
fn jaw_follows_loudness(run: &Run, length: f64) -> f64 {
    let audio =
        bml_realizer::character::sound::read_wav(std::path::Path::new(&fixture("espeak-bob.wav")))
            .unwrap();
    let rate = f64::from(audio.rate);
    let (mut jaw, mut rms) = (Vec::new(), Vec::new());
    for i in 0..(length * 60.0) as usize {
        let t = i as f64 / 60.0;
        let m = run.mouth[(t * FPS).round() as usize];
        let (a, b) = (
            ((t - 1.0 / 120.0).max(0.0) * rate) as usize,
            ((t + 1.0 / 120.0) * rate) as usize,
        );
        let w = &audio.samples[a..b.min(audio.samples.len())];
        let r =
            (w.iter().map(|&s| f64::from(s).powi(2)).sum::<f64>() / w.len().max(1) as f64).sqrt();
        jaw.push(f64::from(m.1));
        rms.push(r);
    }
    let mean = |v: &[f64]| v.iter().sum::<f64>() / v.len() as f64;
    let (mj, mr) = (mean(&jaw), mean(&rms));
    let cov: f64 = jaw.iter().zip(&rms).map(|(j, r)| (j - mj) * (r - mr)).sum();
    let sj: f64 = jaw.iter().map(|j| (j - mj).powi(2)).sum::<f64>().sqrt();
    let sr: f64 = rms.iter().map(|r| (r - mr).powi(2)).sum::<f64>().sqrt();
    cov / (sj * sr)
}

#[test]
fn a_sound_with_its_text_and_no_marks_moves_the_lips_with_it() {
    let truth = truth();
    let attrs = format!(r#"bmlt:audiofile="{}""#, fixture("espeak-bob.wav"));
    let run = run(&attrs, &truth.text_with_syncs(), truth.length + 0.3);
    assert!(run.warnings.is_empty(), "{:?}", run.warnings);
    let r = jaw_follows_loudness(&run, truth.length);
    eprintln!("with text: jaw and loudness correlate {r:.3}");
    assert!(
        r >= 0.5,
        "the jaw and the sound's loudness correlate {r:.2}"
    );
    if let Err(e) = lips_follow(&truth, &run) {
        panic!("{e}");
    }
}

#[test]
fn a_sound_without_text_moves_the_jaw_with_its_loudness() {
    let truth = truth();
    let attrs = format!(r#"bmlt:audiofile="{}""#, fixture("espeak-bob.wav"));
    let run = run(&attrs, "", truth.length + 0.3);
    let r = jaw_follows_loudness(&run, truth.length);
    eprintln!("without text: jaw and loudness correlate {r:.3}");
    assert!(
        r >= 0.5,
        "the jaw and the sound's loudness correlate {r:.2}"
    );
    assert!((run.syncs["end"] - truth.length).abs() <= 0.05);
}

#[test]
fn bad_sounds_and_marks_are_warned_and_the_speech_still_ends() {
    let dir = std::env::temp_dir().join(format!("bmlr-own-sound-bad-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let wav = fixture("espeak-bob.wav");
    let bad = dir.join("bad.marks");
    std::fs::write(
        &bad,
        "{\"time\":0,\"type\":\"word\",\"value\":\"Bob\"}\n{\"time\":\n",
    )
    .unwrap();
    let late = dir.join("late.json");
    std::fs::write(
        &late,
        r#"[{"word": "Bob", "start": 0.0, "end": 0.2}, {"word": "may", "start": 9.0, "end": 9.5}]"#,
    )
    .unwrap();
    let missing = dir.join("missing.wav");
    for (attrs, says) in [
        (
            format!(r#"bmlt:audiofile="{wav}" bmlt:marks="{}""#, bad.display()),
            "bad.marks: line 2:",
        ),
        (
            format!(r#"bmlt:audiofile="{wav}" bmlt:marks="{}""#, late.display()),
            "past the sound's end",
        ),
        (
            format!(r#"bmlt:audiofile="{}""#, missing.display()),
            "missing.wav",
        ),
        (
            format!(
                r#"bmlt:audiofile="{wav}" bmlt:marks="{}""#,
                dir.join("none.vtt").display()
            ),
            "none.vtt",
        ),
    ] {
        let run = run(&attrs, "Bob may", 6.0);
        assert!(
            run.warnings.iter().any(|w| w.contains(says)),
            "{says}: {:?}",
            run.warnings
        );
        assert!(run.syncs.contains_key("end"), "{says}: the speech ends");
    }
    let _ = std::fs::remove_dir_all(&dir);
}
