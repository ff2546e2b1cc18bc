//! Loads the built cdylib with libloading, as a C host would, and drives the error paths:
//! NULL handles, bad sizes, unsupported types and out-of-range parameters each return the
//! right status with a message naming the problem, and nothing panics across the boundary.

use ferrovol::FvStatus::{self, InvalidArgument as Invalid, NullArgument as Null};
use ferrovol::{
    FvBlendMode, FvCamera, FvIntermixedVolume, FvIsoParams, FvLight, FvPathTraceParams,
    FvQuadrature, FvRenderParams, FvScalarType, FvSharedImage, FvVolumeDesc,
};
use libloading::{Library, Symbol};
use std::ffi::{c_char, c_void, CStr};
use std::path::Path;
use std::ptr::{null, null_mut};

mod features;
mod resources;
mod unstructured;

type H = *mut c_void;

struct Lib(Library);

impl Lib {
    fn open() -> Lib {
        let exe = std::env::current_exe().unwrap();
        let path = exe
            .parent()
            .and_then(Path::parent)
            .unwrap()
            .join("libferrovol.so");
        // SAFETY: loading our own library, whose initialisers are Rust's (none run code).
        // (`cargo test` builds only the rlib: `cargo build -p ferrovol-ffi` makes the cdylib,
        // and `make test` runs it first.)
        Lib(unsafe { Library::new(&path) }.unwrap_or_else(|e| {
            panic!(
                "{}: {e}; build it with `cargo build -p ferrovol-ffi` (make test does)",
                path.display()
            )
        }))
    }
    fn f<T>(&self, name: &str) -> Symbol<'_, T> {
        // SAFETY: each call site names the C signature of the symbol it looks up.
        unsafe { self.0.get(name.as_bytes()) }.unwrap_or_else(|e| panic!("{name}: {e}"))
    }
    fn last_error(&self) -> String {
        let f = self.f::<extern "C" fn() -> *const c_char>("fv_last_error");
        // SAFETY: fv_last_error returns a valid NUL-terminated string.
        unsafe { CStr::from_ptr(f()) }
            .to_string_lossy()
            .into_owned()
    }
    /// Asserts that a call returned `want` and that its message contains `needle`; prints
    /// both.
    fn expect(&self, status: FvStatus, want: FvStatus, needle: &str) {
        let msg = self.last_error();
        println!("{needle}: {status:?}: {msg}");
        assert_eq!(status, want, "{needle}: {msg}");
        assert!(msg.contains(needle), "'{msg}' lacks '{needle}'");
    }
    /// Asserts that a call succeeded (the message of its failure otherwise).
    fn ok(&self, status: FvStatus) {
        assert_eq!(status, FvStatus::Ok, "{}", self.last_error());
    }
}

type NewCtx = unsafe extern "C" fn(*mut H) -> FvStatus;
type Free = unsafe extern "C" fn(H);
type NewRenderer = unsafe extern "C" fn(H, *mut H) -> FvStatus;
type NewVolume =
    unsafe extern "C" fn(*const FvVolumeDesc, *const c_void, usize, *mut H) -> FvStatus;
type SetH = unsafe extern "C" fn(H, H) -> FvStatus;
type NewTf = unsafe extern "C" fn(u32, bool, *mut H) -> FvStatus;
type SetPoints = unsafe extern "C" fn(H, u32, *const f64, usize) -> FvStatus;
type Render = unsafe extern "C" fn(H, u32, u32, *const f32, usize) -> FvStatus;
type SetParams = unsafe extern "C" fn(H, *const FvRenderParams) -> FvStatus;
type ParamsDefault = unsafe extern "C" fn(*mut FvRenderParams, usize) -> FvStatus;
type SetCamera = unsafe extern "C" fn(H, *const FvCamera) -> FvStatus;
type SetLights = unsafe extern "C" fn(H, *const FvLight, usize) -> FvStatus;
type SetIso = unsafe extern "C" fn(H, *const FvIsoParams) -> FvStatus;
type SetEnv = unsafe extern "C" fn(H, *const c_char, f32, *const f64, f64) -> FvStatus;
type SetPt = unsafe extern "C" fn(H, *const FvPathTraceParams) -> FvStatus;
type Accumulated = unsafe extern "C" fn(H, *mut u32) -> FvStatus;
type SetCoords =
    unsafe extern "C" fn(H, *const f64, usize, *const f64, usize, *const f64, usize) -> FvStatus;

