//! The intermixed volumes on the device (params::IntermixedVolume): one r32float atlas
//! holding every volume's points, the volumes stacked along z, their transfer tables and
//! the uniforms lib/intermix.wgsl reads them with (ray casting and path tracing).

use super::tables::Tables;
use crate::error::{Error, Result};
use crate::gpu::binding::{bind, bind_view, buffer_entry, entry, texture_entry};
use crate::gpu::buffers::uniform_buffer;
use crate::gpu::slots;
use crate::gpu::texture::{block_grid, texture_2d, upload_texture};
use crate::gpu::uniforms::{mat, IntermixUniforms, PT_MAX_OPACITY, TABLE_SIZE};
use crate::gpu::Context;
use crate::params::{
    build_tables, IntermixedVolume, Interpolation, VolumeData, MAX_INTERMIXED_VOLUMES,
};
use glam::DVec3;
use std::sync::Arc;

/// The intermixed volumes as set, with their atlas and (per sample distance) tables.
pub(crate) struct Intermix {
    pub volumes: Vec<IntermixedVolume>,
    /// Every volume's points (x fastest), volume j from z = `z0[j]`.
    pub atlas: Arc<wgpu::TextureView>,
    z0: Vec<u32>,
    /// Two rows of `TABLE_SIZE` per volume (lib/common.wgsl's layout), for the sample
    /// distance they were built for (its bits).
    tables: Option<(u64, wgpu::Texture, wgpu::TextureView)>,
    pub uniforms: wgpu::Buffer,
}

/// Whether `a` and `b` hold the same data (the same shared volumes, in order).
fn same_data(a: &[IntermixedVolume], b: &[IntermixedVolume]) -> bool {
    a.len() == b.len()
        && a.iter()
            .zip(b)
            .all(|(x, y)| Arc::ptr_eq(&x.volume, &y.volume))
}

impl Intermix {
    /// Validates `volumes` and uploads them, reusing `old`'s atlas when it holds the same
    /// data. None for no volumes.
    pub fn new(
        ctx: &Context,
        old: Option<&Intermix>,
        volumes: &[IntermixedVolume],
    ) -> Result<Option<Intermix>> {
        if volumes.len() > MAX_INTERMIXED_VOLUMES {
            return Err(Error::Unsupported(format!(
                "{} intermixed volumes: at most {MAX_INTERMIXED_VOLUMES} beside the main \
                 volume",
                volumes.len()
            )));
        }
        for (i, v) in volumes.iter().enumerate() {
            v.validate(i)?;
        }
        if volumes.is_empty() {
            return Ok(None);
        }
        let uniforms = uniform_buffer(
            ctx,
            "intermix uniforms",
            std::mem::size_of::<IntermixUniforms>() as u64,
        );
        if let Some(old) = old.filter(|o| same_data(&o.volumes, volumes)) {
            return Ok(Some(Intermix {
                volumes: volumes.to_vec(),
                atlas: old.atlas.clone(),
                z0: old.z0.clone(),
                tables: None,
                uniforms,
            }));
        }
        let data: Vec<&VolumeData> = volumes.iter().map(|v| v.volume.as_ref()).collect();
        let (atlas, z0) = atlas(ctx, &data)?;
        Ok(Some(Intermix {
            volumes: volumes.to_vec(),
            atlas: Arc::new(atlas),
            z0,
            tables: None,
            uniforms,
        }))
    }

    /// The world box holding every intermixed volume's points, as (lo, hi).
    pub fn world_bounds(&self) -> (DVec3, DVec3) {
        let mut lo = DVec3::INFINITY;
        let mut hi = DVec3::NEG_INFINITY;
        for v in &self.volumes {
            let (a, b) = world_box(v.matrix * v.volume.index_to_data(), v.volume.dims);
            lo = lo.min(a);
            hi = hi.max(b);
        }
        (lo, hi)
    }

