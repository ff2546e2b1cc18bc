//! Status codes, the per-thread error message and the panic guard every export runs in.

use std::cell::RefCell;
use std::ffi::{c_char, CStr, CString};
use std::panic::{catch_unwind, AssertUnwindSafe};

/// What a call did. Every function that can fail returns one; on anything but
/// FV_STATUS_OK, fv_last_error() on the same thread says what went wrong.
#[repr(C)]
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum FvStatus {
    /// Success.
    Ok = 0,
    /// A required pointer argument was NULL.
    NullArgument = 1,
    /// An argument is out of range or inconsistent (the message names it).
    InvalidArgument = 2,
    /// The device or this build cannot do what was asked (e.g. no shared-memory export), or
    /// the settings combine what a pass does not draw (docs/REFUSALS.md lists them).
    Unsupported = 3,
    /// A GPU or host allocation failed.
    OutOfMemory = 4,
    /// The GPU device was lost; create a new context.
    DeviceLost = 5,
    /// No GPU adapter could be found or opened.
    NoDevice = 6,
    /// Any other GPU error (validation, shader compilation).
    GpuError = 7,
    /// A file could not be written.
    IoError = 8,
    /// ferrovol panicked inside the call (a bug: please report it with the message).
    Panic = 9,
}

/// An error on its way to C: a status and a message.
#[derive(Debug)]
pub struct FfiError {
    pub status: FvStatus,
    pub message: String,
}

pub type FfiResult<T> = std::result::Result<T, FfiError>;

impl FfiError {
    pub fn new(status: FvStatus, message: impl Into<String>) -> Self {
        FfiError {
            status,
            message: message.into(),
        }
    }
    pub fn invalid(message: impl Into<String>) -> Self {
        Self::new(FvStatus::InvalidArgument, message)
    }
    pub fn null(what: &str) -> Self {
        Self::new(FvStatus::NullArgument, format!("{what} is NULL"))
    }
}

impl FfiError {
    /// The status a core error maps to.
    fn from_status_of(e: &ferrovol_core::Error) -> FvStatus {
        use ferrovol_core::Error as E;
        match e {
            E::NoAdapter(_) | E::RequestDevice { .. } => FvStatus::NoDevice,
            E::InvalidVolume(_) | E::InvalidTransferFunction(_) | E::InvalidParameter(_) => {
                FvStatus::InvalidArgument
            }
            E::Unsupported(_) => FvStatus::Unsupported,
            E::OutOfMemory(_) => FvStatus::OutOfMemory,
            E::DeviceLost(_) => FvStatus::DeviceLost,
            E::Gpu(_) => FvStatus::GpuError,
            E::Source(_) => FvStatus::IoError,
        }
    }
}

impl From<ferrovol_core::Error> for FfiError {
    fn from(e: ferrovol_core::Error) -> Self {
        FfiError::new(FfiError::from_status_of(&e), e.to_string())
    }
}

impl From<ferrovol_io::image::ImageError> for FfiError {
    fn from(e: ferrovol_io::image::ImageError) -> Self {
        use ferrovol_io::image::ImageError as E;
        let status = match &e {
            E::Write { .. } => FvStatus::IoError,
            E::Environment { error, .. } => FfiError::from_status_of(error),
            E::UnknownFormat { .. } | E::Open { .. } | E::Decode { .. } | E::Shape(_) => {
                FvStatus::InvalidArgument
            }
        };
        FfiError::new(status, e.to_string())
    }
}

thread_local! {
    static LAST_ERROR: RefCell<CString> = RefCell::new(CString::default());
}

fn set_last_error(message: &str) {
    let c = CString::new(message.replace('\0', "\\0")).unwrap_or_default();
    LAST_ERROR.with(|e| *e.borrow_mut() = c);
}

/// Runs `f`, turning errors and panics into a status and the thread's last error message.
pub fn guard(f: impl FnOnce() -> FfiResult<()>) -> FvStatus {
    match catch_unwind(AssertUnwindSafe(f)) {
        Ok(Ok(())) => FvStatus::Ok,
        Ok(Err(e)) => {
            set_last_error(&e.message);
            e.status
        }
        Err(panic) => {
            let what = panic
                .downcast_ref::<&str>()
                .map(|s| s.to_string())
                .or_else(|| panic.downcast_ref::<String>().cloned())
                .unwrap_or_else(|| "unknown panic".into());
            set_last_error(&format!("ferrovol panicked: {what}"));
            FvStatus::Panic
        }
    }
}

/// Runs `f` for a value-returning export that cannot report a status: a panic yields
/// `fallback` (and sets the last error).
pub fn guard_value<T>(fallback: T, f: impl FnOnce() -> T) -> T {
    let mut out = None;
    guard(|| {
        out = Some(f());
        Ok(())
    });
    out.unwrap_or(fallback)
}

