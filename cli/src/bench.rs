//! `ferrovol bench`: VTK's TestGPURayCastMapperBenchmark scene (wavelet over extent
//! −127..128, 900×900, colour/opacity as VTK's test, camera azimuth +1° and elevation +1°
//! per frame), unshaded then shaded; optionally the same scene through VTK's
//! vtkGPUVolumeRayCastMapper in the same run, and the ratio. `--mesh-points N`: the same
//! wavelet on tetrahedra instead (the unstructured pass): preparation, device memory per
//! tetrahedron and frame times.

use crate::{presets, spinner, CliError};
use ferrovol_core::{synth, Context, Interpolation, RenderParams, Renderer, View};
use glam::DVec3;
use std::time::Instant;

#[derive(clap::Args)]
pub struct BenchArgs {
    #[arg(long, default_value = "900x900", value_parser = crate::parse_size)]
    size: (u32, u32),
    /// Frames timed per configuration (after two warm-up frames).
    #[arg(long, default_value_t = 20)]
    frames: u32,
    /// Half-extent of the wavelet: −N+1..N... VTK's benchmark uses 127 (−127..128, 256³).
    #[arg(long, default_value_t = 127)]
    extent: i32,
    /// Also run VTK's vtkGPUVolumeRayCastMapper on the same scene (needs a display, e.g. Xvfb).
    #[arg(long)]
    vtk: bool,
    /// Python with Debian ParaView's VTK 9.2.
    #[arg(long, default_value = "/usr/bin/python3")]
    vtk_python: String,
    /// The VTK benchmark script.
    #[arg(long, default_value = "bench/vtk_bench.py")]
    vtk_script: String,
    /// Bench this volume file instead of the wavelet (no VTK run; adds skipping on/off).
    #[arg(long)]
    input: Option<std::path::PathBuf>,
    /// Transfer-function preset or JSON for --input.
    #[arg(long, default_value = "auto")]
    tf: String,
    /// Write the last frame of each configuration to DIR/ferrovol-{unshaded,shaded}.png
    /// (a mesh's to DIR/ferrovol-mesh-{unshaded,shaded}.png).
    #[arg(long)]
    png_dir: Option<std::path::PathBuf>,
    /// Bench an unstructured mesh instead: the wavelet on N points per axis, each cube split
    /// into six tetrahedra (6 (N−1)³: 57 give 1.05 million, 120 give 10.1 million); prints
    /// the preparation and upload time, the device memory per tetrahedron, the host's peak
    /// memory and the frame times, unshaded and shaded.
    #[arg(long, value_name = "N")]
    mesh_points: Option<u32>,
}

/// The benchmark's camera motion: azimuth +1° and elevation +1° per frame.
fn advance(v: &mut View, bounds: [f64; 6]) {
    v.camera.azimuth(1.0);
    v.camera.elevation(1.0);
    v.camera.orthogonalize_view_up();
    v.camera.reset_clipping_range(bounds);
}

/// Samples a full march would take (no early termination or skipping), summed over pixels.
fn nominal_samples(view: &View, bounds: [f64; 6], step: f64) -> f64 {
    let vp_inv = view.camera.view_projection(view.aspect()).inverse();
    let lo = DVec3::new(bounds[0], bounds[2], bounds[4]);
    let hi = DVec3::new(bounds[1], bounds[3], bounds[5]);
    let mut total = 0.0;
    for y in 0..view.height {
        for x in 0..view.width {
            let nx = 2.0 * (x as f64 + 0.5) / view.width as f64 - 1.0;
            let ny = 1.0 - 2.0 * (y as f64 + 0.5) / view.height as f64;
            let a = vp_inv.project_point3(DVec3::new(nx, ny, -1.0));
            let b = vp_inv.project_point3(DVec3::new(nx, ny, 1.0));
            let d = (b - a).normalize();
            let t0 = (lo - a) / d;
            let t1 = (hi - a) / d;
            let tmin = t0.min(t1).max_element().max(0.0);
            let tmax = t0.max(t1).min_element();
            if tmax > tmin {
                total += ((tmax - tmin) / step).ceil();
            }
        }
    }
    total
}

struct Figures {
    ms_per_frame: f64,
    median_ms: f64,
    samples_per_s: f64,
}

fn time_config(
    r: &mut Renderer,
    base: &View,
    params: &RenderParams,
    frames: u32,
    bounds: [f64; 6],
) -> Result<Figures, CliError> {
    let mut view = base.clone();
    let step = r.sample_distance(params)?;
    for _ in 0..2 {
        advance(&mut view, bounds);
        r.render(&view, params, None)?;
        r.context().wait_idle()?;
    }
    let pb = indicatif::ProgressBar::new(frames as u64);
    let mut samples = 0.0;
    let mut elapsed = 0.0;
    let mut times = Vec::with_capacity(frames as usize);
    for _ in 0..frames {
        advance(&mut view, bounds);
        let t = Instant::now();
        r.render(&view, params, None)?;
        r.context().wait_idle()?;
        let dt = t.elapsed().as_secs_f64();
        elapsed += dt;
        times.push(dt);
        samples += nominal_samples(&view, bounds, step);
        pb.inc(1);
    }
    pb.finish_and_clear();
    times.sort_by(f64::total_cmp);
    Ok(Figures {
        ms_per_frame: 1e3 * elapsed / frames as f64,
        median_ms: 1e3 * times[times.len() / 2],
        samples_per_s: samples / elapsed,
    })
}

