//! The voice through the realizer: the built-in TTS's timing is the speech's timing, and the
//! lips move with it — the jaw opens most at each vowel and the lips close on every p, b and m.

use bml_realizer::character::face::VISEMES;
use bml_realizer::language::bml::TextPart;
use bml_realizer::planning::timing::SpeechTiming;
use bml_realizer::realizer::Realizer;

const NS: &str = r#"xmlns="http://www.bml-initiative.org/bml/bml-1.0""#;
const SENTENCE: &str = "Papa bought the map, Bob made my bomb.";
/// Frames a second: fine enough to place a maximum to 5 ms.
const FPS: f64 = 200.0;

/// (time, jawOpen, mouthPress, viseme) of a frame.
type Mouth = (f64, f32, f32, Option<&'static str>);

/// The mouth every frame of the sentence, and the TTS's utterance.
fn speak() -> (Vec<Mouth>, bml_realizer::character::voice::Utterance) {
    let mut r = Realizer::new().with_idle(false);
    r.perform_bml(&format!(
        r#"<bml {NS} id="v"><speech id="s"><text>{SENTENCE}</text></speech></bml>"#
    ))
    .unwrap();
    let u = SpeechTiming::default()
        .speak(&[TextPart::Text(SENTENCE.into())])
        .unwrap();
    let frames = (0..=((u.end + 0.2) * FPS) as u32)
        .map(|i| {
            let t = f64::from(i) / FPS;
            let f = r.tick(t);
            let face = &f.poses[0].face;
            let press = face.morphs.get("mouthPressLeft");
            (
                t,
                face.morphs.get("jawOpen"),
                press,
                face.viseme.map(|v| VISEMES[v]),
            )
        })
        .collect();
    (frames, u)
}

#[test]
fn the_jaw_opens_most_at_each_vowel_in_order() {
    let (frames, u) = speak();
    let vowels: Vec<f64> = u
        .phones
        .iter()
        .filter(|p| p.is_vowel())
        .map(|p| p.centre())
        .collect();
    assert_eq!(vowels.len(), 9, "{:?}", u.phones);
    let maxima: Vec<f64> = frames
        .windows(3)
        .filter(|w| w[1].1 > w[0].1 && w[1].1 >= w[2].1 && w[1].1 > 0.1)
        .map(|w| w[1].0)
        .collect();
    assert_eq!(
        maxima.len(),
        vowels.len(),
        "maxima {maxima:?}\nvowels {vowels:?}"
    );
    for (m, v) in maxima.iter().zip(&vowels) {
        assert!(
            (m - v).abs() <= 0.030,
            "a jaw maximum at {m:.3} s for the vowel at {v:.3} s"
        );
    }
}

#[test]
fn the_lips_close_on_every_p_b_and_m() {
    let (frames, u) = speak();
    let closers: Vec<_> = u
        .phones
        .iter()
        .filter(|p| matches!(p.symbol, "P" | "B" | "M"))
        .collect();
    assert_eq!(closers.len(), 11, "{:?}", u.phones);
    for p in closers {
        let (_, jaw, press, viseme) = frames[(p.centre() * FPS).round() as usize];
        assert_eq!(viseme, Some("PP"), "{} at {:.3} s", p.symbol, p.centre());
        assert!(
            press > 0.35 && jaw < 0.15,
            "{} at {:.3}: press {press}, jaw {jaw}",
            p.symbol,
            p.centre()
        );
    }
    assert!(
        frames.last().unwrap().1 < 1e-6,
        "the mouth closes after the speech"
    );
}
