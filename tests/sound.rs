//! Sound: `bmlt:audiofile` clips timed by their length and mixed into `bmlr run --wav` at their
//! pegs, at their volume, cut with a fade by an interrupt; audio events in the frames; and the
//! flite voice (ignored without Debian's `flite`; `.ci/run` installs it and runs these with
//! `--ignored`): sync times on flite's own boundaries, the WAV as long as the speech, and the
//! conformance suite with flite.

mod common;

use std::path::PathBuf;

const TONE: &str = "fixtures/audio/tone-1.234s.wav";
const NS: &str = r#"xmlns="http://www.bml-initiative.org/bml/bml-1.0""#;
const BMLT: &str = r#"xmlns:bmlt="http://hmi.ewi.utwente.nl/bmlt""#;
const BMLA: &str = r#"xmlns:bmla="http://www.asap-project.org/bmla""#;

fn scratch(name: &str) -> PathBuf {
    let dir = std::path::Path::new(env!("CARGO_TARGET_TMPDIR")).join("sound");
    std::fs::create_dir_all(&dir).unwrap();
    dir.join(name)
}

/// `bmlr run --wav` of `bml` (plus `extra` arguments): (stdout, stderr, samples, rate).
fn run_wav(name: &str, bml: &str, extra: &[&str]) -> (String, String, Vec<i16>, u32) {
    let file = scratch(&format!("{name}.xml"));
    std::fs::write(&file, bml).unwrap();
    let wav = scratch(&format!("{name}.wav"));
    let mut args = vec!["run", "--wav", wav.to_str().unwrap()];
    args.extend_from_slice(extra);
    args.push(file.to_str().unwrap());
    let (code, out, err) = common::bmlr(&args, "");
    assert_eq!(code, 0, "{err}");
    let mut r = hound::WavReader::open(&wav).unwrap();
    let rate = r.spec().sample_rate;
    let samples = r.samples::<i16>().map(Result::unwrap).collect();
    (out, err, samples, rate)
}

/// The loudest sample in `from..to` seconds.
fn peak(samples: &[i16], rate: u32, from: f64, to: f64) -> i16 {
    let at = |t: f64| ((t * f64::from(rate)) as usize).min(samples.len());
    samples[at(from)..at(to)]
        .iter()
        .map(|s| s.saturating_abs())
        .max()
        .unwrap_or(0)
}

