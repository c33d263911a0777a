//! What the command-line tests share: running the built `bmlr`, and driving an avatar with it.
#![allow(dead_code)] // each test file uses its own share of these

use std::io::Write;
use std::process::{Command, Stdio};

/// Runs the built `bmlr` from the repository root with `args` and `input` on its stdin; returns
/// (exit code, stdout, stderr). The input is written from a thread, so that a long one cannot
/// block on a full pipe, and a command that exits early may leave it unread.
pub fn bmlr<I: AsRef<[u8]> + ?Sized>(args: &[&str], input: &I) -> (i32, String, String) {
    let mut child = Command::new(env!("CARGO_BIN_EXE_bmlr"))
        .args(args)
        .current_dir(env!("CARGO_MANIFEST_DIR"))
        .stdin(Stdio::piped())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    let mut stdin = child.stdin.take().unwrap();
    let input = input.as_ref().to_vec();
    let writer = std::thread::spawn(move || {
        let _ = stdin.write_all(&input);
    });
    let out = child.wait_with_output().unwrap();
    writer.join().unwrap();
    (
        out.status.code().unwrap_or(-1),
        String::from_utf8_lossy(&out.stdout).into_owned(),
        String::from_utf8_lossy(&out.stderr).into_owned(),
    )
}

/// `bmlr run --avatar AVATAR EXTRA… --gltf OUT fixtures/examples/welcome.xml`: (exit code,
/// stdout, stderr).
pub fn drive(
    avatar: &std::path::Path,
    extra: &[&str],
    out: &std::path::Path,
) -> (i32, String, String) {
    let mut args = vec!["run", "--avatar", avatar.to_str().unwrap()];
    args.extend_from_slice(extra);
    args.extend([
        "--gltf",
        out.to_str().unwrap(),
        "fixtures/examples/welcome.xml",
    ]);
    bmlr(&args, "")
}
