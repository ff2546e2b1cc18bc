//! `ferrovol`: render volumes to PNG, benchmark against VTK, describe the GPU.

mod bench;
mod iso;
mod mesh;
mod presets;

use clap::{Parser, Subcommand, ValueEnum};
use ferrovol_core::{
    synth, AmbientOcclusion, BlendMode, BsdfParams, ClipPlane, Context, Environment,
    GradientMethod, Interpolation, IsoParams, IsoScatterMode, IsoScattering, IsoValue,
    PathTraceParams, Quadrature, RenderParams, Renderer, ScalarType, ScatterRegions, Shininess,
    SpecularMode, UploadOptions, View, VolumeData,
};
use iso::{environment_setup, iso_setup, parse_axis, IsoArgs};
use std::path::PathBuf;
use std::process::ExitCode;
use std::sync::Arc;
use std::time::Duration;

#[derive(Parser)]
#[command(name = "ferrovol", version, about = "GPU volume ray casting on wgpu")]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
enum Command {
    /// Render a volume (or a built-in one) to a PNG.
    Render(Box<RenderArgs>),
    /// Time VTK's GPU ray cast benchmark scene (wavelet 256³, 900×900), shaded and unshaded.
    Bench(bench::BenchArgs),
    /// Print the GPU adapter, backend and limits ferrovol would use; with a .vtu mesh, what
    /// the renderer makes of it.
    Info {
        /// An unstructured grid (.vtu) to describe instead.
        mesh: Option<PathBuf>,
    },
}

#[derive(Clone, Copy, ValueEnum, PartialEq, Eq, Debug)]
enum DemoType {
    Float32,
    Uint16,
}

#[derive(Clone, Copy, ValueEnum, PartialEq, Eq, Debug)]
enum Demo {
    Wavelet,
    MarschnerLobb,
    Sphere,
}

#[derive(Clone, Copy, ValueEnum, PartialEq, Eq, Debug)]
enum Mode {
    Composite,
    Mip,
    Minip,
    Average,
    Additive,
    /// Isosurfaces (--iso): first hit with bisection, deferred shading with environment
    /// lighting and ambient occlusion.
    Iso,
    /// Monte Carlo path tracing of the volume as a scattering medium (--spp, --g,
    /// --bounces; the environment flags light it).
    Pathtrace,
    /// VTK's slice blend mode: the transfer function on the plane --slice-plane.
    Slice,
}

#[derive(Clone, Copy, ValueEnum, PartialEq, Eq, Debug)]
enum SpecularArg {
    /// Random vectors in a cone blended with the reflection vector (simple, noisy).
    Cone,
    /// Importance sampling of the Phong lobe with mip filtering.
    Importance,
}

#[derive(Clone, Copy, ValueEnum, PartialEq, Eq, Debug)]
enum InterpArg {
    Nearest,
    Linear,
    /// The cubic B-spline of the points (ray casting).
    Cubic,
}

#[derive(Clone, Copy, ValueEnum, PartialEq, Eq, Debug)]
enum GradArg {
    Central,
    Forward,
}

