//! Loads the built cdylib with libloading, as a C host would, and drives the error paths:
//! NULL handles, bad sizes, unsupported types and out-of-range parameters each return the
//! right status with a message naming the problem, and nothing panics across the boundary.

use ferrovol::{FvCamera, FvLight, FvRenderParams, FvStatus, FvVolumeDesc};
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
    /// Asserts `status` and that the message contains `needle`; prints both.
    fn expect(&self, what: &str, status: FvStatus, want: FvStatus, needle: &str) {
        let msg = self.last_error();
        println!("{what}: {status:?}: {msg}");
        assert_eq!(status, want, "{what}: {msg}");
        assert!(msg.contains(needle), "{what}: '{msg}' lacks '{needle}'");
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
type ParamsDefault = unsafe extern "C" fn(*mut FvRenderParams) -> FvStatus;
type SetCamera = unsafe extern "C" fn(H, *const FvCamera) -> FvStatus;
type SetLights = unsafe extern "C" fn(H, *const FvLight, usize) -> FvStatus;

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
    let d = desc([2, 2, 2], 1, ferrovol::FvScalarType::F32 as u32);
    // SAFETY (all calls below): arguments follow the header; invalid ones are the test.
    unsafe {
        lib.expect(
            "NULL out",
            new(&d, bytes, 32, null_mut()),
            FvStatus::NullArgument,
            "out is NULL",
        );
        lib.expect(
            "NULL desc",
            new(null(), bytes, 32, &mut v),
            FvStatus::NullArgument,
            "desc",
        );
        lib.expect(
            "NULL data",
            new(&d, null(), 32, &mut v),
            FvStatus::NullArgument,
            "data",
        );
        lib.expect(
            "short data",
            new(&d, bytes, 31, &mut v),
            FvStatus::InvalidArgument,
            "data_bytes is 31",
        );
        let t = desc([2, 2, 2], 1, 99);
        lib.expect(
            "scalar type 99",
            new(&t, bytes, 32, &mut v),
            FvStatus::Unsupported,
            "scalar type 99",
        );
        let c = desc([2, 2, 1], 5, ferrovol::FvScalarType::U8 as u32);
        lib.expect(
            "5 components",
            new(&c, bytes, 20, &mut v),
            FvStatus::InvalidArgument,
            "5 components",
        );
        let e = desc([0, 2, 2], 1, ferrovol::FvScalarType::F32 as u32);
        lib.expect(
            "empty",
            new(&e, bytes, 0, &mut v),
            FvStatus::InvalidArgument,
            "empty volume",
        );
        let mut s = d;
        s.spacing[1] = 0.0;
        lib.expect(
            "zero spacing",
            new(&s, bytes, 32, &mut v),
            FvStatus::InvalidArgument,
            "spacing along y",
        );
        let mut m = d;
        m.direction = [0.0; 9];
        lib.expect(
            "singular direction",
            new(&m, bytes, 32, &mut v),
            FvStatus::InvalidArgument,
            "singular",
        );
        let mut nan = data.clone();
        nan[5] = f32::NAN;
        lib.expect(
            "NaN",
            new(&d, nan.as_ptr().cast(), 32, &mut v),
            FvStatus::InvalidArgument,
            "NaN",
        );
        assert!(v.is_null(), "a failed fv_volume_new must leave *out NULL");
        assert_eq!(new(&d, bytes, 32, &mut v), FvStatus::Ok);
        assert!(!v.is_null());
        lib.f::<Free>("fv_volume_free")(v);
    }
}

