//! The shared output (Vulkan external memory, opaque fd) on a real device, with OpenGL
//! through EGL's surfaceless platform as the importing host (on lavapipe, the CI device,
//! Mesa's llvmpipe).
//!
//! Every test prints what it measured. The sharing tests need a Vulkan device that can export
//! memory, as every device class is expected to (common/gpu.rs); they fail (they do not skip)
//! when the device cannot. The OpenGL tests skip, saying why, only when libEGL cannot be
//! loaded, its GL lacks GL_EXT_memory_object_fd, or it runs on another device than Vulkan
//! where that is not expected of the device class; everything after that point is asserted.

use ferrovol_core::*;
use std::sync::{MutexGuard, OnceLock};
mod common;

use common::gpu::{expected, shared_renderer};
use common::metrics::{count_diff, footprint};

/// The test binary's renderer, the test volume and a transfer function set (the fd and
/// mapping counts below also need the process to themselves).
fn renderer() -> MutexGuard<'static, Renderer> {
    shared_renderer(|r| {
        r.set_volume_with(
            &test_volume(),
            UploadOptions {
                max_brick_points: Some(24),
                ..Default::default()
            },
        )
        .expect("uploading the volume");
        let mut tf = TransferFunction::ramp([0.0, 1.0], 0.6);
        tf.components[0].color =
            Piecewise::new(vec![(0.0, [0.1, 0.3, 0.9]), (1.0, [1.0, 0.8, 0.3])]).expect("finite");
        r.set_transfer_function(&tf)
            .expect("a valid transfer function");
    })
}

fn params() -> RenderParams {
    RenderParams {
        shading: Shading {
            enabled: true,
            ..Shading::default()
        },
        ..RenderParams::default()
    }
}

/// The test volume: several bricks, so frames go through both the ray-casting and the
/// resolve pass.
fn test_volume() -> VolumeData {
    synth::marschner_lobb(41)
}

/// A view of the test volume (test sizes are odd: rows are not a multiple of wgpu's 256-byte
/// copy alignment).
fn view(width: u32, height: u32) -> View {
    static BOUNDS: OnceLock<[f64; 6]> = OnceLock::new();
    let bounds = *BOUNDS.get_or_init(|| test_volume().bounds());
    let mut v = View::fit(bounds, width, height);
    v.camera.azimuth(30.0);
    v.camera.elevation(20.0);
    v
}

/// Renders `v` without a depth input. Returns that frame; `cut`, the depth of its hit with a
/// `k`th of its hits in front (k = 2: the median); and a depth input that is `cut` at the
/// pixels (row-major indices) where `cut_here` holds and 1 (no cut) elsewhere.
fn depth_cut(
    r: &mut Renderer,
    v: &View,
    p: &RenderParams,
    k: usize,
    cut_here: impl Fn(u32) -> bool,
) -> (Image, f32, Vec<f32>) {
    r.render(v, p, None).expect("rendering");
    let plain = r.read_image().expect("reading back");
    let mut hits: Vec<f32> = plain.depth.iter().copied().filter(|&d| d < 1.0).collect();
    hits.sort_by(f32::total_cmp);
    let cut = hits[hits.len() / k];
    let depth = (0..v.width * v.height)
        .map(|i| if cut_here(i) { cut } else { 1.0 })
        .collect();
    (plain, cut, depth)
}

/// Open file descriptors of this process.
fn open_fds() -> usize {
    std::fs::read_dir("/proc/self/fd")
        .expect("reading /proc/self/fd")
        .count()
}

/// Mappings of memfd files in this process: a driver keeping exportable allocations in host
/// memory (lavapipe) maps each (`Expected::exports_as_memfd`).
fn memfd_mappings() -> usize {
    std::fs::read_to_string("/proc/self/maps")
        .expect("reading /proc/self/maps")
        .lines()
        .filter(|l| l.contains("/memfd:"))
        .count()
}

#[test]
fn device_can_export_and_has_uuids() {
    let r = renderer();
    let ctx = r.context();
    let exp = expected(&ctx.info);
    let support = ctx.external_memory_support();
    println!("external memory: {support:?}");
    assert!(
        exp.exports_memory,
        "the sharing tests need a device expected to export memory: {exp:?}"
    );
    support.expect("opaque fds (VK_KHR_external_memory_fd), expected of this device class");
    assert!(ctx.can_export_memory());
    let ids = ctx.device_uuids().expect("Vulkan 1.1 device UUIDs");
    println!("device UUID {:02x?}", ids.device);
    println!("driver UUID {:02x?}", ids.driver);
    assert_ne!(ids.device, [0; 16], "device UUID is zero");
    assert_ne!(ids.driver, [0; 16], "driver UUID is zero");
}