#[derive(clap::Args)]
struct RenderArgs {
    /// Volume file: .vti, .nii, .nii.gz, .mha, .mhd, .nrrd, .nhdr; or an unstructured grid,
    /// .vtu (composite with --shade and --volumetric, mip, minip, average, additive, iso,
    /// pathtrace). Without it, a built-in volume.
    input: Option<PathBuf>,
    /// Built-in volume to render when no input file is given.
    #[arg(long, value_enum, default_value = "wavelet")]
    demo: Demo,
    /// Points per edge of the built-in wavelet, computed as the renderer reads it (never
    /// held whole in memory, so any size renders; with --gpu-memory it streams).
    #[arg(long, value_name = "N", value_parser = clap::value_parser!(u32).range(2..=65536))]
    demo_size: Option<u32>,
    /// Scalar type of the --demo-size wavelet: float32 (VTK's values) or uint16 (scaled:
    /// (value + 40) · 180; the transfer function defaults to auto).
    #[arg(long, value_enum, default_value = "float32", requires = "demo_size")]
    demo_type: DemoType,
    /// Image size, WIDTHxHEIGHT.
    #[arg(long, default_value = "512x512", value_parser = parse_size)]
    size: (u32, u32),
    #[arg(long, value_enum, default_value = "composite")]
    mode: Mode,
    /// Phong shading from on-the-fly gradients (VTK's Shade on).
    #[arg(long)]
    shade: bool,
    /// Store the central-difference gradients in a texture at upload (one fetch per
    /// shaded sample instead of six; the same gradients; single-component volumes).
    #[arg(long)]
    precompute_gradients: bool,
    /// Volumetric shadows with --shade, blended with the gradient shading as VTK's
    /// VolumetricScatteringBlending: 0 off, 2 volumetric only (anisotropy: --g).
    #[arg(long, default_value_t = 0.0, requires = "shade")]
    volumetric: f32,
    /// How far shadow rays reach, 0 to 1 (VTK's GlobalIlluminationReach).
    #[arg(long, default_value_t = 0.0)]
    reach: f32,
    /// Transfer function: a preset name or a JSON file (the README gives the format); a
    /// name that is neither lists the presets.
    #[arg(long)]
    tf: Option<String>,
    /// The plane --mode slice draws, world coordinates: ox,oy,oz,nx,ny,nz (a point on it,
    /// then its normal). Default: through the volume's centre, normal along z.
    #[arg(long, value_parser = parse_plane, allow_hyphen_values = true)]
    slice_plane: Option<[f64; 6]>,
    /// Camera rotation about the view up vector, degrees (vtkCamera::Azimuth).
    #[arg(long, default_value_t = 0.0, allow_hyphen_values = true)]
    azimuth: f64,
    /// Camera rotation up/down, degrees (vtkCamera::Elevation).
    #[arg(long, default_value_t = 0.0, allow_hyphen_values = true)]
    elevation: f64,
    /// The world axis that is up on screen after azimuth and elevation (x, y, z, -x, -y or
    /// -z; vtkCamera::SetViewUp + OrthogonalizeViewUp), e.g. z for medical volumes seen
    /// from the front with --elevation -90.
    #[arg(long, value_parser = parse_axis, allow_hyphen_values = true)]
    view_up: Option<[f64; 3]>,
    /// Camera rotation about the view direction, degrees (vtkCamera::Roll), after azimuth
    /// and elevation.
    #[arg(long, default_value_t = 0.0, allow_hyphen_values = true)]
    roll: f64,
    /// Zoom factor (vtkCamera::Zoom).
    #[arg(long, default_value_t = 1.0)]
    zoom: f64,
    /// Parallel projection instead of perspective.
    #[arg(long)]
    parallel: bool,
    #[arg(long, value_enum, default_value = "linear")]
    interpolation: InterpArg,
    #[arg(long, value_enum, default_value = "central")]
    gradient: GradArg,
    /// World distance between samples (default: the smallest voxel spacing, as VTK).
    #[arg(long)]
    sample_distance: Option<f64>,
    /// Jitter each ray's first sample (removes wood-grain artefacts).
    #[arg(long)]
    jitter: bool,
    /// Disable empty-space skipping.
    #[arg(long)]
    no_skip: bool,
    /// Pre-integrated classification: composite mode classifies the segment between
    /// consecutive samples (thin opacity peaks without slicing at the default step).
    #[arg(long)]
    preintegration: bool,
    /// Midpoint quadrature: samples in the middle of their steps and the path through the
    /// volume exact (VTK's lattice by default: first order in the step, off at silhouettes).
    #[arg(long)]
    midpoint: bool,
    /// Adaptive midpoint quadrature: unshaded composite rays take 1, 2 or 4 sample distances
    /// per step by how much the transfer function changes per step in each block.
    #[arg(long, conflicts_with = "midpoint")]
    adaptive: bool,
    /// Background colour r,g,b in [0, 1].
    #[arg(long, default_value = "0,0,0", value_parser = parse_rgb)]
    background: [f32; 3],
    /// Split the volume into bricks of at most this many points per edge.
    #[arg(long)]
    brick: Option<u32>,
    /// Most MiB the volume may take on the device. A larger volume is bricked with only the
    /// bricks a frame needs resident; when even those exceed it, ray casting and isosurfaces
    /// stream them through the pool in several passes; path tracing, volumetric shadows, AO
    /// and scattering, whose rays go anywhere, draw the finest coarser level that fits.
    #[arg(long, value_name = "MIB")]
    gpu_memory: Option<u64>,
    /// With --gpu-memory: a frame whose bricks exceed it draws in one pass, as an interactive
    /// frame would, instead of streaming the volume itself (the still image): ray casting
    /// and isosurfaces draw the fine bricks resident and a coarser level's where they are
    /// missing, and bring those their rays read for the next frames (see --repeat)
    #[arg(long)]
    preview_level: bool,
    /// Render this many frames and print the mean time per frame (the first, which builds
    /// pipelines and maps, is not counted). Path tracing: each timed frame starts the
    /// accumulation over, as a moving camera does, and traces --spp paths per pixel.
    #[arg(long, default_value_t = 1, value_parser = clap::value_parser!(u32).range(1..=10000))]
    repeat: u32,
    /// With --repeat: frames the device may still be drawing when the next is recorded. 2
    /// (the default): each frame waits only for the one before it, so the device draws while
    /// the next frame is prepared; 1: each frame waits for its own end.
    #[arg(long, default_value_t = 2, value_parser = clap::value_parser!(u32).range(1..=2))]
    frames_in_flight: u32,
    /// With --repeat: turn the camera by this many degrees about the view up vector
    /// (azimuth) before each frame after the first, an interactive camera path; the summary
    /// adds the bricks uploaded per frame and, with --preview-level, the frames that drew
    /// coarser bricks where fine ones were missing.
    #[arg(long, default_value_t = 0.0, allow_hyphen_values = true)]
    orbit: f64,
    #[command(flatten)]
    iso: IsoArgs,
    #[command(flatten)]
    pt: PathTraceArgs,
    /// Output PNG.
    #[arg(long, short, default_value = "ferrovol.png")]
    out: PathBuf,
}

