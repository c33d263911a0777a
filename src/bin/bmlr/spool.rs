//! The frames file written as the run goes (`bmlr run --frames`): each frame's characters go to
//! a spool file beside the output as they are made, so a long run of a large crowd keeps one
//! frame in memory, not all of them. The header names the characters that received blocks,
//! which is known only at the end; so at the end the spool is copied into the frames file,
//! frame by frame, each line with those characters in order (the rest pose for one that had no
//! pose in a frame), the same bytes as building the file from frames kept in memory.

use std::collections::HashMap;
use std::fs::File;
use std::io::{BufRead, BufReader, BufWriter, Write};
use std::path::{Path, PathBuf};

use bml_realizer::character::body::Skeleton;
use bml_realizer::character::frames::{self, Detail};
use bml_realizer::engines::interface::CharacterPose;

/// Frame lines on their way to a frames file.
pub struct FrameSpool {
    /// The spool: per frame a line `#` and the time's bits in hex, then a line per character:
    /// its id as a JSON string, a tab, its JSON object.
    part: PathBuf,
    out: Option<BufWriter<File>>,
    skeleton: Skeleton,
    detail: Detail,
    /// The first error writing the spool (reported at the end; the run goes on).
    failed: Option<String>,
}

impl FrameSpool {
    /// A spool for the frames file `target` (`TARGET.part` beside it), or why it cannot be made.
    pub fn create(target: &Path, detail: Detail) -> Result<FrameSpool, String> {
        let mut name = target.as_os_str().to_owned();
        name.push(".part");
        let part = PathBuf::from(name);
        let file =
            File::create(&part).map_err(|e| format!("{}: cannot write: {e}", target.display()))?;
        Ok(FrameSpool {
            part,
            out: Some(BufWriter::new(file)),
            skeleton: Skeleton::adult(),
            detail,
            failed: None,
        })
    }

    /// Adds the frame at `time` with `poses` (the characters that had one).
    pub fn push(&mut self, time: f64, poses: &[CharacterPose]) {
        let Some(out) = self.out.as_mut() else {
            return;
        };
        let mut write = || -> std::io::Result<()> {
            writeln!(out, "#{:016x}", time.to_bits())?;
            for p in poses {
                let id = serde_json::to_string(p.character.as_deref().unwrap_or(""))?;
                let part = frames::character(&self.skeleton, p, self.detail);
                writeln!(out, "{id}\t{part}")?;
            }
            Ok(())
        };
        if let Err(e) = write() {
            self.failed = Some(e.to_string());
            self.out = None;
        }
    }

    /// Writes the frames file `target` at `fps` showing `ids` (in that order) from the spool,
    /// each as `rest` has it (in the same order) in a frame in which it had no pose, and
    /// removes the spool. Returns the number of frames.
    pub fn finish(
        mut self,
        target: &Path,
        fps: f64,
        ids: &[&str],
        rest: &[CharacterPose],
    ) -> Result<usize, String> {
        let cannot = |e: &dyn std::fmt::Display| format!("{}: cannot write: {e}", target.display());
        let spooled = self.out.take().map(BufWriter::into_inner);
        if let Some(e) = &self.failed {
            return Err(cannot(e));
        }
        let Some(Ok(_)) = spooled else {
            return Err(cannot(&"the spool could not be flushed"));
        };
        let rest: Vec<String> = (rest.iter())
            .map(|p| frames::character(&self.skeleton, p, self.detail))
            .collect();
        let file = File::create(target).map_err(|e| cannot(&e))?;
        let mut out = BufWriter::new(file);
        let reader = BufReader::new(File::open(&self.part).map_err(|e| cannot(&e))?);
        let copy = || -> std::io::Result<usize> {
            writeln!(
                out,
                "{}",
                frames::header(&self.skeleton, fps, ids, self.detail)
            )?;
            let mut frame: Option<(f64, HashMap<String, String>)> = None;
            let mut count = 0;
            for line in reader.lines() {
                let line = line?;
                if let Some(bits) = line.strip_prefix('#') {
                    if let Some((time, parts)) = frame.take() {
                        writeln!(out, "{}", assemble(time, &parts, ids, &rest))?;
                        count += 1;
                    }
                    let bits = u64::from_str_radix(bits, 16).map_err(std::io::Error::other)?;
                    frame = Some((f64::from_bits(bits), HashMap::new()));
                } else if let (Some((_, parts)), Some((id, part))) =
                    (frame.as_mut(), line.split_once('\t'))
                {
                    let id: String = serde_json::from_str(id)?;
                    parts.insert(id, part.to_string());
                }
            }
            if let Some((time, parts)) = frame.take() {
                writeln!(out, "{}", assemble(time, &parts, ids, &rest))?;
                count += 1;
            }
            out.flush()?;
            Ok(count)
        };
        copy().map_err(|e| cannot(&e))
    }
}