#[test]
fn sharing_does_not_change_the_image() {
    let mut r = renderer();
    let (w, h) = (97, 61);
    let v = view(w, h);
    let p = params();
    // A depth input that cuts the right half of the volume off at the median volume depth.
    r.set_output_path(OutputPath::Readback).expect("readback");
    let (plain, _, depth_in) = depth_cut(&mut r, &v, &p, 2, |i| i % w >= w / 2);
    r.render(&v, &p, Some(&depth_in))
        .expect("rendering with depth");
    let plain_cut = r.read_image().expect("reading back");

    r.set_output_sharing(true)
        .expect("sharing (expected of this device class)");
    assert_eq!(r.output_path(), OutputPath::Shared);
    r.render(&v, &p, None)
        .expect("rendering into shared memory");
    let shared = r.read_image().expect("reading back shared memory");
    r.render(&v, &p, Some(&depth_in))
        .expect("rendering with depth");
    let shared_cut = r.read_image().expect("reading back");
    r.set_output_path(OutputPath::Readback).expect("readback");

    let changed = count_diff(&plain.rgba, &plain_cut.rgba);
    println!(
        "{w}x{h}: footprint {} px; the depth input changes {changed} bytes",
        footprint(&plain)
    );
    assert!(
        footprint(&plain) > (w * h / 8) as usize,
        "the volume is in view"
    );
    assert!(changed > 100, "the depth input has an effect");
    let (dc, dd) = (
        count_diff(&plain.rgba, &shared.rgba),
        count_diff(&plain.depth, &shared.depth),
    );
    let (dc_cut, dd_cut) = (
        count_diff(&plain_cut.rgba, &shared_cut.rgba),
        count_diff(&plain_cut.depth, &shared_cut.depth),
    );
    println!("readback vs shared: {dc} colour bytes, {dd} depths differ; with depth input {dc_cut}, {dd_cut}");
    // Same pipelines, same inputs, only the memory differs: bit-identical.
    assert_eq!((dc, dd, dc_cut, dd_cut), (0, 0, 0, 0));
}

#[test]
fn exported_fds_and_generations() {
    let mut r = renderer();
    let p = params();
    r.set_output_path(OutputPath::Readback).expect("readback");
    let err = r.shared_targets().expect_err("not shared yet");
    println!("readback path: {err}");
    assert!(matches!(err, Error::Unsupported(_)));

    r.set_output_path(OutputPath::Shared)
        .expect("sharing (expected of this device class)");
    r.prepare_targets(64, 40).expect("allocating");
    let g0 = r.output_generation();
    r.render(&view(64, 40), &p, None).expect("rendering");
    r.render(&view(64, 40), &p, None).expect("rendering");
    assert_eq!(r.output_generation(), g0, "same size, no reallocation");

    let fds_before = open_fds();
    let a = r.shared_targets().expect("exporting");
    let b = r.shared_targets().expect("exporting again");
    assert_eq!(a.generation, g0);
    assert_eq!(open_fds(), fds_before + 6, "six new descriptors");
    for (name, img, bpp) in [
        ("colour", &a.color, 4u64),
        ("depth", &a.depth, 4),
        ("depth in", &a.depth_in, 4),
    ] {
        let file = std::fs::File::from(img.fd.try_clone().expect("dup"));
        let meta = file.metadata().expect("fstat on the exported fd");
        println!(
            "{name}: fd {:?}, {}x{} {:?} (GL 0x{:04x}), allocation {} B, fstat size {} B",
            img.fd,
            img.width,
            img.height,
            img.format,
            img.gl_internal_format,
            img.size,
            meta.len()
        );
        assert_eq!((img.width, img.height), (64, 40));
        assert!(
            img.size >= 64 * 40 * bpp,
            "allocation smaller than the image"
        );
        assert!(img.dedicated);
    }
    assert_eq!(a.color.format, wgpu::TextureFormat::Rgba8Unorm);
    assert_eq!(a.depth.format, wgpu::TextureFormat::R32Float);
    assert_eq!(a.depth_in.format, wgpu::TextureFormat::R32Float);
    use std::os::fd::AsRawFd;
    assert_ne!(
        a.color.fd.as_raw_fd(),
        b.color.fd.as_raw_fd(),
        "a new fd per call"
    );
    drop((a, b));
    assert_eq!(open_fds(), fds_before, "dropping the output closes its fds");

    r.render(&view(65, 40), &p, None).expect("rendering");
    let g1 = r.output_generation();
    r.render(&view(64, 40), &p, None).expect("rendering");
    let g2 = r.output_generation();
    r.render(&view(64, 40), &p, None).expect("rendering");
    assert_eq!(r.output_generation(), g2);
    r.set_output_path(OutputPath::Readback).expect("readback");
    r.render(&view(64, 40), &p, None).expect("rendering");
    let g3 = r.output_generation();
    println!("generations: {g0} → resize {g1} → resize back {g2} → readback {g3}");
    assert!(
        g0 != g1 && g1 != g2 && g2 != g3,
        "each reallocation changes it"
    );
    assert_eq!(r.shared_targets().map(|_| ()).ok(), None);
}