/// Path tracing options (--mode pathtrace); --env, --env-up, --env-azimuth,
/// --env-intensity, --env-light and --env-background light it too.
#[derive(clap::Args)]
struct PathTraceArgs {
    /// Paths per pixel (accumulated over frames of at most 64 paths each).
    #[arg(long, default_value_t = 256, value_parser = clap::value_parser!(u32).range(1..=1_000_000))]
    spp: u32,
    /// Ray budget PxS instead of --spp: P primary rays per pixel, each continued by S
    /// secondary rays (P·S paths; 1x64, 8x8 and 64x1 are the lecture's comparison).
    #[arg(long, value_parser = parse_budget, conflicts_with = "spp")]
    budget: Option<(u32, u32)>,
    /// The hybrid model's gradient threshold ψ (scalar units per world unit): the BSDF
    /// where |∇s| > ψ, Henyey–Greenstein elsewhere. Default: Henyey–Greenstein everywhere.
    #[arg(long, allow_hyphen_values = true)]
    psi: Option<f32>,
    /// The stochastic blend instead of the switch at ψ: the BSDF with probability
    /// 1 − exp(−K·|∇s|).
    #[arg(long = "blend-k", conflicts_with = "psi", allow_hyphen_values = true)]
    blend_k: Option<f32>,
    /// Where collisions scatter: none, iso (at surfaces, by the BSDF), between (between
    /// surfaces, by Henyey–Greenstein) or everywhere.
    #[arg(long, value_enum, default_value_t = Scatter::Everywhere)]
    scatter: Scatter,
    /// Collisions that do not scatter are left out instead of absorbing.
    #[arg(long)]
    no_attenuation: bool,
    /// The BSDF's GGX roughness in [0.01, 1].
    #[arg(long, default_value_t = BsdfParams::default().roughness)]
    roughness: f32,
    /// The BSDF's Fresnel reflectance at normal incidence in [0, 1].
    #[arg(long = "bsdf-fresnel", default_value_t = BsdfParams::default().fresnel)]
    bsdf_fresnel: f32,
    /// Share of the BSDF's non-specular part transmitted through the surface, [0, 1].
    #[arg(long, default_value_t = BsdfParams::default().transmission)]
    transmission: f32,
    /// Half the transmitted lobe lies within this angle, degrees in [0.5, 60].
    #[arg(long, default_value_t = BsdfParams::default().cone_angle)]
    cone_angle: f32,
    /// Show the image through the edge-aware à-trous denoiser (guided by the normal and
    /// depth where the paths first meet the medium).
    #[arg(long)]
    denoise: bool,
    /// Seed of the random streams.
    #[arg(long, default_value_t = 0)]
    seed: u32,
    /// Henyey–Greenstein anisotropy g in (−1, 1): 0 isotropic, > 0 forward scattering.
    #[arg(long = "g", default_value_t = 0.0, allow_hyphen_values = true)]
    anisotropy: f32,
    /// Most scattering events per path.
    #[arg(long, default_value_t = 64)]
    bounces: u32,
}

