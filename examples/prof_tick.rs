use bml_realizer::realizer::Realizer;
fn block(character: usize) -> String {
    let mut body = String::new();
    for i in 0..16 {
        body.push_str(&format!(
            r#"<gesture id="g{i}" lexeme="BEAT" start="{}" end="100000"/>"#,
            i as f64 * 0.01
        ));
    }
    for i in 0..2 {
        body.push_str(&format!(
            r#"<head id="h{i}" lexeme="NOD" start="0" end="100000"/>"#
        ));
    }
    body.push_str(r#"<gaze id="look" target="user" start="0" end="100000"/>"#);
    let words = "la ".repeat(1000);
    body.push_str(&format!(r#"<speech id="s"><text>{words}</text></speech>"#));
    format!(
        r#"<bml xmlns="http://www.bml-initiative.org/bml/bml-1.0" id="b" characterId="c{character}">{body}</bml>"#
    )
}
fn main() {
    let mut r = Realizer::new();
    for ch in 0..100 {
        r.perform_bml(&block(ch)).unwrap();
    }
    let mut t = 0.5;
    for _ in 0..200 {
        t += 1.0 / 60.0;
        std::hint::black_box(r.tick(t));
    }
}
