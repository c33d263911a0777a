//! Recording the realized motion of `bmlr run` on the virtual clock: every character's pose once
//! per frame, written at the end as BVH or glTF (one character) or as a frames file (all of them).

use std::path::Path;

use bml_realizer::character::avatar::{animated_document, animated_glb, scene_glb, Frame};
use bml_realizer::character::body::{Pose, Skeleton};
use bml_realizer::character::frames;
use bml_realizer::character::sound::{SoundEvent, Track};
use bml_realizer::engines::interface::CharacterPose;
use bml_realizer::realizer::Realizer;
use bml_realizer::world::World;

use crate::avatar::{Avatar, Avatars};
use crate::spool::FrameSpool;

/// The frame period, the next frame's time, and every character's pose in each frame so far
/// (which characters a file shows is decided at the end).
pub struct Recording {
    pub period: f64,
    pub next: f64,
    /// How many frames were recorded.
    pub count: usize,
    /// (time, the poses of the characters that had one), when they are kept (BVH, glTF, the
    /// viewer).
    pub frames: Vec<(f64, Vec<CharacterPose>)>,
    keep: bool,
    /// The frames file being written as the run goes.
    spool: Option<FrameSpool>,
    /// Where the world file places characters: one without a pose in a frame stands there.
    places: std::collections::HashMap<String, bml_realizer::world::Placement>,
    fps: f64,
    /// Every sound heard, from every tick (not only the recorded frames: an interrupt's cut
    /// falls between them), and whether it still plays.
    heard: Vec<(String, Track, bool)>,
    /// Sounds that started or stopped since the last recorded frame, by character: the ticks
    /// between frames report them, the next frame carries them.
    pending: Vec<(Option<String>, SoundEvent)>,
}

impl Recording {
    /// Nothing recorded yet; frames every 1/`fps` seconds from 0.
    pub fn new(fps: f64) -> Recording {
        Recording {
            period: 1.0 / fps,
            next: 0.0,
            count: 0,
            frames: Vec::new(),
            keep: true,
            spool: None,
            places: Default::default(),
            fps,
            heard: Vec::new(),
            pending: Vec::new(),
        }
    }

    /// Writes the frames to `spool` as they come; keeps them in memory too only when `keep`.
    pub fn streaming(fps: f64, spool: Option<FrameSpool>, keep: bool) -> Recording {
        Recording {
            spool,
            keep,
            ..Recording::new(fps)
        }
    }

    /// Where character `id` stood when the recording began (the world file's place; the
    /// origin for a character it does not place).
    pub fn start_of(&self, id: &str) -> bml_realizer::world::Placement {
        self.places.get(id).copied().unwrap_or_default()
    }

    /// Notes where `world` places characters (see [`Recording::standing`]).
    pub fn placed(mut self, world: &World) -> Recording {
        self.places = (world.placements())
            .map(|(id, at)| (id.to_string(), at))
            .collect();
        self
    }

    /// Records a frame at `time`: the poses, each with the sound events heard since the last
    /// recorded frame (call [`Recording::observe`] for this tick first).
    pub fn push_frame(&mut self, time: f64, mut poses: Vec<CharacterPose>) {
        for p in &mut poses {
            let (mine, rest): (Vec<_>, Vec<_>) = std::mem::take(&mut self.pending)
                .into_iter()
                .partition(|(c, _)| *c == p.character);
            p.events = mine.into_iter().map(|(_, e)| e).collect();
            self.pending = rest;
        }
        self.count += 1;
        if let Some(spool) = self.spool.as_mut() {
            spool.push(time, &poses);
        }
        if self.keep {
            self.frames.push((time, poses));
        }
    }