fn desc(dims: [u32; 3], components: u32, scalar_type: u32) -> FvVolumeDesc {
    FvVolumeDesc {
        dims,
        components,
        scalar_type,
        spacing: [1.0; 3],
        origin: [0.0; 3],
        direction: [1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0],
    }
}

/// A perspective camera (30°, +y up).
fn camera(position: [f64; 3], focal_point: [f64; 3], clipping_range: [f64; 2]) -> FvCamera {
    // SAFETY: FvCamera is plain data; all zeros is a valid value.
    let mut cam: FvCamera = unsafe { std::mem::zeroed() };
    cam.position = position;
    cam.focal_point = focal_point;
    cam.view_up = [0.0, 1.0, 0.0];
    cam.view_angle = 30.0;
    cam.clipping_range = clipping_range;
    cam
}

/// A context and a renderer, with the volume, transfer function and frame a test gives
/// them; dropping it frees every handle (the fv_*_free functions accept NULL).
struct Session<'a> {
    lib: &'a Lib,
    ctx: H,
    r: H,
    volume: H,
    tf: H,
    frame: H,
}

impl<'a> Session<'a> {
    fn new(lib: &'a Lib) -> Self {
        let mut s = Session {
            lib,
            ctx: null_mut(),
            r: null_mut(),
            volume: null_mut(),
            tf: null_mut(),
            frame: null_mut(),
        };
        // SAFETY: valid out-pointers.
        unsafe {
            lib.ok(lib.f::<NewCtx>("fv_context_new")(&mut s.ctx));
            lib.ok(lib.f::<NewRenderer>("fv_renderer_new")(s.ctx, &mut s.r));
        }
        s
    }

    /// Uploads `data`, one component of `scalar_type` per point, as the renderer's volume.
    fn set_volume<T>(&mut self, dims: [u32; 3], scalar_type: FvScalarType, data: &[T]) {
        let d = desc(dims, 1, scalar_type as u32);
        let bytes = std::mem::size_of_val(data);
        let lib = self.lib;
        // SAFETY: `data` holds `bytes` bytes; valid handles and out-pointer.
        unsafe {
            lib.ok(lib.f::<NewVolume>("fv_volume_new")(
                &d,
                data.as_ptr().cast(),
                bytes,
                &mut self.volume,
            ));
            lib.ok(lib.f::<SetH>("fv_renderer_set_volume")(self.r, self.volume));
        }
    }

    /// Gives the renderer a one-component transfer function of colour (x, r, g, b) and
    /// opacity (x, a) points (into the session's transfer function, made if there is none).
    fn set_transfer_function(&mut self, xrgb: &[f64], xa: &[f64]) {
        let lib = self.lib;
        // SAFETY: the point arrays hold the counts given; valid handles.
        unsafe {
            if self.tf.is_null() {
                lib.ok(lib.f::<NewTf>("fv_transfer_function_new")(
                    1,
                    true,
                    &mut self.tf,
                ));
            }
            let color = lib.f::<SetPoints>("fv_transfer_function_set_color");
            lib.ok(color(self.tf, 0, xrgb.as_ptr(), xrgb.len() / 4));
            let opacity = lib.f::<SetPoints>("fv_transfer_function_set_opacity");
            lib.ok(opacity(self.tf, 0, xa.as_ptr(), xa.len() / 2));
            lib.ok(lib.f::<SetH>("fv_renderer_set_transfer_function")(
                self.r, self.tf,
            ));
        }
    }

    fn set_camera(&self, cam: &FvCamera) {
        // SAFETY: a valid handle and camera.
        self.lib
            .ok(unsafe { self.lib.f::<SetCamera>("fv_renderer_set_camera")(self.r, cam) });
    }

    fn set_params(&self, p: &FvRenderParams) {
        // SAFETY: a valid handle and parameters.
        self.lib
            .ok(unsafe { self.lib.f::<SetParams>("fv_renderer_set_params")(self.r, p) });
    }

