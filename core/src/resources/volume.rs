//! The volume on the device: its bricks in the pool texture, the page table that maps each
//! brick to its slot, the uniforms and bind groups the passes sample it through, and the
//! min–max grid (on the CPU, and the first component's ranges on the device).

use super::bricks::{self, BrickGrid, Layout, MinMaxGrid};
use super::Resources;
use crate::error::Result;
use crate::gpu::binding::bind;
use crate::gpu::buffers::uniform_buffer;
use crate::gpu::texture::{block_grid, upload_region};
use crate::gpu::uniforms::{PoolUniforms, PAGE_SLOT_BITS};
use crate::gpu::Context;
use crate::params::{UploadOptions, VolumeData};
use glam::DMat4;

/// Computes the gradient texture of the pool from the pool texture (the gradient build
/// pass).
pub(crate) type GradientBuilder<'a> =
    dyn Fn(&Context, &wgpu::TextureView, wgpu::Extent3d, &Layout) -> Result<wgpu::Texture> + 'a;

/// Whether an upload of `v` with `opts` stores precomputed gradients: one-component volumes,
/// when asked for. Off by default: on lavapipe one rgba16float fetch costs more than the six
/// single-channel fetches it replaces, and 8-bit storage is filtered to 8-bit precision,
/// which VTK's on-the-fly gradients share (exact gradients differ from VTK's on uint8 data).
pub(crate) fn wants_gradients(v: &VolumeData, opts: &UploadOptions) -> bool {
    v.components == 1 && opts.precompute_gradients.unwrap_or(false)
}

/// Slot edge (points) of the bricks of a volume too large for one texture: 123³ cells and
/// an apron of two points, 12% more texels than the bricks' cores.
pub(crate) const SLOT_POINTS: u32 = 128;

pub(crate) struct GpuVolume {
    pub data_dims: [u32; 3],
    pub components: u32,
    pub index_to_data: DMat4,
    pub layout: Layout,
    pub grid: BrickGrid,
    _pool: wgpu::Texture,
    _gradient: Option<wgpu::Texture>,
    _page_table: wgpu::TextureView,
    _uniform: wgpu::Buffer,
    bind_linear: wgpu::BindGroup,
    bind_nearest: wgpu::BindGroup,
    pub minmax: MinMaxGrid,
    /// The first component's scalar range per min–max block, widened to bound every sample
    /// (MinMaxGrid::sample_bounds): an rg32float block grid, (min, max), that MIP and MinIP
    /// skip by (dvr.wgsl, RANGE_SKIP).
    pub ranges: wgpu::TextureView,
    /// The pool carries precomputed gradients (binding 3).
    pub gradients: bool,
}

impl GpuVolume {
    /// The volume's bind group (group 1 of every pass that samples it), read through the
    /// nearest or the linear sampler.
    pub fn bind_group(&self, nearest: bool) -> &wgpu::BindGroup {
        if nearest {
            &self.bind_nearest
        } else {
            &self.bind_linear
        }
    }

    /// The volume is one brick: the passes sample its texture directly.
    pub fn single_brick(&self) -> bool {
        self.grid.len() == 1
    }
}

