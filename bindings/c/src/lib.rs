//! `libbmlr`: the realizer behind a C ABI, for C and C++ hosts, Unity (`[DllImport]`) and
//! Unreal (an external module). A host makes a realizer from JSON options, hands it BML
//! blocks, ticks it with its own clock, and after each tick polls the feedback (one BML 1.0
//! feedback element a call, in the JSON-lines form of `bmlr run --format jsonl`) and the sound
//! events, and reads each character's pose (local joint rotations in the skeleton's joint
//! order, quaternions x y z w), root (world position and rotation) and ARKit blendshape
//! weights as flat float arrays. Every call returns a status (`BMLR_OK` is 0); a failure
//! leaves a sentence in `bmlr_last_error()` (per thread); no panic crosses the boundary. The
//! header `include/bmlr.h` is generated from this file by cbindgen (`tests/header.rs` fails
//! when the committed one is stale). See `docs/embedding.md`.
//!
//! A realizer is `Send` (a host may create it on one thread and use it on another) but not
//! `Sync`: one thread at a time.

#![allow(non_camel_case_types)]

mod status;
mod stream;

use std::collections::VecDeque;
use std::ffi::{c_char, c_int, CString};

use bml_realizer::character::body::Skeleton;
use bml_realizer::character::face::ARKIT;
use bml_realizer::engines::interface::{CharacterPose, Frame};
use bml_realizer::realizer::Realizer;

pub use status::bmlr_status;
use status::{guard, out, text, Failure};
pub use stream::{bmlr_end_audio, bmlr_open_stream, bmlr_push_audio};

/// A realizer with what a host polls from it. Opaque to C.
pub struct bmlr_realizer {
    realizer: Realizer,
    /// Feedback not yet taken, JSON lines.
    feedback: VecDeque<String>,
    /// Sound events not yet taken, JSON lines.
    sounds: VecDeque<String>,
    /// The last tick's frame.
    frame: Option<Frame>,
    /// The frame rate of `bmlr_step` (option `fps`), and the steps taken.
    fps: f64,
    steps: u64,
    joint_names: Vec<CString>,
    morph_names: Vec<CString>,
}

/// The skeleton every character has (the realizer's default adult).
fn skeleton() -> Skeleton {
    Skeleton::adult()
}

/// The realizer behind `r`.
fn get<'a>(r: *mut bmlr_realizer) -> Result<&'a mut bmlr_realizer, Failure> {
    out(r, "the realizer")
}

impl bmlr_realizer {
    /// Advances to `now` and queues the frame's feedback and sound events.
    fn tick(&mut self, now: f64) {
        let r = self;
        // the last frame goes first: its memory is reused for the new one (kept alive, it
        // made a C tick 9.4 µs against the Rust 6.5 µs: benches/tick.rs)
        r.frame = None;
        let frame = r.realizer.tick(now);
        let format = bml_realizer::language::feedback::Format::Jsonl;
        r.feedback
            .extend(frame.feedback.iter().map(|f| format.encode(f)));
        for p in &frame.poses {
            for e in &p.events {
                let event = serde_json::json!({
                    "character": p.character.as_deref().unwrap_or(""),
                    "kind": if e.start { "audio-start" } else { "audio-stop" },
                    "id": e.id,
                    "offset": e.offset,
                });
                r.sounds.push_back(event.to_string());
            }
        }
        r.frame = Some(frame);
    }

    /// Character `id`'s pose in the last frame (NULL or "": the default character).
    ///
    /// # Safety
    /// `id` is NULL or a NUL-terminated string.
    unsafe fn character(&self, id: *const c_char) -> Result<&CharacterPose, Failure> {
        let id = if id.is_null() {
            ""
        } else {
            // SAFETY: the caller's contract
            unsafe { text(id, "the character")? }
        };
        let frame = self.frame.as_ref().ok_or((
            bmlr_status::BMLR_ERR_CHARACTER,
            "no frame yet: call bmlr_tick first".to_string(),
        ))?;
        frame.character(id).ok_or_else(|| {
            let known: Vec<&str> = (frame.poses.iter())
                .map(|p| p.character.as_deref().unwrap_or(""))
                .collect();
            (
                bmlr_status::BMLR_ERR_CHARACTER,
                format!("no character '{id}' in the last frame (it has {known:?})"),
            )
        })
    }
}

