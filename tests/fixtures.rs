//! Every fixture under fixtures/ is checked: RealizerTester BML 1.0 files are all valid except
//! core/bmlnoid.xml (no block id); MURML files give only an unsupported-extension warning.

use std::path::{Path, PathBuf};

use bml_realizer::language::bml::{self, Code, Severity};

fn xml_files(dir: &Path, out: &mut Vec<PathBuf>) {
    for e in std::fs::read_dir(dir).unwrap() {
        let p = e.unwrap().path();
        if p.is_dir() {
            xml_files(&p, out);
        } else if p.extension().is_some_and(|x| x == "xml") {
            out.push(p);
        }
    }
}

#[test]
fn realizertester_bml1_files() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("fixtures/realizertester/bml-1");
    let mut files = Vec::new();
    xml_files(&root, &mut files);
    files.sort();
    assert_eq!(
        files.len(),
        59,
        "all RealizerTester bml-1 files are present"
    );
    let mut invalid = Vec::new();
    for f in &files {
        let rel = f
            .strip_prefix(&root)
            .unwrap()
            .to_string_lossy()
            .replace('\\', "/");
        let (_, diags) = bml::check(&std::fs::read_to_string(f).unwrap());
        let errors: Vec<_> = diags
            .iter()
            .filter(|d| d.severity == Severity::Error)
            .collect();
        if !errors.is_empty() {
            invalid.push(rel.clone());
            assert_eq!(rel, "core/bmlnoid.xml", "{errors:?}");
            assert_eq!(errors.len(), 1);
            assert_eq!(errors[0].code, Code::MissingBlockId);
            assert!(errors[0].message.contains("no id"));
        }
        if rel.starts_with("murml/") {
            let codes: Vec<Code> = diags.iter().map(|d| d.code).collect();
            assert_eq!(codes, [Code::UnsupportedExtension], "{rel}");
            assert!(
                diags[0].message.contains("unsupported extension"),
                "{}",
                diags[0].message
            );
        }
    }
    assert_eq!(invalid, ["core/bmlnoid.xml"]);
}

#[test]
fn thesis_examples_are_valid_without_warnings() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("fixtures/thesis");
    let mut files = Vec::new();
    xml_files(&root, &mut files);
    assert_eq!(files.len(), 10);
    for f in files {
        let (_, diags) = bml::check(&std::fs::read_to_string(&f).unwrap());
        assert!(diags.is_empty(), "{}: {diags:?}", f.display());
    }
}
