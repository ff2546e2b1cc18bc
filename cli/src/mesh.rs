//! `ferrovol render mesh.vtu`: an unstructured volume (VTK XML UnstructuredGrid) drawn with
//! the same camera, blend mode and transfer-function flags as a volume.

use crate::iso::iso_setup;
use crate::presets;
use crate::{
    path_tracing_setup, render_params, spinner, trace_paths, view_of, CliError, Mode, RenderArgs,
};
use ferrovol_core::{
    tetrahedralize, vtk_cell_type_name, Context, Renderer, ScalarLocation, UnstructuredVolume,
};
use std::collections::BTreeMap;
use std::path::Path;

/// Whether a file name ends in `.vtu` (case-insensitive): a mesh, not a volume.
pub fn is_vtu(path: &Path) -> bool {
    path.extension()
        .is_some_and(|e| e.eq_ignore_ascii_case("vtu"))
}

/// The presets' unit distance for a mesh: the length of its bounds' diagonal over the cube
/// root of its cell count, a mean cell size (a volume's is its mean spacing).
fn unit_distance(m: &UnstructuredVolume) -> f64 {
    let b = m.bounds();
    let diagonal = ((b[1] - b[0]).powi(2) + (b[3] - b[2]).powi(2) + (b[5] - b[4]).powi(2)).sqrt();
    let size = diagonal / (m.num_cells() as f64).cbrt();
    if size > 0.0 {
        size
    } else {
        1.0
    }
}

/// The first component's range.
fn range(m: &UnstructuredVolume) -> [f64; 2] {
    let nc = m.components as usize;
    (0..m.scalars.len())
        .step_by(nc)
        .map(|i| m.scalars.get(i))
        .fold([f64::INFINITY, f64::NEG_INFINITY], |r, s| {
            [r[0].min(s), r[1].max(s)]
        })
}

pub fn render(a: &RenderArgs, path: &Path) -> Result<(), CliError> {
    let pb = spinner("reading the mesh");
    let m = ferrovol_io::read_unstructured(path)?;
    let tf = presets::preset(
        a.tf.as_deref().unwrap_or("auto"),
        || Ok(range(&m)),
        unit_distance(&m),
    )?;
    pb.set_message("starting the GPU");
    let mut r = Renderer::new(Context::new()?)?;
    pb.set_message("preparing the mesh");
    let t0 = std::time::Instant::now();
    r.set_unstructured(&m)?;
    r.set_transfer_function(&tf)?;
    let path_tracing = path_tracing_setup(a)?;
    if let Some((p, env)) = &path_tracing {
        r.set_path_tracing(p)?;
        r.set_environment(env)?;
    }
    if a.mode == Mode::Iso {
        let (p, env) = iso_setup(&a.iso, || Ok(range(&m)))?;
        r.set_isosurface(&p)?;
        r.set_environment(&env)?;
    }
    let mut view = view_of(a, m.bounds())?;
    if a.iso.no_lights {
        view.lights.clear();
    }
    let params = render_params(a, m.bounds());
    r.prepare(&view, &params)?;
    let prepared = t0.elapsed().as_secs_f64();
    pb.set_message("rendering");
    let mut img = r.render_image(&view, &params)?;
    if path_tracing.is_some() {
        trace_paths(&mut r, &view, &params, a.pt.paths(), &pb)?;
        img = r.read_image()?;
    }
    let mut timing = None;
    if a.repeat > 1 {
        let t0 = std::time::Instant::now();
        for _ in 1..a.repeat {
            view.camera.azimuth(a.orbit);
            if path_tracing.is_some() {
                r.reset_accumulation();
                trace_paths(&mut r, &view, &params, a.pt.paths(), &pb)?;
            } else {
                r.render(&view, &params, None)?;
            }
            r.finish()?;
        }
        timing = Some(t0.elapsed().as_secs_f64() * 1e3 / (a.repeat - 1) as f64);
        img = r.read_image()?;
    }
    ferrovol_io::image::write_png(&img, &a.out, a.background)?;
    pb.finish_and_clear();
    let (w, h) = a.size;
    println!(
        "ferrovol: rendered {} ({} points, {} cells, {} scalars) at {w}x{h} on {} -> {} \
         (prepared in {prepared:.2} s)",
        path.display(),
        m.points.len(),
        m.num_cells(),
        m.scalar_type().name(),
        r.context().info.name,
        a.out.display()
    );
    if let Some(ms) = timing {
        println!(
            "ferrovol: {ms:.1} ms/frame (mean of {} frames after the first)",
            a.repeat - 1
        );
    }
    Ok(())
}

/// `ferrovol info mesh.vtu`: the mesh as read, and the tetrahedra the renderer splits it
/// into (with the device bytes they take).
pub fn info(path: &Path) -> Result<(), CliError> {
    if !is_vtu(path) {
        return Err(CliError::Usage(format!(
            "{}: `ferrovol info` describes .vtu meshes (or, without a file, the GPU)",
            path.display()
        )));
    }
    let m = ferrovol_io::read_unstructured(path)?;
    let mut types = BTreeMap::new();
    for &t in &m.cell_types {
        *types.entry(t).or_insert(0usize) += 1;
    }
    let b = m.bounds();
    println!("{}", path.display());
    println!("points:     {}", m.points.len());
    println!("cells:      {}", m.num_cells());
    for (t, n) in types {
        println!("  {n} {}", vtk_cell_type_name(t));
    }
    println!(
        "bounds:     [{}, {}] x [{}, {}] x [{}, {}]",
        b[0], b[1], b[2], b[3], b[4], b[5]
    );
    let [lo, hi] = range(&m);
    let location = match m.location {
        ScalarLocation::Points => "point",
        ScalarLocation::Cells => "cell",
    };
    println!(
        "scalars:    {} per {location}, {} component(s); the first spans [{lo}, {hi}]",
        m.scalar_type().name(),
        m.components
    );
    let t = tetrahedralize(&m)?;
    // points 16 bytes, tetrahedra and neighbours 16 each (cell scalars 4 more)
    let cell = if m.location == ScalarLocation::Cells {
        4
    } else {
        0
    };
    let bytes = 16 * t.points.len() + (32 + cell) * t.tets.len();
    println!(
        "tetrahedra: {} ({} flat ones left out), {} points with the added centroids; \
         {:.1} MiB on the device before the boundary hierarchy",
        t.tets.len(),
        t.flat,
        t.points.len(),
        bytes as f64 / (1u64 << 20) as f64
    );
    Ok(())
}
