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
        s.set_params(&p);
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
fn masks_through_the_c_abi() {
    let lib = Lib::open();
    type SetMask = unsafe extern "C" fn(H, *const u8, usize, u32) -> FvStatus;
    let n = 8usize;
    let mut s = Session::new(&lib);
    s.set_volume([8, 8, 8], FvScalarType::U8, &vec![200u8; n * n * n]);
    s.set_transfer_function(
        &[0.0, 1.0, 1.0, 1.0, 255.0, 1.0, 1.0, 1.0],
        &[0.0, 0.0, 255.0, 0.5],
    );
    s.set_camera(&camera([3.5, 3.5, 18.0], [3.5, 3.5, 3.5], [0.1, 100.0]));
    let pixel = |rgba: &[u8], x: usize, y: usize| -> [u8; 4] {
        let i = 4 * (y * 16 + x);
        [rgba[i], rgba[i + 1], rgba[i + 2], rgba[i + 3]]
    };
    let plain = s.frame(16, 16).to_vec();
    // points with x < 4 hold 0 (binary) / label 2 (label map)
    let left: Vec<u8> = (0..n * n * n).map(|i| u8::from(i % n >= 4)).collect();
    let labels: Vec<u8> = left.iter().map(|&v| if v == 0 { 2 } else { 0 }).collect();
    let set_mask = lib.f::<SetMask>("fv_renderer_set_mask");
    let label_color = lib.f::<SetPoints>("fv_transfer_function_set_label_color");
    // SAFETY: arguments follow the header; invalid ones are the test.
    unsafe {
        lib.expect(set_mask(s.r, left.as_ptr(), 7, 0), Invalid, "7 values");
        lib.expect(
            set_mask(s.r, left.as_ptr(), left.len(), 2),
            Invalid,
            "mask type 2",
        );
        lib.expect(set_mask(null_mut(), null(), 0, 0), Null, "renderer");
        let red = [0.0, 1.0, 0.0, 0.0, 255.0, 1.0, 0.0, 0.0];
        lib.expect(label_color(s.tf, 0, red.as_ptr(), 2), Invalid, "label 0");
        lib.expect(
            label_color(s.tf, 256, red.as_ptr(), 2),
            Invalid,
            "label 256",
        );
        lib.ok(label_color(s.tf, 2, red.as_ptr(), 2));
        lib.ok(lib.f::<SetH>("fv_renderer_set_transfer_function")(
            s.r, s.tf,
        ));

        lib.ok(set_mask(s.r, left.as_ptr(), left.len(), 0));
        let binary = s.frame(16, 16).to_vec();
        lib.ok(set_mask(s.r, labels.as_ptr(), labels.len(), 1));
        let labelled = s.frame(16, 16).to_vec();
        let mut p = FvRenderParams::defaults();
        p.mask_blend_factor = 2.0;
        lib.expect(
            lib.f::<SetParams>("fv_renderer_set_params")(s.r, &p),
            Invalid,
            "mask blend factor 2",
        );
        p.mask_blend_factor = 0.0;
        s.set_params(&p);
        let unlabelled = s.frame(16, 16).to_vec();
        lib.ok(set_mask(s.r, null(), 0, 0));
        println!(
            "centre: plain {:?}, binary {:?} / {:?}, labelled {:?} / {:?}",
            pixel(&plain, 8, 8),
            pixel(&binary, 4, 8),
            pixel(&binary, 12, 8),
            pixel(&labelled, 4, 8),
            pixel(&labelled, 12, 8)
        );
        assert_eq!(pixel(&binary, 4, 8)[3], 0, "masked side empty");
        assert_eq!(pixel(&binary, 12, 8), pixel(&plain, 12, 8));
        let [r, g, _, a] = pixel(&labelled, 4, 8);
        assert!(a > 100 && r > 100 && g == 0, "label 2 red");
        assert_eq!(pixel(&labelled, 12, 8), pixel(&plain, 12, 8));
        assert_eq!(unlabelled, plain, "blend factor 0 reads no label");
    }
}