#[derive(Clone, Copy, ValueEnum, PartialEq, Eq, Debug)]
enum Scatter {
    None,
    Iso,
    Between,
    Everywhere,
}

impl PathTraceArgs {
    /// Paths per pixel: the budget's P·S, or --spp.
    fn paths(&self) -> u32 {
        self.budget.map_or(self.spp, |(p, s)| p * s)
    }

    fn params(&self, env_light: f32, background: bool) -> Result<PathTraceParams, CliError> {
        let p = PathTraceParams {
            samples_per_frame: self.paths().min(64),
            max_samples: self.paths(),
            secondary_rays: self.budget.map_or(1, |(_, s)| s),
            max_bounces: self.bounces,
            anisotropy: self.anisotropy,
            gradient_threshold: self.psi.unwrap_or(f32::INFINITY),
            stochastic_blend: self.blend_k.unwrap_or(0.0),
            bsdf: BsdfParams {
                roughness: self.roughness,
                fresnel: self.bsdf_fresnel,
                transmission: self.transmission,
                cone_angle: self.cone_angle,
            },
            scatter: match self.scatter {
                Scatter::None => ScatterRegions::Nowhere,
                Scatter::Iso => ScatterRegions::Surfaces,
                Scatter::Between => ScatterRegions::Between,
                Scatter::Everywhere => ScatterRegions::Everywhere,
            },
            attenuation: !self.no_attenuation,
            environment_light: env_light,
            background,
            denoise: self.denoise,
            seed: self.seed,
            ..PathTraceParams::default()
        };
        p.validate()?;
        Ok(p)
    }
}

/// PxS: primary and secondary rays per pixel, each at least 1, at most 1,000,000 paths.
fn parse_budget(s: &str) -> Result<(u32, u32), String> {
    let bad = || format!("ray budget '{s}': write PxS, e.g. 8x8");
    let (p, q) = s.split_once(['x', 'X', '×']).ok_or_else(bad)?;
    let p: u32 = p.trim().parse().map_err(|_| bad())?;
    let q: u32 = q.trim().parse().map_err(|_| bad())?;
    if p == 0 || q == 0 || p as u64 * q as u64 > 1_000_000 {
        return Err(format!(
            "ray budget '{s}': both counts at least 1, at most 1,000,000 paths in all"
        ));
    }
    Ok((p, q))
}

fn parse_size(s: &str) -> Result<(u32, u32), String> {
    let (w, h) = s
        .split_once(['x', 'X'])
        .ok_or_else(|| format!("size '{s}' must look like 512x512"))?;
    let w: u32 = w
        .trim()
        .parse()
        .map_err(|_| format!("width '{w}' is not a positive integer"))?;
    let h: u32 = h
        .trim()
        .parse()
        .map_err(|_| format!("height '{h}' is not a positive integer"))?;
    if w == 0 || h == 0 || w > 16384 || h > 16384 {
        return Err(format!("size {w}x{h}: each side must be 1 to 16384"));
    }
    Ok((w, h))
}

fn parse_rgb(s: &str) -> Result<[f32; 3], String> {
    let v: Vec<f32> = s
        .split(',')
        .map(|p| p.trim().parse::<f32>())
        .collect::<Result<_, _>>()
        .map_err(|_| format!("colour '{s}' must be r,g,b"))?;
    match v.as_slice() {
        [r, g, b] if v.iter().all(|c| (0.0..=1.0).contains(c)) => Ok([*r, *g, *b]),
        _ => Err(format!(
            "colour '{s}' must be three numbers in [0, 1] separated by commas"
        )),
    }
}

fn parse_plane(s: &str) -> Result<[f64; 6], String> {
    let v: Vec<f64> = s
        .split(',')
        .map(|p| p.trim().parse::<f64>())
        .collect::<Result<_, _>>()
        .map_err(|_| format!("plane '{s}' must be ox,oy,oz,nx,ny,nz"))?;
    match <[f64; 6]>::try_from(v.as_slice()) {
        Ok(p) if p.iter().all(|x| x.is_finite()) && p[3..].iter().any(|x| *x != 0.0) => Ok(p),
        _ => Err(format!(
            "plane '{s}' must be six finite numbers ox,oy,oz,nx,ny,nz with a non-zero normal"
        )),
    }
}

