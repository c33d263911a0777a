//! Recording the realized motion of `bmlr run` on the virtual clock: every character's pose once
//! per frame, written at the end as BVH or glTF (one character) or as a frames file (all of them).

use std::path::Path;

use bml_realizer::body::{Pose, Skeleton};
use bml_realizer::engine::CharacterPose;
use bml_realizer::realizer::Realizer;

/// The frame period, the next frame's time, and every character's pose in each frame so far
/// (which characters a file shows is decided at the end).
pub struct Recording {
    pub period: f64,
    pub next: f64,
    /// (time, the poses of the characters that had one).
    pub frames: Vec<(f64, Vec<CharacterPose>)>,
    fps: f64,
}

impl Recording {
    /// Nothing recorded yet; frames every 1/`fps` seconds from 0.
    pub fn new(fps: f64) -> Recording {
        Recording {
            period: 1.0 / fps,
            next: 0.0,
            frames: Vec::new(),
            fps,
        }
    }

    /// Writes the BVH of the character `asked` (or the one chosen by [`recorded_character`]).
    /// An error has the exit code.
    pub fn write_bvh(
        &self,
        realizer: &Realizer,
        path: &Path,
        asked: Option<&str>,
    ) -> Result<(), (u8, String)> {
        let poses: Vec<Pose> = (self.one_character(realizer, asked, "--bvh")?.into_iter())
            .map(|p| p.pose)
            .collect();
        let skeleton = Skeleton::adult();
        write_file(
            path,
            bml_realizer::body::bvh::write(&skeleton, &poses, self.fps).as_bytes(),
        )?;
        eprintln!(
            "wrote {} ({} frames at {} fps, {} joints)",
            path.display(),
            poses.len(),
            self.fps,
            skeleton.len()
        );
        Ok(())
    }

    /// Writes the glTF mannequin of the character `asked` (or the one chosen as for BVH) with its
    /// motion. An error has the exit code.
    pub fn write_gltf(
        &self,
        realizer: &Realizer,
        path: &Path,
        asked: Option<&str>,
    ) -> Result<(), (u8, String)> {
        let poses = self.one_character(realizer, asked, "--gltf")?;
        let frames: Vec<(f64, &Pose)> = (self.frames.iter().zip(&poses))
            .map(|((t, _), p)| (*t, &p.pose))
            .collect();
        let skeleton = Skeleton::adult();
        let glb = bml_realizer::body::gltf::write(&skeleton, &frames);
        write_file(path, &glb)?;
        eprintln!(
            "wrote {} ({} frames at {} fps, {} joints, {} kB)",
            path.display(),
            frames.len(),
            self.fps,
            skeleton.len(),
            glb.len() / 1024
        );
        Ok(())
    }

    /// The frames of the one character a BVH or glTF file (`flag`) shows.
    fn one_character(
        &self,
        realizer: &Realizer,
        asked: Option<&str>,
        flag: &str,
    ) -> Result<Vec<CharacterPose>, (u8, String)> {
        let character =
            recorded_character(realizer, asked, flag).map_err(|e| (1, format!("{flag}: {e}")))?;
        Ok(self.poses_of(&character))
    }

    /// Writes the frames of every character that received blocks (see [`Recording::lines`]).
    /// An error has the exit code.
    pub fn write_frames(&self, realizer: &Realizer, path: &Path) -> Result<(), (u8, String)> {
        let ids = received(realizer);
        let (header, lines) = self.lines(&ids);
        let mut text = header;
        text.push('\n');
        for line in lines {
            text.push_str(&line);
            text.push('\n');
        }
        write_file(path, text.as_bytes())?;
        eprintln!(
            "wrote {} ({} frames at {} fps, {} character(s))",
            path.display(),
            self.frames.len(),
            self.fps,
            ids.len()
        );
        Ok(())
    }

    /// The frames file's header line and its frame lines, showing the characters `ids` (the
    /// default character is `""`).
    pub fn lines(&self, ids: &[&str]) -> (String, Vec<String>) {
        let skeleton = Skeleton::adult();
        let header = bml_realizer::body::frames::header(&skeleton, self.fps, ids);
        let per_character: Vec<Vec<CharacterPose>> = ids.iter().map(|c| self.poses_of(c)).collect();
        let lines = (self.frames.iter().enumerate())
            .map(|(k, (time, _))| {
                let poses: Vec<bml_realizer::body::frames::Character> = (ids.iter())
                    .zip(&per_character)
                    .map(|(&id, p)| (id, &p[k].pose, p[k].clamped.as_slice(), Some(&p[k].face)))
                    .collect();
                bml_realizer::body::frames::line(&skeleton, *time, &poses)
            })
            .collect();
        (header, lines)
    }

    /// The poses of `character` ("" the default one), frame by frame (the rest pose where a
    /// frame has none for it).
    fn poses_of(&self, character: &str) -> Vec<CharacterPose> {
        let rest = CharacterPose {
            character: Some(character.to_string()),
            pose: Pose::rest(&Skeleton::adult()),
            clamped: Vec::new(),
            face: bml_realizer::face::Face::neutral(bml_realizer::face::FaceModel::default_model()),
        };
        self.frames
            .iter()
            .map(|(_, f)| {
                f.iter()
                    .find(|p| p.character.as_deref().unwrap_or("") == character)
                    .map_or_else(|| rest.clone(), |p| p.clone())
            })
            .collect()
    }
}

/// Every character that received blocks, sorted by id (the default character is `""`).
pub fn received(realizer: &Realizer) -> Vec<&str> {
    let mut ids: Vec<&str> = (realizer.characters())
        .filter(|(_, m)| m.received_blocks())
        .map(|(c, _)| c)
        .collect();
    ids.sort_unstable();
    ids
}

/// Writes `bytes` to `path`; an error has exit code 2.
fn write_file(path: &Path, bytes: &[u8]) -> Result<(), (u8, String)> {
    std::fs::write(path, bytes).map_err(|e| (2, format!("{}: cannot write: {e}", path.display())))
}

/// The character a BVH or glTF file (`flag`) shows: `asked` (--character) if it received blocks, else the only one
/// that did (or, of several, the default one, else the first by id, with a note on stderr).
/// An error names the characters that received blocks.
fn recorded_character(
    realizer: &Realizer,
    asked: Option<&str>,
    flag: &str,
) -> Result<String, String> {
    let received = received(realizer);
    let named = |list: &[&str]| -> String {
        let names: Vec<String> = list
            .iter()
            .map(|c| {
                if c.is_empty() {
                    "the default character".into()
                } else {
                    format!("'{c}'")
                }
            })
            .collect();
        names.join(", ")
    };
    match (asked, received.as_slice()) {
        (Some(c), list) if list.contains(&c) => Ok(c.to_string()),
        (_, []) => Err("no character received a block: the file would show nothing move".into()),
        (Some(c), list) => Err(format!(
            "character '{c}' received no blocks (these did: {}); choose one with --character",
            named(list)
        )),
        (None, [one]) => Ok(one.to_string()),
        (None, list) => {
            let c = if list.contains(&"") { "" } else { list[0] };
            eprintln!(
                "bmlr run: several characters received blocks ({}); {flag} shows {} (choose with --character)",
                named(list),
                named(&[c])
            );
            Ok(c.to_string())
        }
    }
}