#[test]
fn replaced_shared_memory_is_freed() {
    let mut r = renderer();
    let memfd = expected(&r.context().info).exports_as_memfd;
    let p = params();
    r.set_output_path(OutputPath::Shared)
        .expect("sharing (expected of this device class)");
    r.render(&view(40, 30), &p, None).expect("rendering");
    r.finish().expect("waiting");
    let (maps0, fds0) = (memfd_mappings(), open_fds());
    for i in 0..12 {
        r.render(&view(41 + i, 30), &p, None).expect("rendering");
        let out = r.shared_targets().expect("exporting");
        assert_eq!(out.width, 41 + i);
    }
    r.render(&view(40, 30), &p, None).expect("rendering");
    // wgpu frees replaced textures once the GPU is done with them, at the next poll.
    r.finish().expect("waiting");
    r.finish().expect("waiting");
    let (maps1, fds1) = (memfd_mappings(), open_fds());
    r.set_output_path(OutputPath::Readback).expect("readback");
    r.render(&view(40, 30), &p, None).expect("rendering");
    r.finish().expect("waiting");
    r.finish().expect("waiting");
    let (maps2, fds2) = (memfd_mappings(), open_fds());
    println!(
        "memfd mappings / open fds: {maps0} / {fds0} at start, {maps1} / {fds1} after 13 \
         reallocations, {maps2} / {fds2} back on readback"
    );
    if !memfd {
        // device memory: only the fds can be counted
        assert_eq!(fds1, fds0, "reallocation leaks fds");
        return;
    }
    assert!(maps0 >= 3, "lavapipe maps each of the 3 shared allocations");
    assert_eq!((maps1, fds1), (maps0, fds0), "reallocation leaks nothing");
    assert_eq!(
        maps2,
        maps0 - 3,
        "leaving the shared path frees its 3 allocations"
    );
}

/// Sharing is refused with a reason on a device that cannot export (wgpu's GL backend), and
/// the renderer stays on the readback path. Runs in a child process, as the backend is chosen
/// from the environment when the context is made.
#[test]
fn gl_backend_refuses_sharing() {
    let _turn = renderer();
    let exe = std::env::current_exe().expect("test binary path");
    let out = std::process::Command::new(exe)
        .args(["--exact", "gl_backend_child", "--ignored", "--nocapture"])
        .env("FERROVOL_BACKEND", "gl")
        .output()
        .expect("running the child test");
    let text = String::from_utf8_lossy(&out.stdout);
    println!("{text}{}", String::from_utf8_lossy(&out.stderr));
    assert!(out.status.success(), "the GL-backend child failed");
    assert!(text.contains("1 passed"), "the child test ran");
}