#[test]
fn transfer_function_errors() {
    let lib = Lib::open();
    let new = lib.f::<NewTf>("fv_transfer_function_new");
    let color = lib.f::<SetPoints>("fv_transfer_function_set_color");
    let opacity = lib.f::<SetPoints>("fv_transfer_function_set_opacity");
    let unit = lib.f::<unsafe extern "C" fn(H, u32, f64, f64) -> FvStatus>(
        "fv_transfer_function_set_unit_distance",
    );
    let mut tf: H = null_mut();
    // SAFETY: arguments follow the header; invalid ones are the test.
    unsafe {
        lib.expect(
            "0 components",
            new(0, true, &mut tf),
            FvStatus::InvalidArgument,
            "0 components",
        );
        assert_eq!(new(1, true, &mut tf), FvStatus::Ok);
        let pts = [0.0, 1.0, 1.0, 1.0];
        lib.expect(
            "component 3",
            color(tf, 3, pts.as_ptr(), 1),
            FvStatus::InvalidArgument,
            "component 3",
        );
        lib.expect(
            "NULL points",
            color(tf, 0, null(), 2),
            FvStatus::NullArgument,
            "colour points",
        );
        lib.expect(
            "no points",
            opacity(tf, 0, pts.as_ptr(), 0),
            FvStatus::InvalidArgument,
            "at least one point",
        );
        let nan = [0.0, f64::NAN];
        lib.expect(
            "NaN opacity",
            opacity(tf, 0, nan.as_ptr(), 1),
            FvStatus::InvalidArgument,
            "opacity points",
        );
        lib.expect(
            "unit distance",
            unit(tf, 0, 0.0, 1.0),
            FvStatus::InvalidArgument,
            "unit distance 0",
        );
        lib.expect(
            "weight",
            unit(tf, 0, 1.0, -1.0),
            FvStatus::InvalidArgument,
            "weight -1",
        );
        lib.expect(
            "NULL tf",
            unit(null_mut(), 0, 1.0, 1.0),
            FvStatus::NullArgument,
            "tf is NULL",
        );
        lib.f::<Free>("fv_transfer_function_free")(tf);
    }
}

