//! What the broker examples share about the processes they start: the `bmlr` built beside
//! them, and a child killed when dropped.
#![allow(dead_code)]

use std::path::PathBuf;
use std::process::Child;

/// A child process, killed when dropped.
pub struct Kill(pub Child);

impl Drop for Kill {
    fn drop(&mut self) {
        let _ = self.0.kill();
        let _ = self.0.wait();
    }
}

/// The `bmlr` of the same build as the running example (`target/PROFILE/bmlr`).
pub fn bmlr() -> PathBuf {
    let exe = std::env::current_exe().expect("this example's path");
    exe.parent()
        .and_then(|d| d.parent())
        .expect("the target directory")
        .join("bmlr")
}
