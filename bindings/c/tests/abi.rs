//! The C ABI called as a C host calls it (through the same `extern "C"` functions): a block
//! realized and its feedback polled line by line, poses and roots and blendshapes read into
//! flat arrays, and every way of calling it wrongly answered by a status and a sentence —
//! NULLs, bad UTF-8, bad options, a malformed block, small buffers, unknown characters, a
//! panic inside the library.

use std::ffi::{c_char, c_int, CStr, CString};
use std::ptr::{null, null_mut};

use bmlr::*;

const WELCOME: &str = include_str!("../../../fixtures/examples/welcome.xml");

fn last_error() -> String {
    // SAFETY: bmlr_last_error returns a NUL-terminated string valid until the next call
    unsafe { CStr::from_ptr(bmlr_last_error()) }
        .to_string_lossy()
        .into_owned()
}

fn new(options: &str) -> *mut bmlr_realizer {
    let options = CString::new(options).unwrap();
    let mut r = null_mut();
    // SAFETY: valid arguments
    let s = unsafe { bmlr_new(options.as_ptr(), &mut r) };
    assert_eq!(s, bmlr_status::BMLR_OK, "{}", last_error());
    r
}

/// Every feedback line waiting.
fn feedback(r: *mut bmlr_realizer) -> Vec<String> {
    let mut out = Vec::new();
    let mut buf = vec![0 as c_char; 1 << 16];
    loop {
        let mut len = 0;
        // SAFETY: a live realizer, a buffer of its length
        let s = unsafe { bmlr_next_feedback(r, buf.as_mut_ptr(), buf.len(), &mut len) };
        assert_eq!(s, bmlr_status::BMLR_OK, "{}", last_error());
        if len == 0 {
            return out;
        }
        // SAFETY: NUL-terminated by the library
        out.push(
            unsafe { CStr::from_ptr(buf.as_ptr()) }
                .to_string_lossy()
                .into_owned(),
        );
        assert_eq!(out.last().unwrap().len(), len);
    }
}