#[test]
fn intermixed_volumes_through_the_c_abi() {
    let lib = Lib::open();
    type SetIntermixed = unsafe extern "C" fn(H, *const FvIntermixedVolume, usize) -> FvStatus;
    let n = 8usize;
    let mut s = Session::new(&lib);
    s.set_volume([8, 8, 8], FvScalarType::U8, &vec![200u8; n * n * n]);
    s.set_transfer_function(
        &[0.0, 1.0, 1.0, 1.0, 255.0, 1.0, 1.0, 1.0],
        &[0.0, 0.0, 255.0, 0.2],
    );
    s.set_camera(&camera([3.5, 3.5, 18.0], [3.5, 3.5, 3.5], [0.1, 100.0]));
    let pixel = |rgba: &[u8], x: usize, y: usize| -> [u8; 4] {
        let i = 4 * (y * 16 + x);
        [rgba[i], rgba[i + 1], rgba[i + 2], rgba[i + 3]]
    };
    let plain = s.frame(16, 16).to_vec();
    let set = lib.f::<SetIntermixed>("fv_renderer_set_intermixed_volumes");
    let mut red_volume: H = null_mut();
    let mut red_tf: H = null_mut();
    let mut two: H = null_mut();
    // SAFETY: arguments follow the header; invalid ones are the test.
    unsafe {
        let data = vec![200u8; n * n * n];
        lib.ok(lib.f::<NewVolume>("fv_volume_new")(
            &desc([8, 8, 8], 1, FvScalarType::U8 as u32),
            data.as_ptr().cast(),
            data.len(),
            &mut red_volume,
        ));
        lib.ok(lib.f::<NewTf>("fv_transfer_function_new")(
            1,
            true,
            &mut red_tf,
        ));
        let red = [0.0, 1.0, 0.0, 0.0, 255.0, 1.0, 0.0, 0.0];
        let opacity = [0.0, 0.0, 255.0, 0.2];
        lib.ok(lib.f::<SetPoints>("fv_transfer_function_set_color")(
            red_tf,
            0,
            red.as_ptr(),
            2,
        ));
        lib.ok(lib.f::<SetPoints>("fv_transfer_function_set_opacity")(
            red_tf,
            0,
            opacity.as_ptr(),
            2,
        ));
        // the red volume moved half its width to +x: it covers the image's right half
        let mut matrix = [0.0; 16];
        for i in 0..4 {
            matrix[5 * i] = 1.0;
        }
        matrix[12] = 4.0;
        let one = FvIntermixedVolume {
            volume: red_volume.cast_const().cast(),
            transfer_function: red_tf.cast_const().cast(),
            matrix,
            interpolation: 1,
        };
        let cubic = FvIntermixedVolume {
            interpolation: 2,
            ..one
        };
        lib.expect(set(s.r, &cubic, 1), Invalid, "volumes[0].interpolation 2");
        lib.expect(
            set(s.r, [one; 4].as_ptr(), 4),
            FvStatus::Unsupported,
            "at most 3",
        );
        lib.expect(set(s.r, null(), 1), Null, "volumes");
        lib.expect(set(null_mut(), null(), 0), Null, "renderer");
        let no_volume = FvIntermixedVolume {
            volume: null(),
            ..one
        };
        lib.expect(set(s.r, &no_volume, 1), Null, "volumes[0].volume");
        let no_tf = FvIntermixedVolume {
            transfer_function: null(),
            ..one
        };
        lib.expect(set(s.r, &no_tf, 1), Null, "volumes[0].transfer_function");
        let data2 = [0u8; 2 * 4 * 4 * 4];
        lib.ok(lib.f::<NewVolume>("fv_volume_new")(
            &desc([4, 4, 4], 2, FvScalarType::U8 as u32),
            data2.as_ptr().cast(),
            data2.len(),
            &mut two,
        ));
        let two_comp = FvIntermixedVolume {
            volume: two.cast_const().cast(),
            ..one
        };
        lib.expect(
            set(s.r, &two_comp, 1),
            FvStatus::Unsupported,
            "2 components",
        );
        lib.ok(set(s.r, &one, 1));
        // the renderer keeps what it needs: the handles may go
        lib.f::<Free>("fv_volume_free")(red_volume);
        lib.f::<Free>("fv_transfer_function_free")(red_tf);
        lib.f::<Free>("fv_volume_free")(two);
        let mixed = s.frame(16, 16).to_vec();
        let mut p = FvRenderParams::defaults();
        p.blend_mode = FvBlendMode::Maximum as u32;
        s.set_params(&p);
        lib.expect(
            lib.f::<Render>("fv_renderer_render")(s.r, 16, 16, null(), 0),
            FvStatus::Unsupported,
            "composite",
        );
        s.set_params(&FvRenderParams::defaults());
        lib.ok(set(s.r, null(), 0));
        let cleared = s.frame(16, 16).to_vec();
        println!(
            "intermixed: plain {:?} / {:?}, mixed {:?} / {:?}",
            pixel(&plain, 5, 8),
            pixel(&plain, 10, 8),
            pixel(&mixed, 5, 8),
            pixel(&mixed, 10, 8),
        );
        let [r, g, b, a] = pixel(&mixed, 10, 8);
        assert!(
            r > g && r > b && a > pixel(&plain, 10, 8)[3],
            "red over white: {r} {g} {b} {a}"
        );
        let [r, g, b, _] = pixel(&mixed, 5, 8);
        assert!(r == g && g == b, "the left half stays white");
        assert_eq!(cleared, plain, "cleared: the main volume alone");
    }
}

