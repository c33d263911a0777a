//! `--tts espeak` held against espeak-ng itself: the same text said by espeak-ng's own library
//! (`tests/peers/espeak_events.py`, a separate process) reports every phoneme with its time;
//! the realizer's espeak voice (the program, its phonemes timed to its sound) must last as long
//! within 10 % and close the lips on every p, b and m within 45 ms of espeak-ng's report, in
//! English, German and French; a gesture tied to a word's sync lands on it. Needs the Debian
//! package espeak-ng and Python: `.ci/run` installs them and runs these with `--ignored`.

#[path = "common/espeak_report.rs"]
mod espeak_report;

use bml_realizer::character::voice::espeak::{Espeak, VoiceName};
use bml_realizer::character::voice::Tts;
use bml_realizer::language::bml::TextPart;
use bml_realizer::language::feedback::Feedback;
use bml_realizer::planning::timing::{SpeechTiming, Voice};
use bml_realizer::realizer::Realizer;

/// espeak-ng's own report of `text` in `voice`: (IPA, start, end) of each phoneme, and its
/// samples.
fn reported(voice: &str, text: &str) -> (Vec<(String, f64, f64)>, Vec<i16>) {
    let dir = std::env::temp_dir().join(format!("bmlr-espeak-{}-{voice}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let (wav, json) = (dir.join("said.wav"), dir.join("said.json"));
    let script = concat!(env!("CARGO_MANIFEST_DIR"), "/tests/peers/espeak_events.py");
    let out = std::process::Command::new("python3")
        .arg(script)
        .args([voice, text])
        .args([&wav, &json])
        .output()
        .expect("python3 runs");
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let report = espeak_report::read(&std::fs::read_to_string(&json).unwrap());
    let phones = report.phonemes;
    let samples = bml_realizer::character::sound::read_wav(&wav)
        .unwrap()
        .samples;
    let _ = std::fs::remove_dir_all(&dir);
    (phones, samples)
}

#[test]
#[ignore = "needs espeak-ng (Debian espeak-ng) and python3; .ci/run runs it"]
fn espeak_speaks_three_languages_with_its_own_timing_and_lips_on_the_bilabials() {
    for (voice, text) in [
        ("en", "Bob may bring a big map to the market, maybe."),
        ("en", "Please remember the number by the embassy, Tom."),
        ("de", "Mein Bruder baut eine Brücke aus Papier, bitte."),
        ("de", "Am Abend bringt die Mutter ein Paket mit Blumen."),
        ("fr", "Mon papa mange une pomme bien mûre."),
        ("fr", "Le bébé aime beaucoup les bonbons de maman."),
    ] {
        let (truth, theirs) = reported(voice, text);
        let name = VoiceName::new(voice).unwrap();
        let u = Espeak::new(name)
            .speak(&[TextPart::Text(text.into())])
            .unwrap();
        let ours = &u.audio.as_ref().unwrap().samples;
        // the realizer's sound is espeak-ng's with the silence around it cut: find where
        let probe = &ours[..200.min(ours.len())];
        let at = (0..theirs.len().saturating_sub(probe.len()))
            .find(|&i| &theirs[i..i + probe.len()] == probe)
            .expect("the realizer plays espeak-ng's own sound");
        let offset = at as f64 / 22_050.0;
        let length = theirs.len() as f64 / 22_050.0;
        assert!(
            (u.end - length).abs() <= 0.1 * length,
            "{voice}: {:.3} s against espeak-ng's {length:.3} s",
            u.end
        );
        let mut missed = Vec::new();
        let mut checked = 0;
        for (ipa, start, end) in &truth {
            if !matches!(ipa.chars().next(), Some('p' | 'b' | 'm')) {
                continue;
            }
            checked += 1;
            let (a, b) = (start - offset - 0.045, end - offset + 0.045);
            let closed = (u.phones.iter())
                .any(|p| matches!(p.symbol, "P" | "B" | "M") && p.end > a && p.start < b);
            if !closed {
                let near: Vec<_> = (u.phones.iter())
                    .filter(|p| p.end > a - 0.2 && p.start < b + 0.2)
                    .map(|p| format!("{}@{:.3}-{:.3}", p.symbol, p.start, p.end))
                    .collect();
                let around: Vec<_> = (truth.iter())
                    .filter(|p| p.2 > start - 0.2 && p.1 < end + 0.2)
                    .map(|p| format!("{}@{:.3}", p.0, p.1 - offset))
                    .collect();
                missed.push(format!(
                    "{ipa} at {start:.3} (ours {near:?}, theirs {around:?})"
                ));
            }
        }
        eprintln!(
            "{voice}: {:.3} s against {length:.3} s, {checked} bilabials, missed {missed:?}",
            u.end
        );
        // every bilabial: on the old timing (each phoneme its phone's length, stress ignored)
        // German's "eine Brücke" closed 100 ms late
        assert!(
            checked >= 4 && missed.is_empty(),
            "{voice}: missed {missed:?}"
        );
    }
}

#[test]
#[ignore = "needs espeak-ng (Debian espeak-ng); .ci/run runs it"]
fn a_gesture_tied_to_a_word_lands_on_it_and_xml_lang_picks_the_voice() {
    let timing = SpeechTiming {
        voice: Voice::Espeak(VoiceName::default()),
        ..SpeechTiming::default()
    };
    let mut r = Realizer::new().with_idle(false).with_speech_timing(timing);
    let log = std::sync::Arc::new(std::sync::Mutex::new(Vec::new()));
    let sink = log.clone();
    r.add_listener(Box::new(move |f: &Feedback| {
        sink.lock().unwrap().push(f.clone())
    }));
    r.perform_bml(
        r#"<bml xmlns="http://www.bml-initiative.org/bml/bml-1.0" id="b">
        <speech id="s" xml:lang="de"><text>Ich habe einen <sync id="w"/>Bären gesehen.</text></speech>
        <speech id="t" start="s:end" xml:lang="zz"><text>Hello.</text></speech>
        <gesture id="g" lexeme="BEAT" stroke="s:w"/></bml>"#,
    )
    .unwrap();
    for i in 0..=600 {
        r.tick(f64::from(i) / 100.0);
    }
    let log = log.lock().unwrap();
    let time = |behaviour: &str, sync: &str| {
        (log.iter())
            .find_map(|f| match f {
                Feedback::SyncPointProgress(p) if p.behaviour == behaviour && p.sync == sync => {
                    Some(p.global_time)
                }
                _ => None,
            })
            .unwrap()
    };
    assert_eq!(time("g", "stroke"), time("s", "w"));
    let warnings: Vec<String> = (log.iter())
        .filter_map(|f| match f {
            Feedback::Warning(w) => Some(w.text.clone()),
            _ => None,
        })
        .collect();
    assert_eq!(warnings.len(), 1, "{warnings:?}");
    assert!(
        warnings[0].contains("no voice for xml:lang 'zz'"),
        "{warnings:?}"
    );
}
