//! The context: a GPU adapter and device (FvContext).

use super::*;

/// A GPU adapter and device. Create one per process (or per host graphics context) and
/// share it between renderers. Thread use: may be used from any thread; calls on one
/// context may run concurrently (the device is internally synchronised).
pub struct FvContext {
    pub(crate) ctx: Context,
}

/// What a context runs on. Strings are NUL-terminated and truncated to fit.
/// Thread use: plain data.
#[repr(C)]
#[derive(Clone, Copy, Debug)]
pub struct FvAdapterInfo {
    pub name: [c_char; 256],
    /// "Vulkan", "Gl", …
    pub backend: [c_char; 32],
    pub driver: [c_char; 256],
    /// True for a CPU device such as Mesa's lavapipe.
    pub is_cpu: bool,
    pub max_texture_dimension_3d: u32,
    pub max_texture_dimension_2d: u32,
    pub max_buffer_size: u64,
}

fn copy_str<const N: usize>(dst: &mut [c_char; N], s: &str) {
    let bytes = s.as_bytes();
    let n = bytes.len().min(N - 1);
    for (d, &b) in dst.iter_mut().zip(&bytes[..n]) {
        *d = b as c_char;
    }
    dst[n] = 0;
}

/// Opens a GPU device (hardware first, Mesa's lavapipe otherwise; FERROVOL_ADAPTER and
/// FERROVOL_BACKEND override the choice). `*out` receives the context, NULL on failure.
#[no_mangle]
pub unsafe extern "C" fn fv_context_new(out: *mut *mut FvContext) -> FvStatus {
    guard(|| {
        let slot = out_ptr(out, "out")?;
        let ctx = Context::new()?;
        *slot = Box::into_raw(Box::new(FvContext { ctx }));
        Ok(())
    })
}

/// Releases a context (NULL is ignored). Renderers created from it keep the device alive.
#[no_mangle]
pub unsafe extern "C" fn fv_context_free(ctx: *mut FvContext) {
    guard_value((), || free_handle(ctx))
}

/// Fills `*info` with the adapter's name, backend, driver and limits.
#[no_mangle]
pub unsafe extern "C" fn fv_context_info(
    ctx: *const FvContext,
    info: *mut FvAdapterInfo,
) -> FvStatus {
    guard(|| {
        let c = const_ref(ctx, "ctx")?;
        let out = mut_ref(info, "info")?;
        let i = &c.ctx.info;
        copy_str(&mut out.name, &i.name);
        copy_str(&mut out.backend, &i.backend);
        copy_str(&mut out.driver, &format!("{} {}", i.driver, i.driver_info));
        out.is_cpu = i.device_type == "Cpu";
        out.max_texture_dimension_3d = i.limits.max_texture_dimension_3d;
        out.max_texture_dimension_2d = i.limits.max_texture_dimension_2d;
        out.max_buffer_size = i.limits.max_buffer_size;
        Ok(())
    })
}

/// The Vulkan device and driver UUIDs of the context (16 bytes each), to compare with
/// OpenGL's GL_DEVICE_UUID_EXT and GL_DRIVER_UUID_EXT before importing shared images.
/// FV_STATUS_UNSUPPORTED where the device cannot tell (not Vulkan).
#[no_mangle]
pub unsafe extern "C" fn fv_context_uuids(
    ctx: *const FvContext,
    device_uuid: *mut [u8; 16],
    driver_uuid: *mut [u8; 16],
) -> FvStatus {
    guard(|| {
        let c = const_ref(ctx, "ctx")?;
        let dev = mut_ref(device_uuid, "device_uuid")?;
        let drv = mut_ref(driver_uuid, "driver_uuid")?;
        let u = c.ctx.device_uuids()?;
        *dev = u.device;
        *drv = u.driver;
        Ok(())
    })
}

/// Whether renderers on this context can use FV_OUTPUT_PATH_SHARED (false with the reason
/// in fv_last_error() when not).
#[no_mangle]
pub unsafe extern "C" fn fv_context_can_share(ctx: *const FvContext) -> bool {
    let mut can = false;
    guard(|| {
        let c = const_ref(ctx, "ctx")?;
        c.ctx.external_memory_support()?;
        can = true;
        Ok(())
    });
    can
}

/// Fills `*memory` with the buffers, texture views, bind groups and device memory the
/// context holds now.
#[no_mangle]
pub unsafe extern "C" fn fv_context_device_memory(
    ctx: *const FvContext,
    memory: *mut FvDeviceMemory,
) -> FvStatus {
    guard(|| {
        let c = const_ref(ctx, "ctx")?;
        let m = c.ctx.device_memory();
        *mut_ref(memory, "memory")? = FvDeviceMemory {
            buffers: m.buffers,
            texture_views: m.texture_views,
            bind_groups: m.bind_groups,
            buffer_bytes: m.buffer_bytes,
            texture_bytes: m.texture_bytes,
        };
        Ok(())
    })
}

/// Loses the context's device on purpose, as a driver reset or a removed GPU would, so a
/// host can test its recovery (the role of WebGL's WEBGL_lose_context): every later call
/// on the context and its renderers returns FV_STATUS_DEVICE_LOST; free them and create a
/// new context. NULL is ignored.
#[no_mangle]
pub unsafe extern "C" fn fv_context_lose_device(ctx: *const FvContext) {
    guard_value((), || {
        if let Ok(c) = const_ref(ctx, "ctx") {
            c.ctx.lose_device();
        }
    })
}

/// Caps the device memory the context and its renderers may hold together, as a device with
/// that much memory would: an allocation past it fails with FV_STATUS_OUT_OF_MEMORY and what
/// was there before stays usable. For testing a host's handling of out-of-memory on any
/// device; 0 removes the cap. The renderers' memory budget (bricks streamed through a pool)
/// is set apart from this, on the render parameters.
#[no_mangle]
pub unsafe extern "C" fn fv_context_limit_device_memory(
    ctx: *const FvContext,
    bytes: u64,
) -> FvStatus {
    guard(|| {
        let c = const_ref(ctx, "ctx")?;
        c.ctx.limit_device_memory((bytes != 0).then_some(bytes));
        Ok(())
    })
}
