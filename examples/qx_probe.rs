fn main() {
    let src = include_str!("../fixtures/realizertester/bml-1/core/testspeechgestures.xml");
    for _ in 0..200000 {
        let p = bml_realizer::bml::load(std::hint::black_box(src)).unwrap();
        std::hint::black_box(bml_realizer::bml::extract(&p.block));
    }
}
