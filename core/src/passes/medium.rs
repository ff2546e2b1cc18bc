//! What the path tracer samples its medium and its light by (passes/pathtrace.rs): the
//! majorant of each min–max block and the environment's sampling distribution.

use crate::error::Result;
use crate::gpu::buffers::buffer;
use crate::gpu::uniforms::{PT_MAX_OPACITY, TABLE_SIZE};
use crate::gpu::Context;
use crate::params::{ComponentTransfer, CubeImage, MaskKind};
use crate::resources::Resources;

/// Texels per face edge of the cube the environment is importance-sampled on (at most).
const ENV_DIST_SIZE: u32 = 32;
/// Share of the environment's sampling probability spread uniformly over the sphere, so
/// every direction keeps some (the distribution is built from a coarse mip level).
const ENV_DIST_UNIFORM: f64 = 0.1;

/// The cumulative sampling probabilities of the texels of a cube image: luminance × solid
/// angle, mixed with a uniform share (pathtrace.wgsl: env_sample, env_pdf).
fn environment_cdf(cube: &CubeImage) -> Vec<f32> {
    let n = cube.size as usize;
    let mut weights = Vec::with_capacity(6 * n * n);
    let mut solid = Vec::with_capacity(6 * n * n);
    for face in &cube.faces {
        for (i, t) in face.iter().enumerate() {
            let sc = 2.0 * ((i % n) as f64 + 0.5) / n as f64 - 1.0;
            let tc = 2.0 * ((i / n) as f64 + 0.5) / n as f64 - 1.0;
            let q = 1.0 + sc * sc + tc * tc;
            let omega = 4.0 / (n * n) as f64 / (q * q.sqrt());
            let lum = 0.2126 * t[0] as f64 + 0.7152 * t[1] as f64 + 0.0722 * t[2] as f64;
            weights.push(lum.max(0.0) * omega);
            solid.push(omega);
        }
    }
    let total: f64 = weights.iter().sum();
    let total_solid: f64 = solid.iter().sum();
    let mut acc = 0.0;
    let mut cdf: Vec<f32> = weights
        .iter()
        .zip(&solid)
        .map(|(w, o)| {
            let lum_share = if total > 0.0 {
                w / total
            } else {
                o / total_solid
            };
            acc += (1.0 - ENV_DIST_UNIFORM) * lum_share + ENV_DIST_UNIFORM * o / total_solid;
            acc as f32
        })
        .collect();
    if let Some(last) = cdf.last_mut() {
        *last = 1.0;
    }
    cdf
}

/// The current environment's sampling distribution (pathtrace.wgsl: env_cdf): texels per
/// face edge of the cube it is built on, and the buffer of cumulative probabilities.
pub(super) fn environment_distribution(
    ctx: &Context,
    res: &Resources,
) -> Result<(u32, wgpu::Buffer)> {
    let (size, mips) = {
        let env = res.current_environment()?;
        (env.size, env.mips)
    };
    let mut level = 0;
    while level + 1 < mips && (size >> level) > ENV_DIST_SIZE {
        level += 1;
    }
    let cube = res.read_environment(ctx, level)?;
    let cdf = environment_cdf(&cube);
    let buf = buffer(
        ctx,
        "environment sampling distribution",
        (4 * cdf.len()) as u64,
        wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_DST,
    );
    ctx.queue.write_buffer(&buf, 0, bytemuck::cast_slice(&cdf));
    Ok((cube.size, buf))
}

/// The medium's majorant per min–max block: the largest extinction (per world unit) the
/// first component's transfer function gives on the table entries the block's scalar
/// range touches (the table is linear between entries, so its maximum over the range is
/// at one of them); with a 2D table, the largest over its rows of the columns the range
/// touches.
pub(super) fn block_majorants(res: &Resources) -> Result<Vec<f32>> {
    let tf = res.transfer_function()?;
    let vol = res.volume()?;
    let c = tf.component(0);
    let sigma = |alpha: f64| -(1.0 - alpha.clamp(0.0, PT_MAX_OPACITY)).ln() / c.unit_distance;
    let last = (TABLE_SIZE - 1) as f64;
    // Per table: the entry a scalar v reads, (v − lo) / (hi − lo) · scale + offset, and the
    // extinction at each entry; a label map's labels' tables too (a labelled point's medium
    // mixes its label's with the component's).
    struct Entries {
        range: [f64; 2],
        scale: f64,
        offset: f64,
        sigma: Vec<f64>,
    }
    let table = |t: &ComponentTransfer, [lo, hi]: [f64; 2]| Entries {
        range: [lo, hi],
        scale: last,
        offset: 0.0,
        sigma: (0..TABLE_SIZE)
            .map(|i| sigma(t.opacity.eval(lo + (hi - lo) * i as f64 / last)[0] as f64))
            .collect(),
    };
    let mut tables = vec![match &c.table_2d {
        // (texel centres at (i + ½) / width of the range; every row's opacity counts)
        Some(t) => Entries {
            range: t.scalar_range,
            scale: t.width as f64,
            offset: -0.5,
            sigma: (0..t.width as usize)
                .map(|x| {
                    (0..t.height as usize)
                        .map(|y| sigma(t.rgba[y * t.width as usize + x][3] as f64))
                        .fold(0.0, f64::max)
                })
                .collect(),
        },
        None => table(c, c.table_range()),
    }];
    if res.mask_kind() == Some(MaskKind::LabelMap) {
        let (range, _) = tf.label_ranges();
        for label in 1..=tf.max_label() {
            tables.push(table(&tf.label_transfer(label), range));
        }
    }
    let nc = vol.components as usize;
    Ok(vol
        .minmax
        .ranges
        .chunks(nc)
        .map(|r| {
            let [mn, mx] = r[0];
            if mn > mx {
                return 0.0;
            }
            let mut m = 0.0f64;
            for e in &tables {
                let [lo, hi] = e.range;
                let end = (e.sigma.len() - 1) as f64;
                let at = |v: f32| (v as f64 - lo) / (hi - lo) * e.scale + e.offset;
                let i0 = at(mn).floor().clamp(0.0, end) as usize;
                let i1 = at(mx).ceil().clamp(0.0, end) as usize;
                m = e.sigma[i0..=i1].iter().copied().fold(m, f64::max);
            }
            m as f32
        })
        .collect())
}