    /// Notes the sounds playing at tick `t`: new ones, volume changes, and sounds gone before
    /// their end (cut there).
    pub fn observe(&mut self, t: f64, poses: &[CharacterPose]) {
        for p in poses {
            self.pending
                .extend(p.events.iter().map(|e| (p.character.clone(), e.clone())));
        }
        let playing: Vec<&bml_realizer::character::sound::Playing> =
            poses.iter().flat_map(|p| &p.sounds).collect();
        for s in &playing {
            let cut = (s.stop < s.start + s.length() - 1e-6).then_some(s.stop);
            let known = (self.heard.iter_mut())
                .find(|(id, tr, on)| *on && *id == s.id && tr.start == s.start);
            match known {
                Some((_, tr, _)) => {
                    // a streamed sound grows while it plays
                    tr.audio = s.audio.clone();
                    if tr.volume.last().is_none_or(|v| v.1 != s.volume) {
                        tr.volume.push((t, s.volume));
                    }
                    tr.cut = cut;
                }
                None => self.heard.push((
                    s.id.clone(),
                    Track {
                        start: s.start,
                        audio: s.audio.clone(),
                        volume: vec![(t, s.volume)],
                        cut,
                    },
                    true,
                )),
            }
        }
        for (id, tr, on) in self.heard.iter_mut().filter(|h| h.2) {
            if !playing.iter().any(|s| s.id == *id && s.start == tr.start) {
                *on = false;
                if tr.cut.is_none() && t < tr.start + tr.length() - 1e-6 {
                    tr.cut = Some(t);
                }
            }
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
            bml_realizer::character::body::bvh::write(&skeleton, &poses, self.fps).as_bytes(),
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

    /// Writes `avatar` with the motion and face of the character `asked` (or of the one that
    /// received blocks); without one asked among several, a scene of every character's avatar
    /// (mannequins without avatars), each where it stands. An error has the exit code.
    pub fn write_gltf(
        &self,
        realizer: &Realizer,
        path: &Path,
        asked: Option<&str>,
        avatar: Option<&Avatars>,
    ) -> Result<(), (u8, String)> {
        let everyone = received(realizer);
        let ids: Vec<String> = match asked {
            None if everyone.len() > 1 => everyone.into_iter().map(str::to_string).collect(),
            _ => vec![recorded_character(realizer, asked, "--gltf")
                .map_err(|e| (1, format!("--gltf: {e}")))?],
        };
        if let ([id], Some(avatars)) = (ids.as_slice(), avatar) {
            return self.write_avatar(path, id, avatars.of(id));
        }
        if let Some(avatars) = avatar {
            return self.write_avatars(path, &ids, avatars);
        }
        let poses: Vec<Vec<CharacterPose>> = ids.iter().map(|c| self.poses_of(c)).collect();
        let frames: Vec<Vec<(f64, &Pose)>> = (poses.iter())
            .map(|p| {
                (self.frames.iter().zip(p))
                    .map(|((t, _), p)| (*t, &p.pose))
                    .collect()
            })
            .collect();
        let scene: Vec<(&str, &[(f64, &Pose)])> = (ids.iter().zip(&frames))
            .map(|(id, f)| (id.as_str(), f.as_slice()))
            .collect();
        let skeleton = Skeleton::adult();
        let glb = bml_realizer::character::body::gltf::write_scene(&skeleton, &scene);
        write_file(path, &glb)?;
        eprintln!(
            "wrote {} ({} frames at {} fps, {} joints, {} character{}, {} kB)",
            path.display(),
            self.frames.len(),
            self.fps,
            skeleton.len(),
            ids.len(),
            if ids.len() == 1 { "" } else { "s" },
            glb.len() / 1024
        );
        Ok(())
    }

    /// Writes `avatar` moving as character `id` did.
    fn write_avatar(&self, path: &Path, id: &str, avatar: &Avatar) -> Result<(), (u8, String)> {
        let glb = self.avatar_glb(id, avatar);
        write_file(path, &glb)?;
        eprintln!(
            "wrote {} ({} on {}, {} frames at {} fps, {} kB)",
            path.display(),
            if id.is_empty() { "the character" } else { id },
            avatar.model.file,
            self.frames.len(),
            self.fps,
            glb.len() / 1024
        );
        Ok(())
    }

    /// Writes one scene of the characters `ids`, each on its avatar, moving as it did.
    fn write_avatars(
        &self,
        path: &Path,
        ids: &[String],
        avatars: &Avatars,
    ) -> Result<(), (u8, String)> {
        let parts = (ids.iter())
            .map(|id| {
                let avatar = avatars.of(id);
                let poses = self.poses_of(id);
                let frames = self.avatar_frames(&poses);
                let retarget = avatar.placed(self.start_of(id));
                let (doc, bin) = animated_document(&avatar.model, &retarget, &frames, id);
                (id.clone(), doc, bin)
            })
            .collect();
        let glb = scene_glb(parts, "bml");
        write_file(path, &glb)?;
        eprintln!(
            "wrote {} ({} characters on their avatars, {} frames at {} fps, {} kB)",
            path.display(),
            ids.len(),
            self.frames.len(),
            self.fps,
            glb.len() / 1024
        );
        Ok(())
    }

    /// The avatar export's frames of one character's `poses`.
    fn avatar_frames<'a>(&self, poses: &'a [CharacterPose]) -> Vec<Frame<'a>> {
        (self.frames.iter().zip(poses))
            .map(|((t, _), p)| Frame {
                time: *t,
                pose: &p.pose,
                face: &p.face,
            })
            .collect()
    }

