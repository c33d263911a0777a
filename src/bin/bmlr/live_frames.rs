//! The frames file of a served realizer (`bmlr serve … --frames OUT.jsonl`): the same format
//! as `bmlr run --frames` (docs/cli.md, "Frames"), written as the frames happen on the
//! real-time clock — the header first, then a line per frame — and flushed at least twice a
//! second, at `--until` and when the process is told to stop (SIGTERM, SIGINT). The header
//! names the characters shown, which must be known at the start: the `--characters` served, or
//! else the world file's characters and the default one (`""`). A character without a pose in a
//! frame is shown standing where the world places it. The header is written when the clock
//! starts and says the POSIX time of its time 0 (`posix_zero`), so that the frames of several
//! realizers can be put on one clock; with `--frames-roots` the lines carry only where each
//! character stands.

use std::fs::File;
use std::io::{BufWriter, Write};
use std::path::{Path, PathBuf};
use std::time::Instant;

use bml_realizer::character::body::Skeleton;
use bml_realizer::character::frames::{self, Detail};
use bml_realizer::engines::interface::CharacterPose;
use bml_realizer::realizer::Realizer;

use crate::record::Recording;

/// A frames file being written.
pub struct LiveFrames {
    path: PathBuf,
    out: BufWriter<File>,
    ids: Vec<String>,
    rest: Vec<String>,
    skeleton: Skeleton,
    flushed: Instant,
    count: usize,
    fps: f64,
    /// The time of the last frame written (frames closer than a tenth short of 1/fps to it
    /// are skipped: the loop also ticks when messages arrive).
    last: f64,
    /// The first error writing (said at the end; serving goes on).
    failed: Option<String>,
    /// What each character's line carries.
    detail: Detail,
    /// The header, until written (when the clock starts, or at the first frame).
    header: Option<(Vec<String>, f64)>,
}

impl LiveFrames {
    /// Starts `path` showing `ids` (`""` the default character), standing as `realizer`'s world
    /// places them, at a nominal `fps`; or why the file cannot be written.
    pub fn create(
        path: &Path,
        ids: Vec<String>,
        realizer: &Realizer,
        fps: f64,
        detail: Detail,
    ) -> Result<LiveFrames, String> {
        let cannot = |e: std::io::Error| format!("{}: cannot write: {e}", path.display());
        let out = BufWriter::new(File::create(path).map_err(cannot)?);
        let skeleton = Skeleton::adult();
        let places = Recording::new(fps).placed(realizer.world());
        let rest = (ids.iter())
            .map(|id| frames::character(&skeleton, &places.standing(id), detail))
            .collect();
        Ok(LiveFrames {
            path: path.to_path_buf(),
            out,
            header: Some((ids.clone(), fps)),
            ids,
            rest,
            skeleton,
            flushed: Instant::now(),
            count: 0,
            fps,
            last: f64::NEG_INFINITY,
            failed: None,
            detail,
        })
    }

    /// Writes the header, saying that the clock's time 0 was `posix_zero` (POSIX seconds) if
    /// known; the header is written once.
    pub fn start_clock(&mut self, posix_zero: Option<f64>) {
        let Some((ids, fps)) = self.header.take() else {
            return;
        };
        let names: Vec<&str> = ids.iter().map(String::as_str).collect();
        let line = frames::header_on_clock(&self.skeleton, fps, &names, self.detail, posix_zero);
        let written = writeln!(self.out, "{line}").and_then(|_| self.out.flush());
        if let Err(e) = written {
            self.failed = Some(e.to_string());
        }
    }

    /// Writes the frame at `time` from `poses`, unless one was written less than about 1/fps
    /// before.
    pub fn push(&mut self, time: f64, poses: &[CharacterPose]) {
        self.start_clock(None);
        if self.failed.is_some() || time - self.last < 0.9 / self.fps {
            return;
        }
        self.last = time;
        let parts: Vec<String> = (self.ids.iter().zip(&self.rest))
            .map(|(id, rest)| {
                (poses.iter())
                    .find(|p| p.character.as_deref().unwrap_or("") == id)
                    .map_or_else(
                        || rest.clone(),
                        |p| frames::character(&self.skeleton, p, self.detail),
                    )
            })
            .collect();
        let shown: Vec<(&str, &str)> = (self.ids.iter().zip(&parts))
            .map(|(id, p)| (id.as_str(), p.as_str()))
            .collect();
        let mut write = || -> std::io::Result<()> {
            writeln!(self.out, "{}", frames::line_of(time, &shown))?;
            if self.flushed.elapsed().as_secs_f64() >= 0.5 {
                self.out.flush()?;
                self.flushed = Instant::now();
            }
            Ok(())
        };
        match write() {
            Ok(()) => self.count += 1,
            Err(e) => self.failed = Some(e.to_string()),
        }
    }

    /// Flushes and says what was written; an error names the file.
    pub fn finish(mut self) -> Result<(), String> {
        self.start_clock(None);
        if let Some(e) = self.failed.take() {
            return Err(format!("{}: cannot write: {e}", self.path.display()));
        }
        self.out
            .flush()
            .map_err(|e| format!("{}: cannot write: {e}", self.path.display()))?;
        eprintln!(
            "wrote {} ({} frames at about {} fps, {} character(s))",
            self.path.display(),
            self.count,
            self.fps,
            self.ids.len()
        );
        Ok(())
    }
}

/// The characters a served realizer's frames show: `characters` (topic levels; `_` is the
/// default character), or else the world's characters and the default one.
pub fn shown(characters: &[String], realizer: &Realizer) -> Vec<String> {
    if !characters.is_empty() {
        return (characters.iter())
            .map(|c| if c == "_" { String::new() } else { c.clone() })
            .collect();
    }
    let mut ids = vec![String::new()];
    ids.extend(realizer.world().placements().map(|(id, _)| id.to_string()));
    ids.sort();
    ids.dedup();
    ids
}

/// The POSIX time (s) of `clock`'s time 0.
pub fn posix_zero(clock: &impl bml_realizer::realizer::clock::Clock) -> f64 {
    let now = std::time::SystemTime::now().duration_since(std::time::UNIX_EPOCH);
    now.map_or(0.0, |d| d.as_secs_f64()) - clock.now()
}