/// Copies `items` into the caller's `buf` of `n` floats.
fn fill(buf: *mut f32, n: usize, items: impl ExactSizeIterator<Item = f32>) -> Result<(), Failure> {
    let need = items.len();
    if buf.is_null() {
        return Err((bmlr_status::BMLR_ERR_NULL, "the buffer is NULL".into()));
    }
    if n < need {
        return Err((
            bmlr_status::BMLR_ERR_BUFFER,
            format!("the buffer holds {n} floats; {need} are needed"),
        ));
    }
    // SAFETY: `buf` points at `n` >= `need` writable floats by the caller's contract
    let out = unsafe { std::slice::from_raw_parts_mut(buf, need) };
    for (o, v) in out.iter_mut().zip(items) {
        *o = v;
    }
    Ok(())
}

/// Takes the first of `queue` into `buf` (NUL-terminated) if it fits; `*len` is its length in
/// bytes without the NUL (0: the queue is empty).
fn take(
    queue: &mut VecDeque<String>,
    buf: *mut c_char,
    cap: usize,
    len: *mut usize,
) -> Result<(), Failure> {
    let len = out(len, "len")?;
    let Some(first) = queue.front() else {
        *len = 0;
        return Ok(());
    };
    *len = first.len();
    if buf.is_null() || cap < first.len() + 1 {
        return Err((
            bmlr_status::BMLR_ERR_BUFFER,
            format!(
                "the buffer holds {cap} bytes; {} are needed",
                first.len() + 1
            ),
        ));
    }
    // SAFETY: `buf` points at `cap` > len writable bytes by the caller's contract
    let out = unsafe { std::slice::from_raw_parts_mut(buf.cast::<u8>(), first.len() + 1) };
    out[..first.len()].copy_from_slice(first.as_bytes());
    out[first.len()] = 0;
    queue.pop_front();
    Ok(())
}

/// Makes a realizer from `options_json` (NULL or "" for the defaults; see `docs/embedding.md`)
/// into `*out`; free it with `bmlr_free`.
///
/// # Safety
/// `options_json` is NULL or a NUL-terminated string; `out` points at a writable pointer.
#[no_mangle]
pub unsafe extern "C" fn bmlr_new(
    options_json: *const c_char,
    out: *mut *mut bmlr_realizer,
) -> bmlr_status {
    guard(|| {
        let slot = status::out(out, "out")?;
        let options = if options_json.is_null() {
            ""
        } else {
            // SAFETY: the caller's contract
            unsafe { text(options_json, "the options")? }
        };
        let (realizer, fps) = bml_realizer::realizer::from_options(options)
            .map_err(|e| (bmlr_status::BMLR_ERR_OPTIONS, e))?;
        let cstring = |s: &str| CString::new(s).unwrap_or_default();
        let handle = bmlr_realizer {
            realizer,
            feedback: VecDeque::new(),
            sounds: VecDeque::new(),
            frame: None,
            fps,
            steps: 0,
            joint_names: skeleton()
                .joints()
                .iter()
                .map(|j| cstring(&j.name))
                .collect(),
            morph_names: ARKIT.iter().map(|m| cstring(m)).collect(),
        };
        *slot = Box::into_raw(Box::new(handle));
        Ok(())
    })
}

/// Frees a realizer made by `bmlr_new` (NULL: nothing happens).
///
/// # Safety
/// `r` came from `bmlr_new` and is not used after.
#[no_mangle]
pub unsafe extern "C" fn bmlr_free(r: *mut bmlr_realizer) -> bmlr_status {
    guard(|| {
        if !r.is_null() {
            // SAFETY: made by Box::into_raw in bmlr_new, freed once by the caller's contract
            drop(unsafe { Box::from_raw(r) });
        }
        Ok(())
    })
}

/// Hands the realizer one `<bml>` block (UTF-8). A refused block is `BMLR_ERR_BML`; its
/// warning feedback comes with the next tick too.
///
/// # Safety
/// `r` is a live realizer; `bml` a NUL-terminated string.
#[no_mangle]
pub unsafe extern "C" fn bmlr_perform(r: *mut bmlr_realizer, bml: *const c_char) -> bmlr_status {
    guard(|| {
        let r = get(r)?;
        // SAFETY: the caller's contract
        let bml = unsafe { text(bml, "the block")? };
        (r.realizer.perform_bml(bml)).map_err(|e| (bmlr_status::BMLR_ERR_BML, e.to_string()))
    })
}