    /// Builds the tables for sample distance `step` (when it changed) and writes the
    /// uniforms with `box` the world box the rays march (the union of every volume's).
    pub fn prepare(&mut self, ctx: &Context, step: f64, bx: (DVec3, DVec3)) -> Result<()> {
        if self.tables.as_ref().map(|t| t.0) != Some(step.to_bits()) {
            let mut rows = Vec::with_capacity(self.volumes.len() * 2 * TABLE_SIZE);
            for v in &self.volumes {
                rows.extend(build_tables(v.transfer.component(0), step));
            }
            let size = [TABLE_SIZE as u32, (rows.len() / TABLE_SIZE) as u32];
            let texture = ctx.device.create_texture(&texture_2d(
                "intermix tables",
                size,
                wgpu::TextureFormat::Rgba32Float,
                wgpu::TextureUsages::TEXTURE_BINDING | wgpu::TextureUsages::COPY_DST,
            ));
            upload_texture(&ctx.queue, &texture, bytemuck::cast_slice(&rows), 16);
            let view = texture.create_view(&Default::default());
            self.tables = Some((step.to_bits(), texture, view));
        }
        let mut u = IntermixUniforms {
            box_lo: [bx.0.x as f32, bx.0.y as f32, bx.0.z as f32, 0.0],
            box_hi: [bx.1.x as f32, bx.1.y as f32, bx.1.z as f32, 0.0],
            ..bytemuck::Zeroable::zeroed()
        };
        for (j, v) in self.volumes.iter().enumerate() {
            let d = v.volume.dims;
            let world_to_index = (v.matrix * v.volume.index_to_data()).inverse();
            let [lo, hi] = v.transfer.component(0).table_range();
            let g = &mut u.volumes[j];
            g.world_to_index = mat(world_to_index);
            g.gradient_to_world = mat(world_to_index.transpose());
            g.dims = [d[0] as f32, d[1] as f32, d[2] as f32, self.z0[j] as f32];
            let nearest = v.interpolation == Interpolation::Nearest;
            g.range = [
                lo as f32,
                (1.0 / (hi - lo)) as f32,
                f32::from(u8::from(nearest)),
                (1.0 / v.transfer.component(0).unit_distance) as f32,
            ];
        }
        ctx.queue
            .write_buffer(&self.uniforms, 0, bytemuck::bytes_of(&u));
        Ok(())
    }

    /// The tables [`Intermix::prepare`] built.
    pub fn tables(&self) -> &wgpu::TextureView {
        &self.tables.as_ref().expect("tables built by prepare").2
    }

    /// The largest extinction (per world unit) the volumes' media can add up to at a
    /// point: per volume the largest its opacity function takes (σ = −ln(1 − α) / unit
    /// distance, α clamped as the path tracer clamps it; the tables are linear between
    /// entries, so their largest entry bounds them), summed.
    pub fn majorant(&self) -> f32 {
        let last = (TABLE_SIZE - 1) as f64;
        self.volumes
            .iter()
            .map(|v| {
                let c = v.transfer.component(0);
                let [lo, hi] = c.table_range();
                let alpha = (0..TABLE_SIZE)
                    .map(|i| c.opacity.eval(lo + (hi - lo) * i as f64 / last)[0] as f64)
                    .fold(0.0f64, f64::max)
                    .clamp(0.0, PT_MAX_OPACITY);
                -(1.0 - alpha).ln() / c.unit_distance
            })
            .sum::<f64>() as f32
    }
}

/// What a pass binds for the intermixed volumes (lib/intermix.wgsl, bindings 18 to 21):
/// their uniforms, atlas and tables and the atlas's sampler, or placeholders without any.
pub(crate) struct IntermixBinding {
    none: (wgpu::Buffer, wgpu::TextureView, Tables),
    /// Linear where r32float is filterable, else nearest (the shader then interpolates).
    sampler: wgpu::Sampler,
}

impl IntermixBinding {
    pub fn new(ctx: &Context) -> IntermixBinding {
        let filter = if ctx.info.float32_filterable {
            wgpu::FilterMode::Linear
        } else {
            wgpu::FilterMode::Nearest
        };
        IntermixBinding {
            none: (
                uniform_buffer(
                    ctx,
                    "no intermix",
                    std::mem::size_of::<IntermixUniforms>() as u64,
                ),
                block_grid(ctx, "no intermix", [1; 3], &[0f32]),
                Tables::new(&ctx.device, [1, 1]),
            ),
            sampler: ctx.device.create_sampler(&wgpu::SamplerDescriptor {
                label: Some("intermix atlas"),
                mag_filter: filter,
                min_filter: filter,
                ..Default::default()
            }),
        }
    }