/// Runs VTK's mapper on the scene; returns (mean, median) ms/frame, unshaded then shaded.
/// `multisamples`: None keeps VTK's default window (8x multisampling on VTK 9.2, as VTK's
/// benchmark has it), Some(n) sets the window's MultiSamples.
fn run_vtk(a: &BenchArgs, multisamples: Option<u32>) -> Result<[(f64, f64); 2], CliError> {
    let mut args = vec![
        a.vtk_script.clone(),
        "--frames".into(),
        a.frames.to_string(),
        "--size".into(),
        format!("{}x{}", a.size.0, a.size.1),
        "--extent".into(),
        a.extent.to_string(),
    ];
    if let Some(n) = multisamples {
        args.extend(["--multisamples".into(), n.to_string()]);
    }
    let out = std::process::Command::new(&a.vtk_python)
        .args(&args)
        .output()
        .map_err(|e| {
            CliError::Usage(format!("cannot run {} {}: {e}", a.vtk_python, a.vtk_script))
        })?;
    let text = String::from_utf8_lossy(&out.stdout);
    if !out.status.success() {
        return Err(CliError::Usage(format!(
            "VTK benchmark failed ({}): {}{}",
            out.status,
            text,
            String::from_utf8_lossy(&out.stderr)
        )));
    }
    // (mean, median) ms of a `vtk_gpu <mode> ms_per_frame=… median_ms=…` line
    let find = |key: &str| -> Result<(f64, f64), CliError> {
        let line = text.lines().find(|l| l.starts_with(key));
        let field = |name: &str| {
            line.and_then(|l| l.split(name).nth(1))
                .and_then(|v| v.split_whitespace().next())
                .and_then(|v| v.parse::<f64>().ok())
        };
        match (field("ms_per_frame="), field("median_ms=")) {
            (Some(mean), Some(median)) => Ok((mean, median)),
            _ => Err(CliError::Usage(format!(
                "VTK benchmark printed no '{key} ms_per_frame=… median_ms=…' line:\n{text}"
            ))),
        }
    };
    for l in text.lines().filter(|l| l.starts_with('#')) {
        println!("{l}");
    }
    Ok([find("vtk_gpu unshaded")?, find("vtk_gpu shaded")?])
}

/// The host's peak resident memory in MiB (Linux: VmHWM), if it can be read.
fn peak_host_mib() -> Option<f64> {
    let status = std::fs::read_to_string("/proc/self/status").ok()?;
    let line = status.lines().find(|l| l.starts_with("VmHWM:"))?;
    let kib: f64 = line.split_whitespace().nth(1)?.parse().ok()?;
    Some(kib / 1024.0)
}

/// With --png-dir, the renderer's last frame as DIR/ferrovol-{name}.png.
fn write_frame(a: &BenchArgs, r: &Renderer, name: &str) -> Result<(), CliError> {
    if let Some(dir) = &a.png_dir {
        std::fs::create_dir_all(dir)
            .map_err(|e| CliError::Usage(format!("{}: {e}", dir.display())))?;
        ferrovol_io::image::write_png(
            &r.read_image()?,
            &dir.join(format!("ferrovol-{name}.png")),
            [0.0; 3],
        )?;
    }
    Ok(())
}

