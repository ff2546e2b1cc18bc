//! The renderer: settings, frames, the shared output.

use super::*;
use crate::sized;

/// A renderer: the uploaded volume, transfer tables, pipelines and the frame it draws.
/// Camera, lights and parameters persist between frames. Thread use: one thread at a
/// time (it may move between threads).
pub struct FvRenderer {
    pub(crate) r: Renderer,
    view: View,
    params: ferrovol_core::RenderParams,
    upload: UploadOptions,
}

/// Runs `f` on the renderer behind `renderer` inside [`guard`] (NULL: FV_STATUS_NULL_ARGUMENT).
fn with_renderer(
    renderer: *mut FvRenderer,
    f: impl FnOnce(&mut FvRenderer) -> FfiResult<()>,
) -> FvStatus {
    guard(|| f(mut_ref(renderer, "renderer")?))
}

/// [`with_renderer`] for the calls that draw (or prepare) a `width × height` frame: the view
/// takes the size first.
fn with_frame(
    renderer: *mut FvRenderer,
    width: u32,
    height: u32,
    f: impl FnOnce(&mut FvRenderer) -> ferrovol_core::Result<()>,
) -> FvStatus {
    with_renderer(renderer, |r| {
        r.view.width = width;
        r.view.height = height;
        f(r)?;
        Ok(())
    })
}

/// [`with_renderer`] for the calls that only read the renderer.
fn with_renderer_ref(
    renderer: *const FvRenderer,
    f: impl FnOnce(&FvRenderer) -> FfiResult<()>,
) -> FvStatus {
    guard(|| f(const_ref(renderer, "renderer")?))
}

/// Hands what `read` converts from a C description to `apply`.
fn set_from<C>(
    renderer: *mut FvRenderer,
    read: impl FnOnce() -> FfiResult<C>,
    apply: impl FnOnce(&mut FvRenderer, C) -> ferrovol_core::Result<()>,
) -> FvStatus {
    with_renderer(renderer, |r| {
        apply(r, read()?)?;
        Ok(())
    })
}

/// A renderer on `ctx` (which may be freed afterwards). `*out` receives it.
#[no_mangle]
pub unsafe extern "C" fn fv_renderer_new(
    ctx: *const FvContext,
    out: *mut *mut FvRenderer,
) -> FvStatus {
    guard(|| {
        let slot = out_ptr(out, "out")?;
        let c = const_ref(ctx, "ctx")?;
        let r = Renderer::new(c.ctx.clone())?;
        *slot = Box::into_raw(Box::new(FvRenderer {
            r,
            view: View::fit([-1.0, 1.0, -1.0, 1.0, -1.0, 1.0], 1, 1),
            params: Default::default(),
            upload: UploadOptions::default(),
        }));
        Ok(())
    })
}

/// Releases a renderer and its GPU resources (NULL is ignored).
#[no_mangle]
pub unsafe extern "C" fn fv_renderer_free(renderer: *mut FvRenderer) {
    guard_value((), || free_handle(renderer))
}

/// Largest brick edge in points for later volume uploads (0 = the device limit). Volumes
/// beyond it are split into bricks and still rendered whole.
#[no_mangle]
pub unsafe extern "C" fn fv_renderer_set_max_brick_points(
    renderer: *mut FvRenderer,
    points: u32,
) -> FvStatus {
    with_renderer(renderer, |r| {
        if points == 1 || points == 2 {
            return Err(FfiError::invalid(format!(
                "max brick points {points}: a brick needs at least 3 points per edge"
            )));
        }
        r.upload.max_brick_points = (points > 0).then_some(points);
        Ok(())
    })
}

/// Most bytes a later volume upload may take on the device (0 = the device's limit). A
/// larger volume is bricked with only the bricks a frame needs resident; when even those
/// exceed the budget, ray casting and isosurfaces stream them through the pool in several
/// passes of one frame; path tracing, volumetric shadows and isosurfaces with ambient
/// occlusion or scattering, whose rays go anywhere, draw the finest coarser level of the
/// volume whose needed bricks fit (fv_renderer_residency says which).
#[no_mangle]
pub unsafe extern "C" fn fv_renderer_set_memory_budget(
    renderer: *mut FvRenderer,
    bytes: u64,
) -> FvStatus {
    with_renderer(renderer, |r| {
        r.upload.memory_budget = (bytes > 0).then_some(bytes);
        Ok(())
    })
}

