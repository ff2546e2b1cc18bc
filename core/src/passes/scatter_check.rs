//! Checks of the path tracer's sampling code on the device (shaders/phase_test.wgsl): the
//! Henyey–Greenstein phase function and the BSDF, for the tests.

use crate::error::{Error, Result};
use crate::gpu::binding::{bind, buffer_entry};
use crate::gpu::buffers::{buffer, uniform_buffer};
use crate::gpu::pipeline::{encode_single_group, single_group_pipeline};
use crate::gpu::readback::read_buffer;
use crate::gpu::uniforms::PhaseTestUniforms;
use crate::gpu::Context;
use crate::params::BsdfParams;

/// Draws `n` Henyey–Greenstein scattering directions with anisotropy `g` by the path
/// tracer's own sampling code (shaders/lib/phase.wgsl) and returns the cosine of each
/// to the propagation direction: for checking the sampler against the density.
pub(crate) fn sample_phase_cosines(ctx: &Context, g: f32, n: u32, seed: u32) -> Result<Vec<f32>> {
    if g.is_nan() || g.abs() >= 1.0 {
        return Err(Error::InvalidParameter(format!(
            "phase sampling check: anisotropy {g} must be in (−1, 1)"
        )));
    }
    let dir = glam::Vec3::new(0.3, -0.5, 0.8).normalize();
    let u = PhaseTestUniforms {
        params: [g, dir.x, dir.y, dir.z],
        counts: [n, seed, 0, 0],
        ..Default::default()
    };
    Ok(run_phase_check(ctx, &u)?.iter().map(|v| v[0]).collect())
}

/// [`crate::Renderer::sample_bsdf`]: `n` samples of `bsdf` at a surface with gradient
/// direction `normal` for a path arriving along `dir`, from random stream `seed`.
pub(crate) fn sample_bsdf(
    ctx: &Context,
    bsdf: &BsdfParams,
    [normal, dir]: [[f32; 3]; 2],
    [n, seed]: [u32; 2],
) -> Result<Vec<[f32; 3]>> {
    bsdf.validate()?;
    let unit = |v: [f32; 3]| (glam::Vec3::from(v).length() - 1.0).abs() < 1e-3;
    if !unit(normal) || !unit(dir) {
        return Err(Error::InvalidParameter(format!(
            "BSDF check: normal {normal:?} and direction {dir:?} must be unit vectors"
        )));
    }
    let u = PhaseTestUniforms {
        params: [0.0, dir[0], dir[1], dir[2]],
        bsdf: [
            bsdf.roughness,
            bsdf.fresnel,
            bsdf.transmission,
            bsdf.lobe_exponent(),
        ],
        normal: [normal[0], normal[1], normal[2], 0.0],
        counts: [n, seed, 1, 0],
    };
    Ok(run_phase_check(ctx, &u)?
        .iter()
        .map(|v| [v[0], v[1], v[2]])
        .collect())
}

/// Runs shaders/phase_test.wgsl: `u.counts[0]` samples.
/// The check's bind group (phase_test.wgsl).
pub(crate) fn layout_entries() -> [wgpu::BindGroupLayoutEntry; 2] {
    use wgpu::BufferBindingType as B;
    [
        buffer_entry(0, B::Uniform),
        buffer_entry(1, B::Storage { read_only: false }),
    ]
}

fn run_phase_check(ctx: &Context, u: &PhaseTestUniforms) -> Result<Vec<[f32; 4]>> {
    let n = u.counts[0];
    if n == 0 || n > 1 << 24 {
        return Err(Error::InvalidParameter(format!(
            "scattering check: the sample count {n} must be in 1 to 2^24"
        )));
    }
    let (bgl, pipeline) =
        single_group_pipeline(ctx, "phase_test.wgsl", "phase test", &layout_entries())?;
    let ubuf = uniform_buffer(
        ctx,
        "phase test uniforms",
        std::mem::size_of::<PhaseTestUniforms>() as u64,
    );
    ctx.queue.write_buffer(&ubuf, 0, bytemuck::bytes_of(u));
    let out = buffer(
        ctx,
        "phase test results",
        16 * n as u64,
        wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_SRC,
    );
    let mut enc = ctx.device.create_command_encoder(&Default::default());
    encode_single_group(
        ctx,
        &mut enc,
        "phase test",
        (&bgl, &pipeline),
        &[
            bind(0, ubuf.as_entire_binding()),
            bind(1, out.as_entire_binding()),
        ],
        [n.div_ceil(64), 1, 1],
    );
    ctx.checked("running the scattering check", || {
        ctx.submit([enc.finish()]);
    })?;
    let bytes = read_buffer(ctx, &out)?;
    Ok(bytemuck::cast_slice(&bytes).to_vec())
}