#[test]
#[ignore = "run by gl_backend_refuses_sharing with FERROVOL_BACKEND=gl"]
fn gl_backend_child() {
    if std::env::var("FERROVOL_BACKEND").as_deref() != Ok("gl") {
        println!("not the GL-backend child (FERROVOL_BACKEND is not gl): nothing to do");
        return;
    }
    let ctx = match Context::new() {
        Ok(c) => c,
        Err(e) => {
            println!("SKIPPED: no GL adapter for wgpu here: {e}");
            return;
        }
    };
    assert_eq!(ctx.info.backend, "Gl");
    let why = ctx.external_memory_support().expect_err("GL cannot export");
    println!("GL backend: {why}");
    assert!(matches!(why, Error::Unsupported(ref m) if m.contains("Vulkan backend")));
    assert!(!ctx.can_export_memory());
    assert!(matches!(ctx.device_uuids(), Err(Error::Unsupported(_))));
    let mut r = Renderer::new(ctx).expect("renderer");
    let e = r.set_output_sharing(true).expect_err("refused");
    assert!(matches!(e, Error::Unsupported(_)));
    assert_eq!(r.output_path(), OutputPath::Readback);
    assert!(matches!(r.shared_targets(), Err(Error::Unsupported(_))));
    // Not asserted: whether frames render on wgpu's GL backend does not depend on sharing
    // (on llvmpipe it fails allocating the R32Float depth output as a render attachment).
    let vol = synth::marschner_lobb(17);
    r.set_volume(&vol).expect("volume");
    r.set_transfer_function(&TransferFunction::ramp([0.0, 1.0], 0.5))
        .expect("tf");
    let frame = r.render_image(&View::fit(vol.bounds(), 32, 32), &RenderParams::default());
    println!(
        "a frame on wgpu's GL backend: {:?}",
        frame.map(|img| format!("footprint {} px", footprint(&img)))
    );
}

#[cfg(target_os = "linux")]
mod gl {
    //! A minimal OpenGL host: EGL on Mesa's surfaceless platform (no window system), GL
    //! functions loaded through eglGetProcAddress.

    use khronos_egl as egl;
    use std::ffi::{c_void, CStr};

    pub const TEXTURE_2D: u32 = 0x0DE1;
    pub const TEXTURE_MIN_FILTER: u32 = 0x2801;
    pub const TEXTURE_MAG_FILTER: u32 = 0x2800;
    pub const NEAREST: i32 = 0x2600;
    pub const TEXTURE_TILING_EXT: u32 = 0x9580;
    pub const DEDICATED_MEMORY_OBJECT_EXT: u32 = 0x9581;
    pub const OPTIMAL_TILING_EXT: i32 = 0x9584;
    pub const HANDLE_TYPE_OPAQUE_FD_EXT: u32 = 0x9586;
    pub const DEVICE_UUID_EXT: u32 = 0x9597;
    pub const DRIVER_UUID_EXT: u32 = 0x9598;
    pub const FRAMEBUFFER: u32 = 0x8D40;
    pub const COLOR_ATTACHMENT0: u32 = 0x8CE0;
    pub const FRAMEBUFFER_COMPLETE: u32 = 0x8CD5;
    pub const RGBA: u32 = 0x1908;
    pub const RED: u32 = 0x1903;
    pub const UNSIGNED_BYTE: u32 = 0x1401;
    pub const FLOAT: u32 = 0x1406;
    pub const PACK_ALIGNMENT: u32 = 0x0D05;
    pub const UNPACK_ALIGNMENT: u32 = 0x0CF5;
    const RENDERER: u32 = 0x1F01;
    const VERSION: u32 = 0x1F02;
    const EXTENSIONS: u32 = 0x1F03;
    const NUM_EXTENSIONS: u32 = 0x821D;
    const PLATFORM_SURFACELESS_MESA: egl::Enum = 0x31DD;

    macro_rules! gl_functions {
        ($($name:ident : $sym:literal fn($($arg:ty),*) $(-> $ret:ty)?;)*) => {
            /// GL entry points of the current context.
            #[allow(non_snake_case)]
            pub struct Fns {
                $(pub $name: unsafe extern "system" fn($($arg),*) $(-> $ret)?,)*
            }
            impl Fns {
                fn load(egl: &egl::DynamicInstance<egl::EGL1_5>) -> Result<Fns, String> {
                    Ok(Fns {
                        $($name: {
                            let f = egl
                                .get_proc_address($sym)
                                .ok_or_else(|| format!("eglGetProcAddress({}) failed", $sym))?;
                            // SAFETY: the symbol is the GL function of this name, whose C
                            // signature the field type spells out.
                            unsafe {
                                std::mem::transmute::<
                                    extern "system" fn(),
                                    unsafe extern "system" fn($($arg),*) $(-> $ret)?,
                                >(f)
                            }
                        },)*
                    })
                }
            }
        };
    }