/// Uploads a volume (replacing the previous one). Call again only when the data changed:
/// camera and parameter changes never re-upload.
#[no_mangle]
pub unsafe extern "C" fn fv_renderer_set_volume(
    renderer: *mut FvRenderer,
    volume: *const FvVolume,
) -> FvStatus {
    with_renderer(renderer, |r| {
        let v = const_ref(volume, "volume")?;
        r.r.set_shared_volume(v.data.clone(), r.upload)?;
        Ok(())
    })
}

/// Blanks points of the current volume's grid (VTK's ghost arrays and vtkUniformGrid
/// blanking): `count` bytes at `mask`, one per point, x fastest, non-zero where the point is
/// hidden; ray casting leaves out the samples next to a hidden point. NULL clears the mask;
/// setting a volume clears it too. FV_STATUS_UNSUPPORTED for a bricked volume.
#[no_mangle]
pub unsafe extern "C" fn fv_renderer_set_blanking(
    renderer: *mut FvRenderer,
    mask: *const u8,
    count: usize,
) -> FvStatus {
    with_renderer(renderer, |r| {
        let mask = if mask.is_null() {
            None
        } else {
            // SAFETY: the caller guarantees `count` bytes at `mask`.
            Some(unsafe { std::slice::from_raw_parts(mask, count) })
        };
        r.r.set_blanking(mask)?;
        Ok(())
    })
}

/// Masks the current volume (vtkGPUVolumeRayCastMapper's MaskInput and MaskType): `count`
/// bytes at `values`, one per point of the volume's grid, x fastest, read at the point
/// nearest to each sample; `mask_type` an FvMaskType. FV_MASK_TYPE_BINARY leaves out the
/// samples at points holding 0; FV_MASK_TYPE_LABEL_MAP classifies labelled samples with
/// their labels' functions (fv_transfer_function_set_label_*), mixed by
/// FvRenderParams::mask_blend_factor. Ray casting and path tracing read it, isosurfaces a
/// binary one. NULL clears it; setting a volume
/// clears it too.
#[no_mangle]
pub unsafe extern "C" fn fv_renderer_set_mask(
    renderer: *mut FvRenderer,
    values: *const u8,
    count: usize,
    mask_type: u32,
) -> FvStatus {
    with_renderer(renderer, |r| {
        let kind = types::mask_kind(mask_type)?;
        let values = if values.is_null() {
            None
        } else {
            // SAFETY: the caller guarantees `count` bytes at `values`.
            Some(unsafe { std::slice::from_raw_parts(values, count) })
        };
        r.r.set_mask(values.map(|v| (v, kind)))?;
        Ok(())
    })
}

/// Sets the transfer function; only its tables are re-uploaded.
#[no_mangle]
pub unsafe extern "C" fn fv_renderer_set_transfer_function(
    renderer: *mut FvRenderer,
    tf: *const FvTransferFunction,
) -> FvStatus {
    set_from(
        renderer,
        || const_ref(tf, "tf")?.to_core(),
        |r, t| r.r.set_transfer_function(&t),
    )
}

/// Sets the camera for the following frames.
#[no_mangle]
pub unsafe extern "C" fn fv_renderer_set_camera(
    renderer: *mut FvRenderer,
    camera: *const FvCamera,
) -> FvStatus {
    set_from(
        renderer,
        || const_ref(camera, "camera")?.to_core(),
        |r, c| {
            r.view.camera = c;
            Ok(())
        },
    )
}

