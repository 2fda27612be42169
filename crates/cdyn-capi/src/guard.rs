//! Running an entry point's body with panics caught, and the thread's last
//! error message (what [`cdyn_last_error`](crate::api::cdyn_last_error) returns).

use std::cell::RefCell;
use std::ffi::CString;
use std::panic::{AssertUnwindSafe, catch_unwind};

thread_local! {
    static LAST_ERROR: RefCell<CString> = RefCell::new(CString::default());
}

/// Keeps `message` (one line; NUL bytes dropped) as this thread's last error.
pub(crate) fn set_last_error(message: &str) {
    let line = message.replace('\n', " ").replace('\0', "");
    LAST_ERROR.with(|e| *e.borrow_mut() = CString::new(line).unwrap_or_default());
}

/// The thread's last error, valid until the next failing call on this thread.
pub(crate) fn last_error() -> *const std::ffi::c_char {
    LAST_ERROR.with(|e| e.borrow().as_ptr())
}

/// Runs `body`; a panic becomes `Err` with its message.
pub(crate) fn guarded<T>(body: impl FnOnce() -> Result<T, String>) -> Result<T, String> {
    match catch_unwind(AssertUnwindSafe(body)) {
        Ok(result) => result,
        Err(panic) => {
            let what = panic
                .downcast_ref::<&str>()
                .map(|s| s.to_string())
                .or_else(|| panic.downcast_ref::<String>().cloned())
                .unwrap_or_else(|| "unknown".into());
            Err(format!("internal error (a bug of cdyn, please report it): {what}"))
        }
    }
}
