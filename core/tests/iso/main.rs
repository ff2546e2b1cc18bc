//! Isosurfaces on a real wgpu device (see common/gpu.rs for what is expected of each
//! device class), by topic: surfaces (first hit with bisection, the G-buffer, nested
//! translucent layers, ambient occlusion, scattering between isosurfaces, the errors of the
//! API) and environments (irradiance, specular sampling, environment files).
//!
//! Every test prints what it measured and asserts a tolerance with the reason for it.
//! Images go to `target/test-images/iso-*.png` for inspection.

use ferrovol_core::*;

#[path = "../common/mod.rs"]
mod common;
mod environment;
mod surfaces;

/// Plain lighting for geometric tests: the headlight, VTK's default material.
fn params() -> RenderParams {
    RenderParams {
        blend: BlendMode::Isosurface,
        ..RenderParams::default()
    }
}

/// Isosurface frames shaded two-sided with these material weights (specular power 1).
fn lit(ambient: f32, diffuse: f32, specular: f32) -> RenderParams {
    RenderParams {
        blend: BlendMode::Isosurface,
        shading: Shading {
            enabled: true,
            ambient,
            diffuse,
            specular,
            specular_power: 1.0,
            two_sided: true,
            ..Shading::default()
        },
        ..RenderParams::default()
    }
}

/// Iso-values from (value, colour, opacity).
fn iso(values: &[(f64, [f32; 3], f32)]) -> IsoParams {
    IsoParams::with_values(
        values
            .iter()
            .map(|&(v, c, a)| IsoValue::new(v, c, a))
            .collect(),
    )
}

/// A sphere volume's view, zoomed 2×, with the headlight or no lights.
fn sphere_view(vol: &VolumeData, size: u32, lights: bool) -> View {
    let mut view = View::fit(vol.bounds(), size, size);
    view.camera.zoom(2.0);
    if !lights {
        view.lights.clear();
    }
    view
}