/// `--mesh-points N`: the tetrahedralised wavelet through the unstructured pass.
fn run_mesh(a: &BenchArgs, n: u32) -> Result<(), CliError> {
    if n < 2 || a.frames == 0 {
        return Err(CliError::Usage(
            "--mesh-points must be at least 2 and --frames at least 1".into(),
        ));
    }
    let pb = spinner("building the mesh");
    let t = Instant::now();
    let mesh = synth::tet_wavelet(n);
    let built = t.elapsed().as_secs_f64();
    let tets = 6 * (n as u64 - 1).pow(3);
    let bounds = mesh.bounds();
    pb.set_message("preparing and uploading");
    let mut r = Renderer::new(Context::new()?)?;
    let before = r.context().device_memory().buffer_bytes;
    let t = Instant::now();
    r.set_unstructured(&mesh)?;
    r.context().wait_idle()?;
    let uploaded = t.elapsed().as_secs_f64();
    drop(mesh);
    r.set_transfer_function(&presets::wavelet_tf())?;
    let (w, h) = a.size;
    // (read after a frame: the upload's staging copies are gone by then)
    r.render(&View::fit(bounds, w, h), &RenderParams::default(), None)?;
    r.context().wait_idle()?;
    let bytes = r
        .context()
        .device_memory()
        .buffer_bytes
        .saturating_sub(before);
    pb.finish_and_clear();
    println!(
        "# ferrovol bench: wavelet on {n}^3 points, {tets} tetrahedra, {w}x{h}, {} frames, \
         adapter {} ({})",
        a.frames,
        r.context().info.name,
        r.context().info.backend
    );
    println!(
        "mesh built_s={built:.2} prepared_and_uploaded_s={uploaded:.2} device_mib={:.1} \
         bytes_per_tet={:.1} peak_host_mib={}",
        bytes as f64 / (1 << 20) as f64,
        bytes as f64 / tets as f64,
        peak_host_mib().map_or("?".into(), |m| format!("{m:.0}"))
    );
    for shaded in [false, true] {
        let mut params = RenderParams::default();
        params.shading.enabled = shaded;
        let mut view = View::fit(bounds, w, h);
        advance(&mut view, bounds);
        r.render(&view, &params, None)?;
        r.context().wait_idle()?;
        let mut times = Vec::with_capacity(a.frames as usize);
        for _ in 0..a.frames {
            advance(&mut view, bounds);
            let t = Instant::now();
            r.render(&view, &params, None)?;
            r.context().wait_idle()?;
            times.push(t.elapsed().as_secs_f64());
        }
        let mean = times.iter().sum::<f64>() / times.len() as f64;
        times.sort_by(f64::total_cmp);
        let name = if shaded { "shaded" } else { "unshaded" };
        println!(
            "ferrovol mesh {name} ms_per_frame={:.1} median_ms={:.1}",
            1e3 * mean,
            1e3 * times[times.len() / 2]
        );
        write_frame(a, &r, &format!("mesh-{name}"))?;
    }
    Ok(())
}

pub fn run(a: BenchArgs) -> Result<(), CliError> {
    if let Some(n) = a.mesh_points {
        return run_mesh(&a, n);
    }
    if a.extent < 1 || a.frames == 0 {
        return Err(CliError::Usage(
            "--extent and --frames must be at least 1".into(),
        ));
    }
    let pb = spinner("loading the volume");
    let e = a.extent;
    let (vol, tf, name) = match &a.input {
        Some(p) => {
            let v = ferrovol_io::read_volume(p)?;
            let tf = presets::transfer_function(&a.tf, &v)?;
            (v, tf, p.display().to_string())
        }
        None => (
            synth::wavelet([-e, e + 1, -e, e + 1, -e, e + 1]),
            presets::wavelet_tf(),
            format!("wavelet {}^3 float32", 2 * e + 2),
        ),
    };
    let bounds = vol.bounds();
    pb.set_message("uploading");
    let mut r = Renderer::new(Context::new()?)?;
    r.set_volume(&vol)?;
    r.set_transfer_function(&tf)?;
    pb.finish_and_clear();
    let (w, h) = a.size;
    let view = View::fit(bounds, w, h);
    println!(
        "# ferrovol bench: {name}, {w}x{h}, {} frames, adapter {} ({})",
        a.frames,
        r.context().info.name,
        r.context().info.backend
    );
    println!("# timing: wall clock per frame (submit to GPU idle); samples = nominal ray samples without early termination");
    let mut ours = Vec::new();
    let skips: &[bool] = if a.input.is_some() {
        &[true, false]
    } else {
        &[true]
    };
    for &skip in skips {
        for shaded in [false, true] {
            // VTK's benchmark keeps vtkVolumeProperty's default nearest interpolation.
            let mut params = RenderParams {
                interpolation: Interpolation::Nearest,
                empty_space_skipping: skip,
                ..Default::default()
            };
            params.shading.enabled = shaded;
            let f = time_config(&mut r, &view, &params, a.frames, bounds)?;
            let name = if shaded { "shaded" } else { "unshaded" };
            let skip_note = if skip {
                format!(
                    "skipping=on occupied_blocks={:.3}",
                    r.occupied_fraction().unwrap_or(1.0)
                )
            } else {
                "skipping=off".to_string()
            };
            println!(
                "ferrovol {name} ms_per_frame={:.1} median_ms={:.1} samples_per_s={:.3e} {skip_note}",
                f.ms_per_frame, f.median_ms, f.samples_per_s
            );
            write_frame(&a, &r, name)?;
            ours.push((f.ms_per_frame, f.median_ms));
        }
    }
    if a.vtk {
        // VTK's benchmark window (8x multisampling), then the same without multisampling:
        // the window's own clear and resolve are part of the first, not of the second.
        let runs = [("vtk_gpu", "", None), ("vtk_gpu_msaa0", "_msaa0", Some(0))];
        for (label, suffix, ms) in runs {
            let vtk = run_vtk(&a, ms)?;
            for (i, name) in ["unshaded", "shaded"].into_iter().enumerate() {
                let (mean, median) = vtk[i];
                println!("{label} {name} ms_per_frame={mean:.1} median_ms={median:.1}");
            }
            for (i, name) in ["unshaded", "shaded"].into_iter().enumerate() {
                println!(
                    "ratio{suffix} {name} ferrovol/vtk mean={:.3} median={:.3}",
                    ours[i].0 / vtk[i].0,
                    ours[i].1 / vtk[i].1
                );
            }
        }
    }
    Ok(())
}