    fn render(&self, width: u32, height: u32) {
        // SAFETY: a valid handle, no depth input.
        let render = self.lib.f::<Render>("fv_renderer_render");
        self.lib
            .ok(unsafe { render(self.r, width, height, null(), 0) });
    }

    /// Renders a `width × height` frame and reads it back: its premultiplied RGBA8 pixels.
    fn frame(&mut self, width: u32, height: u32) -> &[u8] {
        self.render(width, height);
        let lib = self.lib;
        // SAFETY: valid handles; the pixels live as long as the frame, which the session
        // frees only on drop or on the next read.
        unsafe {
            lib.f::<Free>("fv_frame_free")(self.frame);
            self.frame = null_mut();
            let read =
                lib.f::<unsafe extern "C" fn(H, *mut H) -> FvStatus>("fv_renderer_read_frame");
            lib.ok(read(self.r, &mut self.frame));
            let rgba = lib.f::<unsafe extern "C" fn(H) -> *const u8>("fv_frame_rgba")(self.frame);
            std::slice::from_raw_parts(rgba, (4 * width * height) as usize)
        }
    }
}

impl Drop for Session<'_> {
    fn drop(&mut self) {
        let handles = [
            ("fv_frame_free", self.frame),
            ("fv_transfer_function_free", self.tf),
            ("fv_volume_free", self.volume),
            ("fv_renderer_free", self.r),
            ("fv_context_free", self.ctx),
        ];
        for (free, h) in handles {
            // SAFETY: each handle came from its fv_*_new (or is NULL) and is freed once.
            unsafe { self.lib.f::<Free>(free)(h) };
        }
    }
}

#[test]
fn free_functions_accept_null() {
    let lib = Lib::open();
    for name in [
        "fv_context_free",
        "fv_renderer_free",
        "fv_volume_free",
        "fv_unstructured_volume_free",
        "fv_transfer_function_free",
        "fv_frame_free",
    ] {
        // SAFETY: every fv_*_free takes one handle and accepts NULL.
        unsafe { lib.f::<Free>(name)(null_mut()) };
    }
}

#[test]
fn volume_errors() {
    let lib = Lib::open();
    let new = lib.f::<NewVolume>("fv_volume_new");
    let data = vec![0f32; 8];
    let bytes = data.as_ptr().cast::<c_void>();
    let mut v: H = null_mut();
    let f32_type = FvScalarType::F32 as u32;
    let d = desc([2, 2, 2], 1, f32_type);
    let mut zero_spacing = d;
    zero_spacing.spacing[1] = 0.0;
    let mut singular = d;
    singular.direction = [0.0; 9];
    let mut huge_spacing = d;
    huge_spacing.spacing[2] = 1e308;
    let mut far_origin = d;
    far_origin.origin[0] = -1e39;
    far_origin.spacing[0] = 1e-300;
    let mut nan = data.clone();
    nan[5] = f32::NAN;
    // SAFETY (all calls below): arguments follow the header; invalid ones are the test.
    unsafe {
        lib.expect(new(&d, bytes, 32, null_mut()), Null, "out is NULL");
        lib.expect(new(null(), bytes, 32, &mut v), Null, "desc");
        lib.expect(new(&d, null(), 32, &mut v), Null, "data");
        for (desc, len, want, needle) in [
            (d, 31, Invalid, "data_bytes is 31"),
            (
                desc([2, 2, 2], 1, 99),
                32,
                FvStatus::Unsupported,
                "scalar type 99",
            ),
            (
                desc([2, 2, 1], 5, FvScalarType::U8 as u32),
                20,
                Invalid,
                "5 components",
            ),
            (desc([0, 2, 2], 1, f32_type), 0, Invalid, "empty volume"),
            (zero_spacing, 32, Invalid, "spacing along y"),
            (singular, 32, Invalid, "singular"),
            (huge_spacing, 32, Invalid, "bounds along z are [0e0, 1e308]"),
            (far_origin, 32, Invalid, "bounds along x are [-1e39, -1e39]"),
        ] {
            lib.expect(new(&desc, bytes, len, &mut v), want, needle);
        }
        lib.expect(new(&d, nan.as_ptr().cast(), 32, &mut v), Invalid, "NaN");
        assert!(v.is_null(), "a failed fv_volume_new must leave *out NULL");
        lib.ok(new(&d, bytes, 32, &mut v));
        assert!(!v.is_null());
        lib.f::<Free>("fv_volume_free")(v);
    }
}