/// Sets the lights (`count` may be 0: shading then has ambient light only; at most
/// FV_MAX_LIGHTS with shading on).
#[no_mangle]
pub unsafe extern "C" fn fv_renderer_set_lights(
    renderer: *mut FvRenderer,
    lights: *const FvLight,
    count: usize,
) -> FvStatus {
    with_renderer(renderer, |r| {
        if count > FV_MAX_LIGHTS {
            return Err(FfiError::invalid(format!(
                "{count} lights: at most {FV_MAX_LIGHTS}"
            )));
        }
        let ls = if count == 0 {
            &[][..]
        } else {
            if lights.is_null() {
                return Err(FfiError::null("lights"));
            }
            // SAFETY: the caller guarantees `count` lights at `lights`.
            unsafe { std::slice::from_raw_parts(lights, count) }
        };
        r.view.lights = ls
            .iter()
            .enumerate()
            .map(|(i, l)| l.to_core(i))
            .collect::<FfiResult<_>>()?;
        Ok(())
    })
}

/// Fills `*params` with the defaults (VTK's: composite, linear, automatic sample
/// distance, no shading, early termination at 1 − 1/255). `size` is `sizeof *params`: it
/// goes into `params->size`, which tells a later library which fields the program knows
/// (those it does not take their defaults).
#[no_mangle]
pub unsafe extern "C" fn fv_render_params_default(
    params: *mut FvRenderParams,
    size: usize,
) -> FvStatus {
    guard(|| sized::write_defaults(params, size, "params"))
}

/// Sets the render parameters (validated: out-of-range values are refused and the previous
/// parameters kept).
#[no_mangle]
pub unsafe extern "C" fn fv_renderer_set_params(
    renderer: *mut FvRenderer,
    params: *const FvRenderParams,
) -> FvStatus {
    set_from(
        renderer,
        || sized::read(params, "params")?.to_core(),
        |r, p| {
            r.params = p;
            Ok(())
        },
    )
}

/// Fills `*params` with the isosurface defaults (no iso-values yet: set `value_count` and
/// `values`; 8 bisection steps, 4 layers, 16 importance-sampled specular samples,
/// shininess 8 to 64 by gradient magnitude, no Fresnel, no ambient occlusion, environment
/// weight 0.6, no background). `size` is `sizeof *params` (see fv_render_params_default).
#[no_mangle]
pub unsafe extern "C" fn fv_iso_params_default(params: *mut FvIsoParams, size: usize) -> FvStatus {
    guard(|| sized::write_defaults(params, size, "params"))
}

/// Sets the isosurfaces and their shading for frames with FV_BLEND_MODE_ISOSURFACE
/// (validated: out-of-range values are refused and the previous settings kept).
#[no_mangle]
pub unsafe extern "C" fn fv_renderer_set_isosurface(
    renderer: *mut FvRenderer,
    params: *const FvIsoParams,
) -> FvStatus {
    set_from(
        renderer,
        || sized::read(params, "params")?.to_core(),
        |r, p| r.r.set_isosurface(&p),
    )
}

/// Sets the environment that lights isosurfaces and path-traced media and builds its maps
/// now (an irradiance cube and a mip-filtered environment cube). `path` (UTF-8) is an
/// equirectangular .hdr, .exr, .png or .jpg image twice as wide as high, or NULL for the
/// built-in procedural sky. `up` (3 doubles, or NULL for +Y) is the world direction that
/// is up in the environment; `azimuth_degrees` turns it about that axis; `intensity`
/// multiplies its radiance. Without a call, the first isosurface frame uses the sky.
#[no_mangle]
pub unsafe extern "C" fn fv_renderer_set_environment(
    renderer: *mut FvRenderer,
    path: *const c_char,
    intensity: f32,
    up: *const f64,
    azimuth_degrees: f64,
) -> FvStatus {
    with_renderer(renderer, |r| {
        let mut env = if path.is_null() {
            Environment::default()
        } else {
            // SAFETY: the caller passes a NUL-terminated string.
            let p = unsafe { CStr::from_ptr(path) }
                .to_str()
                .map_err(|_| FfiError::invalid("environment path is not UTF-8"))?;
            ferrovol_io::image::read_environment(p.as_ref())?
        };
        if !up.is_null() {
            // SAFETY: the caller passes 3 doubles at `up`.
            let u = unsafe { std::slice::from_raw_parts(up, 3) };
            env.up = glam::DVec3::new(u[0], u[1], u[2]);
        }
        env.intensity = intensity;
        env.azimuth = azimuth_degrees;
        r.r.set_environment(&env)?;
        Ok(())
    })
}