#[test]
fn renderer_errors() {
    let lib = Lib::open();
    let mut ctx: H = null_mut();
    let mut r: H = null_mut();
    let render = lib.f::<Render>("fv_renderer_render");
    let set_params = lib.f::<SetParams>("fv_renderer_set_params");
    let mut p = FvRenderParams::defaults();
    // SAFETY: arguments follow the header; invalid ones are the test.
    unsafe {
        lib.expect(
            "NULL ctx",
            lib.f::<NewCtx>("fv_context_new")(null_mut()),
            FvStatus::NullArgument,
            "out",
        );
        assert_eq!(
            lib.f::<NewCtx>("fv_context_new")(&mut ctx),
            FvStatus::Ok,
            "{}",
            lib.last_error()
        );
        let new_r = lib.f::<NewRenderer>("fv_renderer_new");
        lib.expect(
            "NULL context",
            new_r(null_mut(), &mut r),
            FvStatus::NullArgument,
            "ctx is NULL",
        );
        assert_eq!(new_r(ctx, &mut r), FvStatus::Ok);
        lib.expect(
            "NULL renderer",
            render(null_mut(), 8, 8, null(), 0),
            FvStatus::NullArgument,
            "renderer",
        );
        lib.expect(
            "no volume",
            render(r, 8, 8, null(), 0),
            FvStatus::InvalidArgument,
            "volume",
        );

        let data = [7u16; 4 * 4 * 4];
        let d = desc([4, 4, 4], 1, ferrovol::FvScalarType::U16 as u32);
        let mut v: H = null_mut();
        assert_eq!(
            lib.f::<NewVolume>("fv_volume_new")(&d, data.as_ptr().cast(), 128, &mut v),
            FvStatus::Ok
        );
        assert_eq!(lib.f::<SetH>("fv_renderer_set_volume")(r, v), FvStatus::Ok);
        let mut tf: H = null_mut();
        assert_eq!(
            lib.f::<NewTf>("fv_transfer_function_new")(1, true, &mut tf),
            FvStatus::Ok
        );
        let set_tf = lib.f::<SetH>("fv_renderer_set_transfer_function");
        lib.expect(
            "incomplete tf",
            set_tf(r, tf),
            FvStatus::InvalidArgument,
            "needs both a colour and an opacity",
        );
        let c = [0.0, 1.0, 1.0, 1.0, 10.0, 1.0, 1.0, 1.0];
        let o = [0.0, 0.0, 10.0, 1.0];
        assert_eq!(
            lib.f::<SetPoints>("fv_transfer_function_set_color")(tf, 0, c.as_ptr(), 2),
            FvStatus::Ok
        );
        assert_eq!(
            lib.f::<SetPoints>("fv_transfer_function_set_opacity")(tf, 0, o.as_ptr(), 2),
            FvStatus::Ok
        );
        assert_eq!(set_tf(r, tf), FvStatus::Ok);

        lib.expect(
            "0x0 frame",
            render(r, 0, 0, null(), 0),
            FvStatus::InvalidArgument,
            "image size 0x0",
        );
        lib.expect(
            "huge frame",
            render(r, 1 << 20, 4, null(), 0),
            FvStatus::InvalidArgument,
            "each side must be",
        );
        let depth = [1.0f32; 10];
        lib.expect(
            "depth size",
            render(r, 8, 8, depth.as_ptr(), 10),
            FvStatus::InvalidArgument,
            "10 values",
        );

        for (what, edit, needle) in [
            (
                "blend",
                (|p: &mut FvRenderParams| p.blend_mode = 42) as fn(&mut FvRenderParams),
                "blend_mode 42",
            ),
            ("interp", |p| p.interpolation = 2, "interpolation 2"),
            ("gradient", |p| p.gradient_method = 9, "gradient_method 9"),
            (
                "sample distance",
                |p| p.sample_distance = -1.0,
                "sample_distance -1",
            ),
            (
                "termination",
                |p| p.termination_threshold = 0.0,
                "termination threshold 0",
            ),
            (
                "clip count",
                |p| p.clip_plane_count = 7,
                "clip_plane_count 7",
            ),
            ("clip normal", |p| p.clip_plane_count = 1, "non-zero normal"),
            (
                "cropping",
                |p| {
                    p.cropping = true;
                    p.cropping_planes = [1.0, 0.0, 0.0, 1.0, 0.0, 1.0];
                },
                "min ≤ max",
            ),
            ("matrix", |p| p.volume_matrix = [0.0; 16], "singular"),
            (
                "specular power",
                |p| p.specular_power = f32::NAN,
                "specular power",
            ),
        ] {
            let mut bad = p;
            edit(&mut bad);
            lib.expect(what, set_params(r, &bad), FvStatus::InvalidArgument, needle);
        }

        let defaults = lib.f::<ParamsDefault>("fv_render_params_default");
        lib.expect(
            "NULL params",
            defaults(null_mut()),
            FvStatus::NullArgument,
            "params is NULL",
        );
        let mut from_c: FvRenderParams = std::mem::zeroed();
        assert_eq!(defaults(&mut from_c), FvStatus::Ok);
        assert_eq!(from_c.termination_threshold, 1.0 - 1.0 / 255.0);

        let set_cam = lib.f::<SetCamera>("fv_renderer_set_camera");
        let mut cam: FvCamera = std::mem::zeroed();
        cam.view_up = [0.0, 1.0, 0.0];
        cam.view_angle = 30.0;
        cam.clipping_range = [0.1, 100.0];
        lib.expect(
            "camera at focal point",
            set_cam(r, &cam),
            FvStatus::InvalidArgument,
            "equals its focal point",
        );
        cam.position = [2.0, 2.0, 30.0];
        cam.focal_point = [2.0, 2.0, 2.0];
        cam.view_angle = 200.0;
        lib.expect(
            "view angle",
            set_cam(r, &cam),
            FvStatus::InvalidArgument,
            "view angle 200",
        );
        cam.view_angle = 30.0;
        assert_eq!(set_cam(r, &cam), FvStatus::Ok);

        let set_lights = lib.f::<SetLights>("fv_renderer_set_lights");
        let mut light: FvLight = std::mem::zeroed();
        light.space = 7;
        lib.expect(
            "light space",
            set_lights(r, &light, 1),
            FvStatus::InvalidArgument,
            "light 0 space 7",
        );
        lib.expect(
            "9 lights",
            set_lights(r, &light, 9),
            FvStatus::InvalidArgument,
            "9 lights",
        );
        lib.expect(
            "NULL lights",
            set_lights(r, null(), 2),
            FvStatus::NullArgument,
            "lights",
        );
        assert_eq!(set_lights(r, null(), 0), FvStatus::Ok);

        let set_path =
            lib.f::<unsafe extern "C" fn(H, u32) -> FvStatus>("fv_renderer_set_output_path");
        lib.expect(
            "output path 5",
            set_path(r, 5),
            FvStatus::InvalidArgument,
            "output path 5",
        );
        let shared = lib
            .f::<unsafe extern "C" fn(H, u32, *mut ferrovol::FvSharedImage) -> FvStatus>(
                "fv_renderer_shared_image",
            );
        let mut img: ferrovol::FvSharedImage = std::mem::zeroed();
        lib.expect(
            "shared image while reading back",
            shared(r, 0, &mut img),
            FvStatus::InvalidArgument,
            "shared",
        );
        lib.expect(
            "target 9",
            shared(r, 9, &mut img),
            FvStatus::InvalidArgument,
            "target 9",
        );
        lib.expect(
            "NULL image",
            shared(r, 0, null_mut()),
            FvStatus::NullArgument,
            "image is NULL",
        );

        // A valid frame still renders after all those refusals.
        p.shade = true;
        assert_eq!(set_params(r, &p), FvStatus::Ok);
        assert_eq!(
            render(r, 16, 16, null(), 0),
            FvStatus::Ok,
            "{}",
            lib.last_error()
        );
        let mut frame: H = null_mut();
        let read = lib.f::<unsafe extern "C" fn(H, *mut H) -> FvStatus>("fv_renderer_read_frame");
        assert_eq!(read(r, &mut frame), FvStatus::Ok);
        let rgba = lib.f::<unsafe extern "C" fn(H) -> *const u8>("fv_frame_rgba")(frame);
        let centre = *rgba.add(4 * (8 * 16 + 8) + 3);
        println!("centre alpha after the refusals: {centre}");
        assert!(
            centre > 100,
            "the uniform volume must be opaque at the centre"
        );
        let png = lib.f::<unsafe extern "C" fn(H, *const c_char, *const [f32; 3]) -> FvStatus>(
            "fv_frame_write_png",
        );
        let bg = [0.0f32; 3];
        lib.expect(
            "bad path",
            png(frame, c"/nonexistent/dir/x.png".as_ptr(), &bg),
            FvStatus::IoError,
            "/nonexistent/dir/x.png",
        );

        lib.f::<Free>("fv_frame_free")(frame);
        lib.f::<Free>("fv_transfer_function_free")(tf);
        lib.f::<Free>("fv_volume_free")(v);
        lib.f::<Free>("fv_renderer_free")(r);
        lib.f::<Free>("fv_context_free")(ctx);
    }
}

