//! Status codes, the per-thread error message and the panic guard every export runs in.

use std::cell::RefCell;
use std::ffi::{c_char, CString};
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
    /// The device or this build cannot do what was asked (e.g. no shared-memory export).
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

impl From<ferrovol_core::Error> for FfiError {
    fn from(e: ferrovol_core::Error) -> Self {
        use ferrovol_core::Error as E;
        let status = match &e {
            E::NoAdapter(_) | E::RequestDevice { .. } => FvStatus::NoDevice,
            E::InvalidVolume(_) | E::InvalidTransferFunction(_) | E::InvalidParameter(_) => {
                FvStatus::InvalidArgument
            }
            E::Unsupported(_) => FvStatus::Unsupported,
            E::OutOfMemory(_) => FvStatus::OutOfMemory,
            E::DeviceLost(_) => FvStatus::DeviceLost,
            E::Gpu(_) => FvStatus::GpuError,
            E::ImageWrite { .. } => FvStatus::IoError,
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

/// A static name for a status ("FV_STATUS_OK", …); never NULL.
#[no_mangle]
pub extern "C" fn fv_status_name(status: FvStatus) -> *const c_char {
    let s: &'static [u8] = match status {
        FvStatus::Ok => b"FV_STATUS_OK\0",
        FvStatus::NullArgument => b"FV_STATUS_NULL_ARGUMENT\0",
        FvStatus::InvalidArgument => b"FV_STATUS_INVALID_ARGUMENT\0",
        FvStatus::Unsupported => b"FV_STATUS_UNSUPPORTED\0",
        FvStatus::OutOfMemory => b"FV_STATUS_OUT_OF_MEMORY\0",
        FvStatus::DeviceLost => b"FV_STATUS_DEVICE_LOST\0",
        FvStatus::NoDevice => b"FV_STATUS_NO_DEVICE\0",
        FvStatus::GpuError => b"FV_STATUS_GPU_ERROR\0",
        FvStatus::IoError => b"FV_STATUS_IO_ERROR\0",
        FvStatus::Panic => b"FV_STATUS_PANIC\0",
    };
    s.as_ptr().cast()
}