/// Everything that can go wrong in the CLI, each with a message for the user.
#[derive(Debug, thiserror::Error)]
pub enum CliError {
    #[error(transparent)]
    Read(#[from] ferrovol_io::ReadError),
    #[error(transparent)]
    Image(#[from] ferrovol_io::image::ImageError),
    #[error("{0}")]
    Core(#[from] ferrovol_core::Error),
    #[error("{0}")]
    Usage(String),
}

/// A spinner that appears only if the work takes longer than a second.
pub fn spinner(msg: &str) -> indicatif::ProgressBar {
    let pb = indicatif::ProgressBar::new_spinner();
    pb.set_draw_target(indicatif::ProgressDrawTarget::hidden());
    pb.set_message(msg.to_string());
    let p2 = pb.clone();
    std::thread::spawn(move || {
        std::thread::sleep(Duration::from_secs(1));
        if !p2.is_finished() {
            p2.set_draw_target(indicatif::ProgressDrawTarget::stderr());
            p2.enable_steady_tick(Duration::from_millis(120));
        }
    });
    pb
}

fn demo_volume(d: Demo) -> VolumeData {
    match d {
        Demo::Wavelet => synth::wavelet([-63, 64, -63, 64, -63, 64]),
        Demo::MarschnerLobb => synth::marschner_lobb(41),
        Demo::Sphere => synth::sphere(64, 0.35),
    }
}

/// The camera of `render`'s flags around `bounds` (world coordinates).
fn view_of(a: &RenderArgs, bounds: [f64; 6]) -> Result<View, CliError> {
    let (w, h) = a.size;
    let mut view = View::fit(bounds, w, h);
    view.camera.parallel = a.parallel;
    view.camera.azimuth(a.azimuth);
    view.camera.elevation(a.elevation);
    if let Some(up) = a.view_up {
        let up = glam::DVec3::from_array(up);
        let dir = view.camera.focal_point - view.camera.position;
        if up.cross(dir).length() <= 1e-9 * dir.length() {
            return Err(CliError::Usage(format!(
                "--view-up {up}: that axis is parallel to the view direction {dir} after \
                 --azimuth/--elevation; choose another axis or turn the camera first"
            )));
        }
        view.camera.view_up = up;
    }
    view.camera.orthogonalize_view_up();
    view.camera.roll(a.roll);
    view.camera.zoom(a.zoom);
    view.camera.reset_clipping_range(bounds);
    Ok(view)
}

/// The render parameters of `render`'s flags for a volume or mesh within `bounds`.
fn render_params(a: &RenderArgs, bounds: [f64; 6]) -> RenderParams {
    let mut params = RenderParams {
        blend: match a.mode {
            Mode::Composite => BlendMode::Composite,
            Mode::Mip => BlendMode::Maximum,
            Mode::Minip => BlendMode::Minimum,
            Mode::Average => BlendMode::Average,
            Mode::Additive => BlendMode::Additive,
            Mode::Iso => BlendMode::Isosurface,
            Mode::Pathtrace => BlendMode::PathTrace,
            Mode::Slice => BlendMode::Slice,
        },
        interpolation: match a.interpolation {
            InterpArg::Nearest => Interpolation::Nearest,
            InterpArg::Linear => Interpolation::Linear,
            InterpArg::Cubic => Interpolation::Cubic,
        },
        gradient: if a.gradient == GradArg::Forward {
            GradientMethod::Forward
        } else {
            GradientMethod::Central
        },
        sample_distance: a.sample_distance,
        jitter: a.jitter,
        empty_space_skipping: !a.no_skip,
        preintegration: a.preintegration,
        preview_level: a.preview_level,
        quadrature: if a.adaptive {
            Quadrature::Adaptive
        } else if a.midpoint {
            Quadrature::Midpoint
        } else {
            Quadrature::Vtk
        },
        slice_plane: (a.mode == Mode::Slice).then(|| {
            let b = bounds;
            let p = a.slice_plane.unwrap_or([
                0.5 * (b[0] + b[1]),
                0.5 * (b[2] + b[3]),
                0.5 * (b[4] + b[5]),
                0.0,
                0.0,
                1.0,
            ]);
            ClipPlane {
                origin: glam::DVec3::new(p[0], p[1], p[2]),
                normal: glam::DVec3::new(p[3], p[4], p[5]),
            }
        }),
        ..Default::default()
    };
    params.shading.enabled = a.shade;
    params.shading.volumetric_blending = a.volumetric;
    params.shading.global_illumination_reach = a.reach;
    params.shading.scattering_anisotropy = a.pt.anisotropy;
    params
}

/// `--mode pathtrace`'s settings and environment, None in the other modes.
fn path_tracing_setup(a: &RenderArgs) -> Result<Option<(PathTraceParams, Environment)>, CliError> {
    if a.mode != Mode::Pathtrace {
        return Ok(None);
    }
    let p =
        a.pt.params(a.iso.env_light.unwrap_or(1.0), a.iso.env_background)?;
    Ok(Some((p, environment_setup(&a.iso)?)))
}

/// Path-traced frames until `paths` paths per pixel have accumulated, counted on `pb`.
fn trace_paths(
    r: &mut Renderer,
    view: &View,
    params: &RenderParams,
    paths: u32,
    pb: &indicatif::ProgressBar,
) -> Result<(), CliError> {
    while r.accumulated_samples() < paths {
        pb.set_message(format!(
            "path tracing: {} of {paths} paths per pixel",
            r.accumulated_samples()
        ));
        r.render(view, params, None)?;
    }
    Ok(())
}

fn render(a: RenderArgs) -> Result<(), CliError> {
    if let Some(p) = a.input.as_ref().filter(|p| mesh::is_vtu(p)) {
        return mesh::render(&a, p);
    }
    let pb = spinner("loading volume");
    let (vol, default_tf) = match (&a.input, a.demo_size) {
        (Some(p), _) => (ferrovol_io::open_volume(p)?, "auto"),
        (None, Some(n)) => {
            if a.demo != Demo::Wavelet {
                return Err(CliError::Usage(
                    "--demo-size generates the wavelet only (--demo wavelet)".into(),
                ));
            }
            let (ty, tf) = match a.demo_type {
                DemoType::Float32 => (ScalarType::F32, "wavelet"),
                DemoType::Uint16 => (ScalarType::U16, "auto"),
            };
            (synth::wavelet_generated(synth::wavelet_extent(n), ty)?, tf)
        }
        (None, None) => (
            demo_volume(a.demo),
            match a.demo {
                Demo::Wavelet => "wavelet",
                Demo::MarschnerLobb => "marschner-lobb",
                Demo::Sphere => "sphere",
            },
        ),
    };
    // Shared with the renderer, which reads a bricked volume's bricks from it (no copy).
    let vol = Arc::new(vol);
    let tf = presets::transfer_function(a.tf.as_deref().unwrap_or(default_tf), &vol)?;
    let iso = if a.mode == Mode::Iso {
        Some(iso_setup(&a.iso, || Ok(vol.try_range(0)?))?)
    } else {
        None
    };
    let path_tracing = path_tracing_setup(&a)?;
    pb.set_message("starting the GPU");
    let mut r = Renderer::new(Context::new()?)?;
    pb.set_message("uploading");
    r.set_shared_volume(
        vol.clone(),
        UploadOptions {
            max_brick_points: a.brick,
            memory_budget: a.gpu_memory.map(|m| m << 20),
            precompute_gradients: Some(a.precompute_gradients),
        },
    )?;
    let streaming = pb.clone();
    r.set_progress(Some(Box::new(move |done, total| {
        streaming.set_message(format!("streaming the bricks: pass {done} of {total}"));
    })));
    r.set_transfer_function(&tf)?;
    if let Some((p, env)) = &iso {
        pb.set_message("filtering the environment");
        r.set_isosurface(p)?;
        r.set_environment(env)?;
    }
    if let Some((p, env)) = &path_tracing {
        pb.set_message("filtering the environment");
        r.set_path_tracing(p)?;
        r.set_environment(env)?;
    }
    let (w, h) = a.size;
    let mut view = view_of(&a, vol.bounds())?;
    let params = render_params(&a, vol.bounds());
    if a.iso.no_lights {
        view.lights.clear();
    }
    pb.set_message("compiling the pipelines");
    r.prepare(&view, &params)?;
    pb.set_message("rendering");
    let t0 = std::time::Instant::now();
    let mut img = r.render_image(&view, &params)?;
    if path_tracing.is_some() {
        trace_paths(&mut r, &view, &params, a.pt.paths(), &pb)?;
        img = r.read_image()?;
        eprintln!(
            "ferrovol: {} paths per pixel in {:.2} s",
            r.accumulated_samples(),
            t0.elapsed().as_secs_f64()
        );
    }
    let mut timing = None;
    let mut uploads = None;
    let mut stand_ins = vec![r.residency().stand_ins];
    if a.repeat > 1 {
        let before = r.stats().brick_uploads;
        let t0 = std::time::Instant::now();
        for _ in 1..a.repeat {
            view.camera.azimuth(a.orbit);
            if path_tracing.is_some() {
                r.reset_accumulation();
                trace_paths(&mut r, &view, &params, a.pt.paths(), &pb)?;
            } else {
                r.render(&view, &params, None)?;
            }
            if a.frames_in_flight == 1 {
                r.finish()?;
            } else {
                r.wait_for_previous_frame()?;
            }
            stand_ins.push(r.residency().stand_ins);
        }
        r.finish()?;
        timing = Some(t0.elapsed().as_secs_f64() * 1e3 / (a.repeat - 1) as f64);
        uploads = Some((r.stats().brick_uploads - before) as f64 / (a.repeat - 1) as f64);
        img = r.read_image()?;
    }
    ferrovol_io::image::write_png(&img, &a.out, a.background)?;
    pb.finish_and_clear();
    let src = a.input.as_ref().map_or_else(
        || format!("built-in {:?}", a.demo),
        |p| p.display().to_string(),
    );
    let res = r.residency();
    let mib = |b: u64| b as f64 / (1u64 << 20) as f64;
    println!(
        "ferrovol: rendered {src} ({}x{}x{} {}, {} of {} brick(s) resident: {:.1} MiB on the \
         device, {:.1} MiB dense) at {w}x{h} on {} -> {}",
        vol.dims[0],
        vol.dims[1],
        vol.dims[2],
        vol.scalars.scalar_type().name(),
        res.resident,
        res.bricks,
        mib(res.pool_bytes),
        mib(res.dense_bytes),
        r.context().info.name,
        a.out.display()
    );
    if res.level > 1 {
        let [x, y, z] = res.level_dims;
        println!(
            "ferrovol: the bricks this frame's rays need exceed --gpu-memory: drew a level {} \
             times coarser per axis ({x}x{y}x{z})",
            res.level
        );
    }
    let passes = r.stats().streamed_passes;
    if passes > 0 {
        println!(
            "ferrovol: the visible bricks exceed --gpu-memory: {passes} streamed pass(es) over \
             {} frame(s)",
            r.stats().frames
        );
    }
    if a.preview_level && stand_ins.iter().any(|&n| n > 0) {
        let drew = stand_ins.iter().filter(|&&n| n > 0).count();
        let complete = match stand_ins.iter().rposition(|&n| n > 0) {
            Some(k) if k + 1 < stand_ins.len() => format!("complete from frame {} on", k + 2),
            _ => "not complete by the last frame".into(),
        };
        println!(
            "ferrovol: {drew} of {} frame(s) drew a coarser level's bricks where fine ones \
             were missing (bricks read from them per frame: {stand_ins:?}); {complete}",
            stand_ins.len()
        );
    }
    if let (Some(ms), Some(uploads)) = (timing, uploads) {
        println!(
            "ferrovol: {:.1} ms/frame, {uploads:.1} bricks uploaded per frame (mean of {} \
             frames after the first, {} in flight)",
            ms,
            a.repeat - 1,
            a.frames_in_flight
        );
    }
    Ok(())
}

fn main() -> ExitCode {
    let cli = Cli::parse();
    let result = match cli.command {
        Command::Render(a) => render(*a),
        Command::Bench(a) => bench::run(a),
        Command::Info { mesh: Some(p) } => mesh::info(&p),
        Command::Info { mesh: None } => Context::new()
            .map(|c| println!("{}", c.info))
            .map_err(CliError::from),
    };
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("ferrovol: error: {e}");
            ExitCode::FAILURE
        }
    }
}