#[test]
fn last_error_is_per_thread_and_status_names_are_static() {
    let lib = Lib::open();
    let name = lib.f::<extern "C" fn(FvStatus) -> *const c_char>("fv_status_name");
    // SAFETY: fv_status_name returns static strings.
    let s = unsafe { CStr::from_ptr(name(FvStatus::Panic)) };
    assert_eq!(s.to_str().unwrap(), "FV_STATUS_PANIC");
    let new = lib.f::<NewTf>("fv_transfer_function_new");
    // SAFETY: NULL out is the error under test.
    unsafe { new(1, true, null_mut()) };
    assert!(lib.last_error().contains("out is NULL"));
    let other = std::thread::spawn(|| Lib::open().last_error())
        .join()
        .unwrap();
    assert_eq!(other, "", "another thread must not see this thread's error");
}

type SetIso = unsafe extern "C" fn(H, *const ferrovol::FvIsoParams) -> FvStatus;
type SetEnv = unsafe extern "C" fn(H, *const c_char, f32, *const f64, f64) -> FvStatus;

/// The isosurface mode through the C ABI: every refusal names its problem, then a sphere
/// renders opaque at the centre and empty in the corner.
#[test]
fn isosurface_errors_and_a_frame() {
    let lib = Lib::open();
    let mut ctx: H = null_mut();
    let mut r: H = null_mut();
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
    let set_params = lib.f::<SetParams>("fv_renderer_set_params");
    let render = lib.f::<Render>("fv_renderer_render");
    // SAFETY: arguments follow the header; invalid ones are the test.
    unsafe {
        assert_eq!(lib.f::<NewCtx>("fv_context_new")(&mut ctx), FvStatus::Ok);
        assert_eq!(
            lib.f::<NewRenderer>("fv_renderer_new")(ctx, &mut r),
            FvStatus::Ok
        );
        let d = desc([16, 16, 16], 1, ferrovol::FvScalarType::F32 as u32);
        let mut v: H = null_mut();
        assert_eq!(
            lib.f::<NewVolume>("fv_volume_new")(&d, data.as_ptr().cast(), 4 * n * n * n, &mut v),
            FvStatus::Ok,
            "{}",
            lib.last_error()
        );
        assert_eq!(lib.f::<SetH>("fv_renderer_set_volume")(r, v), FvStatus::Ok);
        let mut cam: FvCamera = std::mem::zeroed();
        cam.position = [7.5, 7.5, 60.0];
        cam.focal_point = [7.5, 7.5, 7.5];
        cam.view_up = [0.0, 1.0, 0.0];
        cam.view_angle = 30.0;
        cam.clipping_range = [1.0, 200.0];
        assert_eq!(
            lib.f::<SetCamera>("fv_renderer_set_camera")(r, &cam),
            FvStatus::Ok
        );
        let mut p = FvRenderParams::defaults();
        p.blend_mode = ferrovol::FvBlendMode::Isosurface as u32;
        assert_eq!(set_params(r, &p), FvStatus::Ok);
        lib.expect(
            "no iso-values",
            render(r, 32, 32, null(), 0),
            FvStatus::InvalidArgument,
            "iso-values",
        );

        let mut iso: ferrovol::FvIsoParams = std::mem::zeroed();
        let defaults = lib.f::<unsafe extern "C" fn(*mut ferrovol::FvIsoParams) -> FvStatus>(
            "fv_iso_params_default",
        );
        lib.expect(
            "NULL iso defaults",
            defaults(null_mut()),
            FvStatus::NullArgument,
            "params is NULL",
        );
        assert_eq!(defaults(&mut iso), FvStatus::Ok);
        assert_eq!(iso.bisection_steps, 8);
        lib.expect(
            "0 values",
            set_iso(r, &iso),
            FvStatus::InvalidArgument,
            "value_count 0",
        );
        iso.value_count = 1;
        iso.values[0] = ferrovol::FvIsoValue {
            value: 5.0,
            color: [0.9, 0.8, 0.7],
            opacity: 1.0,
        };
        type Edit = fn(&mut ferrovol::FvIsoParams);
        let cases: [(&str, Edit, &str); 7] = [
            ("9 values", |i| i.value_count = 9, "value_count 9"),
            ("opacity 0", |i| i.values[0].opacity = 0.0, "opacity 0"),
            ("colour 2", |i| i.values[0].color[0] = 2.0, "colour"),
            ("mode 7", |i| i.specular_mode = 7, "specular_mode 7"),
            (
                "0 samples",
                |i| i.specular_samples = 0,
                "0 specular samples",
            ),
            ("AO radius", |i| i.ao_radius = -1.0, "ao_radius -1"),
            (
                "40 bisections",
                |i| i.bisection_steps = 40,
                "40 bisection steps",
            ),
        ];
        for (what, edit, needle) in cases {
            let mut bad = iso;
            edit(&mut bad);
            lib.expect(what, set_iso(r, &bad), FvStatus::InvalidArgument, needle);
        }
        lib.expect(
            "NULL renderer",
            set_iso(null_mut(), &iso),
            FvStatus::NullArgument,
            "renderer",
        );
        lib.expect(
            "missing map",
            set_env(r, c"/nonexistent/sky.hdr".as_ptr(), 1.0, null(), 0.0),
            FvStatus::InvalidArgument,
            "cannot be opened",
        );
        lib.expect(
            "text map",
            set_env(r, c"/etc/hostname.txt".as_ptr(), 1.0, null(), 0.0),
            FvStatus::InvalidArgument,
            "unsupported file type",
        );
        let up = [0.0, 0.0, 1.0];
        assert_eq!(
            set_env(r, null(), 1.0, up.as_ptr(), 30.0),
            FvStatus::Ok,
            "{}",
            lib.last_error()
        );
        iso.ao_samples = 8;
        assert_eq!(set_iso(r, &iso), FvStatus::Ok, "{}", lib.last_error());
        assert_eq!(
            render(r, 32, 32, null(), 0),
            FvStatus::Ok,
            "{}",
            lib.last_error()
        );
        let mut frame: H = null_mut();
        let read = lib.f::<unsafe extern "C" fn(H, *mut H) -> FvStatus>("fv_renderer_read_frame");
        assert_eq!(read(r, &mut frame), FvStatus::Ok);
        let rgba = lib.f::<unsafe extern "C" fn(H) -> *const u8>("fv_frame_rgba")(frame);
        let px = |x: usize, y: usize| std::slice::from_raw_parts(rgba.add(4 * (y * 32 + x)), 4);
        println!("sphere centre {:?}, corner {:?}", px(16, 16), px(0, 0));
        assert_eq!(px(16, 16)[3], 255, "the opaque sphere covers the centre");
        assert!(px(16, 16)[0] > 100, "and it is lit");
        assert_eq!(px(0, 0), [0, 0, 0, 0], "the corner misses it");
        lib.f::<Free>("fv_frame_free")(frame);
        lib.f::<Free>("fv_volume_free")(v);
        lib.f::<Free>("fv_renderer_free")(r);
        lib.f::<Free>("fv_context_free")(ctx);
    }
}

