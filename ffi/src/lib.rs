//! ferrovol's C ABI (library `ferrovol`): opaque handles with `_new`/`_free` pairs, an
//! [`FvStatus`] from every call that can fail with a per-thread message
//! ([`fv_last_error`]), and no panic crossing the boundary. The header
//! `include/ferrovol.h` is generated from this crate by cbindgen.
//!
//! A frame: fv_context_new → fv_renderer_new → fv_volume_new + fv_renderer_set_volume →
//! fv_transfer_function_new (+ set_color / set_opacity) + fv_renderer_set_transfer_function
//! → fv_renderer_set_camera / set_lights / set_params → fv_renderer_render →
//! fv_renderer_read_frame (CPU) or the shared images (zero copy).
#![allow(clippy::missing_safety_doc)] // each export documents its pointer rules in the header

mod iso;
mod status;
mod types;

pub use iso::*;
pub use status::*;
pub use types::*;

use ferrovol_core::{
    ComponentTransfer, Context, Environment, Image, OutputPath, Piecewise, Renderer, Scalars,
    TransferFunction, UploadOptions, View, VolumeData,
};
use std::ffi::{c_char, c_void, CStr};

/// Major version of this header; equals fv_version_major() of a compatible library.
pub const FV_VERSION_MAJOR: u32 = 0;
/// Minor version of this header.
pub const FV_VERSION_MINOR: u32 = 1;
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

// ---------------------------------------------------------------------------------------
// Context