/// The message of the most recent call on this thread that did not return
/// FV_STATUS_OK ("" if there was none). The pointer stays valid until the next failing
/// ferrovol call on this thread.
#[no_mangle]
pub extern "C" fn fv_last_error() -> *const c_char {
    LAST_ERROR.with(|e| e.borrow().as_ptr())
}

/// The names of the statuses, indexed by their value.
const STATUS_NAMES: [&CStr; 10] = [
    c"FV_STATUS_OK",
    c"FV_STATUS_NULL_ARGUMENT",
    c"FV_STATUS_INVALID_ARGUMENT",
    c"FV_STATUS_UNSUPPORTED",
    c"FV_STATUS_OUT_OF_MEMORY",
    c"FV_STATUS_DEVICE_LOST",
    c"FV_STATUS_NO_DEVICE",
    c"FV_STATUS_GPU_ERROR",
    c"FV_STATUS_IO_ERROR",
    c"FV_STATUS_PANIC",
];

/// A static name for a status value ("FV_STATUS_OK", …), "FV_STATUS_UNKNOWN" for a value
/// that is not an FvStatus; never NULL. Takes an integer so that any value is safe to pass.
#[no_mangle]
pub extern "C" fn fv_status_name(status: i32) -> *const c_char {
    usize::try_from(status)
        .ok()
        .and_then(|i| STATUS_NAMES.get(i))
        .unwrap_or(&c"FV_STATUS_UNKNOWN")
        .as_ptr()
}

#[cfg(test)]
mod tests {
    use super::*;
    use ferrovol_core::Error as E;

    const ALL: [FvStatus; 10] = [
        FvStatus::Ok,
        FvStatus::NullArgument,
        FvStatus::InvalidArgument,
        FvStatus::Unsupported,
        FvStatus::OutOfMemory,
        FvStatus::DeviceLost,
        FvStatus::NoDevice,
        FvStatus::GpuError,
        FvStatus::IoError,
        FvStatus::Panic,
    ];

    fn name(status: i32) -> &'static str {
        // SAFETY: fv_status_name returns a static NUL-terminated string.
        unsafe { CStr::from_ptr(fv_status_name(status)) }
            .to_str()
            .unwrap()
    }

    #[test]
    fn every_core_error_maps_to_its_status() {
        let s = || "x".to_string();
        let cases = [
            (E::NoAdapter(s()), FvStatus::NoDevice),
            (
                E::RequestDevice {
                    adapter: s(),
                    message: s(),
                },
                FvStatus::NoDevice,
            ),
            (E::InvalidVolume(s()), FvStatus::InvalidArgument),
            (E::InvalidTransferFunction(s()), FvStatus::InvalidArgument),
            (E::InvalidParameter(s()), FvStatus::InvalidArgument),
            (E::Unsupported(s()), FvStatus::Unsupported),
            (E::Gpu(s()), FvStatus::GpuError),
            (E::OutOfMemory(s()), FvStatus::OutOfMemory),
            (E::DeviceLost(s()), FvStatus::DeviceLost),
            (E::Source(s()), FvStatus::IoError),
        ];
        for (error, want) in cases {
            // A new core variant must get a row here: this match stops compiling without it.
            match &error {
                E::NoAdapter(_)
                | E::RequestDevice { .. }
                | E::InvalidVolume(_)
                | E::InvalidTransferFunction(_)
                | E::InvalidParameter(_)
                | E::Unsupported(_)
                | E::Gpu(_)
                | E::OutOfMemory(_)
                | E::DeviceLost(_)
                | E::Source(_) => {}
            }
            let text = error.to_string();
            let e = FfiError::from(error);
            println!("{text} -> {:?}", e.status);
            assert_eq!(e.status, want, "{text}");
            assert_eq!(e.message, text, "the message is the core error's text");
        }
    }

    #[test]
    fn status_names_answer_any_value() {
        for (i, s) in ALL.into_iter().enumerate() {
            assert_eq!(s as i32, i as i32, "FvStatus values are 0, 1, 2, …");
            let debug = format!("{s:?}");
            let mut want = String::from("FV_STATUS");
            for c in debug.chars() {
                if c.is_uppercase() {
                    want.push('_');
                }
                want.push(c.to_ascii_uppercase());
            }
            assert_eq!(name(s as i32), want);
        }
        for v in [-1, 10, 42, i32::MIN, i32::MAX] {
            assert_eq!(name(v), "FV_STATUS_UNKNOWN", "value {v}");
        }
    }
}