/// fv_volume_set_coordinates: NULL arrays, a count that is not one per point, values not
/// finite or not increasing are refused naming the axis, and leave the volume as it was.
#[test]
fn rectilinear_coordinates_through_the_c_abi() {
    let lib = Lib::open();
    let set = lib.f::<SetCoords>("fv_volume_set_coordinates");
    let data = [
        0f32, 1.0, 2.0, 3.0, 4.0, 5.0, 6.0, 7.0, 8.0, 9.0, 10.0, 11.0,
    ];
    let mut v: H = null_mut();
    let (x, y, z) = ([0.0, 1.0, 4.0], [0.0, 2.0], [-1.0, 1.0]);
    let (bad_order, nan) = ([0.0, 4.0, 1.0], [0.0, f64::NAN]);
    // SAFETY (all calls below): arguments follow the header; invalid ones are the test.
    unsafe {
        lib.ok(lib.f::<NewVolume>("fv_volume_new")(
            &desc([3, 2, 2], 1, FvScalarType::F32 as u32),
            data.as_ptr().cast(),
            48,
            &mut v,
        ));
        let p = |a: &[f64]| a.as_ptr();
        lib.expect(
            set(null_mut(), p(&x), 3, p(&y), 2, p(&z), 2),
            Null,
            "volume",
        );
        lib.expect(set(v, p(&x), 3, null(), 2, p(&z), 2), Null, "y is NULL");
        for (args, needle) in [
            (
                (p(&x), 2, p(&y), 2, p(&z), 2),
                "2 x coordinates for a grid of 3 points along x",
            ),
            (
                (p(&bad_order), 3, p(&y), 2, p(&z), 2),
                "strictly increasing",
            ),
            ((p(&x), 3, p(&y), 2, p(&nan), 2), "z coordinate 1 is NaN"),
        ] {
            let (a, na, b, nb, c, nc) = args;
            lib.expect(set(v, a, na, b, nb, c, nc), Invalid, needle);
        }
        lib.ok(set(v, p(&x), 3, p(&y), 2, p(&z), 2));
        let mut r = [0.0; 2];
        type Range = unsafe extern "C" fn(H, u32, *mut [f64; 2]) -> FvStatus;
        lib.ok(lib.f::<Range>("fv_volume_range")(v, 0, &mut r));
        assert_eq!(r, [0.0, 11.0]);
        lib.f::<Free>("fv_volume_free")(v);
    }
}

#[test]
fn transfer_function_errors() {
    let lib = Lib::open();
    let mut tf: H = null_mut();
    let pts = [0.0, 1.0, 1.0, 1.0];
    let nan = [0.0, f64::NAN];
    let new = lib.f::<NewTf>("fv_transfer_function_new");
    let color = lib.f::<SetPoints>("fv_transfer_function_set_color");
    let opacity = lib.f::<SetPoints>("fv_transfer_function_set_opacity");
    let gradient = lib.f::<SetPoints>("fv_transfer_function_set_gradient_opacity");
    let unit = lib.f::<unsafe extern "C" fn(H, u32, f64, f64) -> FvStatus>(
        "fv_transfer_function_set_unit_distance",
    );
    // SAFETY: arguments follow the header; invalid ones are the test.
    unsafe {
        lib.expect(new(0, true, &mut tf), Invalid, "0 components");
        lib.ok(new(1, true, &mut tf));
        lib.expect(color(tf, 3, pts.as_ptr(), 1), Invalid, "component 3");
        lib.expect(color(tf, 0, null(), 2), Null, "colour points");
        lib.expect(color(tf, 0, pts.as_ptr(), 0), Invalid, "a colour function");
        lib.expect(opacity(tf, 0, pts.as_ptr(), 0), Invalid, "opacity function");
        lib.expect(opacity(tf, 0, nan.as_ptr(), 1), Invalid, "opacity points");
        lib.expect(gradient(tf, 2, pts.as_ptr(), 1), Invalid, "component 2");
        lib.expect(gradient(tf, 0, nan.as_ptr(), 1), Invalid, "gradient");
        // Positions beyond ±1e38 made the table sampling panic; refused, naming the point.
        let far = [0.0, 0.0, 0.0, 0.0, 1e308, 1.0, 1.0, 1.0];
        lib.expect(
            color(tf, 0, far.as_ptr(), 2),
            Invalid,
            "point 1 is at 1e308",
        );
        let far = [-1e308, 1.0];
        lib.expect(
            opacity(tf, 0, far.as_ptr(), 1),
            Invalid,
            "point 0 is at -1e308",
        );
        lib.expect(gradient(tf, 0, far.as_ptr(), 1), Invalid, "beyond ±1e38");
        lib.ok(gradient(tf, 0, null(), 0));
        lib.expect(unit(tf, 0, 0.0, 1.0), Invalid, "unit distance 0");
        lib.expect(unit(tf, 0, 1.0, -1.0), Invalid, "weight -1");
        lib.expect(unit(null_mut(), 0, 1.0, 1.0), Null, "tf is NULL");
        let material = lib.f::<unsafe extern "C" fn(H, u32, *const [f32; 4]) -> FvStatus>(
            "fv_transfer_function_set_material",
        );
        lib.expect(
            material(tf, 0, &[0.1, 0.7, -0.2, 10.0]),
            Invalid,
            "material",
        );
        lib.expect(
            material(tf, 0, &[0.1, f32::NAN, 0.2, 10.0]),
            Invalid,
            "non-negative",
        );
        lib.expect(
            material(tf, 1, &[0.1, 0.7, 0.2, 10.0]),
            Invalid,
            "component 1",
        );
        lib.ok(material(tf, 0, &[0.1, 0.7, 0.2, 10.0]));
        lib.ok(material(tf, 0, null()));
        lib.f::<Free>("fv_transfer_function_free")(tf);
    }
}