/// Fills `*params` with the path tracing defaults (4 paths per pixel and frame, at most 64
/// scattering events, isotropic scattering, environment weight 1, no background, seed 0).
/// `size` is `sizeof *params` (see fv_render_params_default).
#[no_mangle]
pub unsafe extern "C" fn fv_path_trace_params_default(
    params: *mut FvPathTraceParams,
    size: usize,
) -> FvStatus {
    guard(|| sized::write_defaults(params, size, "params"))
}

/// Sets how frames with FV_BLEND_MODE_PATH_TRACE sample (validated: out-of-range values are
/// refused and the previous settings kept). A change other than of the paths per frame
/// starts the accumulation over.
#[no_mangle]
pub unsafe extern "C" fn fv_renderer_set_path_tracing(
    renderer: *mut FvRenderer,
    params: *const FvPathTraceParams,
) -> FvStatus {
    set_from(
        renderer,
        || sized::read(params, "params")?.to_core(),
        |r, p| r.r.set_path_tracing(&p),
    )
}

/// Paths per pixel the last path-traced frame shows into `*samples` (0 before the first);
/// a frame after any change of camera, data, transfer function or settings starts over.
#[no_mangle]
pub unsafe extern "C" fn fv_renderer_accumulated_samples(
    renderer: *const FvRenderer,
    samples: *mut u32,
) -> FvStatus {
    with_renderer_ref(renderer, |r| {
        *mut_ref(samples, "samples")? = r.r.accumulated_samples();
        Ok(())
    })
}

/// How far the path tracer's accumulation has come (zeros before the first path-traced
/// frame). Waits for the last frame and reads the accumulation back: call it when the
/// figure is wanted, not every frame.
#[no_mangle]
pub unsafe extern "C" fn fv_renderer_convergence(
    renderer: *const FvRenderer,
    out: *mut FvConvergence,
) -> FvStatus {
    with_renderer_ref(renderer, |r| {
        let c = r.r.convergence()?;
        *mut_ref(out, "convergence")? = FvConvergence {
            paths_per_pixel: c.paths_per_pixel,
            mean_paths_per_pixel: c.mean_paths_per_pixel,
            relative_error: c.relative_error.unwrap_or(-1.0),
        };
        Ok(())
    })
}

/// Renders a `width × height` frame. `depth` (NULL for none) holds `depth_count` =
/// width·height window depths (0 near … 1 far, rows top to bottom) of opaque geometry
/// that stops rays. Returns once the work is submitted; read the result with
/// fv_renderer_read_frame or the shared images.
#[no_mangle]
pub unsafe extern "C" fn fv_renderer_render(
    renderer: *mut FvRenderer,
    width: u32,
    height: u32,
    depth: *const f32,
    depth_count: usize,
) -> FvStatus {
    with_frame(renderer, width, height, |r| {
        let depth = if depth.is_null() {
            None
        } else {
            // SAFETY: the caller guarantees `depth_count` floats at `depth`.
            Some(unsafe { std::slice::from_raw_parts(depth, depth_count) })
        };
        r.r.render(&r.view, &r.params, depth)
    })
}

/// Prepares what a `width × height` frame with the current settings needs, without drawing
/// it: the blend mode's pass, the transfer function's tables, the output images, the bricks
/// it reads and its pipelines, compiled. Call it at set-up (after the volume and the transfer
/// function) so that the first fv_renderer_render does not pay for them; settings a frame
/// would refuse are refused here with the same status and message.
#[no_mangle]
pub unsafe extern "C" fn fv_renderer_prepare(
    renderer: *mut FvRenderer,
    width: u32,
    height: u32,
) -> FvStatus {
    with_frame(renderer, width, height, |r| r.r.prepare(&r.view, &r.params))
}