impl Resources {
    /// Uploads a volume (replacing any previous one). With precomputed gradients (one
    /// component and [`UploadOptions::precompute_gradients`]), `gradients` computes the
    /// pool's gradient texture from it.
    pub fn set_volume(
        &mut self,
        ctx: &Context,
        v: &VolumeData,
        opts: UploadOptions,
        gradients: Option<&GradientBuilder<'_>>,
    ) -> Result<()> {
        v.validate()?;
        let info = &ctx.info;
        let (storage, format, texel_bytes, scale, shift) = bricks::choose_storage(v, info);
        let max_pool = info.limits.max_texture_dimension_3d;
        let max_brick = opts.max_brick_points.unwrap_or(max_pool);
        let max_bytes = opts.max_brick_bytes.unwrap_or(info.limits.max_buffer_size);
        let grid = bricks::plan_bricks(
            v.dims,
            texel_bytes,
            max_brick,
            max_pool,
            max_bytes,
            SLOT_POINTS,
        )?;
        let layout = Layout {
            storage,
            format,
            texel_bytes,
            channels: bricks::channels_for(v.components),
            scale,
            shift,
        };
        let build_gradients = gradients.filter(|_| wants_gradients(v, &opts));
        let d = &ctx.device;
        let [px, py, pz] = grid.pool_size();
        let size = wgpu::Extent3d {
            width: px,
            height: py,
            depth_or_array_layers: pz,
        };
        let mut pages = vec![0u32; grid.len()];
        let pool = ctx.checked("uploading the volume", || {
            let pool = d.create_texture(&wgpu::TextureDescriptor {
                label: Some("brick pool"),
                size,
                mip_level_count: 1,
                sample_count: 1,
                dimension: wgpu::TextureDimension::D3,
                format,
                usage: wgpu::TextureUsages::TEXTURE_BINDING | wgpu::TextureUsages::COPY_DST,
                view_formats: &[],
            });
            for (i, page) in pages.iter_mut().enumerate() {
                let slot = grid.slot_cell(i);
                let texels = bricks::brick_texels(
                    v,
                    &layout,
                    grid.slot_origin_point(grid.cell(i)),
                    grid.slot,
                );
                let origin = [0, 1, 2].map(|a| slot[a] * grid.slot[a]);
                upload_region(&ctx.queue, &pool, origin, grid.slot, &texels, texel_bytes);
                *page = slot[0] | slot[1] << PAGE_SLOT_BITS | slot[2] << (2 * PAGE_SLOT_BITS);
            }
            pool
        })?;
        let view = pool.create_view(&Default::default());
        let gradient = match build_gradients {
            Some(build) => Some(build(ctx, &view, size, &layout)?),
            None => None,
        };
        let gradient_view = gradient
            .as_ref()
            .map(|t| t.create_view(&Default::default()));
        let page_table = block_grid(ctx, "page table", grid.counts, &pages);
        let f = |v: [u32; 3]| [v[0] as f32, v[1] as f32, v[2] as f32, 0.0];
        let pu = PoolUniforms {
            brick: [grid.brick_cells as f32, grid.apron as f32, 0.0, 0.0],
            grid: [grid.counts[0], grid.counts[1], grid.counts[2], 0],
            slot: f(grid.slot),
            inv_size: [1.0 / px as f32, 1.0 / py as f32, 1.0 / pz as f32, 0.0],
        };
        let uniform = uniform_buffer(
            ctx,
            "pool uniforms",
            std::mem::size_of::<PoolUniforms>() as u64,
        );
        ctx.queue.write_buffer(&uniform, 0, bytemuck::bytes_of(&pu));
        let group = |s: &wgpu::Sampler| {
            d.create_bind_group(&wgpu::BindGroupDescriptor {
                label: Some("volume"),
                layout: &self.brick_bgl,
                entries: &[
                    bind(0, uniform.as_entire_binding()),
                    bind(1, wgpu::BindingResource::TextureView(&view)),
                    bind(2, wgpu::BindingResource::Sampler(s)),
                    bind(
                        3,
                        wgpu::BindingResource::TextureView(gradient_view.as_ref().unwrap_or(&view)),
                    ),
                    bind(4, wgpu::BindingResource::TextureView(&page_table)),
                ],
            })
        };
        let bind_linear = group(&self.linear);
        let bind_nearest = group(&self.nearest);
        let minmax = MinMaxGrid::new(v);
        let bounds = minmax.sample_bounds(0, v.components as usize, &layout);
        let ranges = block_grid(ctx, "block ranges", minmax.dims, &bounds);
        self.volume = Some(GpuVolume {
            data_dims: v.dims,
            components: v.components,
            index_to_data: v.index_to_data(),
            layout,
            grid,
            _pool: pool,
            _gradient: gradient,
            _page_table: page_table,
            _uniform: uniform,
            bind_linear,
            bind_nearest,
            minmax,
            ranges,
            gradients: build_gradients.is_some(),
        });
        self.occupancy = None;
        self.stats.volume_uploads += 1;
        Ok(())
    }
}
