//! A host loop that embeds the realizer: it submits BML, ticks at 60 Hz on its own clock, reads the
//! engines' output from each frame and prints the feedback as it arrives.
//!
//! Run: `cargo run --example embed`

use bml_realizer::language::feedback::{Feedback, Format};
use bml_realizer::realizer::Realizer;

const GREETING: &str = r#"<bml xmlns="http://www.bml-initiative.org/bml/bml-1.0" id="greet">
  <speech id="hello"><text>Hello and <sync id="stress"/>welcome!</text></speech>
  <gesture id="beat" lexeme="BEAT" stroke="hello:stress"/>
  <head id="nod" lexeme="NOD" start="hello:end"/>
</bml>"#;

const SOFTER: &str = r#"<bml xmlns="http://www.bml-initiative.org/bml/bml-1.0" xmlns:bmla="http://www.asap-project.org/bmla" id="softer">
  <bmla:parametervaluechange id="v" target="greet:hello" paramId="volume" start="0" end="0.5">
    <bmla:trajectory type="linear" targetValue="40"/>
  </bmla:parametervaluechange>
</bml>"#;

fn main() {
    let mut realizer = Realizer::new();
    // listeners see every message as soon as it exists (e.g. to forward it over a network)
    realizer.add_listener(Box::new(|fb: &Feedback| {
        if let Feedback::Warning(w) = fb {
            eprintln!("warning {}: {}", w.id, w.text);
        }
    }));
    if let Err(e) = realizer.perform_bml(GREETING) {
        eprintln!("rejected: {e}");
    }
    let fps = 60.0;
    for frame_no in 0..240u32 {
        let now = f64::from(frame_no) / fps;
        if frame_no == 30 {
            // half a second in, the host decides to speak softer
            let _ = realizer.perform_bml(SOFTER);
        }
        let frame = realizer.tick(now);
        for fb in &frame.feedback {
            println!("{}", Format::Jsonl.encode(fb));
        }
        if frame_no % 15 == 0 {
            for out in &frame.outputs {
                let mut line = format!(
                    "# t={now:.3} {} {} {:.0}%",
                    out.engine,
                    out.key,
                    out.progress * 100.0
                );
                for (k, v) in &out.params {
                    line.push_str(&format!(" {k}={v:.1}"));
                }
                println!("{line}");
            }
        }
        if realizer.next_event().is_none() && frame_no > 30 {
            break; // nothing left to do
        }
    }
}