    gl_functions! {
        GetString: "glGetString" fn(u32) -> *const u8;
        GetStringi: "glGetStringi" fn(u32, u32) -> *const u8;
        GetIntegerv: "glGetIntegerv" fn(u32, *mut i32);
        GetError: "glGetError" fn() -> u32;
        Finish: "glFinish" fn();
        PixelStorei: "glPixelStorei" fn(u32, i32);
        GetUnsignedBytevEXT: "glGetUnsignedBytevEXT" fn(u32, *mut u8);
        GetUnsignedBytei_vEXT: "glGetUnsignedBytei_vEXT" fn(u32, u32, *mut u8);
        CreateMemoryObjectsEXT: "glCreateMemoryObjectsEXT" fn(i32, *mut u32);
        DeleteMemoryObjectsEXT: "glDeleteMemoryObjectsEXT" fn(i32, *const u32);
        MemoryObjectParameterivEXT: "glMemoryObjectParameterivEXT" fn(u32, u32, *const i32);
        ImportMemoryFdEXT: "glImportMemoryFdEXT" fn(u32, u64, u32, i32);
        TexStorageMem2DEXT: "glTexStorageMem2DEXT" fn(u32, i32, u32, i32, i32, u32, u64);
        GenTextures: "glGenTextures" fn(i32, *mut u32);
        DeleteTextures: "glDeleteTextures" fn(i32, *const u32);
        BindTexture: "glBindTexture" fn(u32, u32);
        TexParameteri: "glTexParameteri" fn(u32, u32, i32);
        TexSubImage2D: "glTexSubImage2D" fn(u32, i32, i32, i32, i32, i32, u32, u32, *const c_void);
        GenFramebuffers: "glGenFramebuffers" fn(i32, *mut u32);
        DeleteFramebuffers: "glDeleteFramebuffers" fn(i32, *const u32);
        BindFramebuffer: "glBindFramebuffer" fn(u32, u32);
        FramebufferTexture2D: "glFramebufferTexture2D" fn(u32, u32, u32, u32, i32);
        CheckFramebufferStatus: "glCheckFramebufferStatus" fn(u32) -> u32;
        ReadPixels: "glReadPixels" fn(i32, i32, i32, i32, u32, u32, *mut c_void);
    }

    /// An OpenGL 4.5 core context, current on the thread that made it.
    pub struct Host {
        egl: egl::DynamicInstance<egl::EGL1_5>,
        display: egl::Display,
        context: egl::Context,
        pub fns: Fns,
        pub renderer: String,
        pub version: String,
    }

    impl Host {
        /// `Err` says why no suitable GL is available.
        pub fn new() -> Result<Host, String> {
            // SAFETY: libEGL.so.1 is the system's EGL (glvnd or Mesa).
            let egl = unsafe { egl::DynamicInstance::<egl::EGL1_5>::load_required() }
                .map_err(|e| format!("cannot load libEGL.so.1 with EGL 1.5: {e}"))?;
            // SAFETY: the surfaceless platform takes EGL_DEFAULT_DISPLAY as native display.
            let display = unsafe {
                egl.get_platform_display(
                    PLATFORM_SURFACELESS_MESA,
                    egl::DEFAULT_DISPLAY,
                    &[egl::ATTRIB_NONE],
                )
            }
            .map_err(|e| {
                format!("no EGL surfaceless display (EGL_MESA_platform_surfaceless): {e}")
            })?;
            egl.initialize(display)
                .map_err(|e| format!("eglInitialize: {e}"))?;
            egl.bind_api(egl::OPENGL_API)
                .map_err(|e| format!("eglBindAPI(OpenGL): {e}"))?;
            let config = egl
                .choose_first_config(
                    display,
                    &[
                        egl::RENDERABLE_TYPE,
                        egl::OPENGL_BIT,
                        egl::SURFACE_TYPE,
                        egl::PBUFFER_BIT,
                        egl::NONE,
                    ],
                )
                .map_err(|e| format!("eglChooseConfig: {e}"))?
                .ok_or("no EGL config for desktop OpenGL")?;
            let context = egl
                .create_context(
                    display,
                    config,
                    None,
                    &[
                        egl::CONTEXT_MAJOR_VERSION,
                        4,
                        egl::CONTEXT_MINOR_VERSION,
                        5,
                        egl::CONTEXT_OPENGL_PROFILE_MASK,
                        egl::CONTEXT_OPENGL_CORE_PROFILE_BIT,
                        egl::NONE,
                    ],
                )
                .map_err(|e| format!("no OpenGL 4.5 core context: {e}"))?;
            egl.make_current(display, None, None, Some(context))
                .map_err(|e| format!("eglMakeCurrent without surface: {e}"))?;
            let fns = Fns::load(&egl)?;
            let text = |p: *const u8| {
                if p.is_null() {
                    String::new()
                } else {
                    // SAFETY: GL returns NUL-terminated static strings.
                    unsafe { CStr::from_ptr(p.cast()) }
                        .to_string_lossy()
                        .into_owned()
                }
            };
            // SAFETY: a context is current on this thread; the enums are valid.
            let (renderer, version) = unsafe {
                (
                    text((fns.GetString)(RENDERER)),
                    text((fns.GetString)(VERSION)),
                )
            };
            Ok(Host {
                egl,
                display,
                context,
                fns,
                renderer,
                version,
            })
        }