/// Advances the realizer to `now` (seconds on the host's clock, never going back): what is due
/// happens, the frame is made, its feedback and sound events are queued for polling.
///
/// # Safety
/// `r` is a live realizer.
#[no_mangle]
pub unsafe extern "C" fn bmlr_tick(r: *mut bmlr_realizer, now: f64) -> bmlr_status {
    guard(|| {
        let r = get(r)?;
        if !now.is_finite() {
            return Err((bmlr_status::BMLR_ERR_RANGE, format!("now is {now}")));
        }
        r.tick(now);
        Ok(())
    })
}

/// Advances the realizer by one frame at the options' `fps` (60 when not given): the first
/// step is at time 0, the k-th at k / fps; `*now` (if not NULL) is the step's time. For hosts
/// without a clock of their own; use either this or `bmlr_tick`.
///
/// # Safety
/// `r` is a live realizer; `now` is NULL or points at a writable double.
#[no_mangle]
pub unsafe extern "C" fn bmlr_step(r: *mut bmlr_realizer, now: *mut f64) -> bmlr_status {
    guard(|| {
        let r = get(r)?;
        let t = r.steps as f64 / r.fps;
        r.steps += 1;
        r.tick(t);
        // SAFETY: NULL or a writable double by the caller's contract
        if let Some(now) = unsafe { now.as_mut() } {
            *now = t;
        }
        Ok(())
    })
}

/// When the next thing is due (`*has` 1 and `*at` its time), or `*has` 0 when nothing more is
/// scheduled: a host may stop ticking then.
///
/// # Safety
/// `r` is a live realizer; `at` and `has` point at writable values.
#[no_mangle]
pub unsafe extern "C" fn bmlr_next_event(
    r: *mut bmlr_realizer,
    at: *mut f64,
    has: *mut c_int,
) -> bmlr_status {
    guard(|| {
        let r = get(r)?;
        let (at, has) = (out(at, "at")?, out(has, "has")?);
        let next = r.realizer.next_event();
        *has = c_int::from(next.is_some());
        *at = next.unwrap_or(0.0);
        Ok(())
    })
}

/// Takes the oldest feedback message (one JSON line, NUL-terminated) into `buf` of `cap`
/// bytes; `*len` is its length (0 when none is left). A buffer too small is
/// `BMLR_ERR_BUFFER` with `*len` the length needed (plus 1 for the NUL); the message stays.
///
/// # Safety
/// `r` is a live realizer; `buf` points at `cap` writable bytes; `len` at a writable size.
#[no_mangle]
pub unsafe extern "C" fn bmlr_next_feedback(
    r: *mut bmlr_realizer,
    buf: *mut c_char,
    cap: usize,
    len: *mut usize,
) -> bmlr_status {
    guard(|| take(&mut get(r)?.feedback, buf, cap, len))
}

/// Takes the oldest sound event (`{"character", "kind": "audio-start" | "audio-stop", "id",
/// "offset"}`, one JSON line) as `bmlr_next_feedback` takes feedback.
///
/// # Safety
/// As `bmlr_next_feedback`.
#[no_mangle]
pub unsafe extern "C" fn bmlr_next_audio_event(
    r: *mut bmlr_realizer,
    buf: *mut c_char,
    cap: usize,
    len: *mut usize,
) -> bmlr_status {
    guard(|| take(&mut get(r)?.sounds, buf, cap, len))
}

/// The number of joints of every character's skeleton.
///
/// # Safety
/// `r` is a live realizer; `n` points at a writable size.
#[no_mangle]
pub unsafe extern "C" fn bmlr_joint_count(r: *mut bmlr_realizer, n: *mut usize) -> bmlr_status {
    guard(|| {
        *out(n, "n")? = get(r)?.joint_names.len();
        Ok(())
    })
}

/// Name `i` of `names` (a `what`) into `*name`.
fn name_at(
    names: &[CString],
    i: usize,
    what: &str,
    name: *mut *const c_char,
) -> Result<(), Failure> {
    let n = names.len();
    let s = (names.get(i)).ok_or((bmlr_status::BMLR_ERR_RANGE, format!("{what} {i} of {n}")))?;
    *out(name, "name")? = s.as_ptr();
    Ok(())
}

