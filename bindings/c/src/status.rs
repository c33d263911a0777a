//! Status codes, the thread-local last error, and the guard every entry point runs in: a
//! panic inside the library is caught there and becomes `BMLR_ERR_PANIC` with its message,
//! never an unwind across the C boundary.

use std::cell::RefCell;
use std::ffi::{c_char, CStr, CString};
use std::panic::{catch_unwind, AssertUnwindSafe};

/// What a call did: `BMLR_OK` (0), or why it did nothing (`bmlr_last_error()` says more).
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum bmlr_status {
    /// Done.
    BMLR_OK = 0,
    /// A pointer that must not be NULL was NULL.
    BMLR_ERR_NULL = 1,
    /// A string was not UTF-8.
    BMLR_ERR_UTF8 = 2,
    /// The options were not a JSON object of known options with good values.
    BMLR_ERR_OPTIONS = 3,
    /// The BML block was refused (malformed, or over a limit); its feedback says why too.
    BMLR_ERR_BML = 4,
    /// The caller's buffer is too small; the size needed was written and nothing was taken.
    BMLR_ERR_BUFFER = 5,
    /// No such character in the last frame (or no frame yet: call `bmlr_tick` first).
    BMLR_ERR_CHARACTER = 6,
    /// An index out of range, or a time that is not a finite number.
    BMLR_ERR_RANGE = 7,
    /// The library panicked (a bug): the realizer may be left half-way; free it.
    BMLR_ERR_PANIC = 8,
    /// No open stream of that name, or a chunk it refused (another rate than the first chunk's,
    /// the stream ended or full, marks that do not parse).
    BMLR_ERR_STREAM = 9,
}

thread_local! {
    static LAST_ERROR: RefCell<CString> = RefCell::new(CString::default());
}

/// An error: its status and a sentence for `bmlr_last_error`.
pub type Failure = (bmlr_status, String);

/// Sets this thread's last error.
fn set_last_error(message: &str) {
    let text = CString::new(message.replace('\0', " ")).unwrap_or_default();
    LAST_ERROR.with(|e| *e.borrow_mut() = text);
}

/// Runs `f` behind a panic guard; its failure (or panic) is this thread's last error.
pub fn guard(f: impl FnOnce() -> Result<(), Failure>) -> bmlr_status {
    match catch_unwind(AssertUnwindSafe(f)) {
        Ok(Ok(())) => {
            set_last_error("");
            bmlr_status::BMLR_OK
        }
        Ok(Err((status, message))) => {
            set_last_error(&message);
            status
        }
        Err(panic) => {
            let what = (panic.downcast_ref::<&str>().map(|s| s.to_string()))
                .or_else(|| panic.downcast_ref::<String>().cloned())
                .unwrap_or_else(|| "a panic".into());
            set_last_error(&format!("the library panicked (a bug): {what}"));
            bmlr_status::BMLR_ERR_PANIC
        }
    }
}

/// The message of this thread's last failed call (empty after a call that succeeded).
pub fn last_error() -> *const c_char {
    LAST_ERROR.with(|e| e.borrow().as_ptr())
}

/// A C string argument as `&str`.
///
/// # Safety
/// `s` is NULL or points at a NUL-terminated string that lives for the call.
pub unsafe fn text<'a>(s: *const c_char, what: &str) -> Result<&'a str, Failure> {
    if s.is_null() {
        return Err((bmlr_status::BMLR_ERR_NULL, format!("{what} is NULL")));
    }
    // SAFETY: not NULL; NUL-terminated by the caller's contract
    unsafe { CStr::from_ptr(s) }.to_str().map_err(|e| {
        (
            bmlr_status::BMLR_ERR_UTF8,
            format!("{what} is not UTF-8: {e}"),
        )
    })
}

/// An out-pointer argument, checked for NULL.
pub fn out<'a, T>(p: *mut T, what: &str) -> Result<&'a mut T, Failure> {
    // SAFETY: a non-NULL out-pointer points at a writable T by the caller's contract
    unsafe { p.as_mut() }.ok_or((bmlr_status::BMLR_ERR_NULL, format!("{what} is NULL")))
}
