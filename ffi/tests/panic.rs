//! The panic boundary, exercised: the test-only export fv_test_panic (feature `test-hooks`,
//! which this crate's dev-dependency on itself turns on) panics inside the guard every
//! export runs in. The call must return FV_STATUS_PANIC with the panic's message in
//! fv_last_error, and the library must stay usable: handles made before the panic render
//! afterwards, and new ones can be made.

use ferrovol::*;
use std::ffi::{c_void, CStr};
use std::ptr::{null, null_mut};

fn last_error() -> String {
    // SAFETY: fv_last_error returns a valid NUL-terminated string.
    unsafe { CStr::from_ptr(fv_last_error()) }
        .to_string_lossy()
        .into_owned()
}

fn ok(status: FvStatus) {
    assert_eq!(status, FvStatus::Ok, "{}", last_error());
}

/// A context, a renderer with a 16³ ball and a transfer function; freed on drop.
struct Scene {
    ctx: *mut FvContext,
    renderer: *mut FvRenderer,
    volume: *mut FvVolume,
    tf: *mut FvTransferFunction,
}

impl Scene {
    fn new() -> Scene {
        let n = 16u32;
        let data: Vec<u8> = (0..n * n * n)
            .map(|p| {
                let c = |v: u32| v as f64 - 7.5;
                let r = (c(p % n).powi(2) + c(p / n % n).powi(2) + c(p / (n * n)).powi(2)).sqrt();
                if r < 7.0 {
                    255 - (30.0 * r) as u8
                } else {
                    0
                }
            })
            .collect();
        let desc = FvVolumeDesc {
            dims: [n; 3],
            components: 1,
            scalar_type: FvScalarType::U8 as u32,
            spacing: [1.0; 3],
            origin: [0.0; 3],
            direction: [1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0],
        };
        let mut s = Scene {
            ctx: null_mut(),
            renderer: null_mut(),
            volume: null_mut(),
            tf: null_mut(),
        };
        let color = [0.0, 1.0, 1.0, 1.0];
        let opacity = [0.0, 0.0, 255.0, 1.0];
        // SAFETY: valid out-pointers, data of the size given, point arrays of the counts given.
        unsafe {
            ok(fv_context_new(&mut s.ctx));
            ok(fv_renderer_new(s.ctx, &mut s.renderer));
            ok(fv_volume_new(
                &desc,
                data.as_ptr().cast::<c_void>(),
                data.len(),
                &mut s.volume,
            ));
            ok(fv_renderer_set_volume(s.renderer, s.volume));
            ok(fv_transfer_function_new(1, true, &mut s.tf));
            ok(fv_transfer_function_set_color(s.tf, 0, color.as_ptr(), 1));
            ok(fv_transfer_function_set_opacity(
                s.tf,
                0,
                opacity.as_ptr(),
                2,
            ));
            ok(fv_renderer_set_transfer_function(s.renderer, s.tf));
            // SAFETY: FvCamera is plain data; all zeros is a valid value.
            let mut cam: FvCamera = std::mem::zeroed();
            cam.position = [7.5, 7.5, 60.0];
            cam.focal_point = [7.5; 3];
            cam.view_up = [0.0, 1.0, 0.0];
            cam.view_angle = 30.0;
            cam.clipping_range = [30.0, 90.0];
            ok(fv_renderer_set_camera(s.renderer, &cam));
        }
        s
    }

    /// Renders 32×32 and returns how many pixels have opacity.
    fn covered(&self) -> usize {
        let mut frame = null_mut();
        // SAFETY: valid handles; the pixels are read before the frame is freed.
        unsafe {
            ok(fv_renderer_render(self.renderer, 32, 32, null(), 0));
            ok(fv_renderer_read_frame(self.renderer, &mut frame));
            let rgba = std::slice::from_raw_parts(fv_frame_rgba(frame), 32 * 32 * 4);
            let covered = rgba.chunks_exact(4).filter(|p| p[3] > 0).count();
            fv_frame_free(frame);
            covered
        }
    }
}

impl Drop for Scene {
    fn drop(&mut self) {
        // SAFETY: each handle came from its fv_*_new and is freed once.
        unsafe {
            fv_transfer_function_free(self.tf);
            fv_volume_free(self.volume);
            fv_renderer_free(self.renderer);
            fv_context_free(self.ctx);
        }
    }
}

#[test]
fn a_panic_becomes_a_status_and_the_library_stays_usable() {
    let before = Scene::new();
    let covered = before.covered();
    println!("before the panic: {covered} of 1024 pixels with opacity");
    assert!(covered > 100, "the ball covers {covered} pixels");

    // SAFETY: a NUL-terminated message, then NULL (allowed).
    let status = unsafe { fv_test_panic(c"deliberate panic 19".as_ptr()) };
    let message = last_error();
    println!("{status:?}: {message}");
    assert_eq!(status, FvStatus::Panic);
    assert_eq!(message, "ferrovol panicked: deliberate panic 19");
    // SAFETY: fv_status_name returns a static string.
    let name = unsafe { CStr::from_ptr(fv_status_name(status as i32)) };
    assert_eq!(name.to_str().unwrap(), "FV_STATUS_PANIC");
    // SAFETY: NULL is allowed.
    assert_eq!(unsafe { fv_test_panic(null()) }, FvStatus::Panic);
    assert_eq!(last_error(), "ferrovol panicked: fv_test_panic called");

    // Handles made before the panic still render the same frame; new ones work too.
    assert_eq!(before.covered(), covered, "the same frame after the panic");
    let after = Scene::new();
    assert_eq!(
        after.covered(),
        covered,
        "a new context renders the same frame"
    );
    // An error after the panic replaces its message.
    let mut tf = null_mut();
    // SAFETY: a valid out-pointer; 0 components is the error.
    let status = unsafe { fv_transfer_function_new(0, true, &mut tf) };
    assert_eq!(status, FvStatus::InvalidArgument);
    assert!(last_error().contains("0 components"), "{}", last_error());
}

/// A panic on one thread sets that thread's message only and leaves the others' calls
/// working.
#[test]
fn a_panic_on_one_thread_leaves_the_others_alone() {
    let scene = Scene::new();
    let covered = scene.covered();
    std::thread::scope(|s| {
        s.spawn(|| {
            // SAFETY: a NUL-terminated message.
            let status = unsafe { fv_test_panic(c"panic on a worker".as_ptr()) };
            assert_eq!(status, FvStatus::Panic);
            assert_eq!(last_error(), "ferrovol panicked: panic on a worker");
        })
        .join()
        .unwrap();
    });
    assert!(
        !last_error().contains("panic on a worker"),
        "the worker's message leaked to this thread: {}",
        last_error()
    );
    assert_eq!(scene.covered(), covered);
}
