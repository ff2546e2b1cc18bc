//! ferrovol's C ABI (library `ferrovol`): opaque handles with `_new`/`_free` pairs, an
//! [`FvStatus`] from every call that can fail with a per-thread message
//! ([`fv_last_error`]), and no panic crossing the boundary. The header
//! `include/ferrovol.h` is generated from this crate by cbindgen.
//!
//! A frame: fv_context_new → fv_renderer_new → fv_volume_new + fv_renderer_set_volume →
//! fv_transfer_function_new (+ set_color / set_opacity) + fv_renderer_set_transfer_function
//! → fv_renderer_set_camera / set_lights / set_params → fv_renderer_render →
//! fv_renderer_read_frame (CPU) or the shared images (zero copy). A mesh instead of an image:
//! fv_unstructured_volume_new + fv_renderer_set_unstructured.
#![allow(clippy::missing_safety_doc)] // each export documents its pointer rules in the header

mod context;
mod frame;
mod intermix;
mod iso;
mod renderer;
mod sized;
mod status;
/// cbindgen:ignore
#[cfg(feature = "test-hooks")]
mod test_hooks;
mod transfer;
mod types;
mod unstructured;
mod volume;

pub use context::*;
pub use frame::*;
pub use intermix::*;
pub use iso::*;
pub use renderer::*;
pub use status::*;
#[cfg(feature = "test-hooks")]
pub use test_hooks::*;
pub use transfer::*;
pub use types::*;
pub use unstructured::*;
pub use volume::*;

use ferrovol_core::{
    ComponentTransfer, Context, Environment, Image, LabelTransfer, OutputPath, Piecewise, Renderer,
    Scalars, Table2D, TransferFunction, UploadOptions, View, VolumeData,
};
use std::ffi::{c_char, c_void, CStr};

/// Major version of this header; equals fv_version_major() of a compatible library.
pub const FV_VERSION_MAJOR: u32 = 0;
/// Minor version of this header.
pub const FV_VERSION_MINOR: u32 = 2;
/// Patch version of this header.
pub const FV_VERSION_PATCH: u32 = 0;

/// The library's version as "MAJOR.MINOR.PATCH" (static string, never NULL).
#[no_mangle]
pub extern "C" fn fv_version() -> *const c_char {
    concat!(env!("CARGO_PKG_VERSION"), "\0").as_ptr().cast()
}

/// The library's major version (compare with FV_VERSION_MAJOR: they must agree).
#[no_mangle]
pub extern "C" fn fv_version_major() -> u32 {
    FV_VERSION_MAJOR
}

fn mut_ref<'a, T>(p: *mut T, what: &str) -> FfiResult<&'a mut T> {
    // SAFETY: the caller passes a handle from the matching fv_*_new (documented per function);
    // NULL is checked here.
    unsafe { p.as_mut() }.ok_or_else(|| FfiError::null(what))
}

fn const_ref<'a, T>(p: *const T, what: &str) -> FfiResult<&'a T> {
    // SAFETY: as mut_ref.
    unsafe { p.as_ref() }.ok_or_else(|| FfiError::null(what))
}

fn out_ptr<T>(p: *mut *mut T, what: &str) -> FfiResult<&'static mut *mut T> {
    // SAFETY: the caller passes a writable pointer to a handle slot; NULL is checked.
    let slot = unsafe { p.as_mut() }.ok_or_else(|| FfiError::null(what))?;
    *slot = std::ptr::null_mut();
    Ok(slot)
}

fn free_handle<T>(p: *mut T) {
    if !p.is_null() {
        // SAFETY: p came from Box::into_raw in the matching fv_*_new and is freed once.
        drop(unsafe { Box::from_raw(p) });
    }
}
