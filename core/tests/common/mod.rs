//! Helpers shared by the GPU test binaries (render.rs, iso.rs, pathtrace.rs).

use ferrovol_core::*;
use std::sync::{Mutex, MutexGuard, OnceLock};

/// One GPU context per test binary; tests take turns on it.
pub fn renderer() -> MutexGuard<'static, Renderer> {
    static R: OnceLock<Mutex<Renderer>> = OnceLock::new();
    R.get_or_init(|| {
        let ctx = Context::new().expect("a wgpu device (lavapipe: mesa-vulkan-drivers)");
        println!("{}", ctx.info);
        Mutex::new(Renderer::new(ctx).expect("creating the renderer"))
    })
    .lock()
    // a failed test must not take the others down with a poisoned lock
    .unwrap_or_else(|e| e.into_inner())
}

/// A single-component float volume with unit spacing, `f` evaluated at index coordinates.
pub fn volume(dims: [u32; 3], f: impl Fn(f64, f64, f64) -> f64) -> VolumeData {
    let mut data = Vec::with_capacity(dims.iter().map(|&d| d as usize).product());
    for k in 0..dims[2] {
        for j in 0..dims[1] {
            for i in 0..dims[0] {
                data.push(f(i as f64, j as f64, k as f64) as f32);
            }
        }
    }
    VolumeData::new(dims, 1, Scalars::F32(data)).expect("valid volume")
}
