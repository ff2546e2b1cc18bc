//! Test-only exports, compiled with the `test-hooks` feature (which this crate's own tests
//! enable through its dev-dependency on itself). They are not in include/ferrovol.h and
//! not in a library built without the feature, such as `cargo build -p ferrovol-ffi`.

use crate::status::{guard, FvStatus};
use std::ffi::{c_char, CStr};

/// Panics inside the export guard with `message` (NUL-terminated; NULL gives a fixed
/// message), as a bug in ferrovol would: returns FV_STATUS_PANIC and fv_last_error() on
/// this thread names the message.
#[no_mangle]
pub unsafe extern "C" fn fv_test_panic(message: *const c_char) -> FvStatus {
    guard(|| {
        let text = if message.is_null() {
            "fv_test_panic called".to_string()
        } else {
            // SAFETY: the caller passes a NUL-terminated string (documented above).
            unsafe { CStr::from_ptr(message) }
                .to_string_lossy()
                .into_owned()
        };
        panic!("{text}")
    })
}
