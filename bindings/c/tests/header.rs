//! `include/bmlr.h` is what cbindgen makes of the library now: a change to the ABI that is not
//! in the committed header fails here. `BMLR_WRITE_HEADER=1 cargo test -p bmlr-c --test header`
//! writes it.

#[test]
fn the_committed_header_is_the_generated_one() {
    let dir = env!("CARGO_MANIFEST_DIR");
    let config = cbindgen::Config::from_file(format!("{dir}/cbindgen.toml")).unwrap();
    let mut generated = Vec::new();
    cbindgen::Builder::new()
        .with_crate(dir)
        .with_config(config)
        .generate()
        .expect("cbindgen reads the crate")
        .write(&mut generated);
    let path = format!("{dir}/include/bmlr.h");
    if std::env::var_os("BMLR_WRITE_HEADER").is_some() {
        std::fs::write(&path, &generated).unwrap();
    }
    let committed = std::fs::read(&path).unwrap_or_default();
    assert!(
        committed == generated,
        "include/bmlr.h is stale: run `BMLR_WRITE_HEADER=1 cargo test -p bmlr-c --test header` \
         and commit it"
    );
}