/// Joint `i`'s H-Anim name into `*name` (valid while the realizer lives).
///
/// # Safety
/// `r` is a live realizer; `name` points at a writable pointer.
#[no_mangle]
pub unsafe extern "C" fn bmlr_joint_name(
    r: *mut bmlr_realizer,
    i: usize,
    name: *mut *const c_char,
) -> bmlr_status {
    guard(|| name_at(&get(r)?.joint_names, i, "joint", name))
}

/// Character `character`'s (NULL or "": the default one) local joint rotations in the last
/// frame, relative to the rest pose, quaternions x y z w in `bmlr_joint_name` order, into
/// `xyzw` of `n` floats (at least 4 × the joint count).
///
/// # Safety
/// `r` is a live realizer; `character` NULL or a NUL-terminated string; `xyzw` points at `n`
/// writable floats.
#[no_mangle]
pub unsafe extern "C" fn bmlr_pose(
    r: *mut bmlr_realizer,
    character: *const c_char,
    xyzw: *mut f32,
    n: usize,
) -> bmlr_status {
    guard(|| {
        // SAFETY: the caller's contract
        let p = unsafe { get(r)?.character(character)? };
        let values: Vec<f32> = p
            .pose
            .rotations
            .iter()
            .flat_map(|q| q.normalize().to_array())
            .collect();
        fill(xyzw, n, values.into_iter())
    })
}

/// Character `character`'s root (HumanoidRoot) in the world in the last frame: its position
/// (metres, y up) into `pos3` and its rotation (x y z w) into `xyzw`.
///
/// # Safety
/// `r` is a live realizer; `character` NULL or a NUL-terminated string; `pos3` and `xyzw`
/// point at 3 and 4 writable floats.
#[no_mangle]
pub unsafe extern "C" fn bmlr_root(
    r: *mut bmlr_realizer,
    character: *const c_char,
    pos3: *mut f32,
    xyzw: *mut f32,
) -> bmlr_status {
    guard(|| {
        // SAFETY: the caller's contract
        let p = unsafe { get(r)?.character(character)? };
        let world = p.pose.world(&skeleton());
        fill(pos3, 3, world.positions[0].to_array().into_iter())?;
        fill(
            xyzw,
            4,
            world.orientations[0].normalize().to_array().into_iter(),
        )
    })
}

/// The number of face blendshapes (the 52 ARKit ones).
///
/// # Safety
/// `r` is a live realizer; `n` points at a writable size.
#[no_mangle]
pub unsafe extern "C" fn bmlr_morph_count(r: *mut bmlr_realizer, n: *mut usize) -> bmlr_status {
    guard(|| {
        *out(n, "n")? = get(r)?.morph_names.len();
        Ok(())
    })
}

/// Blendshape `i`'s ARKit name into `*name` (valid while the realizer lives).
///
/// # Safety
/// `r` is a live realizer; `name` points at a writable pointer.
#[no_mangle]
pub unsafe extern "C" fn bmlr_morph_name(
    r: *mut bmlr_realizer,
    i: usize,
    name: *mut *const c_char,
) -> bmlr_status {
    guard(|| name_at(&get(r)?.morph_names, i, "blendshape", name))
}

/// Character `character`'s blendshape weights (0–1, `bmlr_morph_name` order) in the last frame
/// into `w` of `n` floats (at least the morph count).
///
/// # Safety
/// As `bmlr_pose`.
#[no_mangle]
pub unsafe extern "C" fn bmlr_morphs(
    r: *mut bmlr_realizer,
    character: *const c_char,
    w: *mut f32,
    n: usize,
) -> bmlr_status {
    guard(|| {
        // SAFETY: the caller's contract
        let p = unsafe { get(r)?.character(character)? };
        fill(w, n, p.face.morphs.0.into_iter())
    })
}

/// The sentence of this thread's last failed call ("" after one that succeeded); valid until
/// the next call on this thread.
#[no_mangle]
pub extern "C" fn bmlr_last_error() -> *const c_char {
    status::last_error()
}

/// Panics inside the library, for hosts that test their error handling: it returns
/// `BMLR_ERR_PANIC` with the panic's message in `bmlr_last_error()`; nothing aborts.
#[no_mangle]
pub extern "C" fn bmlr_debug_panic() -> bmlr_status {
    guard(|| panic!("bmlr_debug_panic was called"))
}