        pub fn has_extension(&self, name: &str) -> bool {
            let mut n = 0;
            // SAFETY: current context; `n` outlives the call.
            unsafe { (self.fns.GetIntegerv)(NUM_EXTENSIONS, &mut n) };
            (0..n as u32).any(|i| {
                // SAFETY: current context, index below GL_NUM_EXTENSIONS.
                let p = unsafe { (self.fns.GetStringi)(EXTENSIONS, i) };
                // SAFETY: GL returns NUL-terminated static strings.
                !p.is_null() && unsafe { CStr::from_ptr(p.cast()) }.to_bytes() == name.as_bytes()
            })
        }

        /// Device and driver UUIDs of this GL (GL_EXT_memory_object).
        pub fn uuids(&self) -> ([u8; 16], [u8; 16]) {
            let (mut device, mut driver) = ([0u8; 16], [0u8; 16]);
            // SAFETY: current context; GL writes GL_UUID_SIZE_EXT (16) bytes into each.
            unsafe {
                (self.fns.GetUnsignedBytei_vEXT)(DEVICE_UUID_EXT, 0, device.as_mut_ptr());
                (self.fns.GetUnsignedBytevEXT)(DRIVER_UUID_EXT, driver.as_mut_ptr());
            }
            (device, driver)
        }

        pub fn error(&self) -> u32 {
            // SAFETY: current context.
            unsafe { (self.fns.GetError)() }
        }

        /// `Err` naming `what` and the GL error, if GL has one.
        pub fn check(&self, what: &str) -> Result<(), String> {
            match self.error() {
                0 => Ok(()),
                e => Err(format!("{what}: GL error 0x{e:04x}")),
            }
        }
    }

    impl Drop for Host {
        fn drop(&mut self) {
            let _ = self.egl.make_current(self.display, None, None, None);
            let _ = self.egl.destroy_context(self.display, self.context);
        }
    }
}

/// An exported image imported into GL as a 2D texture, with a framebuffer to read it.
#[cfg(target_os = "linux")]
struct Imported<'a> {
    host: &'a gl::Host,
    memory: u32,
    texture: u32,
    framebuffer: u32,
}