/// A GPU adapter and device. Create one per process (or per host graphics context) and
/// share it between renderers. Thread use: may be used from any thread; calls on one
/// context may run concurrently (the device is internally synchronised).
pub struct FvContext {
    ctx: Context,
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

// ---------------------------------------------------------------------------------------
// Volume

/// Volume data on the CPU (a copy of the caller's array), ready to upload to renderers.
/// Thread use: immutable after creation; may be read from several threads at once.
pub struct FvVolume {
    data: VolumeData,
}

fn scalars_from_bytes(t: FvScalarType, bytes: &[u8]) -> Scalars {
    fn read<T: Copy, const N: usize>(b: &[u8], f: fn([u8; N]) -> T) -> Vec<T> {
        b.chunks_exact(N)
            .map(|c| f(c.try_into().expect("chunk of N")))
            .collect()
    }
    use FvScalarType as T;
    match t {
        T::U8 => Scalars::U8(bytes.to_vec()),
        T::I8 => Scalars::I8(read(bytes, i8::from_ne_bytes)),
        T::U16 => Scalars::U16(read(bytes, u16::from_ne_bytes)),
        T::I16 => Scalars::I16(read(bytes, i16::from_ne_bytes)),
        T::U32 => Scalars::U32(read(bytes, u32::from_ne_bytes)),
        T::I32 => Scalars::I32(read(bytes, i32::from_ne_bytes)),
        T::F32 => Scalars::F32(read(bytes, f32::from_ne_bytes)),
        T::F64 => Scalars::F64(read(bytes, f64::from_ne_bytes)),
        T::I64 => Scalars::F64(read(bytes, |b| i64::from_ne_bytes(b) as f64)),
        T::U64 => Scalars::F64(read(bytes, |b| u64::from_ne_bytes(b) as f64)),
    }
}

const SCALAR_TYPES: [FvScalarType; 10] = [
    FvScalarType::U8,
    FvScalarType::I8,
    FvScalarType::U16,
    FvScalarType::I16,
    FvScalarType::U32,
    FvScalarType::I32,
    FvScalarType::F32,
    FvScalarType::F64,
    FvScalarType::I64,
    FvScalarType::U64,
];

fn scalar_size(t: FvScalarType) -> usize {
    use FvScalarType as T;
    match t {
        T::U8 | T::I8 => 1,
        T::U16 | T::I16 => 2,
        T::U32 | T::I32 | T::F32 => 4,
        T::F64 | T::I64 | T::U64 => 8,
    }
}

/// Copies a volume: `data` holds dims[0]·dims[1]·dims[2]·components values of
/// `desc->scalar_type`, components interleaved, x fastest; `data_bytes` is its size in
/// bytes (checked). Scalars are validated (NaN/Inf refused, spacing > 0, direction
/// invertible). `*out` receives the volume, NULL on failure.
#[no_mangle]
pub unsafe extern "C" fn fv_volume_new(
    desc: *const FvVolumeDesc,
    data: *const c_void,
    data_bytes: usize,
    out: *mut *mut FvVolume,
) -> FvStatus {
    guard(|| {
        let slot = out_ptr(out, "out")?;
        let d = const_ref(desc, "desc")?;
        if data.is_null() {
            return Err(FfiError::null("data"));
        }
        let t = *SCALAR_TYPES.get(d.scalar_type as usize).ok_or_else(|| {
            FfiError::new(
                FvStatus::Unsupported,
                format!(
                    "scalar type {} is not an FvScalarType (0 to {})",
                    d.scalar_type,
                    SCALAR_TYPES.len() - 1
                ),
            )
        })?;
        let count = d
            .dims
            .iter()
            .map(|&n| n as u64)
            .product::<u64>()
            .checked_mul(d.components as u64)
            .ok_or_else(|| FfiError::invalid("volume size overflows"))?;
        let expected = count
            .checked_mul(scalar_size(t) as u64)
            .filter(|&b| b <= usize::MAX as u64)
            .ok_or_else(|| FfiError::invalid("volume size overflows"))?;
        if expected != data_bytes as u64 {
            return Err(FfiError::invalid(format!(
                "data_bytes is {data_bytes} but {}x{}x{} points × {} component(s) of {:?} need {expected}",
                d.dims[0], d.dims[1], d.dims[2], d.components, t
            )));
        }
        // SAFETY: the caller guarantees `data` points to `data_bytes` readable bytes.
        let bytes = unsafe { std::slice::from_raw_parts(data.cast::<u8>(), data_bytes) };
        let m = &d.direction;
        let direction = [[m[0], m[1], m[2]], [m[3], m[4], m[5]], [m[6], m[7], m[8]]];
        let v = VolumeData {
            dims: d.dims,
            spacing: d.spacing,
            origin: d.origin,
            direction,
            components: d.components,
            scalars: scalars_from_bytes(t, bytes),
        };
        v.validate()?;
        *slot = Box::into_raw(Box::new(FvVolume { data: v }));
        Ok(())
    })
}

/// Releases a volume (NULL is ignored). Renderers keep what they uploaded.
#[no_mangle]
pub unsafe extern "C" fn fv_volume_free(volume: *mut FvVolume) {
    guard_value((), || free_handle(volume))
}

/// Minimum and maximum of one component into `range[0..2]`.
#[no_mangle]
pub unsafe extern "C" fn fv_volume_range(
    volume: *const FvVolume,
    component: u32,
    range: *mut [f64; 2],
) -> FvStatus {
    guard(|| {
        let v = const_ref(volume, "volume")?;
        let out = mut_ref(range, "range")?;
        if component >= v.data.components {
            return Err(FfiError::invalid(format!(
                "component {component}: the volume has {}",
                v.data.components
            )));
        }
        *out = v.data.range(component);
        Ok(())
    })
}

// ---------------------------------------------------------------------------------------
// Transfer function

#[derive(Clone, Default)]
struct PartialComponent {
    color: Option<Piecewise<3>>,
    opacity: Option<Piecewise<1>>,
    gradient_opacity: Option<Piecewise<1>>,
    unit_distance: Option<f64>,
    weight: Option<f32>,
}

/// Colour, scalar opacity and gradient opacity per component (vtkVolumeProperty's
/// functions). Thread use: one thread at a time.
pub struct FvTransferFunction {
    components: Vec<PartialComponent>,
    independent: bool,
}

impl FvTransferFunction {
    fn component(&mut self, c: u32) -> FfiResult<&mut PartialComponent> {
        let n = self.components.len();
        self.components.get_mut(c as usize).ok_or_else(|| {
            FfiError::invalid(format!(
                "component {c}: this transfer function has {n} (0 to {})",
                n - 1
            ))
        })
    }
}

impl ToCore for FvTransferFunction {
    type Core = TransferFunction;
    fn to_core(&self) -> FfiResult<TransferFunction> {
        let mut components = Vec::with_capacity(self.components.len());
        for (i, c) in self.components.iter().enumerate() {
            let (Some(color), Some(opacity)) = (&c.color, &c.opacity) else {
                return Err(FfiError::invalid(format!(
                    "component {i} needs both a colour and an opacity function (fv_transfer_function_set_color / _set_opacity)"
                )));
            };
            let mut t = ComponentTransfer::new(color.clone(), opacity.clone());
            t.gradient_opacity = c.gradient_opacity.clone();
            t.unit_distance = c.unit_distance.unwrap_or(t.unit_distance);
            t.weight = c.weight.unwrap_or(t.weight);
            components.push(t);
        }
        Ok(TransferFunction {
            components,
            independent: self.independent,
        })
    }
}

fn points<const N: usize>(
    what: &str,
    p: *const f64,
    count: usize,
) -> FfiResult<Option<Piecewise<N>>> {
    if count == 0 {
        return Ok(None);
    }
    if p.is_null() {
        return Err(FfiError::null(what));
    }
    // SAFETY: the caller guarantees `count` points of 1 + N doubles.
    let flat = unsafe { std::slice::from_raw_parts(p, count * (N + 1)) };
    let pts = flat
        .chunks_exact(N + 1)
        .map(|c| (c[0], std::array::from_fn(|i| c[i + 1] as f32)))
        .collect();
    Piecewise::new(pts)
        .map(Some)
        .map_err(|e| FfiError::invalid(format!("{what}: {e}")))
}

/// A transfer function for `components` (1–4) components; `independent` is
/// vtkVolumeProperty::IndependentComponents (with dependent components, give one
/// component's functions). `*out` receives it, NULL on failure.
#[no_mangle]
pub unsafe extern "C" fn fv_transfer_function_new(
    components: u32,
    independent: bool,
    out: *mut *mut FvTransferFunction,
) -> FvStatus {
    guard(|| {
        let slot = out_ptr(out, "out")?;
        if !(1..=4).contains(&components) {
            return Err(FfiError::invalid(format!(
                "{components} components: a transfer function has 1 to 4"
            )));
        }
        *slot = Box::into_raw(Box::new(FvTransferFunction {
            components: vec![PartialComponent::default(); components as usize],
            independent,
        }));
        Ok(())
    })
}

/// Releases a transfer function (NULL is ignored).
#[no_mangle]
pub unsafe extern "C" fn fv_transfer_function_free(tf: *mut FvTransferFunction) {
    guard_value((), || free_handle(tf))
}

/// Replaces one of a component's piecewise functions (`field`) with `count` points of
/// 1 + N doubles at `p`. `empty` is the refusal for count = 0, or None where no points
/// turn the function off.
fn set_component_points<const N: usize>(
    tf: *mut FvTransferFunction,
    component: u32,
    what: &str,
    p: *const f64,
    count: usize,
    empty: Option<&str>,
    field: fn(&mut PartialComponent) -> &mut Option<Piecewise<N>>,
) -> FvStatus {
    guard(|| {
        let f = field(mut_ref(tf, "tf")?.component(component)?);
        *f = points::<N>(what, p, count)?;
        match empty {
            Some(refusal) if f.is_none() => Err(FfiError::invalid(refusal)),
            _ => Ok(()),
        }
    })
}

/// Colour points of one component: `count` quadruples (x, r, g, b), x increasing.
#[no_mangle]
pub unsafe extern "C" fn fv_transfer_function_set_color(
    tf: *mut FvTransferFunction,
    component: u32,
    xrgb: *const f64,
    count: usize,
) -> FvStatus {
    set_component_points(
        tf,
        component,
        "colour points",
        xrgb,
        count,
        Some("a colour function needs at least one point"),
        |c| &mut c.color,
    )
}

/// Scalar opacity points of one component: `count` pairs (x, opacity), x increasing.
#[no_mangle]
pub unsafe extern "C" fn fv_transfer_function_set_opacity(
    tf: *mut FvTransferFunction,
    component: u32,
    xa: *const f64,
    count: usize,
) -> FvStatus {
    set_component_points(
        tf,
        component,
        "opacity points",
        xa,
        count,
        Some("an opacity function needs at least one point"),
        |c| &mut c.opacity,
    )
}

/// Gradient-magnitude opacity points of one component: `count` pairs (|∇s| in scalar units
/// per world unit, opacity multiplier); count = 0 turns gradient opacity off.
#[no_mangle]
pub unsafe extern "C" fn fv_transfer_function_set_gradient_opacity(
    tf: *mut FvTransferFunction,
    component: u32,
    xa: *const f64,
    count: usize,
) -> FvStatus {
    set_component_points(
        tf,
        component,
        "gradient opacity points",
        xa,
        count,
        None,
        |c| &mut c.gradient_opacity,
    )
}

/// ScalarOpacityUnitDistance (> 0) and the component weight (≥ 0) of one component.
#[no_mangle]
pub unsafe extern "C" fn fv_transfer_function_set_unit_distance(
    tf: *mut FvTransferFunction,
    component: u32,
    unit_distance: f64,
    weight: f64,
) -> FvStatus {
    guard(|| {
        let t = mut_ref(tf, "tf")?;
        if !(unit_distance.is_finite() && unit_distance > 0.0) {
            return Err(FfiError::invalid(format!(
                "scalar opacity unit distance {unit_distance} must be positive"
            )));
        }
        if !(weight.is_finite() && weight >= 0.0) {
            return Err(FfiError::invalid(format!(
                "component weight {weight} must be finite and non-negative"
            )));
        }
        let c = t.component(component)?;
        c.unit_distance = Some(unit_distance);
        c.weight = Some(weight as f32);
        Ok(())
    })
}

// ---------------------------------------------------------------------------------------
// Renderer

/// A renderer: the uploaded volume, transfer tables, pipelines and the frame it draws.
/// Camera, lights and parameters persist between frames. Thread use: one thread at a
/// time (it may move between threads).
pub struct FvRenderer {
    r: Renderer,
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

/// [`with_renderer`] for the calls that only read the renderer.
fn with_renderer_ref(
    renderer: *const FvRenderer,
    f: impl FnOnce(&FvRenderer) -> FfiResult<()>,
) -> FvStatus {
    guard(|| f(const_ref(renderer, "renderer")?))
}

/// Converts the C description at `value` (`what` names it when NULL) and hands it to `apply`.
fn set_from<T: ToCore>(
    renderer: *mut FvRenderer,
    value: *const T,
    what: &str,
    apply: impl FnOnce(&mut FvRenderer, T::Core) -> ferrovol_core::Result<()>,
) -> FvStatus {
    with_renderer(renderer, |r| {
        let v = const_ref(value, what)?.to_core()?;
        apply(r, v)?;
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

/// Uploads a volume (replacing the previous one). Call again only when the data changed:
/// camera and parameter changes never re-upload.
#[no_mangle]
pub unsafe extern "C" fn fv_renderer_set_volume(
    renderer: *mut FvRenderer,
    volume: *const FvVolume,
) -> FvStatus {
    with_renderer(renderer, |r| {
        let v = const_ref(volume, "volume")?;
        r.r.set_volume_with(&v.data, r.upload)?;
        Ok(())
    })
}

/// Sets the transfer function; only its tables are re-uploaded.
#[no_mangle]
pub unsafe extern "C" fn fv_renderer_set_transfer_function(
    renderer: *mut FvRenderer,
    tf: *const FvTransferFunction,
) -> FvStatus {
    set_from(renderer, tf, "tf", |r, t| r.r.set_transfer_function(&t))
}

/// Sets the camera for the following frames.
#[no_mangle]
pub unsafe extern "C" fn fv_renderer_set_camera(
    renderer: *mut FvRenderer,
    camera: *const FvCamera,
) -> FvStatus {
    set_from(renderer, camera, "camera", |r, c| {
        r.view.camera = c;
        Ok(())
    })
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
/// distance, no shading, early termination at 1 − 1/255).
#[no_mangle]
pub unsafe extern "C" fn fv_render_params_default(params: *mut FvRenderParams) -> FvStatus {
    guard(|| {
        *mut_ref(params, "params")? = FvRenderParams::defaults();
        Ok(())
    })
}

/// Sets the render parameters (validated: out-of-range values are refused and the previous
/// parameters kept).
#[no_mangle]
pub unsafe extern "C" fn fv_renderer_set_params(
    renderer: *mut FvRenderer,
    params: *const FvRenderParams,
) -> FvStatus {
    set_from(renderer, params, "params", |r, p| {
        r.params = p;
        Ok(())
    })
}

/// Fills `*params` with the isosurface defaults (no iso-values yet: set `value_count` and
/// `values`; 8 bisection steps, 4 layers, 16 importance-sampled specular samples,
/// shininess 8 to 64 by gradient magnitude, no Fresnel, no ambient occlusion, environment
/// weight 0.6, no background).
#[no_mangle]
pub unsafe extern "C" fn fv_iso_params_default(params: *mut FvIsoParams) -> FvStatus {
    guard(|| {
        *mut_ref(params, "params")? = FvIsoParams::defaults();
        Ok(())
    })
}

/// Sets the isosurfaces and their shading for frames with FV_BLEND_MODE_ISOSURFACE
/// (validated: out-of-range values are refused and the previous settings kept).
#[no_mangle]
pub unsafe extern "C" fn fv_renderer_set_isosurface(
    renderer: *mut FvRenderer,
    params: *const FvIsoParams,
) -> FvStatus {
    set_from(renderer, params, "params", |r, p| r.r.set_isosurface(&p))
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
#[no_mangle]
pub unsafe extern "C" fn fv_path_trace_params_default(params: *mut FvPathTraceParams) -> FvStatus {
    guard(|| {
        *mut_ref(params, "params")? = FvPathTraceParams::defaults();
        Ok(())
    })
}

/// Sets how frames with FV_BLEND_MODE_PATH_TRACE sample (validated: out-of-range values are
/// refused and the previous settings kept). A change other than of the paths per frame
/// starts the accumulation over.
#[no_mangle]
pub unsafe extern "C" fn fv_renderer_set_path_tracing(
    renderer: *mut FvRenderer,
    params: *const FvPathTraceParams,
) -> FvStatus {
    set_from(renderer, params, "params", |r, p| r.r.set_path_tracing(&p))
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
    with_renderer(renderer, |r| {
        r.view.width = width;
        r.view.height = height;
        let depth = if depth.is_null() {
            None
        } else {
            // SAFETY: the caller guarantees `depth_count` floats at `depth`.
            Some(unsafe { std::slice::from_raw_parts(depth, depth_count) })
        };
        r.r.render(&r.view, &r.params, depth)?;
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
        r.r.prepare_output(width, height)?;
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
        let shared = r.r.shared_output()?;
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
    with_renderer(renderer, |r| {
        r.view.width = width;
        r.view.height = height;
        r.r.render_with_shared_depth(&r.view, &r.params)?;
        Ok(())
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
        };
        Ok(())
    })
}

// ---------------------------------------------------------------------------------------
// Frame

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