type SetPt = unsafe extern "C" fn(H, *const ferrovol::FvPathTraceParams) -> FvStatus;
type Accumulated = unsafe extern "C" fn(H, *mut u32) -> FvStatus;

/// Path tracing through the C ABI: refusals name their problem, frames accumulate and a
/// camera change starts over.
#[test]
fn path_tracing_accumulates_and_refuses_bad_settings() {
    let lib = Lib::open();
    let mut ctx: H = null_mut();
    let mut r: H = null_mut();
    let data: Vec<f32> = (0..8 * 8 * 8).map(|i| (i % 8) as f32 / 7.0).collect();
    // SAFETY: arguments follow the header; invalid ones are the test.
    unsafe {
        assert_eq!(lib.f::<NewCtx>("fv_context_new")(&mut ctx), FvStatus::Ok);
        assert_eq!(
            lib.f::<NewRenderer>("fv_renderer_new")(ctx, &mut r),
            FvStatus::Ok
        );
        let d = desc([8, 8, 8], 1, ferrovol::FvScalarType::F32 as u32);
        let mut v: H = null_mut();
        assert_eq!(
            lib.f::<NewVolume>("fv_volume_new")(&d, data.as_ptr().cast(), 4 * 512, &mut v),
            FvStatus::Ok
        );
        assert_eq!(lib.f::<SetH>("fv_renderer_set_volume")(r, v), FvStatus::Ok);
        let mut tf: H = null_mut();
        assert_eq!(
            lib.f::<NewTf>("fv_transfer_function_new")(1, true, &mut tf),
            FvStatus::Ok
        );
        let c = [0.0, 0.9, 0.8, 0.7, 1.0, 0.9, 0.8, 0.7];
        let o = [0.0, 0.0, 1.0, 0.6];
        let set_points = lib.f::<SetPoints>("fv_transfer_function_set_color");
        assert_eq!(set_points(tf, 0, c.as_ptr(), 2), FvStatus::Ok);
        let set_points = lib.f::<SetPoints>("fv_transfer_function_set_opacity");
        assert_eq!(set_points(tf, 0, o.as_ptr(), 2), FvStatus::Ok);
        assert_eq!(
            lib.f::<SetH>("fv_renderer_set_transfer_function")(r, tf),
            FvStatus::Ok
        );
        let mut cam: FvCamera = std::mem::zeroed();
        cam.position = [3.5, 3.5, 40.0];
        cam.focal_point = [3.5, 3.5, 3.5];
        cam.view_up = [0.0, 1.0, 0.0];
        cam.view_angle = 30.0;
        cam.clipping_range = [1.0, 100.0];
        let set_cam = lib.f::<SetCamera>("fv_renderer_set_camera");
        assert_eq!(set_cam(r, &cam), FvStatus::Ok);
        let mut p = FvRenderParams::defaults();
        p.blend_mode = ferrovol::FvBlendMode::PathTrace as u32;
        assert_eq!(
            lib.f::<SetParams>("fv_renderer_set_params")(r, &p),
            FvStatus::Ok
        );
        let set_pt = lib.f::<SetPt>("fv_renderer_set_path_tracing");
        let defaults = lib.f::<unsafe extern "C" fn(*mut ferrovol::FvPathTraceParams) -> FvStatus>(
            "fv_path_trace_params_default",
        );
        let mut pt: ferrovol::FvPathTraceParams = std::mem::zeroed();
        assert_eq!(defaults(&mut pt), FvStatus::Ok);
        let mut bad = pt;
        bad.anisotropy = 1.0;
        lib.expect(
            "g = 1",
            set_pt(r, &bad),
            FvStatus::InvalidArgument,
            "anisotropy 1",
        );
        bad = pt;
        bad.samples_per_frame = 0;
        lib.expect(
            "0 paths",
            set_pt(r, &bad),
            FvStatus::InvalidArgument,
            "0 paths per pixel",
        );
        for (what, edit, words) in [
            (
                "scatter regions 7",
                (|p: &mut ferrovol::FvPathTraceParams| p.scatter_regions = 7)
                    as fn(&mut ferrovol::FvPathTraceParams),
                "not an FvScatterRegions",
            ),
            ("roughness 0", |p| p.roughness = 0.0, "roughness 0"),
            ("cone 90°", |p| p.cone_angle = 90.0, "cone angle 90"),
            (
                "ψ < 0",
                |p| p.gradient_threshold = -1.0,
                "gradient threshold",
            ),
            (
                "k NaN",
                |p| p.stochastic_blend = f32::NAN,
                "stochastic blend",
            ),
            (
                "0 secondary rays",
                |p| p.secondary_rays = 0,
                "secondary rays",
            ),
        ] {
            bad = pt;
            edit(&mut bad);
            lib.expect(what, set_pt(r, &bad), FvStatus::InvalidArgument, words);
        }
        lib.expect(
            "NULL params",
            set_pt(r, null()),
            FvStatus::NullArgument,
            "params is NULL",
        );
        // the hybrid model with a 2×2 budget renders
        bad = pt;
        bad.gradient_threshold = 0.5;
        bad.secondary_rays = 2;
        bad.scatter_regions = ferrovol::FvScatterRegions::Surfaces as u32;
        assert_eq!(set_pt(r, &bad), FvStatus::Ok);
        assert_eq!(
            lib.f::<Render>("fv_renderer_render")(r, 16, 16, null(), 0),
            FvStatus::Ok,
            "{}",
            lib.last_error()
        );
        pt.samples_per_frame = 2;
        assert_eq!(set_pt(r, &pt), FvStatus::Ok);
        let render = lib.f::<Render>("fv_renderer_render");
        let accumulated = lib.f::<Accumulated>("fv_renderer_accumulated_samples");
        let mut counts = vec![];
        for i in 0..4 {
            if i == 3 {
                cam.position = [3.5, 10.0, 40.0];
                assert_eq!(set_cam(r, &cam), FvStatus::Ok);
            }
            assert_eq!(
                render(r, 16, 16, null(), 0),
                FvStatus::Ok,
                "{}",
                lib.last_error()
            );
            let mut n = 0u32;
            assert_eq!(accumulated(r, &mut n), FvStatus::Ok);
            counts.push(n);
        }
        println!("accumulated paths per pixel: {counts:?} (camera moved before the last)");
        assert_eq!(counts, vec![2, 4, 6, 2]);
        lib.f::<Free>("fv_transfer_function_free")(tf);
        lib.f::<Free>("fv_volume_free")(v);
        lib.f::<Free>("fv_renderer_free")(r);
        lib.f::<Free>("fv_context_free")(ctx);
    }
}