#[cfg(target_os = "linux")]
impl<'a> Imported<'a> {
    /// Imports `img`, consuming its fd.
    fn new(host: &'a gl::Host, img: SharedImage) -> std::result::Result<Imported<'a>, String> {
        use std::os::fd::IntoRawFd;
        let f = &host.fns;
        let (mut memory, mut texture, mut framebuffer) = (0, 0, 0);
        // SAFETY: current context; every pointer outlives its call; the fd is handed over to
        // GL, which owns it once glImportMemoryFdEXT succeeds.
        unsafe {
            (f.CreateMemoryObjectsEXT)(1, &mut memory);
            (f.MemoryObjectParameterivEXT)(memory, gl::DEDICATED_MEMORY_OBJECT_EXT, &1);
            (f.ImportMemoryFdEXT)(
                memory,
                img.size,
                gl::HANDLE_TYPE_OPAQUE_FD_EXT,
                img.fd.into_raw_fd(),
            );
            host.check("glImportMemoryFdEXT")?;
            (f.GenTextures)(1, &mut texture);
            (f.BindTexture)(gl::TEXTURE_2D, texture);
            (f.TexParameteri)(
                gl::TEXTURE_2D,
                gl::TEXTURE_TILING_EXT,
                gl::OPTIMAL_TILING_EXT,
            );
            (f.TexParameteri)(gl::TEXTURE_2D, gl::TEXTURE_MIN_FILTER, gl::NEAREST);
            (f.TexParameteri)(gl::TEXTURE_2D, gl::TEXTURE_MAG_FILTER, gl::NEAREST);
            (f.TexStorageMem2DEXT)(
                gl::TEXTURE_2D,
                1,
                img.gl_internal_format,
                img.width as i32,
                img.height as i32,
                memory,
                0,
            );
            host.check("glTexStorageMem2DEXT")?;
            (f.GenFramebuffers)(1, &mut framebuffer);
            (f.BindFramebuffer)(gl::FRAMEBUFFER, framebuffer);
            (f.FramebufferTexture2D)(
                gl::FRAMEBUFFER,
                gl::COLOR_ATTACHMENT0,
                gl::TEXTURE_2D,
                texture,
                0,
            );
            let status = (f.CheckFramebufferStatus)(gl::FRAMEBUFFER);
            if status != gl::FRAMEBUFFER_COMPLETE {
                return Err(format!(
                    "framebuffer on the imported texture: status 0x{status:04x}"
                ));
            }
        }
        Ok(Imported {
            host,
            memory,
            texture,
            framebuffer,
        })
    }

    /// Reads `width × height` texels of `format`/`ty` (4-byte texels), GL row 0 first.
    fn read(&self, width: u32, height: u32, format: u32, ty: u32) -> Vec<u8> {
        let f = &self.host.fns;
        let mut out = vec![0u8; 4 * (width * height) as usize];
        // SAFETY: current context; `out` holds width × height 4-byte texels, tightly packed.
        unsafe {
            (f.Finish)();
            (f.BindFramebuffer)(gl::FRAMEBUFFER, self.framebuffer);
            (f.PixelStorei)(gl::PACK_ALIGNMENT, 1);
            (f.ReadPixels)(
                0,
                0,
                width as i32,
                height as i32,
                format,
                ty,
                out.as_mut_ptr().cast(),
            );
        }
        assert_eq!(self.host.error(), 0, "glReadPixels");
        out
    }

    /// Writes `width × height` floats (GL row 0 first) into the texture and waits for GL.
    fn write_f32(&self, width: u32, height: u32, data: &[f32]) {
        assert_eq!(data.len(), (width * height) as usize);
        let f = &self.host.fns;
        // SAFETY: current context; `data` holds width × height floats.
        unsafe {
            (f.BindTexture)(gl::TEXTURE_2D, self.texture);
            (f.PixelStorei)(gl::UNPACK_ALIGNMENT, 4);
            (f.TexSubImage2D)(
                gl::TEXTURE_2D,
                0,
                0,
                0,
                width as i32,
                height as i32,
                gl::RED,
                gl::FLOAT,
                data.as_ptr().cast(),
            );
            (f.Finish)();
        }
        assert_eq!(self.host.error(), 0, "glTexSubImage2D");
    }
}

#[cfg(target_os = "linux")]
impl Drop for Imported<'_> {
    fn drop(&mut self) {
        let f = &self.host.fns;
        // SAFETY: current context; the names are ours.
        unsafe {
            (f.DeleteFramebuffers)(1, &self.framebuffer);
            (f.DeleteTextures)(1, &self.texture);
            (f.DeleteMemoryObjectsEXT)(1, &self.memory);
        }
    }
}

/// A GL host that can import the opaque fds of `ctx`'s device, or why not (then the caller
/// skips).
#[cfg(target_os = "linux")]
fn gl_host(ctx: &Context) -> Option<gl::Host> {
    let host = match gl::Host::new() {
        Ok(h) => h,
        Err(e) => {
            println!("SKIPPED: no OpenGL through EGL here: {e}");
            return None;
        }
    };
    println!("GL: {} — {}", host.renderer, host.version);
    for ext in ["GL_EXT_memory_object", "GL_EXT_memory_object_fd"] {
        if !host.has_extension(ext) {
            println!("SKIPPED: this GL lacks {ext}");
            return None;
        }
    }
    println!(
        "GL_EXT_semaphore_fd: {}",
        if host.has_extension("GL_EXT_semaphore_fd") {
            "yes"
        } else {
            "no (the CPU wait Renderer::finish is the sync)"
        }
    );
    let ids = ctx.device_uuids().expect("UUIDs");
    let (gl_device, gl_driver) = host.uuids();
    println!(
        "Vulkan device {:02x?} driver {:02x?}",
        ids.device, ids.driver
    );
    println!("GL     device {gl_device:02x?} driver {gl_driver:02x?}");
    let exp = expected(&ctx.info);
    if exp.surfaceless_gl_same_device {
        assert_eq!(
            (gl_device, gl_driver),
            (ids.device, ids.driver),
            "lavapipe and llvmpipe report the same device and driver"
        );
    } else if (gl_device, gl_driver) != (ids.device, ids.driver) {
        println!(
            "SKIPPED: this GL runs on another device than Vulkan (not expected otherwise of a \
             {:?} device): memory cannot be shared between them",
            exp.class
        );
        return None;
    }
    Some(host)
}