fn sync_time(log: &str, id: &str) -> f64 {
    let line = log
        .lines()
        .find(|l| l.contains(&format!(r#"id="{id}""#)))
        .unwrap_or_else(|| panic!("{id}\n{log}"));
    let v = line.split("globalTime=\"").nth(1).unwrap();
    v[..v.find('"').unwrap()].parse().unwrap()
}

#[test]
fn an_audiofile_lasts_as_long_as_its_file_and_plays_at_its_peg() {
    let bml = format!(
        r#"<bml {NS} {BMLT} id="a"><bmlt:audiofile id="c" fileName="{TONE}" start="0.5"/></bml>"#
    );
    let (out, _, samples, rate) = run_wav("clip", &bml, &[]);
    assert!(
        (sync_time(&out, "a:c:end") - sync_time(&out, "a:c:start") - 1.234).abs() < 0.0015,
        "{out}"
    );
    assert_eq!(rate, 8000);
    assert_eq!(
        samples.len(),
        (1.734f64 * 8000.0).round() as usize,
        "the run ends with the clip"
    );
    assert_eq!(
        peak(&samples, rate, 0.0, 0.499),
        0,
        "silent before its start"
    );
    assert!(peak(&samples, rate, 0.5, 1.0) > 7000, "the tone from 0.5 s");
    assert!(peak(&samples, rate, 1.6, 1.73) > 7000, "to its end");
}

#[test]
fn an_interrupt_cuts_the_clip_with_a_short_fade_and_volume_applies() {
    let bml =
        format!(r#"<bml {NS} {BMLT} id="a"><bmlt:audiofile id="c" fileName="{TONE}"/></bml>"#);
    let stop = format!(
        r#"<bml {NS} {BMLA} id="s" bmla:onStart="a"><bmla:interrupt id="i" target="a" start="0.6"/></bml>"#
    );
    let dir = scratch("cut");
    let _ = std::fs::create_dir_all(&dir);
    let (a, b) = (dir.join("a.xml"), dir.join("s.xml"));
    std::fs::write(&a, &bml).unwrap();
    std::fs::write(&b, &stop).unwrap();
    let wav = dir.join("cut.wav");
    let (code, _, err) = common::bmlr(
        &[
            "run",
            "--wav",
            wav.to_str().unwrap(),
            a.to_str().unwrap(),
            b.to_str().unwrap(),
        ],
        "",
    );
    assert_eq!(code, 0, "{err}");
    let samples: Vec<i16> = hound::WavReader::open(&wav)
        .unwrap()
        .samples::<i16>()
        .map(Result::unwrap)
        .collect();
    assert!(peak(&samples, 8000, 0.5, 0.6) > 7000);
    assert_eq!(
        peak(&samples, 8000, 0.611, 1.3),
        0,
        "cut at 0.6 s, faded by 0.61 s"
    );
    assert!(
        peak(&samples, 8000, 0.605, 0.61) < 7000,
        "fading, not chopped"
    );
    // half the volume
    let half = format!(
        r#"<bml {NS} {BMLT} {BMLA} id="v"><bmlt:audiofile id="c" fileName="{TONE}"/><bmla:parametervaluechange id="p" target="v:c" paramId="volume" start="0.5"><bmla:trajectory type="instant" targetValue="50"/></bmla:parametervaluechange></bml>"#
    );
    let (_, _, samples, rate) = run_wav("half", &half, &["--fps", "100"]);
    let (full, halved) = (
        peak(&samples, rate, 0.2, 0.45),
        peak(&samples, rate, 0.7, 1.2),
    );
    assert!(
        (f64::from(halved) / f64::from(full) - 0.5).abs() < 0.02,
        "{full} → {halved}"
    );
}

#[test]
fn a_clip_that_cannot_be_read_warns_and_keeps_its_default_timing() {
    let bml =
        format!(r#"<bml {NS} {BMLT} id="a"><bmlt:audiofile id="c" fileName="no/such.wav"/></bml>"#);
    let (out, _, samples, _) = run_wav("missing", &bml, &[]);
    assert!(out.contains("cannot read no/such.wav"), "{out}");
    assert!((sync_time(&out, "a:c:end") - 1.0).abs() < 1e-9);
    assert!(samples.iter().all(|&s| s == 0));
}

#[test]
fn the_frames_say_when_a_clip_starts_and_stops() {
    let bml = format!(
        r#"<bml {NS} {BMLT} id="a"><bmlt:audiofile id="c" fileName="{TONE}" start="0.2"/></bml>"#
    );
    let file = scratch("events.xml");
    std::fs::write(&file, bml).unwrap();
    let frames = scratch("events.jsonl");
    let (code, _, err) = common::bmlr(
        &[
            "run",
            "--until",
            "2",
            "--frames",
            frames.to_str().unwrap(),
            file.to_str().unwrap(),
        ],
        "",
    );
    assert_eq!(code, 0, "{err}");
    let events: Vec<(f64, serde_json::Value)> = std::fs::read_to_string(&frames)
        .unwrap()
        .lines()
        .skip(1)
        .map(|l| serde_json::from_str::<serde_json::Value>(l).unwrap())
        .filter_map(|f| {
            let e = f["characters"][""]["events"].clone();
            (!e.is_null()).then(|| (f["time"].as_f64().unwrap(), e))
        })
        .collect();
    assert_eq!(events.len(), 2, "{events:?}");
    assert_eq!(events[0].1[0]["kind"], "audio-start");
    assert_eq!(events[0].1[0]["id"], "a:c");
    assert!((events[0].0 - 0.2).abs() < 1.0 / 60.0 + 1e-9);
    assert_eq!(events[1].1[0]["kind"], "audio-stop");
    assert!((events[1].0 - 1.434).abs() < 1.0 / 60.0 + 1e-9);
}

/// flite's phones of `text`: (symbol, end time).
fn flite_phones(text: &str) -> Vec<(String, f64)> {
    let out = std::process::Command::new("flite")
        .args(["-psdur", "-t", text, "-o", "none"])
        .output()
        .expect("Debian's flite (apt-get install flite; .ci/run installs it)");
    String::from_utf8_lossy(&out.stdout)
        .split_whitespace()
        .filter_map(|s| {
            let (p, t) = s.split_once(':')?;
            Some((p.to_string(), t.parse().ok()?))
        })
        .collect()
}

/// How long flite speaks `text`, its silence at both ends left out.
fn flite_speaks(text: &str) -> f64 {
    let p = flite_phones(text);
    let lead = p.first().filter(|x| x.0 == "pau").map_or(0.0, |x| x.1);
    let tail = if p.last().is_some_and(|x| x.0 == "pau") {
        p[p.len() - 2].1
    } else {
        p.last().unwrap().1
    };
    tail - lead
}

#[test]
#[ignore = "needs Debian's flite; .ci/run installs it and runs this with --ignored"]
fn with_flite_syncs_fall_on_its_own_boundaries_and_the_wav_is_as_long_as_the_speech() {
    let bml = format!(
        r#"<bml {NS} id="f"><speech id="s"><text>Hello there, <sync id="a"/>my friend. How are <sync id="b"/>you today?</text></speech></bml>"#
    );
    let (out, _, samples, rate) = run_wav("flite", &bml, &["--tts", "flite"]);
    let first = flite_speaks("Hello there,");
    let second = flite_speaks("my friend. How are");
    let third = flite_speaks("you today?");
    let (a, b, end) = (
        sync_time(&out, "f:s:a"),
        sync_time(&out, "f:s:b"),
        sync_time(&out, "f:s:end"),
    );
    assert!(
        (a - first).abs() < 0.0015,
        "a at {a}, flite's boundary {first}"
    );
    assert!((b - (first + second)).abs() < 0.0015, "b at {b}");
    assert!(
        (end - (first + second + third)).abs() < 0.0015,
        "end at {end}"
    );
    let length = samples.len() as f64 / f64::from(rate);
    assert!(
        (length - end).abs() < 0.020,
        "the WAV lasts {length} s, the speech {end} s"
    );
    // sound where the speech is, not a silent file
    assert!(peak(&samples, rate, 0.0, end) > 1000);
}

#[test]
#[ignore = "needs Debian's flite; .ci/run installs it and runs this with --ignored"]
fn the_conformance_suite_passes_with_flite() {
    let (code, out, err) = common::bmlr(&["conformance", "--tts", "flite"], "");
    assert_eq!(code, 0, "{out}{err}");
    assert_eq!(out.lines().last(), Some("41 passed, 0 failed"), "{out}");
}

#[test]
fn without_flite_the_tts_option_says_which_package_to_install() {
    let out = std::process::Command::new(env!("CARGO_BIN_EXE_bmlr"))
        .args(["run", "--tts", "flite", "fixtures/examples/welcome.xml"])
        .current_dir(env!("CARGO_MANIFEST_DIR"))
        .env("PATH", "/nonexistent")
        .output()
        .unwrap();
    assert_eq!(out.status.code(), Some(2));
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(err.contains("install the Debian package 'flite'"), "{err}");
}