impl Drop for FrameSpool {
    fn drop(&mut self) {
        self.out = None;
        let _ = std::fs::remove_file(&self.part);
    }
}

/// One frame line showing `ids` in order, from the frame's `parts` (id, object) or `rest`.
fn assemble(time: f64, parts: &HashMap<String, String>, ids: &[&str], rest: &[String]) -> String {
    let shown: Vec<(&str, &str)> = (ids.iter().zip(rest))
        .map(|(&id, rest)| (id, parts.get(id).unwrap_or(rest).as_str()))
        .collect();
    frames::line_of(time, &shown)
}

#[cfg(test)]
mod tests {
    use super::*;
    use bml_realizer::character::body::Pose;
    use bml_realizer::character::face::{Face, FaceModel};

    fn posed(id: &str, turn: f32, skeleton: &Skeleton) -> CharacterPose {
        let mut pose = Pose::rest(skeleton);
        pose.rotate(
            skeleton.joint("l_elbow").unwrap(),
            glam::Quat::from_rotation_x(turn),
        );
        CharacterPose {
            character: Some(id.to_string()),
            pose,
            clamped: Vec::new(),
            face: Face::neutral(FaceModel::default_model()),
            sounds: Vec::new(),
            events: Vec::new(),
            contacts: Some([true, false]),
        }
    }

    #[test]
    fn the_spooled_file_is_the_file_built_in_memory() {
        let skeleton = Skeleton::adult();
        let target = std::env::temp_dir().join(format!("bmlr-{}-spool.jsonl", std::process::id()));
        let frames_in = [
            (
                0.0,
                vec![posed("b", 0.1, &skeleton), posed("a\t\"x", 0.2, &skeleton)],
            ),
            (1.0 / 60.0, vec![posed("b", 0.3, &skeleton)]),
        ];
        let ids = ["a\t\"x", "b"];
        let mut spool = FrameSpool::create(&target, Detail::Full).unwrap();
        for (t, poses) in &frames_in {
            spool.push(*t, poses);
        }
        let rest = posed("a\t\"x", -0.4, &skeleton);
        let rests = [rest.clone(), posed("b", 0.0, &skeleton)];
        assert_eq!(spool.finish(&target, 60.0, &ids, &rests).unwrap(), 2);
        let mut expected = frames::header(&skeleton, 60.0, &ids, Detail::Full) + "\n";
        for (t, poses) in &frames_in {
            let a = poses
                .iter()
                .find(|p| p.character.as_deref() == Some(ids[0]));
            let line = frames::line(
                &skeleton,
                *t,
                &[(ids[0], a.unwrap_or(&rest)), ("b", &poses[0])],
            );
            expected += &(line + "\n");
        }
        assert_eq!(std::fs::read_to_string(&target).unwrap(), expected);
        let mut part = target.as_os_str().to_owned();
        part.push(".part");
        assert!(!Path::new(&part).exists(), "the spool is removed");
        std::fs::remove_file(&target).unwrap();
    }

    #[test]
    fn a_spool_that_cannot_be_made_names_the_file() {
        let e = FrameSpool::create(Path::new("/no/such/dir/f.jsonl"), Detail::Roots).err();
        assert!(e.unwrap().starts_with("/no/such/dir/f.jsonl: cannot write"));
    }
}