/// Runs `test` on the renderer with its output in shared memory and an OpenGL host on the
/// same device (or skips, saying why, where there is none), then returns the output to
/// readback: what `test` imported into GL is gone by then.
#[cfg(target_os = "linux")]
fn with_gl_sharing(test: impl FnOnce(&mut Renderer, &gl::Host)) {
    let mut r = renderer();
    let Some(host) = gl_host(r.context()) else {
        return;
    };
    r.set_output_path(OutputPath::Shared).expect("sharing");
    test(&mut r, &host);
    r.set_output_path(OutputPath::Readback).expect("readback");
}

/// OpenGL imports the exported colour and depth and sees exactly the frame read_image gives.
#[cfg(target_os = "linux")]
#[test]
fn opengl_sees_the_frame() {
    with_gl_sharing(|r, host| {
        let (w, h) = (97, 61);
        r.prepare_targets(w, h).expect("allocating");
        let out = r.shared_targets().expect("exporting");
        let generation = out.generation;
        let color = Imported::new(host, out.color).expect("importing the colour into GL");
        let depth = Imported::new(host, out.depth).expect("importing the depth into GL");

        // Import once, render several frames into the same memory.
        for azimuth in [0.0, 40.0] {
            let mut v = view(w, h);
            v.camera.azimuth(azimuth);
            r.render(&v, &params(), None).expect("rendering");
            r.finish().expect("waiting for the GPU");
            assert_eq!(r.output_generation(), generation, "no reallocation");
            let gl_rgba = color.read(w, h, gl::RGBA, gl::UNSIGNED_BYTE);
            let gl_depth = depth.read(w, h, gl::RED, gl::FLOAT);
            let img = r.read_image().expect("reading back");
            let gl_depth: Vec<f32> = gl_depth
                .chunks(4)
                .map(|b| f32::from_ne_bytes([b[0], b[1], b[2], b[3]]))
                .collect();
            let (dc, dd) = (
                count_diff(&gl_rgba, &img.rgba),
                count_diff(&gl_depth, &img.depth),
            );
            println!(
                "azimuth {azimuth}: footprint {} px; GL vs read_image: {dc} of {} colour bytes, \
                 {dd} of {} depths differ",
                footprint(&img),
                img.rgba.len(),
                img.depth.len()
            );
            assert!(
                footprint(&img) > (w * h / 8) as usize,
                "the volume is in view"
            );
            // The same memory read two ways: exact.
            assert_eq!((dc, dd), (0, 0), "GL sees a different frame");
        }
    });
}

/// The host writes the depth input through GL; the frame equals one with the same depth
/// uploaded from the CPU.
#[cfg(target_os = "linux")]
#[test]
fn opengl_writes_the_depth_input() {
    with_gl_sharing(|r, host| {
        let (w, h) = (80, 56);
        let v = view(w, h);
        let p = params();
        let e = r.render_with_shared_depth(&view(w + 1, h), &p);
        assert!(
            e.is_err(),
            "a size the depth input does not have is refused"
        );
        // Rows top to bottom: the upper half is cut at `cut`, the lower half not at all.
        let (plain, cut, depth) = depth_cut(r, &v, &p, 3, |i| i / w < h / 2);
        r.render(&v, &p, Some(&depth))
            .expect("rendering with uploaded depth");
        let uploaded = r.read_image().expect("reading back");

        let out = r.shared_targets().expect("exporting");
        let depth_in = Imported::new(host, out.depth_in).expect("importing the depth input");
        // GL row 0 is memory row 0, which is the top row of the frame: write the rows as they are.
        depth_in.write_f32(w, h, &depth);
        let read_back = depth_in.read(w, h, gl::RED, gl::FLOAT);
        assert_eq!(
            read_back,
            bytemuck::cast_slice::<f32, u8>(&depth),
            "GL wrote"
        );
        r.render_with_shared_depth(&v, &p)
            .expect("rendering with the shared depth");
        let shared = r.read_image().expect("reading back");
        let changed = count_diff(&plain.rgba, &uploaded.rgba);
        let (dc, dd) = (
            count_diff(&uploaded.rgba, &shared.rgba),
            count_diff(&uploaded.depth, &shared.depth),
        );
        println!(
            "depth cut at {cut}: changes {changed} colour bytes; GL-written vs uploaded depth \
             input: {dc} colour bytes, {dd} depths differ"
        );
        assert!(changed > 100, "the depth input has an effect");
        assert_eq!((dc, dd), (0, 0));
    });
}