#[test]
fn renderer_errors() {
    let lib = Lib::open();
    let render = lib.f::<Render>("fv_renderer_render");
    let set_params = lib.f::<SetParams>("fv_renderer_set_params");
    let mut p = FvRenderParams::defaults();
    // SAFETY: arguments follow the header; invalid ones are the test.
    unsafe {
        lib.expect(lib.f::<NewCtx>("fv_context_new")(null_mut()), Null, "out");
        let mut s = Session::new(&lib);
        let mut r: H = null_mut();
        let new_r = lib.f::<NewRenderer>("fv_renderer_new");
        lib.expect(new_r(null_mut(), &mut r), Null, "ctx is NULL");
        lib.expect(render(null_mut(), 8, 8, null(), 0), Null, "renderer");
        lib.expect(render(s.r, 8, 8, null(), 0), Invalid, "volume");

        s.set_volume([4, 4, 4], FvScalarType::U16, &[7u16; 4 * 4 * 4]);
        lib.ok(lib.f::<NewTf>("fv_transfer_function_new")(
            1, true, &mut s.tf,
        ));
        let set_tf = lib.f::<SetH>("fv_renderer_set_transfer_function");
        lib.expect(
            set_tf(s.r, s.tf),
            Invalid,
            "needs both a colour and an opacity",
        );
        s.set_transfer_function(
            &[0.0, 1.0, 1.0, 1.0, 10.0, 1.0, 1.0, 1.0],
            &[0.0, 0.0, 10.0, 1.0],
        );

        lib.expect(render(s.r, 0, 0, null(), 0), Invalid, "image size 0x0");
        lib.expect(
            render(s.r, 1 << 20, 4, null(), 0),
            Invalid,
            "each side must be",
        );
        let depth = [1.0f32; 10];
        lib.expect(render(s.r, 8, 8, depth.as_ptr(), 10), Invalid, "10 values");

        type Edit = fn(&mut FvRenderParams);
        let cases: [(Edit, &str); 15] = [
            (|p| p.blend_mode = 42, "blend_mode 42"),
            (|p| p.quadrature = 5, "quadrature 5"),
            (
                |p| {
                    p.quadrature = FvQuadrature::Midpoint as u32;
                    p.jitter = true;
                },
                "midpoint quadrature",
            ),
            (
                |p| {
                    p.quadrature = FvQuadrature::Adaptive as u32;
                    p.jitter = true;
                },
                "adaptive quadrature",
            ),
            (
                |p| {
                    p.blend_mode = FvBlendMode::Slice as u32;
                    p.slice_plane.normal = [0.0; 3];
                },
                "slice plane",
            ),
            (
                |p| {
                    p.blend_mode = FvBlendMode::Slice as u32;
                    p.slice_plane.origin[1] = f64::INFINITY;
                },
                "finite origin",
            ),
            (|p| p.interpolation = 3, "interpolation 3"),
            (|p| p.gradient_method = 9, "gradient_method 9"),
            (|p| p.sample_distance = -1.0, "sample_distance -1"),
            (|p| p.termination_threshold = 0.0, "termination threshold 0"),
            (|p| p.clip_plane_count = 9, "clip_plane_count 9"),
            (|p| p.clip_plane_count = 1, "non-zero normal"),
            (
                |p| {
                    p.cropping = true;
                    p.cropping_planes = [1.0, 0.0, 0.0, 1.0, 0.0, 1.0];
                },
                "min ≤ max",
            ),
            (|p| p.volume_matrix = [0.0; 16], "singular"),
            (|p| p.specular_power = f32::NAN, "specular power"),
        ];
        for (edit, needle) in cases {
            let mut bad = p;
            edit(&mut bad);
            lib.expect(set_params(s.r, &bad), Invalid, needle);
        }

        let defaults = lib.f::<ParamsDefault>("fv_render_params_default");
        let size = size_of::<FvRenderParams>();
        lib.expect(defaults(null_mut(), size), Null, "params is NULL");
        let mut from_c: FvRenderParams = std::mem::zeroed();
        lib.ok(defaults(&mut from_c, size));
        assert_eq!(from_c.termination_threshold, 1.0 - 1.0 / 255.0);
        assert_eq!(from_c.size, size);
        // The size a struct carries: a program that zero-fills the struct instead of
        // calling fv_render_params_default, or was built against a newer header, is told.
        lib.expect(
            defaults(&mut from_c, 4),
            Invalid,
            "FvRenderParams.size is 4",
        );
        let mut unsized_params = from_c;
        unsized_params.size = 0;
        lib.expect(
            set_params(s.r, &unsized_params),
            Invalid,
            "FvRenderParams.size is 0",
        );
        unsized_params.size = size + 8;
        lib.expect(
            set_params(s.r, &unsized_params),
            Invalid,
            "built against a newer ferrovol.h",
        );

        let set_cam = lib.f::<SetCamera>("fv_renderer_set_camera");
        let mut cam = camera([0.0; 3], [0.0; 3], [0.1, 100.0]);
        lib.expect(set_cam(s.r, &cam), Invalid, "equals its focal point");
        cam = camera([2.0, 2.0, 30.0], [2.0, 2.0, 2.0], [0.1, 100.0]);
        cam.view_angle = 200.0;
        lib.expect(set_cam(s.r, &cam), Invalid, "view angle 200");
        cam.view_angle = 30.0;
        s.set_camera(&cam);

        let set_lights = lib.f::<SetLights>("fv_renderer_set_lights");
        let mut light: FvLight = std::mem::zeroed();
        light.space = 7;
        lib.expect(set_lights(s.r, &light, 1), Invalid, "light 0 space 7");
        lib.expect(set_lights(s.r, &light, 9), Invalid, "9 lights");
        lib.expect(set_lights(s.r, null(), 2), Null, "lights");
        lib.ok(set_lights(s.r, null(), 0));

        let set_path =
            lib.f::<unsafe extern "C" fn(H, u32) -> FvStatus>("fv_renderer_set_output_path");
        lib.expect(set_path(s.r, 5), Invalid, "output path 5");
        let shared = lib.f::<unsafe extern "C" fn(H, u32, *mut FvSharedImage) -> FvStatus>(
            "fv_renderer_shared_image",
        );
        let mut img: FvSharedImage = std::mem::zeroed();
        lib.expect(shared(s.r, 0, &mut img), Invalid, "shared");
        lib.expect(shared(s.r, 9, &mut img), Invalid, "target 9");
        lib.expect(shared(s.r, 0, null_mut()), Null, "image is NULL");

        // A valid frame still renders after all those refusals.
        p.shade = true;
        s.set_params(&p);
        let centre = s.frame(16, 16)[4 * (8 * 16 + 8) + 3];
        println!("centre alpha after the refusals: {centre}");
        assert!(
            centre > 100,
            "the uniform volume must be opaque at the centre"
        );

        // Rays between two depths: nothing where near = far, the whole ray from 0 to 1.
        type Between = unsafe extern "C" fn(H, u32, u32, *const f32, *const f32, usize) -> FvStatus;
        let between = lib.f::<Between>("fv_renderer_render_between");
        let (zeros, ones) = ([0.0f32; 256], [1.0f32; 256]);
        lib.expect(
            between(s.r, 16, 16, null(), ones.as_ptr(), 256),
            Null,
            "near",
        );
        lib.expect(
            between(s.r, 16, 16, zeros.as_ptr(), null(), 256),
            Null,
            "far",
        );
        lib.expect(
            between(s.r, 16, 16, zeros.as_ptr(), ones.as_ptr(), 10),
            Invalid,
            "10 values",
        );
        let read = lib.f::<unsafe extern "C" fn(H, *mut H) -> FvStatus>("fv_renderer_read_frame");
        let rgba = lib.f::<unsafe extern "C" fn(H) -> *const u8>("fv_frame_rgba");
        let free = lib.f::<Free>("fv_frame_free");
        for (near, expect_drawn) in [(&ones, false), (&zeros, true)] {
            lib.ok(between(s.r, 16, 16, near.as_ptr(), ones.as_ptr(), 256));
            let mut f: H = null_mut();
            lib.ok(read(s.r, &mut f));
            let a = *rgba(f).add(4 * (8 * 16 + 8) + 3);
            free(f);
            assert_eq!(
                a == centre,
                expect_drawn,
                "near {}: centre alpha {a}",
                near[0]
            );
            assert_eq!(a == 0, !expect_drawn, "near {}: centre alpha {a}", near[0]);
        }
        let mut iso = p;
        iso.blend_mode = FvBlendMode::Isosurface as u32;
        s.set_params(&iso);
        lib.expect(
            between(s.r, 16, 16, zeros.as_ptr(), ones.as_ptr(), 256),
            FvStatus::Unsupported,
            "depth range",
        );
        // Prepared at set-up: the same refusals as a frame, then the frame it prepared.
        let prepare = lib.f::<unsafe extern "C" fn(H, u32, u32) -> FvStatus>("fv_renderer_prepare");
        lib.expect(prepare(null_mut(), 16, 16), Null, "renderer");
        lib.expect(prepare(s.r, 16, 16), Invalid, "set_isosurface");
        s.set_params(&p);
        lib.expect(prepare(s.r, 0, 16), Invalid, "0x16");
        lib.ok(prepare(s.r, 16, 16));
        assert_eq!(s.frame(16, 16)[4 * (8 * 16 + 8) + 3], centre);
        let png = lib.f::<unsafe extern "C" fn(H, *const c_char, *const [f32; 3]) -> FvStatus>(
            "fv_frame_write_png",
        );
        let path = c"/nonexistent/dir/x.png";
        lib.expect(
            png(s.frame, path.as_ptr(), &[0.0; 3]),
            FvStatus::IoError,
            "/nonexistent/dir/x.png",
        );
    }
}

#[test]
fn last_error_is_per_thread_and_status_names_are_static() {
    let lib = Lib::open();
    let name = lib.f::<extern "C" fn(i32) -> *const c_char>("fv_status_name");
    for (value, want) in [
        (FvStatus::Panic as i32, "FV_STATUS_PANIC"),
        (FvStatus::Ok as i32, "FV_STATUS_OK"),
        (10, "FV_STATUS_UNKNOWN"),
        (-1, "FV_STATUS_UNKNOWN"),
    ] {
        // SAFETY: fv_status_name returns static strings for any value.
        let s = unsafe { CStr::from_ptr(name(value)) };
        assert_eq!(s.to_str().unwrap(), want, "fv_status_name({value})");
    }
    let new = lib.f::<NewTf>("fv_transfer_function_new");
    // SAFETY: NULL out is the error under test.
    unsafe { new(1, true, null_mut()) };
    assert!(lib.last_error().contains("out is NULL"));
    let other = std::thread::spawn(|| Lib::open().last_error())
        .join()
        .unwrap();
    assert_eq!(other, "", "another thread must not see this thread's error");
}
