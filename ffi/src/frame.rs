//! Frames copied to the CPU, and PNG output.

use super::*;

/// A rendered frame copied to the CPU: premultiplied RGBA8 and window depth, rows top to
/// bottom. Thread use: immutable; may be read from several threads at once.
pub struct FvFrame {
    image: Image,
}

/// Waits for the last frame and copies it to the CPU. `*out` receives the frame.
#[no_mangle]
pub unsafe extern "C" fn fv_renderer_read_frame(
    renderer: *const FvRenderer,
    out: *mut *mut FvFrame,
) -> FvStatus {
    guard(|| {
        let slot = out_ptr(out, "out")?;
        let r = const_ref(renderer, "renderer")?;
        let image = r.r.read_image()?;
        *slot = Box::into_raw(Box::new(FvFrame { image }));
        Ok(())
    })
}

/// Releases a frame (NULL is ignored).
#[no_mangle]
pub unsafe extern "C" fn fv_frame_free(frame: *mut FvFrame) {
    guard_value((), || free_handle(frame))
}

/// Width and height of a frame (0 × 0 for NULL).
#[no_mangle]
pub unsafe extern "C" fn fv_frame_size(frame: *const FvFrame, width: *mut u32, height: *mut u32) {
    guard_value((), || {
        // SAFETY: NULL-checked; the caller passes a frame handle and writable u32s.
        let f = unsafe { frame.as_ref() };
        let (w, h) = f.map_or((0, 0), |f| (f.image.width, f.image.height));
        if let Some(p) = unsafe { width.as_mut() } {
            *p = w;
        }
        if let Some(p) = unsafe { height.as_mut() } {
            *p = h;
        }
    })
}

/// Premultiplied RGBA8 pixels, width·height·4 bytes, rows top to bottom; valid until the
/// frame is freed (NULL for a NULL frame).
#[no_mangle]
pub unsafe extern "C" fn fv_frame_rgba(frame: *const FvFrame) -> *const u8 {
    guard_value(std::ptr::null(), || {
        // SAFETY: NULL-checked frame handle.
        unsafe { frame.as_ref() }.map_or(std::ptr::null(), |f| f.image.rgba.as_ptr())
    })
}

/// Window depth per pixel (1 where the volume is transparent), width·height floats, rows top
/// to bottom; valid until the frame is freed (NULL for a NULL frame).
#[no_mangle]
pub unsafe extern "C" fn fv_frame_depth(frame: *const FvFrame) -> *const f32 {
    guard_value(std::ptr::null(), || {
        // SAFETY: NULL-checked frame handle.
        unsafe { frame.as_ref() }.map_or(std::ptr::null(), |f| f.image.depth.as_ptr())
    })
}

/// Writes the frame over an opaque `background` (RGB in [0, 1]) as a PNG at `path` (UTF-8).
#[no_mangle]
pub unsafe extern "C" fn fv_frame_write_png(
    frame: *const FvFrame,
    path: *const c_char,
    background: *const [f32; 3],
) -> FvStatus {
    guard(|| {
        let f = const_ref(frame, "frame")?;
        if path.is_null() {
            return Err(FfiError::null("path"));
        }
        // SAFETY: the caller passes a NUL-terminated string.
        let p = unsafe { CStr::from_ptr(path) }
            .to_str()
            .map_err(|_| FfiError::invalid("path is not UTF-8"))?;
        let bg = const_ref(background, "background")?;
        ferrovol_io::image::write_png(&f.image, p.as_ref(), *bg)?;
        Ok(())
    })
}
