//! Sound a host streams in (a realtime voice, a cloud TTS answering in chunks), through the C
//! ABI: `bmlr_open_stream` opens a stream by name for a character, `bmlr_push_audio` adds a
//! chunk of 16-bit mono samples with the chunk's timing marks (Polly speech marks or a word
//! list, times from the stream's first sample), `bmlr_end_audio` ends it. A speech plays it
//! with `bmlt:stream="NAME"` and is timed by `start="anticipators:NAME:start"
//! end="anticipators:NAME:end"` (see `docs/voice.md`, "Streaming").

use std::ffi::c_char;

use crate::status::{guard, text};
use crate::{bmlr_realizer, bmlr_status, get};

/// Opens the stream `name` for `character` (NULL or "": blocks without a characterId); open
/// it before performing the block whose speech plays it. Opening a name again replaces the
/// stream.
///
/// # Safety
/// `r` is a live realizer; `character` is NULL or a NUL-terminated string; `name` a
/// NUL-terminated string.
#[no_mangle]
pub unsafe extern "C" fn bmlr_open_stream(
    r: *mut bmlr_realizer,
    character: *const c_char,
    name: *const c_char,
) -> bmlr_status {
    guard(|| {
        let r = get(r)?;
        // SAFETY: the caller's contract
        let name = unsafe { text(name, "the stream's name")? };
        if name.is_empty() {
            return Err((
                bmlr_status::BMLR_ERR_STREAM,
                "the stream's name is empty".into(),
            ));
        }
        let character = match character.is_null() {
            true => None,
            // SAFETY: the caller's contract
            false => Some(unsafe { text(character, "the character")? }).filter(|c| !c.is_empty()),
        };
        r.realizer.open_stream(character, name);
        Ok(())
    })
}

/// Adds `n` samples at `pcm` (mono, 16-bit, `rate` Hz: every chunk of a stream at the same
/// rate) and the chunk's `marks` (NULL or "": none) to the stream `name`. The sound plays from
/// the next tick on.
///
/// # Safety
/// `r` is a live realizer; `name` a NUL-terminated string; `pcm` points at `n` samples (NULL
/// when `n` is 0); `marks` is NULL or a NUL-terminated string.
#[no_mangle]
pub unsafe extern "C" fn bmlr_push_audio(
    r: *mut bmlr_realizer,
    name: *const c_char,
    pcm: *const i16,
    n: usize,
    rate: u32,
    marks: *const c_char,
) -> bmlr_status {
    guard(|| {
        let r = get(r)?;
        // SAFETY: the caller's contract
        let name = unsafe { text(name, "the stream's name")? };
        let pcm: &[i16] = match (pcm.is_null(), n) {
            (_, 0) => &[],
            (true, _) => return Err((bmlr_status::BMLR_ERR_NULL, "pcm is NULL".into())),
            // SAFETY: `pcm` points at `n` samples by the caller's contract
            (false, _) => unsafe { std::slice::from_raw_parts(pcm, n) },
        };
        let marks = match marks.is_null() {
            true => None,
            // SAFETY: the caller's contract
            false => Some(unsafe { text(marks, "the marks")? }),
        };
        (r.realizer.push_audio(name, pcm, rate, marks))
            .map_err(|e| (bmlr_status::BMLR_ERR_STREAM, e))
    })
}

/// Ends the stream `name`: the speech playing it ends with its sound.
///
/// # Safety
/// `r` is a live realizer; `name` a NUL-terminated string.
#[no_mangle]
pub unsafe extern "C" fn bmlr_end_audio(r: *mut bmlr_realizer, name: *const c_char) -> bmlr_status {
    guard(|| {
        let r = get(r)?;
        // SAFETY: the caller's contract
        let name = unsafe { text(name, "the stream's name")? };
        (r.realizer.end_audio(name)).map_err(|e| (bmlr_status::BMLR_ERR_STREAM, e))
    })
}