#[test]
fn table_2d_through_the_c_abi() {
    let lib = Lib::open();
    type SetTable = unsafe extern "C" fn(H, u32, u32, u32, *const f32, f64, f64, f64) -> FvStatus;
    let mut s = Session::new(&lib);
    s.set_volume([8, 8, 8], FvScalarType::U8, &vec![200u8; 512]);
    s.set_transfer_function(
        &[0.0, 1.0, 1.0, 1.0, 255.0, 1.0, 1.0, 1.0],
        &[0.0, 0.0, 255.0, 0.5],
    );
    s.set_camera(&camera([3.5, 3.5, 18.0], [3.5, 3.5, 3.5], [0.1, 100.0]));
    let white = s.frame(16, 16).to_vec();
    let set_table = lib.f::<SetTable>("fv_transfer_function_set_table_2d");
    // 4 x 2 entries: green and half as opaque as the 1D function over [0, 255]
    let rgba: Vec<f32> = (0..8)
        .flat_map(|_| [0.0, 1.0, 0.0, 0.5 * 200.0 / 255.0])
        .collect();
    // SAFETY: arguments follow the header; invalid ones are the test.
    unsafe {
        lib.expect(
            set_table(s.tf, 0, 0, 2, rgba.as_ptr(), 0.0, 255.0, 0.0),
            Invalid,
            "0x2",
        );
        lib.expect(
            set_table(s.tf, 1, 4, 2, rgba.as_ptr(), 0.0, 255.0, 0.0),
            Invalid,
            "component 1",
        );
        lib.expect(
            set_table(s.tf, 0, 4, 2, rgba.as_ptr(), 5.0, 5.0, 0.0),
            Invalid,
            "scalar range",
        );
        lib.expect(
            set_table(s.tf, 0, 4, 2, rgba.as_ptr(), 0.0, 255.0, -1.0),
            Invalid,
            "gradient magnitude -1",
        );
        lib.ok(set_table(s.tf, 0, 4, 2, rgba.as_ptr(), 0.0, 255.0, 0.0));
        lib.ok(lib.f::<SetH>("fv_renderer_set_transfer_function")(
            s.r, s.tf,
        ));
        let green = s.frame(16, 16).to_vec();
        let i = 4 * (8 * 16 + 8);
        println!(
            "centre: 1D {:?}, 2D {:?}",
            &white[i..i + 4],
            &green[i..i + 4]
        );
        assert!(
            green[i + 1] > 100 && green[i] == 0 && green[i + 2] == 0,
            "green"
        );
        assert_eq!(green[i + 3], white[i + 3], "the same opacity");
        lib.ok(set_table(s.tf, 0, 0, 0, null(), 0.0, 0.0, 0.0));
        lib.ok(lib.f::<SetH>("fv_renderer_set_transfer_function")(
            s.r, s.tf,
        ));
        assert_eq!(s.frame(16, 16), &white[..], "removed: the 1D image again");
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

/// The isosurface mode through the C ABI: every refusal names its problem, then a sphere
/// renders opaque at the centre and empty in the corner.
#[test]
fn isosurface_errors_and_a_frame() {
    let lib = Lib::open();
    let n = 16usize;
    // Distance from the volume's centre: the iso-value 5 is a sphere of radius 5 voxels.
    let data: Vec<f32> = (0..n * n * n)
        .map(|i| {
            let (x, y, z) = (i % n, (i / n) % n, i / (n * n));
            let c = (n - 1) as f32 / 2.0;
            ((x as f32 - c).powi(2) + (y as f32 - c).powi(2) + (z as f32 - c).powi(2)).sqrt()
        })
        .collect();
    let set_iso = lib.f::<SetIso>("fv_renderer_set_isosurface");
    let set_env = lib.f::<SetEnv>("fv_renderer_set_environment");
    let mut s = Session::new(&lib);
    s.set_volume([16, 16, 16], FvScalarType::F32, &data);
    s.set_camera(&camera([7.5, 7.5, 60.0], [7.5; 3], [1.0, 200.0]));
    let mut p = FvRenderParams::defaults();
    p.blend_mode = FvBlendMode::Isosurface as u32;
    s.set_params(&p);
    // SAFETY: arguments follow the header; invalid ones are the test.
    unsafe {
        let render = lib.f::<Render>("fv_renderer_render");
        lib.expect(render(s.r, 32, 32, null(), 0), Invalid, "iso-values");

        let mut iso: FvIsoParams = std::mem::zeroed();
        let defaults = lib.f::<unsafe extern "C" fn(*mut FvIsoParams, usize) -> FvStatus>(
            "fv_iso_params_default",
        );
        lib.expect(
            defaults(null_mut(), size_of_val(&iso)),
            Null,
            "params is NULL",
        );
        lib.ok(defaults(&mut iso, size_of_val(&iso)));
        assert_eq!(iso.bisection_steps, 8);
        lib.expect(set_iso(s.r, &iso), Invalid, "value_count 0");
        iso.value_count = 1;
        iso.values[0] = ferrovol::FvIsoValue {
            value: 5.0,
            color: [0.9, 0.8, 0.7],
            opacity: 1.0,
        };
        type Edit = fn(&mut FvIsoParams);
        let cases: [(Edit, &str); 7] = [
            (|i| i.value_count = 9, "value_count 9"),
            (|i| i.values[0].opacity = 0.0, "opacity 0"),
            (|i| i.values[0].color[0] = 2.0, "colour"),
            (|i| i.specular_mode = 7, "specular_mode 7"),
            (|i| i.specular_samples = 0, "0 specular samples"),
            (|i| i.ao_radius = -1.0, "ao_radius -1"),
            (|i| i.bisection_steps = 40, "40 bisection steps"),
        ];
        for (edit, needle) in cases {
            let mut bad = iso;
            edit(&mut bad);
            lib.expect(set_iso(s.r, &bad), Invalid, needle);
        }
        lib.expect(set_iso(null_mut(), &iso), Null, "renderer");
        let missing = c"/nonexistent/sky.hdr";
        lib.expect(
            set_env(s.r, missing.as_ptr(), 1.0, null(), 0.0),
            Invalid,
            "cannot be opened",
        );
        let text = c"/etc/hostname.txt";
        lib.expect(
            set_env(s.r, text.as_ptr(), 1.0, null(), 0.0),
            Invalid,
            "unsupported file type",
        );
        let up = [0.0, 0.0, 1.0];
        lib.ok(set_env(s.r, null(), 1.0, up.as_ptr(), 30.0));
        iso.ao_samples = 8;
        lib.ok(set_iso(s.r, &iso));
    }
    let rgba = s.frame(32, 32);
    let px = |x: usize, y: usize| &rgba[4 * (y * 32 + x)..][..4];
    println!("sphere centre {:?}, corner {:?}", px(16, 16), px(0, 0));
    assert_eq!(px(16, 16)[3], 255, "the opaque sphere covers the centre");
    assert!(px(16, 16)[0] > 100, "and it is lit");
    assert_eq!(px(0, 0), [0, 0, 0, 0], "the corner misses it");
}

/// Path tracing through the C ABI: refusals name their problem, frames accumulate and a
/// camera change starts over.
#[test]
fn path_tracing_accumulates_and_refuses_bad_settings() {
    let lib = Lib::open();
    let data: Vec<f32> = (0..8 * 8 * 8).map(|i| (i % 8) as f32 / 7.0).collect();
    let mut s = Session::new(&lib);
    s.set_volume([8, 8, 8], FvScalarType::F32, &data);
    s.set_transfer_function(
        &[0.0, 0.9, 0.8, 0.7, 1.0, 0.9, 0.8, 0.7],
        &[0.0, 0.0, 1.0, 0.6],
    );
    let mut cam = camera([3.5, 3.5, 40.0], [3.5; 3], [1.0, 100.0]);
    s.set_camera(&cam);
    let mut p = FvRenderParams::defaults();
    p.blend_mode = FvBlendMode::PathTrace as u32;
    s.set_params(&p);
    let set_pt = lib.f::<SetPt>("fv_renderer_set_path_tracing");
    let defaults = lib.f::<unsafe extern "C" fn(*mut FvPathTraceParams, usize) -> FvStatus>(
        "fv_path_trace_params_default",
    );
    // SAFETY: arguments follow the header; invalid ones are the test.
    unsafe {
        let mut pt: FvPathTraceParams = std::mem::zeroed();
        lib.ok(defaults(&mut pt, size_of_val(&pt)));
        type Edit = fn(&mut FvPathTraceParams);
        let cases: [(Edit, &str); 9] = [
            (|p| p.anisotropy = 1.0, "anisotropy 1"),
            (|p| p.time_budget = -1.0, "time budget -1"),
            (|p| p.samples_per_frame = 0, "0 paths per pixel"),
            (|p| p.scatter_regions = 7, "not an FvScatterRegions"),
            (|p| p.roughness = 0.0, "roughness 0"),
            (|p| p.cone_angle = 90.0, "cone angle 90"),
            (|p| p.gradient_threshold = -1.0, "gradient threshold"),
            (|p| p.stochastic_blend = f32::NAN, "stochastic blend"),
            (|p| p.secondary_rays = 0, "secondary rays"),
        ];
        for (edit, needle) in cases {
            let mut bad = pt;
            edit(&mut bad);
            lib.expect(set_pt(s.r, &bad), Invalid, needle);
        }
        lib.expect(set_pt(s.r, null()), Null, "params is NULL");
        // the hybrid model with a 2×2 budget renders
        let mut hybrid = pt;
        hybrid.gradient_threshold = 0.5;
        hybrid.secondary_rays = 2;
        hybrid.scatter_regions = ferrovol::FvScatterRegions::Surfaces as u32;
        lib.ok(set_pt(s.r, &hybrid));
        s.render(16, 16);
        pt.samples_per_frame = 2;
        lib.ok(set_pt(s.r, &pt));
    }
    let accumulated = lib.f::<Accumulated>("fv_renderer_accumulated_samples");
    let mut counts = vec![];
    for i in 0..4 {
        if i == 3 {
            cam.position = [3.5, 10.0, 40.0];
            s.set_camera(&cam);
        }
        s.render(16, 16);
        let mut n = 0u32;
        // SAFETY: a valid handle and out-pointer.
        lib.ok(unsafe { accumulated(s.r, &mut n) });
        counts.push(n);
    }
    println!("accumulated paths per pixel: {counts:?} (camera moved before the last)");
    assert_eq!(counts, vec![2, 4, 6, 2]);
    let convergence = lib.f::<unsafe extern "C" fn(H, *mut ferrovol::FvConvergence) -> FvStatus>(
        "fv_renderer_convergence",
    );
    let mut c = ferrovol::FvConvergence::default();
    // SAFETY: a valid handle; the out-pointer is checked for NULL.
    unsafe {
        lib.ok(convergence(s.r, &mut c));
        lib.expect(convergence(s.r, null_mut()), Null, "convergence is NULL");
    }
    println!("convergence after 2 paths per pixel: {c:?}");
    assert_eq!(c.paths_per_pixel, 2);
    assert_eq!(c.mean_paths_per_pixel, 2.0);
    assert!(c.relative_error > 0.0 && c.relative_error.is_finite());
}

/// A bricked volume keeps only the bricks something visible lies in, reports it through
/// fv_renderer_residency, and keeps rendering after the caller frees its FvVolume (the
/// renderer shares the data it reads bricks from).
#[test]
fn bricked_volume_residency_outlives_the_volume() {
    let lib = Lib::open();
    let n = 24usize;
    // a bright ball in one corner of a dark volume
    let data: Vec<u8> = (0..n * n * n)
        .map(|i| {
            let (x, y, z) = (i % n, (i / n) % n, i / (n * n));
            let r2 = (x as f32 - 5.0).powi(2) + (y as f32 - 5.0).powi(2) + (z as f32 - 5.0).powi(2);
            if r2 < 16.0 {
                200
            } else {
                0
            }
        })
        .collect();
    let mut s = Session::new(&lib);
    let set_bricks =
        lib.f::<unsafe extern "C" fn(H, u32) -> FvStatus>("fv_renderer_set_max_brick_points");
    let residency = lib.f::<unsafe extern "C" fn(H, *mut ferrovol::FvResidency) -> FvStatus>(
        "fv_renderer_residency",
    );
    // SAFETY: a valid handle; the residency out-pointer is checked for NULL.
    unsafe {
        lib.ok(set_bricks(s.r, 10));
        lib.expect(residency(s.r, null_mut()), Null, "residency");
    }
    s.set_volume([24, 24, 24], FvScalarType::U8, &data);
    s.set_transfer_function(
        &[0.0, 1.0, 1.0, 1.0, 255.0, 1.0, 1.0, 1.0],
        &[0.0, 0.0, 100.0, 0.0, 255.0, 1.0],
    );
    s.set_camera(&camera([11.5, 11.5, 80.0], [11.5; 3], [1.0, 200.0]));
    let before = s.frame(32, 32).to_vec();
    assert!(before.chunks(4).any(|p| p[3] > 100), "the ball is drawn");
    let mut res = ferrovol::FvResidency::default();
    // SAFETY: valid handles; the volume is freed once and forgotten by the session.
    unsafe {
        lib.ok(residency(s.r, &mut res));
        lib.f::<Free>("fv_volume_free")(s.volume);
    }
    s.volume = null_mut();
    let after = s.frame(32, 32).to_vec();
    println!(
        "{} of {} bricks resident ({} uploaded), pool {} bytes, dense {} bytes",
        res.resident, res.bricks, res.brick_uploads, res.pool_bytes, res.dense_bytes
    );
    assert!(res.bricks >= 8);
    assert!(
        res.resident >= 1 && res.resident * 3 <= res.bricks,
        "{res:?}"
    );
    assert_eq!(res.brick_uploads, res.resident);
    assert_eq!(res.dense_bytes, (n * n * n) as u64);
    assert_eq!(before, after, "the renderer still has the data");
}

/// The brick pool follows what a frame needs: a transfer function that shows a corner of
/// the volume after one that shows all of it shrinks the pool the residency reports, the
/// needed bricks copied on the device (no upload); showing all again grows it back.
#[test]
fn brick_pool_shrinks_to_what_is_shown() {
    let lib = Lib::open();
    let n = 24usize;
    let data: Vec<u8> = (0..n * n * n)
        .map(|i| {
            let (x, y, z) = (i % n, (i / n) % n, i / (n * n));
            ((x + y + z) * 255 / (3 * (n - 1))) as u8
        })
        .collect();
    let mut s = Session::new(&lib);
    let set_bricks =
        lib.f::<unsafe extern "C" fn(H, u32) -> FvStatus>("fv_renderer_set_max_brick_points");
    let residency = lib.f::<unsafe extern "C" fn(H, *mut ferrovol::FvResidency) -> FvStatus>(
        "fv_renderer_residency",
    );
    // SAFETY: a valid handle.
    unsafe { lib.ok(set_bricks(s.r, 8)) };
    s.set_volume([24, 24, 24], FvScalarType::U8, &data);
    s.set_camera(&camera([11.5, 11.5, 80.0], [11.5; 3], [1.0, 200.0]));
    let white = [0.0, 1.0, 1.0, 1.0, 255.0, 1.0, 1.0, 1.0];
    let mut seen = Vec::new();
    for from in [1.0, 235.0, 1.0] {
        s.set_transfer_function(&white, &[0.0, 0.0, from, 0.0, 255.0, 0.8]);
        assert!(s.frame(32, 32).chunks(4).any(|p| p[3] > 20), "drawn");
        let mut res = ferrovol::FvResidency::default();
        // SAFETY: valid handles.
        unsafe { lib.ok(residency(s.r, &mut res)) };
        println!(
            "opacity from {from}: {} of {} bricks resident, pool {} bytes, {} uploaded",
            res.resident, res.bricks, res.pool_bytes, res.brick_uploads
        );
        seen.push(res);
    }
    let (all, corner, again) = (seen[0], seen[1], seen[2]);
    assert!(
        2 * corner.pool_bytes <= all.pool_bytes,
        "showing a corner shrinks the pool: {corner:?} after {all:?}"
    );
    assert!(corner.resident < all.resident);
    assert_eq!(
        corner.brick_uploads, all.brick_uploads,
        "the corner's bricks were resident: copied, not uploaded"
    );
    assert_eq!(again.pool_bytes, all.pool_bytes, "and grows back");
}

/// Progress of a streamed frame: a memory budget under what a frame needs makes ray casting
/// stream the bricks in several passes, and the callback hears of each one in order.
#[test]
fn streamed_frames_report_progress() {
    unsafe extern "C" fn record(user: *mut c_void, done: u32, total: u32) {
        // SAFETY: `user` is the test's Vec, alive for the whole render.
        unsafe { (*(user as *mut Vec<(u32, u32)>)).push((done, total)) };
    }
    let lib = Lib::open();
    let n = 32usize;
    let data: Vec<f32> = (0..n * n * n).map(|i| (i % n) as f32).collect();
    let mut s = Session::new(&lib);
    let budget = lib.f::<unsafe extern "C" fn(H, u64) -> FvStatus>("fv_renderer_set_memory_budget");
    let progress = lib
        .f::<unsafe extern "C" fn(H, ferrovol::FvProgressFn, *mut c_void) -> FvStatus>(
            "fv_renderer_set_progress",
        );
    let mut calls: Vec<(u32, u32)> = Vec::new();
    // SAFETY: a valid handle; `calls` outlives every frame rendered with the callback.
    unsafe {
        lib.ok(budget(s.r, (n * n * n) as u64)); // a quarter of the float32 volume
        lib.ok(progress(
            s.r,
            Some(record),
            (&mut calls as *mut Vec<(u32, u32)>).cast(),
        ));
    }
    s.set_volume([32, 32, 32], FvScalarType::F32, &data);
    s.set_transfer_function(
        &[0.0, 1.0, 1.0, 1.0, 31.0, 1.0, 1.0, 1.0],
        &[0.0, 0.1, 31.0, 0.5],
    );
    s.set_camera(&camera([15.5, 15.5, 100.0], [15.5; 3], [1.0, 300.0]));
    let streamed = s.frame(32, 32).to_vec();
    // SAFETY: a valid handle; NULL turns the callback off.
    unsafe { lib.ok(progress(s.r, None, null_mut())) };
    println!("progress calls: {calls:?}");
    let total = calls.last().map_or(0, |c| c.1);
    assert!(total >= 2, "the frame was streamed: {calls:?}");
    assert_eq!(
        calls,
        (1..=total).map(|d| (d, total)).collect::<Vec<_>>(),
        "one call per pass, in order"
    );
    assert!(streamed.chunks(4).any(|p| p[3] > 50), "drawn");
}

/// Path tracing past the memory budget traces a coarser level, and fv_renderer_residency
/// says which: 2 fine points per point for a budget of a quarter of the volume; a ray-cast
/// frame after it draws the volume itself again; a preview frame of ray casting reports the
/// bricks it read from a coarser level's stand-ins, and a still frame none.
#[test]
fn path_tracing_past_the_budget_reports_its_level() {
    let lib = Lib::open();
    let n = 32usize;
    let data: Vec<f32> = (0..n * n * n).map(|i| (i % n) as f32).collect();
    let mut s = Session::new(&lib);
    let budget = lib.f::<unsafe extern "C" fn(H, u64) -> FvStatus>("fv_renderer_set_memory_budget");
    let residency = lib.f::<unsafe extern "C" fn(H, *mut ferrovol::FvResidency) -> FvStatus>(
        "fv_renderer_residency",
    );
    let read = |s: &Session| {
        let mut res = ferrovol::FvResidency::default();
        // SAFETY: a valid handle and out-pointer.
        unsafe { lib.ok(residency(s.r, &mut res)) };
        res
    };
    // SAFETY: a valid handle.
    unsafe { lib.ok(budget(s.r, (n * n * n) as u64)) }; // a quarter of the float32 volume
    s.set_volume([32, 32, 32], FvScalarType::F32, &data);
    s.set_transfer_function(
        &[0.0, 0.9, 0.8, 0.7, 31.0, 0.9, 0.8, 0.7],
        &[0.0, 0.0, 31.0, 0.5],
    );
    s.set_camera(&camera([15.5, 15.5, 100.0], [15.5; 3], [1.0, 300.0]));
    let mut p = FvRenderParams::defaults();
    p.blend_mode = FvBlendMode::PathTrace as u32;
    s.set_params(&p);
    let traced = s.frame(24, 24).to_vec();
    let res = read(&s);
    println!("path traced past the budget: {res:?}");
    assert!(traced.chunks(4).any(|p| p[3] > 20), "drawn");
    assert_eq!((res.level, res.level_dims), (2, [17; 3]));
    assert!(
        res.pool_bytes <= (n * n * n) as u64,
        "within the budget: {res:?}"
    );
    p.blend_mode = FvBlendMode::Composite as u32;
    s.set_params(&p);
    s.frame(24, 24);
    let res = read(&s);
    assert_eq!((res.level, res.level_dims), (1, [32; 3]), "{res:?}");
    assert_eq!(res.stand_ins, 0, "{res:?}");
    p.preview_level = true;
    s.set_params(&p);
    let preview = s.frame(24, 24).to_vec();
    let res = read(&s);
    println!("a preview past the budget: {res:?}");
    assert!(preview.chunks(4).any(|p| p[3] > 20), "drawn");
    assert!(res.stand_ins > 0 && res.level == 1, "{res:?}");
}

/// The context's device memory counters: a renderer's frames allocate once (repeated
/// frames hold the same buffers and textures), and a renderer freed and made again holds no
/// more than the first one did.
#[test]
fn device_memory_stays_flat_over_frames_and_renderers() {
    type Memory = unsafe extern "C" fn(H, *mut ferrovol::FvDeviceMemory) -> FvStatus;
    let lib = Lib::open();
    let n = 16usize;
    let data: Vec<f32> = (0..n * n * n).map(|i| (i % n) as f32).collect();
    let mut s = Session::new(&lib);
    let memory = lib.f::<Memory>("fv_context_device_memory");
    let read = |s: &Session| {
        let mut m = ferrovol::FvDeviceMemory::default();
        // SAFETY: a valid context and out-pointer.
        unsafe { lib.ok(memory(s.ctx, &mut m)) };
        m
    };
    // SAFETY: a NULL out-pointer is refused, not written.
    unsafe { lib.expect(memory(s.ctx, null_mut()), Null, "memory") };
    s.set_volume([16, 16, 16], FvScalarType::F32, &data);
    s.set_transfer_function(
        &[0.0, 1.0, 1.0, 1.0, 15.0, 1.0, 0.5, 0.0],
        &[0.0, 0.0, 15.0, 1.0],
    );
    s.set_camera(&camera([7.5, 7.5, 60.0], [7.5; 3], [1.0, 200.0]));
    s.frame(24, 24);
    let first = read(&s);
    for _ in 0..5 {
        s.frame(24, 24);
    }
    let again = read(&s);
    println!("after one frame {first:?}\nafter six       {again:?}");
    assert!(first.texture_views > 0 && first.texture_bytes > 0 && first.buffers > 0);
    assert_eq!(
        (again.buffers, again.texture_views, again.bind_groups),
        (first.buffers, first.texture_views, first.bind_groups)
    );
    assert_eq!(
        (again.buffer_bytes, again.texture_bytes),
        (first.buffer_bytes, first.texture_bytes)
    );
    for _ in 0..3 {
        // SAFETY: the renderer came from fv_renderer_new and is replaced by a new one.
        unsafe {
            lib.f::<Free>("fv_renderer_free")(s.r);
            s.r = null_mut();
            lib.ok(lib.f::<NewRenderer>("fv_renderer_new")(s.ctx, &mut s.r));
            lib.ok(lib.f::<SetH>("fv_renderer_set_volume")(s.r, s.volume));
        }
        s.set_transfer_function(
            &[0.0, 1.0, 1.0, 1.0, 15.0, 1.0, 0.5, 0.0],
            &[0.0, 0.0, 15.0, 1.0],
        );
        s.set_camera(&camera([7.5, 7.5, 60.0], [7.5; 3], [1.0, 200.0]));
        s.frame(24, 24);
        s.frame(24, 24);
    }
    let renewed = read(&s);
    println!("after three new renderers {renewed:?}");
    assert!(
        renewed.buffer_bytes + renewed.texture_bytes <= first.buffer_bytes + first.texture_bytes,
        "{renewed:?} holds more than {first:?}"
    );
}

/// Out of device memory (a cap set with fv_context_limit_device_memory, as a smaller device
/// would have): a frame that needs more memory returns FV_STATUS_OUT_OF_MEMORY naming the
/// sizes, the renderer stays usable, and without the cap it draws the same frame as before.
#[test]
fn out_of_memory_is_reported_and_the_renderer_recovers() {
    let lib = Lib::open();
    let n = 16usize;
    let data: Vec<f32> = (0..n * n * n).map(|i| (i % n) as f32).collect();
    let mut s = Session::new(&lib);
    s.set_volume([16, 16, 16], FvScalarType::F32, &data);
    s.set_transfer_function(
        &[0.0, 1.0, 1.0, 1.0, 15.0, 1.0, 0.5, 0.0],
        &[0.0, 0.0, 15.0, 1.0],
    );
    s.set_camera(&camera([7.5, 7.5, 60.0], [7.5; 3], [1.0, 200.0]));
    let before = s.frame(24, 24).to_vec();
    assert!(before.chunks(4).any(|p| p[3] > 100), "the volume is drawn");
    type Limit = unsafe extern "C" fn(H, u64) -> FvStatus;
    let limit = lib.f::<Limit>("fv_context_limit_device_memory");
    let render = lib.f::<Render>("fv_renderer_render");
    let mut memory = ferrovol::FvDeviceMemory::default();
    // SAFETY: valid handles and a live FvDeviceMemory.
    unsafe {
        lib.expect(limit(null_mut(), 1), Null, "ctx");
        lib.f::<unsafe extern "C" fn(H, *mut ferrovol::FvDeviceMemory) -> FvStatus>(
            "fv_context_device_memory",
        )(s.ctx, &mut memory);
        let held = memory.buffer_bytes + memory.texture_bytes;
        assert!(held > 0, "the frame holds device memory");
        assert_eq!(limit(s.ctx, held + 1024), FvStatus::Ok);
        lib.expect(
            render(s.r, 512, 512, null(), 0),
            FvStatus::OutOfMemory,
            "limited to",
        );
        assert_eq!(limit(s.ctx, 0), FvStatus::Ok);
    }
    assert_eq!(
        s.frame(24, 24),
        &before[..],
        "without the cap the renderer draws the same frame"
    );
}

/// A lost device (fv_context_lose_device, as a driver reset would): the renderer's next
/// frame returns FV_STATUS_DEVICE_LOST with a message saying what to do, and a new context
/// and renderer draw the same frame as before.
#[test]
fn device_loss_is_reported_and_a_new_context_draws() {
    let lib = Lib::open();
    let n = 16usize;
    let data: Vec<f32> = (0..n * n * n).map(|i| (i % n) as f32).collect();
    let scene = |s: &mut Session| {
        s.set_volume([16, 16, 16], FvScalarType::F32, &data);
        s.set_transfer_function(
            &[0.0, 1.0, 1.0, 1.0, 15.0, 1.0, 0.5, 0.0],
            &[0.0, 0.0, 15.0, 1.0],
        );
        s.set_camera(&camera([7.5, 7.5, 60.0], [7.5; 3], [1.0, 200.0]));
    };
    let mut s = Session::new(&lib);
    scene(&mut s);
    let before = s.frame(24, 24).to_vec();
    assert!(before.chunks(4).any(|p| p[3] > 100), "the volume is drawn");
    let render = lib.f::<Render>("fv_renderer_render");
    // SAFETY: a valid context (NULL is ignored) and renderer.
    unsafe {
        lib.f::<unsafe extern "C" fn(H)>("fv_context_lose_device")(null_mut());
        lib.f::<unsafe extern "C" fn(H)>("fv_context_lose_device")(s.ctx);
        lib.expect(
            render(s.r, 24, 24, null(), 0),
            FvStatus::DeviceLost,
            "create a new context",
        );
    }
    drop(s);
    let mut fresh = Session::new(&lib);
    scene(&mut fresh);
    assert_eq!(
        fresh.frame(24, 24),
        &before[..],
        "a new context draws the same frame"
    );
}