/// Renders like fv_renderer_render, each pixel's ray sampling only between two window depths:
/// `near` and `far` hold `count` = width·height depths each (0 near … 1 far, rows top to
/// bottom), the interval half-open and empty where near ≥ far, the samples on the lattice of
/// the whole ray (segments that meet share none). For hosts that peel translucent geometry.
/// Ray casting only: FV_STATUS_UNSUPPORTED in the isosurface, slice and path-tracing blend
/// modes and with volumetric shadows.
#[no_mangle]
pub unsafe extern "C" fn fv_renderer_render_between(
    renderer: *mut FvRenderer,
    width: u32,
    height: u32,
    near: *const f32,
    far: *const f32,
    count: usize,
) -> FvStatus {
    with_renderer(renderer, |r| {
        if near.is_null() {
            return Err(FfiError::null("near"));
        }
        if far.is_null() {
            return Err(FfiError::null("far"));
        }
        r.view.width = width;
        r.view.height = height;
        // SAFETY: the caller guarantees `count` floats at `near` and at `far`.
        let (near, far) = unsafe {
            (
                std::slice::from_raw_parts(near, count),
                std::slice::from_raw_parts(far, count),
            )
        };
        r.r.render_between(&r.view, &r.params, near, far)?;
        Ok(())
    })
}

/// Chooses where frames go (an FvOutputPath). FV_OUTPUT_PATH_SHARED is refused with
/// FV_STATUS_UNSUPPORTED and the reason (backend, missing Vulkan extension) where the
/// device cannot export memory; the path is then unchanged.
#[no_mangle]
pub unsafe extern "C" fn fv_renderer_set_output_path(
    renderer: *mut FvRenderer,
    path: u32,
) -> FvStatus {
    with_renderer(renderer, |r| {
        let p = match path {
            0 => OutputPath::Readback,
            1 => OutputPath::Shared,
            _ => {
                return Err(FfiError::invalid(format!(
                    "output path {path} is not an FvOutputPath (0 readback, 1 shared)"
                )))
            }
        };
        r.r.set_output_path(p)?;
        Ok(())
    })
}

/// The active output path (an FvOutputPath) into `*path`.
#[no_mangle]
pub unsafe extern "C" fn fv_renderer_output_path(
    renderer: *const FvRenderer,
    path: *mut u32,
) -> FvStatus {
    with_renderer_ref(renderer, |r| {
        *mut_ref(path, "path")? = match r.r.output_path() {
            OutputPath::Readback => FvOutputPath::Readback as u32,
            OutputPath::Shared => FvOutputPath::Shared as u32,
        };
        Ok(())
    })
}

/// Allocates the frame images for `width × height` now (a render does it too), so a host
/// can import the shared images, and fill the depth input, before the first frame.
#[no_mangle]
pub unsafe extern "C" fn fv_renderer_prepare_targets(
    renderer: *mut FvRenderer,
    width: u32,
    height: u32,
) -> FvStatus {
    with_renderer(renderer, |r| {
        r.r.prepare_targets(width, height)?;
        Ok(())
    })
}

/// Exports one image of the shared output path (an FvTarget) into `*image`, with a new file
/// descriptor the caller owns. FV_STATUS_INVALID_ARGUMENT unless the path is
/// FV_OUTPUT_PATH_SHARED and the images exist (after fv_renderer_prepare_targets or a
/// render).
#[no_mangle]
pub unsafe extern "C" fn fv_renderer_shared_image(
    renderer: *const FvRenderer,
    target: u32,
    image: *mut FvSharedImage,
) -> FvStatus {
    with_renderer_ref(renderer, |r| {
        let out = mut_ref(image, "image")?;
        if target > FvTarget::DepthInput as u32 {
            return Err(FfiError::invalid(format!(
                "target {target} is not an FvTarget (0 colour, 1 depth, 2 depth input)"
            )));
        }
        if r.r.output_path() != OutputPath::Shared {
            return Err(FfiError::invalid(
                "the output is not shared: call fv_renderer_set_output_path(renderer, FV_OUTPUT_PATH_SHARED) first, or read frames with fv_renderer_read_frame",
            ));
        }
        let shared = r.r.shared_targets()?;
        let img = match target {
            0 => shared.color,
            1 => shared.depth,
            _ => shared.depth_in,
        };
        *out = FvSharedImage {
            fd: std::os::fd::IntoRawFd::into_raw_fd(img.fd),
            size: img.size,
            width: img.width,
            height: img.height,
            gl_internal_format: img.gl_internal_format,
            dedicated: img.dedicated,
            generation: shared.generation,
        };
        Ok(())
    })
}