    /// `avatar` moving as character `id` did, as GLB bytes.
    pub fn avatar_glb(&self, id: &str, avatar: &Avatar) -> Vec<u8> {
        let poses = self.poses_of(id);
        let frames = self.avatar_frames(&poses);
        let name = if id.is_empty() { "bml" } else { id };
        animated_glb(
            &avatar.model,
            &avatar.placed(self.start_of(id)),
            &frames,
            name,
        )
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

    /// Writes the frames of every character that received blocks from the spool (see
    /// [`FrameSpool`]); without one, from the frames kept. An error has the exit code.
    pub fn write_frames(&mut self, realizer: &Realizer, path: &Path) -> Result<(), (u8, String)> {
        let ids = received(realizer);
        let count = match self.spool.take() {
            Some(spool) => {
                let rest: Vec<CharacterPose> = ids.iter().map(|id| self.standing(id)).collect();
                spool
                    .finish(path, self.fps, &ids, &rest)
                    .map_err(|e| (2, e))?
            }
            None => {
                let (header, lines) = self.lines(&ids);
                let mut text = header;
                text.push('\n');
                for line in lines {
                    text.push_str(&line);
                    text.push('\n');
                }
                write_file(path, text.as_bytes())?;
                self.frames.len()
            }
        };
        eprintln!(
            "wrote {} ({count} frames at {} fps, {} character(s))",
            path.display(),
            self.fps,
            ids.len()
        );
        Ok(())
    }

    /// The frames file's header line and its frame lines, showing the characters `ids` (the
    /// default character is `""`).
    pub fn lines(&self, ids: &[&str]) -> (String, Vec<String>) {
        let skeleton = Skeleton::adult();
        let header = frames::header(&skeleton, self.fps, ids, frames::Detail::Full);
        let per_character: Vec<Vec<CharacterPose>> = ids.iter().map(|c| self.poses_of(c)).collect();
        let lines = (self.frames.iter().enumerate())
            .map(|(k, (time, _))| {
                let poses: Vec<(&str, &CharacterPose)> = (ids.iter())
                    .zip(&per_character)
                    .map(|(&id, p)| (id, &p[k]))
                    .collect();
                frames::line(&skeleton, *time, &poses)
            })
            .collect();
        (header, lines)
    }

    /// Writes the sound of the run (every character's speech and clips) as a WAV file, the
    /// clips where they played, from time 0 to the end. An error has the exit code.
    pub fn write_wav(&self, realizer: &Realizer, path: &Path) -> Result<(), (u8, String)> {
        let (bytes, clips, seconds, rate) = self
            .wav(realizer)
            .map_err(|e| (2, format!("{}: {e}", path.display())))?;
        write_file(path, &bytes)?;
        eprintln!(
            "wrote {} ({clips} clip(s), {seconds:.3} s at {rate} Hz)",
            path.display()
        );
        Ok(())
    }

    /// The run's sound as WAV bytes, with the number of clips, the length and the rate.
    pub fn wav(&self, realizer: &Realizer) -> Result<(Vec<u8>, usize, f64, u32), String> {
        let tracks: Vec<Track> = self.heard.iter().map(|(_, t, _)| t.clone()).collect();
        let rate = tracks.iter().map(|t| t.audio.rate).max().unwrap_or(16_000);
        let end = (tracks.iter())
            .map(|t| {
                t.cut.map_or(t.start + t.length(), |c| {
                    c + bml_realizer::character::sound::CUT_FADE
                })
            })
            .fold(realizer.now(), f64::max);
        let samples = bml_realizer::character::sound::mix(&tracks, rate, end);
        let bytes = bml_realizer::character::sound::wav(&samples, rate)?;
        Ok((
            bytes,
            tracks.len(),
            samples.len() as f64 / f64::from(rate),
            rate,
        ))
    }

    /// Whether any sound was heard.
    pub fn heard_any(&self) -> bool {
        !self.heard.is_empty()
    }

    /// The poses of `character` ("" the default one), frame by frame (standing where the
    /// world places it, at rest, where a frame has none for it).
    pub fn poses_of(&self, character: &str) -> Vec<CharacterPose> {
        let rest = self.standing(character);
        self.frames
            .iter()
            .map(|(_, f)| {
                f.iter()
                    .find(|p| p.character.as_deref().unwrap_or("") == character)
                    .map_or_else(|| rest.clone(), |p| p.clone())
            })
            .collect()
    }

    /// Per character of `ids`, its body in every frame, borrowed (`rests`, in the order of
    /// `ids`, where a frame has none for it): for a crowd, whose poses are too many to copy.
    pub fn bodies<'a>(&'a self, ids: &[&str], rests: &'a [CharacterPose]) -> Vec<Vec<&'a Pose>> {
        let mut out: Vec<Vec<&Pose>> = vec![Vec::with_capacity(self.frames.len()); ids.len()];
        for (_, poses) in &self.frames {
            let by_id: std::collections::HashMap<&str, &Pose> = (poses.iter())
                .map(|p| (p.character.as_deref().unwrap_or(""), &p.pose))
                .collect();
            for ((id, rest), list) in ids.iter().zip(rests).zip(&mut out) {
                list.push(by_id.get(id).copied().unwrap_or(&rest.pose));
            }
        }
        out
    }

    /// `character` at rest where the world places it, for a frame in which it has no pose.
    pub fn standing(&self, character: &str) -> CharacterPose {
        let mut pose = Pose::rest(&Skeleton::adult());
        if let Some(at) = self.places.get(character) {
            pose.root = at.to_world(pose.root);
            pose.rotations[0] = at.rotation() * pose.rotations[0];
        }
        CharacterPose {
            character: Some(character.to_string()),
            pose,
            clamped: Vec::new(),
            face: bml_realizer::character::face::Face::neutral(
                bml_realizer::character::face::FaceModel::default_model(),
            ),
            sounds: Vec::new(),
            events: Vec::new(),
            contacts: None,
        }
    }
}

/// Every character that received blocks, or moved without (a character placed by the world
/// file that stepped aside for a walker), sorted by id (the default character is `""`).
pub fn received(realizer: &Realizer) -> Vec<&str> {
    let mut ids: Vec<&str> = (realizer.characters())
        .filter(|(_, m)| m.received_blocks() || m.moved())
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
