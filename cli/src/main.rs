//! `ferrovol`: render volumes to PNG, benchmark against VTK, describe the GPU.

mod bench;
mod presets;
mod readers;

use clap::{Parser, Subcommand, ValueEnum};
use ferrovol_core::{
    synth, BlendMode, Context, GradientMethod, Interpolation, RenderParams, Renderer,
    UploadOptions, View, VolumeData,
};
use std::path::PathBuf;
use std::process::ExitCode;
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
    Render(RenderArgs),
    /// Time VTK's GPU ray cast benchmark scene (wavelet 256³, 900×900), shaded and unshaded.
    Bench(bench::BenchArgs),
    /// Print the GPU adapter, backend and limits ferrovol would use.
    Info,
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
}

#[derive(Clone, Copy, ValueEnum, PartialEq, Eq, Debug)]
enum InterpArg {
    Nearest,
    Linear,
}

#[derive(Clone, Copy, ValueEnum, PartialEq, Eq, Debug)]
enum GradArg {
    Central,
    Forward,
}

#[derive(clap::Args)]
struct RenderArgs {
    /// Volume file: .vti, .nii, .nii.gz, .mha, .mhd, .nrrd, .nhdr. Without it, a built-in volume.
    input: Option<PathBuf>,
    /// Built-in volume to render when no input file is given.
    #[arg(long, value_enum, default_value = "wavelet")]
    demo: Demo,
    /// Image size, WIDTHxHEIGHT.
    #[arg(long, default_value = "512x512", value_parser = parse_size)]
    size: (u32, u32),
    #[arg(long, value_enum, default_value = "composite")]
    mode: Mode,
    /// Phong shading from on-the-fly gradients (VTK's Shade on).
    #[arg(long)]
    shade: bool,
    /// Transfer function: a preset name (see --help-presets) or a JSON file.
    #[arg(long)]
    tf: Option<String>,
    /// Camera rotation about the view up vector, degrees (vtkCamera::Azimuth).
    #[arg(long, default_value_t = 0.0, allow_hyphen_values = true)]
    azimuth: f64,
    /// Camera rotation up/down, degrees (vtkCamera::Elevation).
    #[arg(long, default_value_t = 0.0, allow_hyphen_values = true)]
    elevation: f64,
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
    /// Background colour r,g,b in [0, 1].
    #[arg(long, default_value = "0,0,0", value_parser = parse_rgb)]
    background: [f32; 3],
    /// Split the volume into bricks of at most this many points per edge.
    #[arg(long)]
    brick: Option<u32>,
    /// Output PNG.
    #[arg(long, short, default_value = "ferrovol.png")]
    out: PathBuf,
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

/// Everything that can go wrong in the CLI, each with a message for the user.
#[derive(Debug, thiserror::Error)]
pub enum CliError {
    #[error(transparent)]
    Read(#[from] readers::ReadError),
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

fn render(a: RenderArgs) -> Result<(), CliError> {
    let pb = spinner("loading volume");
    let (vol, default_tf) = match &a.input {
        Some(p) => (readers::read_volume(p)?, "auto"),
        None => (
            demo_volume(a.demo),
            match a.demo {
                Demo::Wavelet => "wavelet",
                Demo::MarschnerLobb => "marschner-lobb",
                Demo::Sphere => "sphere",
            },
        ),
    };
    let tf = presets::transfer_function(a.tf.as_deref().unwrap_or(default_tf), &vol)?;
    pb.set_message("starting the GPU");
    let mut r = Renderer::new(Context::new()?)?;
    pb.set_message("uploading");
    r.set_volume_with(
        &vol,
        UploadOptions {
            max_brick_points: a.brick,
            max_brick_bytes: None,
        },
    )?;
    r.set_transfer_function(&tf)?;
    let (w, h) = a.size;
    let mut view = View::fit(vol.bounds(), w, h);
    view.camera.parallel = a.parallel;
    view.camera.azimuth(a.azimuth);
    view.camera.elevation(a.elevation);
    view.camera.orthogonalize_view_up();
    view.camera.zoom(a.zoom);
    view.camera.reset_clipping_range(vol.bounds());
    let mut params = RenderParams {
        blend: match a.mode {
            Mode::Composite => BlendMode::Composite,
            Mode::Mip => BlendMode::Maximum,
            Mode::Minip => BlendMode::Minimum,
            Mode::Average => BlendMode::Average,
            Mode::Additive => BlendMode::Additive,
        },
        interpolation: if a.interpolation == InterpArg::Nearest {
            Interpolation::Nearest
        } else {
            Interpolation::Linear
        },
        gradient: if a.gradient == GradArg::Forward {
            GradientMethod::Forward
        } else {
            GradientMethod::Central
        },
        sample_distance: a.sample_distance,
        jitter: a.jitter,
        empty_space_skipping: !a.no_skip,
        ..Default::default()
    };
    params.shading.enabled = a.shade;
    pb.set_message("rendering");
    let img = r.render_image(&view, &params)?;
    img.save_png(&a.out, a.background)?;
    pb.finish_and_clear();
    let src = a.input.as_ref().map_or_else(
        || format!("built-in {:?}", a.demo),
        |p| p.display().to_string(),
    );
    println!(
        "ferrovol: rendered {src} ({}x{}x{} {}, {} brick(s)) at {w}x{h} on {} -> {}",
        vol.dims[0],
        vol.dims[1],
        vol.dims[2],
        vol.scalars.scalar_type().name(),
        r.brick_count(),
        r.context().info.name,
        a.out.display()
    );
    Ok(())
}

fn main() -> ExitCode {
    let cli = Cli::parse();
    let result = match cli.command {
        Command::Render(a) => render(a),
        Command::Bench(a) => bench::run(a),
        Command::Info => Context::new()
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