/// Renders like fv_renderer_render, with the opaque depth taken from the shared
/// FV_TARGET_DEPTH_INPUT image the host wrote (it must glFinish before this call).
#[no_mangle]
pub unsafe extern "C" fn fv_renderer_render_with_shared_depth(
    renderer: *mut FvRenderer,
    width: u32,
    height: u32,
) -> FvStatus {
    with_frame(renderer, width, height, |r| {
        r.r.render_with_shared_depth(&r.view, &r.params)
    })
}

/// Waits until the last frame is finished on the GPU: after it, the host may sample the
/// shared images. This CPU wait is the synchronisation of the shared path (no semaphores).
#[no_mangle]
pub unsafe extern "C" fn fv_renderer_finish(renderer: *const FvRenderer) -> FvStatus {
    with_renderer_ref(renderer, |r| {
        r.r.finish()?;
        Ok(())
    })
}

/// Counters of what was uploaded and rendered so far.
#[no_mangle]
pub unsafe extern "C" fn fv_renderer_stats(
    renderer: *const FvRenderer,
    stats: *mut FvStats,
) -> FvStatus {
    with_renderer_ref(renderer, |r| {
        let s = r.r.stats();
        *mut_ref(stats, "stats")? = FvStats {
            volume_uploads: s.volume_uploads,
            table_uploads: s.table_uploads,
            frames: s.frames,
            bricks: r.r.brick_count() as u32,
            accumulation_restarts: s.accumulation_restarts,
        };
        Ok(())
    })
}

/// How much of the volume is on the device (resident bricks and bytes).
#[no_mangle]
pub unsafe extern "C" fn fv_renderer_residency(
    renderer: *const FvRenderer,
    residency: *mut FvResidency,
) -> FvStatus {
    with_renderer_ref(renderer, |r| {
        let s = r.r.residency();
        *mut_ref(residency, "residency")? = FvResidency {
            bricks: s.bricks,
            resident: s.resident,
            brick_uploads: r.r.stats().brick_uploads,
            pool_bytes: s.pool_bytes,
            dense_bytes: s.dense_bytes,
            level: s.level,
            level_dims: s.level_dims,
            stand_ins: s.stand_ins,
        };
        Ok(())
    })
}

/// Told after each pass of a streamed frame (its bricks exceed the memory budget) is
/// submitted: `user` as given to fv_renderer_set_progress, the passes so far and the passes
/// in the frame. Called on the thread rendering the frame, inside fv_renderer_render.
pub type FvProgressFn = Option<unsafe extern "C" fn(user: *mut c_void, done: u32, total: u32)>;

/// The caller's `user` pointer, handed back to its callback on the rendering thread.
struct UserData(*mut c_void);

// SAFETY: ferrovol only hands the pointer back to the caller's callback, on the thread
// that renders; what it points to is the caller's to make safe.
unsafe impl Send for UserData {}

impl UserData {
    fn get(&self) -> *mut c_void {
        self.0
    }
}

/// Calls `progress(user, done, total)` after each pass of a streamed frame (NULL: no
/// calls).
#[no_mangle]
pub unsafe extern "C" fn fv_renderer_set_progress(
    renderer: *mut FvRenderer,
    progress: FvProgressFn,
    user: *mut c_void,
) -> FvStatus {
    with_renderer(renderer, |r| {
        r.r.set_progress(progress.map(|f| {
            let user = UserData(user);
            Box::new(move |done: u32, total: u32| {
                // SAFETY: the caller's callback with the caller's pointer, as documented.
                unsafe { f(user.get(), done, total) }
            }) as ferrovol_core::StreamProgress
        }));
        Ok(())
    })
}
