//! The device the tests run on: the shared renderer, what the tests expect of the device
//! (declared per device class rather than assumed from the CI machine), path-traced frames
//! and refused calls.

use ferrovol_core::*;
use std::sync::{Mutex, MutexGuard, OnceLock};

/// The kinds of device the tests are written for.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum DeviceClass {
    /// A Vulkan implementation on the CPU: Mesa's lavapipe, the CI device.
    Cpu,
    /// Any other adapter: a hardware GPU (the expectations are written for a discrete one,
    /// e.g. an NVIDIA H200 on Vulkan).
    Gpu,
}

impl DeviceClass {
    /// The class of the adapter `info` describes.
    pub fn of(info: &DeviceInfo) -> DeviceClass {
        if info.device_type == "Cpu" {
            DeviceClass::Cpu
        } else {
            DeviceClass::Gpu
        }
    }
}

/// What the tests expect of a device class: a test that depends on one of these reads it
/// here instead of assuming the CI device.
#[derive(Clone, Copy, Debug)]
pub struct Expected {
    pub class: DeviceClass,
    /// float32 volumes are stored filterable (R32Float) and 16-bit ones as 16-bit normalised
    /// textures: the reference comparisons' tolerances assume lossless storage (checked by
    /// [`context`] for every test binary).
    pub lossless_volumes: bool,
    /// The shared output: the output images are exported as opaque fds
    /// (VK_KHR_external_memory_fd; on the Vulkan backend only). The interop tests need it.
    pub exports_memory: bool,
    /// Each exported allocation shows in this process as a memfd mapping: the driver keeps
    /// it in host memory (lavapipe). A GPU's is device memory, mapped no such way, so
    /// interop's replaced_shared_memory_is_freed counts only fds there.
    pub exports_as_memfd: bool,
    /// OpenGL from EGL's surfaceless platform runs on this device (its device and driver
    /// UUIDs are Vulkan's): lavapipe and llvmpipe are one Mesa device. On a GPU it depends
    /// on which vendor's EGL glvnd picks: interop's OpenGL tests then skip, saying so, where
    /// the UUIDs differ.
    pub surfaceless_gl_same_device: bool,
}

/// The declared expectations, one row per device class.
const EXPECTED: [Expected; 2] = [
    Expected {
        class: DeviceClass::Cpu,
        lossless_volumes: true,
        exports_memory: true,
        exports_as_memfd: true,
        surfaceless_gl_same_device: true,
    },
    Expected {
        class: DeviceClass::Gpu,
        lossless_volumes: true,
        exports_memory: true,
        exports_as_memfd: false,
        surfaceless_gl_same_device: false,
    },
];

/// What the tests expect of the device `info` describes (memory export only on Vulkan).
pub fn expected(info: &DeviceInfo) -> Expected {
    let class = DeviceClass::of(info);
    let row = EXPECTED
        .iter()
        .find(|e| e.class == class)
        .expect("a row per class");
    Expected {
        exports_memory: row.exports_memory && info.backend == "Vulkan",
        ..*row
    }
}

/// A new context, its adapter described, checked against what is expected of its class.
pub fn context() -> Context {
    let ctx = Context::new().expect("a wgpu device (lavapipe: mesa-vulkan-drivers)");
    let e = expected(&ctx.info);
    println!("{}", ctx.info);
    println!("expected of a {:?} device: {e:?}", e.class);
    if e.lossless_volumes {
        assert!(
            ctx.info.float32_filterable && ctx.info.norm16,
            "a {:?} device is expected to store volumes losslessly (float32 filterable, \
             16-bit norm), which the reference tolerances assume",
            e.class
        );
    }
    ctx
}

/// A renderer of its own on a new context (most tests share [`renderer`]'s).
pub fn new_renderer() -> Renderer {
    Renderer::new(context()).expect("creating the renderer")
}

/// One renderer per test binary, made on first use; tests take turns on it.
pub fn renderer() -> MutexGuard<'static, Renderer> {
    shared_renderer(|_| {})
}

/// [`renderer`], with `setup` applied when it is made (the first call's `setup` is the one
/// used).
pub fn shared_renderer(setup: fn(&mut Renderer)) -> MutexGuard<'static, Renderer> {
    static R: OnceLock<Mutex<Renderer>> = OnceLock::new();
    R.get_or_init(|| {
        let mut r = new_renderer();
        setup(&mut r);
        Mutex::new(r)
    })
    .lock()
    // a failed test must not take the others down with a poisoned lock
    .unwrap_or_else(|e| e.into_inner())
}

/// Uploads `vol` in bricks of at most `max_points` points along each axis.
pub fn set_bricked(r: &mut Renderer, vol: &VolumeData, max_points: u32) {
    r.set_volume_with(
        vol,
        UploadOptions {
            max_brick_points: Some(max_points),
            ..Default::default()
        },
    )
    .unwrap();
}

/// Path-traced frames (the blend mode and nothing else set).
pub fn pt_params() -> RenderParams {
    RenderParams {
        blend: BlendMode::PathTrace,
        ..Default::default()
    }
}

/// Renders frames until `spp` paths per pixel are accumulated; returns the mean per pixel.
pub fn trace(r: &mut Renderer, view: &View, p: &PathTraceParams, spp: u32) -> Vec<[f32; 4]> {
    trace_with(r, view, &pt_params(), p, spp)
}

/// [`trace`] with these render parameters (their blend mode path tracing).
pub fn trace_with(
    r: &mut Renderer,
    view: &View,
    params: &RenderParams,
    p: &PathTraceParams,
    spp: u32,
) -> Vec<[f32; 4]> {
    // (a budget of exactly `spp`: the last frame adds only what is missing)
    let p = PathTraceParams {
        max_samples: spp,
        ..*p
    };
    r.set_path_tracing(&p).expect("valid path tracing settings");
    r.reset_accumulation();
    while r.accumulated_samples() < spp {
        r.render(view, params, None).expect("a path-traced frame");
    }
    assert_eq!(r.accumulated_samples(), spp);
    r.read_accumulation().expect("the accumulation")
}

/// The message of the error `res` must be, printed ("LABEL: message", or the message alone
/// without a label); it must contain each of `words`.
pub fn assert_error<T>(res: Result<T>, label: &str, words: &[&str]) -> String {
    let e = match res {
        Ok(_) => panic!("{label}: accepted, an error was expected"),
        Err(e) => e.to_string(),
    };
    if label.is_empty() {
        println!("{e}");
    } else {
        println!("{label}: {e}");
    }
    for w in words {
        assert!(e.contains(w), "'{e}' lacks '{w}'");
    }
    e
}
