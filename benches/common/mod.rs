//! Inputs shared by the benches (the chained blocks and the RealizerTester core files), and the
//! allocator policy of the chained-block runs.

use bml_realizer::language::bml;

/// N blocks, each tied to the one before: its speech starts when the previous block's speech
/// ends, with a beat gesture on its own speech's end.
pub fn chain_texts(n: usize) -> Vec<String> {
    (0..n)
        .map(|i| {
            let start = if i == 0 {
                String::new()
            } else {
                format!(r#" start="b{}:s:end""#, i - 1)
            };
            format!(
                r#"<bml xmlns="http://www.bml-initiative.org/bml/bml-1.0" id="b{i}"><speech id="s"{start}><text>One two three.</text></speech><gesture id="g" lexeme="BEAT" stroke="s:end"/></bml>"#
            )
        })
        .collect()
}

/// The RealizerTester core files that are valid blocks, as (file stem, text), by name. A file
/// that is not (`bmlnoid.xml` tests the missing-id error) is left out.
pub fn core_files() -> Vec<(String, String)> {
    let dir = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/fixtures/realizertester/bml-1/core"
    );
    let mut files: Vec<_> = std::fs::read_dir(dir)
        .expect("the core fixtures")
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| p.extension().is_some_and(|x| x == "xml"))
        .collect();
    files.sort();
    files
        .into_iter()
        .filter_map(|path| {
            let text = std::fs::read_to_string(&path).expect("a core file");
            let name = path.file_stem()?.to_string_lossy().into_owned();
            bml::load(&text).is_ok().then_some((name, text))
        })
        .collect()
}