    /// The layout entries of the four bindings.
    pub fn layout_entries(filterable: bool) -> [wgpu::BindGroupLayoutEntry; 4] {
        let sampler = if filterable {
            wgpu::SamplerBindingType::Filtering
        } else {
            wgpu::SamplerBindingType::NonFiltering
        };
        [
            buffer_entry(slots::INTERMIX, wgpu::BufferBindingType::Uniform),
            texture_entry(
                slots::INTERMIX_ATLAS,
                filterable,
                wgpu::TextureViewDimension::D3,
            ),
            texture_entry(
                slots::INTERMIX_TABLES,
                false,
                wgpu::TextureViewDimension::D2,
            ),
            entry(slots::INTERMIX_SAMPLER, wgpu::BindingType::Sampler(sampler)),
        ]
    }

    /// The bind group entries for `intermix` (prepared), or the placeholders.
    pub fn entries<'a>(&'a self, intermix: Option<&'a Intermix>) -> [wgpu::BindGroupEntry<'a>; 4] {
        let (uniforms, atlas, tables) = match intermix {
            Some(m) => (&m.uniforms, m.atlas.as_ref(), m.tables()),
            None => (&self.none.0, &self.none.1, &self.none.2.view),
        };
        [
            bind(slots::INTERMIX, uniforms.as_entire_binding()),
            bind_view(slots::INTERMIX_ATLAS, atlas),
            bind_view(slots::INTERMIX_TABLES, tables),
            bind(
                slots::INTERMIX_SAMPLER,
                wgpu::BindingResource::Sampler(&self.sampler),
            ),
        ]
    }
}

/// The world box (lo, hi) of the index box of `dims` points under `index_to_world`.
pub(crate) fn world_box(index_to_world: glam::DMat4, dims: [u32; 3]) -> (DVec3, DVec3) {
    let mut lo = DVec3::INFINITY;
    let mut hi = DVec3::NEG_INFINITY;
    for c in 0..8u32 {
        let corner = |a: usize| {
            if c & (1 << a) != 0 {
                dims[a] as f64 - 1.0
            } else {
                0.0
            }
        };
        let p = index_to_world.transform_point3(DVec3::new(corner(0), corner(1), corner(2)));
        lo = lo.min(p);
        hi = hi.max(p);
    }
    (lo, hi)
}

/// The atlas of `volumes` (r32float, as wide and high as the largest, the volumes one
/// after the other along z) and each volume's first z.
fn atlas(ctx: &Context, volumes: &[&VolumeData]) -> Result<(wgpu::TextureView, Vec<u32>)> {
    let max = ctx.info.limits.max_texture_dimension_3d;
    let w = volumes.iter().map(|v| v.dims[0]).max().unwrap_or(1);
    let h = volumes.iter().map(|v| v.dims[1]).max().unwrap_or(1);
    let depth: u64 = volumes.iter().map(|v| v.dims[2] as u64).sum();
    if w > max || h > max || depth > max as u64 {
        return Err(Error::Unsupported(format!(
            "the intermixed volumes need a {w}x{h}x{depth} texture (their points side by \
             side along z), beyond this device's {max} per axis: intermix smaller volumes"
        )));
    }
    let plane = w as usize * h as usize;
    let mut texels = vec![0f32; plane * depth as usize];
    let mut z0 = Vec::with_capacity(volumes.len());
    let mut z = 0usize;
    for v in volumes {
        z0.push(z as u32);
        let [nx, ny, nz] = v.dims.map(|d| d as usize);
        let mut row = vec![0f64; nx];
        for k in 0..nz {
            for j in 0..ny {
                v.scalars.read_run((k * ny + j) * nx, &mut row)?;
                let at = (z + k) * plane + j * w as usize;
                for (t, &x) in texels[at..at + nx].iter_mut().zip(&row) {
                    *t = x as f32;
                }
            }
        }
        z += nz;
    }
    let view = block_grid(ctx, "intermix atlas", [w, h, depth as u32], &texels);
    Ok((view, z0))
}
