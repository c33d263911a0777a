//! What the viewer tests share: pages made by `bmlr view`, their data, and headless Chromium
//! (Debian's `chromium`) with screenshots to read pixels from.
#![allow(dead_code)] // each test file uses its own share of these

use std::io::BufReader;
use std::path::{Path, PathBuf};
use std::process::Command;

use serde_json::Value;

use crate::common;

/// A fresh directory under the target directory.
pub fn scratch(name: &str) -> PathBuf {
    let dir = Path::new(env!("CARGO_TARGET_TMPDIR")).join(name);
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

/// The page of `bmlr view ARGS --out DIR` and its directory.
pub fn page(name: &str, args: &[&str]) -> (String, PathBuf) {
    let dir = scratch(name);
    let mut all = vec!["view", "--out", dir.to_str().unwrap()];
    all.extend_from_slice(args);
    let (code, _, err) = common::bmlr(&all, "");
    assert_eq!(code, 0, "{err}");
    (
        std::fs::read_to_string(dir.join("index.html")).unwrap(),
        dir,
    )
}

/// The run data in a page.
pub fn data(page: &str) -> Value {
    let start = page.find(r#"id="bmlr-data">"#).expect("the data element") + 15;
    let end = start + page[start..].find("</script>").unwrap();
    serde_json::from_str(&page[start..end]).expect("the data is JSON")
}

/// Where `chromium` is, if it is installed.
pub fn chromium() -> Option<PathBuf> {
    let path = std::env::var_os("PATH")?;
    std::env::split_paths(&path)
        .map(|d| d.join("chromium"))
        .find(|p| p.exists())
}

/// Headless Chromium on `url` with `what` (e.g. `--dump-dom` or `--screenshot=OUT.png`):
/// (stdout, the page's console lines).
pub fn browse(url: &str, what: &str) -> (String, Vec<String>) {
    browse_for(url, what, 5_000)
}

/// [`browse`] with `budget` ms of virtual time (more for avatars whose textures decode off the
/// page's thread: the screenshot is taken when the budget is spent).
pub fn browse_for(url: &str, what: &str, budget: u32) -> (String, Vec<String>) {
    let chromium =
        chromium().expect("Debian's chromium (apt-get install chromium; .ci/run installs it)");
    // one profile per run: Chromium locks its profile, and the tests run browsers in parallel
    // (a profile named by the arguments' lengths was shared, now and then, by two of them, and
    // one wrote no screenshot)
    static RUNS: std::sync::atomic::AtomicUsize = std::sync::atomic::AtomicUsize::new(0);
    let run = RUNS.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
    let profile = scratch(&format!("chromium-{run}"));
    let out = Command::new(chromium)
        .args([
            "--headless",
            "--no-sandbox",
            "--disable-gpu",
            "--use-angle=swiftshader",
            "--enable-unsafe-swiftshader",
            "--disable-quic",
            "--no-first-run",
            "--disable-background-networking",
            "--disable-component-update",
            "--disable-sync",
            "--window-size=1280,720",
            "--enable-logging=stderr",
            "--v=0",
        ])
        .arg(format!("--virtual-time-budget={budget}"))
        .arg(format!("--user-data-dir={}", profile.display()))
        .arg(what)
        .arg(url)
        .output()
        .unwrap();
    // (SwiftShader's notes on reading pixels back for the screenshot are the browser's, not the
    // page's)
    let console = String::from_utf8_lossy(&out.stderr)
        .lines()
        .filter(|l| l.contains(":CONSOLE") && !l.contains("GL Driver Message"))
        .map(str::to_string)
        .collect();
    (String::from_utf8_lossy(&out.stdout).into_owned(), console)
}

/// An RGB screenshot: width, height, pixels.
pub struct Shot(pub usize, pub usize, pub Vec<u8>);

impl Shot {
    pub fn load(path: &Path) -> Shot {
        let decoder = png::Decoder::new(BufReader::new(std::fs::File::open(path).unwrap()));
        let mut reader = decoder.read_info().unwrap();
        let mut buf = vec![0; reader.output_buffer_size().unwrap()];
        let info = reader.next_frame(&mut buf).unwrap();
        let channels = info.color_type.samples();
        let rgb = buf[..info.buffer_size()]
            .chunks(channels)
            .flat_map(|p| [p[0], p[1], p[2]])
            .collect();
        Shot(info.width as usize, info.height as usize, rgb)
    }

    pub fn px(&self, x: usize, y: usize) -> [u8; 3] {
        let i = 3 * (y * self.0 + x);
        [self.2[i], self.2[i + 1], self.2[i + 2]]
    }

    /// The share of pixels in the box (x0..x1, y0..y1) for which `differs` holds.
    pub fn share(
        &self,
        (x0, x1, y0, y1): (usize, usize, usize, usize),
        differs: impl Fn(usize, usize) -> bool,
    ) -> f64 {
        let hits = (y0..y1)
            .flat_map(|y| (x0..x1).map(move |x| (x, y)))
            .filter(|&(x, y)| differs(x, y))
            .count();
        hits as f64 / ((x1 - x0) * (y1 - y0)) as f64
    }
}

pub fn far([a, b, c]: [u8; 3], [x, y, z]: [u8; 3]) -> bool {
    a.abs_diff(x).max(b.abs_diff(y)).max(c.abs_diff(z)) > 24
}