#[test]
fn a_host_realizes_a_block_and_reads_feedback_poses_roots_and_faces() {
    let r = new(r#"{"idle": false}"#);
    let block = CString::new(WELCOME).unwrap();
    // SAFETY: valid arguments throughout
    unsafe {
        assert_eq!(bmlr_perform(r, block.as_ptr()), bmlr_status::BMLR_OK);
        let (mut n, mut morphs) = (0usize, 0usize);
        assert_eq!(bmlr_joint_count(r, &mut n), bmlr_status::BMLR_OK);
        assert_eq!(bmlr_morph_count(r, &mut morphs), bmlr_status::BMLR_OK);
        assert_eq!((n, morphs), (57, 52));
        let mut name = null();
        assert_eq!(bmlr_joint_name(r, 0, &mut name), bmlr_status::BMLR_OK);
        assert_eq!(CStr::from_ptr(name).to_str().unwrap(), "HumanoidRoot");
        assert_eq!(bmlr_morph_name(r, 24, &mut name), bmlr_status::BMLR_OK);
        assert!(!CStr::from_ptr(name).to_bytes().is_empty());
        let (mut lines, mut widest_jaw, mut t) = (Vec::new(), 0.0f32, 0.0);
        let jaw = (0..morphs)
            .find(|&i| {
                bmlr_morph_name(r, i, &mut name);
                CStr::from_ptr(name).to_bytes() == b"jawOpen"
            })
            .unwrap();
        let mut q = vec![0.0f32; 4 * n];
        let mut w = vec![0.0f32; morphs];
        loop {
            assert_eq!(bmlr_tick(r, t), bmlr_status::BMLR_OK);
            lines.extend(feedback(r));
            assert_eq!(
                bmlr_pose(r, null(), q.as_mut_ptr(), q.len()),
                bmlr_status::BMLR_OK
            );
            assert!(q
                .chunks(4)
                .all(|c| (c.iter().map(|x| x * x).sum::<f32>() - 1.0).abs() < 1e-4));
            assert_eq!(
                bmlr_morphs(r, c"".as_ptr(), w.as_mut_ptr(), w.len()),
                bmlr_status::BMLR_OK
            );
            widest_jaw = widest_jaw.max(w[jaw]);
            let (mut at, mut has): (f64, c_int) = (0.0, 0);
            assert_eq!(bmlr_next_event(r, &mut at, &mut has), bmlr_status::BMLR_OK);
            if has == 0 {
                break;
            }
            t += 1.0 / 60.0;
        }
        let (mut pos, mut rot) = ([0.0f32; 3], [0.0f32; 4]);
        assert_eq!(
            bmlr_root(r, null(), pos.as_mut_ptr(), rot.as_mut_ptr()),
            bmlr_status::BMLR_OK
        );
        assert!(
            (pos[1] - 0.95).abs() < 0.05,
            "the root at hip height: {pos:?}"
        );
        assert!(
            lines.iter().any(|l| l.contains("\"greet:start\"")),
            "{lines:?}"
        );
        assert!(lines.iter().any(|l| l.contains("\"greet:beat:stroke\"")));
        assert!(lines.last().unwrap().contains("\"greet:end\""), "{lines:?}");
        assert!(
            widest_jaw > 0.1,
            "the jaw opens while speaking: {widest_jaw}"
        );
        assert_eq!(bmlr_free(r), bmlr_status::BMLR_OK);
    }
}

#[test]
fn every_wrong_call_is_a_status_and_a_sentence_never_a_crash() {
    // SAFETY: every pointer below is valid or NULL on purpose
    unsafe {
        let mut r = null_mut();
        let bad = |options: &str| {
            let o = CString::new(options).unwrap();
            let mut r = null_mut();
            (bmlr_new(o.as_ptr(), &mut r), last_error())
        };
        assert_eq!(bad("{").0, bmlr_status::BMLR_ERR_OPTIONS);
        let (s, e) = bad(r#"{"idel": false}"#);
        assert_eq!(s, bmlr_status::BMLR_ERR_OPTIONS);
        assert!(e.contains("unknown option 'idel'"), "{e}");
        assert_eq!(bad(r#"{"tts": "espeak"}"#).0, bmlr_status::BMLR_ERR_OPTIONS);
        assert_eq!(
            bad(r#"{"world": {"points": 5}}"#).0,
            bmlr_status::BMLR_ERR_OPTIONS
        );
        assert_eq!(bmlr_new(null(), null_mut()), bmlr_status::BMLR_ERR_NULL);
        assert_eq!(bmlr_new(null(), &mut r), bmlr_status::BMLR_OK);
        assert_eq!(last_error(), "");
        // a malformed block
        let s = bmlr_perform(r, c"<bml id=\"broken\"><gesture".as_ptr());
        assert_eq!(s, bmlr_status::BMLR_ERR_BML);
        assert!(!last_error().is_empty());
        // not UTF-8
        let s = bmlr_perform(r, c"<bml \xff/>".as_ptr());
        assert_eq!(s, bmlr_status::BMLR_ERR_UTF8);
        assert_eq!(
            bmlr_perform(null_mut(), c"<bml/>".as_ptr()),
            bmlr_status::BMLR_ERR_NULL
        );
        // no frame yet, then a character that is not there
        let mut q = [0.0f32; 4 * 57];
        assert_eq!(
            bmlr_pose(r, null(), q.as_mut_ptr(), q.len()),
            bmlr_status::BMLR_ERR_CHARACTER
        );
        assert!(last_error().contains("bmlr_tick"));
        assert_eq!(bmlr_tick(r, f64::NAN), bmlr_status::BMLR_ERR_RANGE);
        let block = CString::new(WELCOME).unwrap();
        assert_eq!(bmlr_perform(r, block.as_ptr()), bmlr_status::BMLR_OK);
        assert_eq!(bmlr_tick(r, 0.5), bmlr_status::BMLR_OK);
        let s = bmlr_pose(r, c"nobody".as_ptr(), q.as_mut_ptr(), q.len());
        assert_eq!(s, bmlr_status::BMLR_ERR_CHARACTER);
        assert!(last_error().contains("'nobody'"), "{}", last_error());
        // buffers too small: the size needed, nothing taken
        assert_eq!(
            bmlr_pose(r, null(), q.as_mut_ptr(), 10),
            bmlr_status::BMLR_ERR_BUFFER
        );
        assert!(last_error().contains("228 are needed"), "{}", last_error());
        let mut small = [0 as c_char; 8];
        let mut len = 0;
        let s = bmlr_next_feedback(r, small.as_mut_ptr(), small.len(), &mut len);
        assert_eq!(
            s,
            bmlr_status::BMLR_ERR_BUFFER,
            "the refused block's warning waits"
        );
        assert!(len > 8);
        let waiting = feedback(r);
        assert_eq!(waiting[0].len(), len);
        assert!(waiting[0].contains("warningFeedback"), "{waiting:?}");
        assert!(
            waiting.iter().any(|l| l.contains("greet:start")),
            "{waiting:?}"
        );
        // out of range
        let mut name = null();
        assert_eq!(
            bmlr_joint_name(r, 57, &mut name),
            bmlr_status::BMLR_ERR_RANGE
        );
        // a panic inside the library is an error, and the realizer goes on
        assert_eq!(bmlr_debug_panic(), bmlr_status::BMLR_ERR_PANIC);
        assert!(last_error().contains("bmlr_debug_panic was called"));
        assert_eq!(bmlr_tick(r, 1.0), bmlr_status::BMLR_OK);
        assert_eq!(bmlr_free(r), bmlr_status::BMLR_OK);
        assert_eq!(bmlr_free(null_mut()), bmlr_status::BMLR_OK);
    }
}

/// A realizer made on one thread is used and freed on another (it is `Send`).
#[test]
fn a_realizer_crosses_threads() {
    fn send<T: Send>() {}
    send::<bml_realizer::realizer::Realizer>();
    struct Handle(*mut bmlr_realizer);
    // SAFETY: the realizer is Send; the handle is used by one thread at a time
    unsafe impl Send for Handle {}
    let h = Handle(new(""));
    std::thread::spawn(move || {
        let h = h;
        // SAFETY: a live realizer
        unsafe {
            assert_eq!(
                bmlr_perform(h.0, CString::new(WELCOME).unwrap().as_ptr()),
                bmlr_status::BMLR_OK
            );
            assert_eq!(bmlr_tick(h.0, 0.0), bmlr_status::BMLR_OK);
            assert_eq!(bmlr_free(h.0), bmlr_status::BMLR_OK);
        }
    })
    .join()
    .unwrap();
}

/// `bmlr_step` advances one frame at the options' fps: 0, 1/30, 2/30…
#[test]
fn steps_advance_a_frame_at_fps() {
    let r = new(r#"{"fps": 30}"#);
    let mut times = Vec::new();
    for _ in 0..4 {
        let mut now = -1.0;
        // SAFETY: a live realizer, a writable double
        assert_eq!(unsafe { bmlr_step(r, &mut now) }, bmlr_status::BMLR_OK);
        times.push(now);
    }
    assert_eq!(times, [0.0, 1.0 / 30.0, 2.0 / 30.0, 3.0 / 30.0]);
    // SAFETY: a live realizer; NULL is allowed for `now`
    unsafe {
        assert_eq!(bmlr_step(r, null_mut()), bmlr_status::BMLR_OK);
        bmlr_free(r);
    }
}
