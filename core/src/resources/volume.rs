//! The volume on the device: its bricks in the pool texture, the page table that maps each
//! brick to its slot (or marks it empty), the uniforms and bind groups the passes sample it
//! through, and the min–max grid. A volume that fits one texture is uploaded whole; a
//! bricked one keeps only the bricks a frame needs resident (`ensure_resident`), read from
//! the host's data when they are first needed. The min–max grid is on the CPU, and the
//! first component's ranges on the device.

use super::bricks::{self, BrickGrid, FrontToBack, Layout, MinMaxGrid};
use super::gradients::GradientPass;
use super::residency::{self, Slots, NOT_LATER};
use super::Resources;
use crate::error::{Error, Result};
use crate::gpu::binding::{bind, bind_view, sampled_texture_entry};
use crate::gpu::buffers::{buffer, uniform_buffer};
use crate::gpu::readback::ReadbackRing;
use crate::gpu::slots;
use crate::gpu::texture::{block_grid, block_grid_texture, upload_region, upload_texture};
use crate::gpu::uniforms::{PoolUniforms, PAGE_EMPTY, PAGE_MISSING, PAGE_SLOT_BITS};
use crate::gpu::Context;
use crate::params::downsample::Reduction;
use crate::params::{MaskKind, Residency, UploadOptions, VolumeData};
use glam::DMat4;
use std::sync::{Arc, Mutex};

/// A rectilinear grid's lookup's layout entry (lib/rectilinear.wgsl).
pub(crate) fn grid_lookup_layout_entry() -> wgpu::BindGroupLayoutEntry {
    sampled_texture_entry(
        slots::GRID_LOOKUP,
        wgpu::TextureSampleType::Float { filterable: false },
        wgpu::TextureViewDimension::D3,
    )
}

/// What a uniform grid binds in place of a rectilinear grid's lookup.
pub(crate) fn no_grid_lookup(ctx: &Context) -> wgpu::TextureView {
    block_grid(ctx, "no grid lookup", [2, 3, 1], &[0f32; 6])
}

/// The blanking mask's layout entry (lib/blanking.wgsl).
pub(crate) fn blanking_layout_entry() -> wgpu::BindGroupLayoutEntry {
    sampled_texture_entry(
        slots::BLANKING,
        wgpu::TextureSampleType::Uint,
        wgpu::TextureViewDimension::D3,
    )
}

/// Whether an upload of `v` with `opts` stores precomputed gradients: one-component volumes,
/// when asked for. Off by default: on lavapipe one rgba16float fetch costs more than the six
/// single-channel fetches it replaces, and 8-bit storage is filtered to 8-bit precision,
/// which VTK's on-the-fly gradients share (exact gradients differ from VTK's on uint8 data).
fn wants_gradients(v: &VolumeData, opts: &UploadOptions) -> bool {
    v.components == 1 && opts.precompute_gradients.unwrap_or(false)
}

/// Slot edge (points) of the bricks of a volume too large for one texture: 123³ cells and
/// an apron of two points, 12% more texels than the bricks' cores.
pub(crate) const SLOT_POINTS: u32 = 128;

/// The volume data as the caller hands it over: borrowed (copied where a bricked volume
/// must keep it) or shared.
pub(crate) enum HostVolume<'a> {
    Borrowed(&'a VolumeData),
    Shared(Arc<VolumeData>),
}

impl HostVolume<'_> {
    fn data(&self) -> &VolumeData {
        match self {
            HostVolume::Borrowed(v) => v,
            HostVolume::Shared(v) => v,
        }
    }

    fn into_shared(self) -> Arc<VolumeData> {
        match self {
            HostVolume::Borrowed(v) => Arc::new(v.clone()),
            HostVolume::Shared(v) => v,
        }
    }
}

/// Which bricks a frame needs resident.
#[derive(Clone, Copy)]
pub(crate) enum Needed<'a> {
    /// All of them (the projection modes read every value).
    All,
    /// Those overlapping a min–max block the transfer function makes visible (the
    /// resources' occupancy, built first).
    Occupied,
    /// Those overlapping a min–max block flagged non-zero here (the iso-values' blocks).
    Blocks(&'a [u32]),
}

pub(crate) struct GpuVolume {
    pub data_dims: [u32; 3],
    pub components: u32,
    pub index_to_data: DMat4,
    pub layout: Layout,
    pub grid: BrickGrid,
    pub minmax: MinMaxGrid,
    /// The first component's scalar range per min–max block, widened to bound every sample
    /// (MinMaxGrid::sample_bounds): an rg32float block grid, (min, max), that MIP and MinIP
    /// skip by (dvr.wgsl, RANGE_SKIP).
    pub ranges: wgpu::TextureView,
    /// The pool carries precomputed gradients (binding 3).
    pub gradients: bool,
    /// A rectilinear grid's lattice-to-index lookup (VolumeData::grid_lookup), an r32float
    /// grid of width × 3 × 1; none for a uniform grid.
    pub grid_lookup: Option<wgpu::TextureView>,
    /// Bricked volumes: the data bricks are read from when they become resident.
    pub(super) host: Option<Arc<VolumeData>>,
    /// The memory budget: most bytes of the pool (with precomputed gradients).
    pub(super) max_bytes: u64,
    /// Which brick is in which slot, and when each was last used.
    pub(super) slots: Slots,
    /// Layers of slots the pool texture has.
    pub(super) layers: u32,
    pool: Option<wgpu::Texture>,
    gradient: Option<wgpu::Texture>,
    /// Per brick, the page table's entry: x the slot (or PAGE_EMPTY / PAGE_MISSING), y the
    /// log2 factor of a coarser level's brick standing in for it (lod.rs), else 0.
    pub(super) page: Vec<[u32; 2]>,
    page_table: wgpu::Texture,
    /// Per brick, set by rays that read it from a coarser level's stand-in (binding 6).
    pub(super) requests: wgpu::Buffer,
    /// The coarser level whose bricks stand in for missing ones in preview frames.
    pub(super) lod: Option<Lod>,
    /// What preview frames' rays read, as their requests come back (lod.rs; a lock:
    /// [`GpuVolume::residency`] takes what came back).
    pub(super) reads: Mutex<BrickReads>,
    constants: wgpu::Texture,
    uniform: wgpu::Buffer,
    /// Bind groups through the linear and the nearest sampler, once the pool exists.
    pub(super) groups: Option<[wgpu::BindGroup; 2]>,
    /// What the volume was uploaded with (its coarser levels are uploaded alike).
    pub opts: UploadOptions,
}

/// What preview frames' rays read, as it comes back from the device (lod.rs).
#[derive(Default)]
pub(crate) struct BrickReads {
    /// Copies of the request buffer on their way back (made at the first preview frame).
    pub(super) ring: Option<ReadbackRing>,
    /// Per fine brick, what the rays of the newest preview frame whose copy came back read
    /// there (0: nothing; empty before any came back).
    pub(super) latest: Vec<u32>,
}

/// A coarser level of the volume whose bricks stand in for fine ones in preview frames
/// (lod.rs).
pub(crate) struct Lod {
    /// log2 of the level's factor (fine points per coarse point along each axis).
    pub shift: u32,
    /// How its points combine the fine ones (MIP and MinIP previews keep the extremes).
    pub reduction: Reduction,
    /// The level's bricks: the volume's brick size, a coarse brick over the box of
    /// factor³ fine ones.
    pub grid: BrickGrid,
    /// The level's points (coarse point i at fine point i·factor).
    pub host: Arc<VolumeData>,
    /// The level's bricks are in the slots, by ids after the volume's bricks.
    pub active: bool,
    /// The levels built so far, by shift and reduction (kept: the level a preview takes
    /// follows what its rays read, and building one reads the whole volume).
    pub built: Vec<((u32, Reduction), Arc<VolumeData>)>,
}

impl GpuVolume {
    /// The volume's bind group (group 1 of every pass that samples it), read through the
    /// nearest or the linear sampler. Passes call [`Resources::ensure_resident`] first.
    pub fn bind_group(&self, nearest: bool) -> &wgpu::BindGroup {
        let groups = self
            .groups
            .as_ref()
            .expect("ensure_resident before binding");
        &groups[nearest as usize]
    }

    /// The volume is one brick: the passes sample its texture directly.
    pub fn single_brick(&self) -> bool {
        self.grid.len() == 1
    }

    /// What is resident against what the dense volume would take.
    pub fn residency(&self) -> Residency {
        // bytes per point: the volume's texel and, with precomputed gradients, 4 halves
        let point = self.layout.texel_bytes as u64 + if self.gradients { 8 } else { 0 };
        let bytes = |n: [u32; 3]| n.iter().map(|&d| d as u64).product::<u64>() * point;
        Residency {
            bricks: self.grid.len() as u32,
            resident: (0..self.grid.len())
                .filter(|&b| self.slots.slot_of(b).is_some())
                .count() as u32,
            pool_bytes: self.pool.as_ref().map_or(0, |t| {
                let s = t.size();
                bytes([s.width, s.height, s.depth_or_array_layers])
            }),
            dense_bytes: bytes(self.data_dims),
            level: 1,
            level_dims: self.data_dims,
            stand_ins: self.stand_ins_read(),
        }
    }
}

impl Resources {
    /// Uploads a volume (replacing any previous one): whole when it fits one texture,
    /// otherwise as bricks that become resident when a frame needs them.
    pub fn set_volume(
        &mut self,
        ctx: &Context,
        host: HostVolume<'_>,
        opts: UploadOptions,
    ) -> Result<()> {
        let (volume, whole) = new_volume(ctx, host, opts)?;
        self.volume = Some(volume);
        self.mesh = None;
        self.new_volume_state();
        let uploaded = match whole {
            Some(texels) => self.upload_whole(ctx, &texels),
            None => Ok(()),
        };
        if uploaded.is_err() {
            // (no half-made volume: the next frame reports that none is set)
            self.volume = None;
        }
        uploaded
    }
}

/// A volume on the device, not yet installed: its bricks planned, its min–max grid read,
/// and, when it is one brick, the texels [`Resources::upload_whole`] uploads.
pub(super) fn new_volume(
    ctx: &Context,
    host: HostVolume<'_>,
    opts: UploadOptions,
) -> Result<(GpuVolume, Option<Vec<u8>>)> {
    let v = host.data();
    v.validate()?;
    let info = &ctx.info;
    let layout = bricks::choose_storage(v, info)?;
    let texel_bytes = layout.texel_bytes;
    let max_pool = info.limits.max_texture_dimension_3d;
    let max_brick = opts.max_brick_points.unwrap_or(max_pool);
    let max_bytes = opts
        .memory_budget
        .unwrap_or(u64::MAX)
        .min(info.limits.max_buffer_size);
    let grid = bricks::plan_bricks(
        v.dims,
        texel_bytes,
        max_brick,
        max_pool,
        max_bytes,
        SLOT_POINTS,
    )?;
    if v.coordinates.is_some() && grid.len() > 1 {
        return Err(Error::Unsupported(format!(
            "a rectilinear grid (per-axis coordinates) is rendered from one brick, and this \
                 {}x{}x{} one is bricked (larger than one texture of the device or than the \
                 memory budget): resample it to a uniform grid or raise the budget",
            v.dims[0], v.dims[1], v.dims[2]
        )));
    }
    let grid_lookup = v
        .grid_lookup(info.limits.max_texture_dimension_3d)
        .map(|(width, table)| block_grid(ctx, "grid lookup", [width, 3, 1], &table));
    let minmax = MinMaxGrid::new(v)?;
    let bounds = minmax.sample_bounds(0, v.components as usize, &layout);
    let ranges = block_grid(ctx, "block ranges", minmax.dims, &bounds);
    let gradients = wants_gradients(v, &opts);
    let nc = v.components as usize;
    // Empty bricks read as a constant that lies in their range: the lowest value of each
    // component (as a texel), transparent wherever the whole range is.
    let mut constants = vec![[0f32; 4]; grid.len()];
    for (i, c) in constants.iter_mut().enumerate() {
        let mut lo = [f32::INFINITY; 4];
        for block in grid.blocks_of(i, minmax.dims) {
            for (comp, l) in lo.iter_mut().enumerate().take(nc) {
                *l = l.min(minmax.ranges[block * nc + comp][0]);
            }
        }
        for comp in 0..nc {
            c[comp] = (lo[comp] - layout.shift[comp]) / layout.scale[comp];
        }
    }
    let page = vec![[PAGE_EMPTY, 0]; grid.len()];
    let page_table = block_grid_texture(ctx, "page table", grid.counts, &page);
    let constants = block_grid_texture(ctx, "empty bricks' values", grid.counts, &constants);
    let requests = buffer(
        ctx,
        "brick requests",
        4 * grid.len() as u64,
        wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_SRC | wgpu::BufferUsages::COPY_DST,
    );
    let uniform = uniform_buffer(
        ctx,
        "pool uniforms",
        std::mem::size_of::<PoolUniforms>() as u64,
    );
    let data_dims = v.dims;
    let components = v.components;
    let index_to_data = v.index_to_data();
    let (host, whole) = if grid.len() == 1 {
        (
            None,
            Some(bricks::brick_texels(v, &layout, [0; 3], v.dims)?),
        )
    } else {
        (Some(host.into_shared()), None)
    };
    let volume = GpuVolume {
        data_dims,
        components,
        index_to_data,
        layout,
        grid,
        minmax,
        ranges,
        gradients,
        grid_lookup,
        host,
        max_bytes,
        slots: Slots::new(grid.len()),
        layers: 0,
        pool: None,
        gradient: None,
        page,
        page_table,
        requests,
        lod: None,
        reads: Default::default(),
        constants,
        uniform,
        groups: None,
        opts,
    };
    Ok((volume, whole))
}

impl Resources {
    /// The current volume's grid of points, which `count` values (of `what`) must cover one
    /// per point.
    fn point_grid(&self, what: &str, count: usize) -> Result<[u32; 3]> {
        let d = self.volume()?.data_dims;
        let n = d.iter().map(|&x| x as usize).product::<usize>();
        if count != n {
            return Err(Error::InvalidParameter(format!(
                "the {what} has {count} values; the volume's {}x{}x{} grid needs {n}, one per \
                 point",
                d[0], d[1], d[2]
            )));
        }
        Ok(d)
    }

    /// The blanking mask of the current volume (Renderer::set_blanking).
    pub fn set_blanking(&mut self, ctx: &Context, mask: Option<&[u8]>) -> Result<()> {
        let Some(mask) = mask else {
            self.blanking = None;
            return Ok(());
        };
        let d = self.point_grid("blanking mask", mask.len())?;
        if !self.volume()?.single_brick() {
            return Err(Error::Unsupported(
                "blanking needs the volume in one brick, and this one is bricked (larger than \
                 one texture or than the memory budget)"
                    .into(),
            ));
        }
        self.blanking = Some(block_grid(ctx, "blanking", d, mask));
        Ok(())
    }

    /// The rectilinear grid's lookup's bind group entry (lib/rectilinear.wgsl), or `none`
    /// for a uniform grid.
    pub fn grid_lookup_entry<'a>(
        &'a self,
        none: &'a wgpu::TextureView,
    ) -> Result<wgpu::BindGroupEntry<'a>> {
        Ok(bind(
            slots::GRID_LOOKUP,
            wgpu::BindingResource::TextureView(self.volume()?.grid_lookup.as_ref().unwrap_or(none)),
        ))
    }

    /// The blanking mask's bind group entry (lib/blanking.wgsl), or `none` without one.
    pub fn blanking_entry<'a>(&'a self, none: &'a wgpu::TextureView) -> wgpu::BindGroupEntry<'a> {
        bind(
            slots::BLANKING,
            wgpu::BindingResource::TextureView(self.blanking.as_ref().unwrap_or(none)),
        )
    }

    /// The mask of the current volume (Renderer::set_mask): one value per point of its
    /// grid, in one texture whatever the volume's bricking.
    pub fn set_mask(&mut self, ctx: &Context, mask: Option<(&[u8], MaskKind)>) -> Result<()> {
        self.mask_generation += 1;
        let Some((values, kind)) = mask else {
            self.mask = None;
            return Ok(());
        };
        let d = self.point_grid("mask", values.len())?;
        let max = ctx.info.limits.max_texture_dimension_3d;
        if d.iter().any(|&x| x > max) {
            return Err(Error::Unsupported(format!(
                "a mask is one 3D texture, and this device's are at most {max} points along \
                 an axis: the volume's grid is {}x{}x{}",
                d[0], d[1], d[2]
            )));
        }
        let texture = ctx.checked("the mask", || block_grid(ctx, "mask", d, values))?;
        self.mask = Some((texture, kind));
        Ok(())
    }

    /// A one-brick volume: its texture (of `texels`) is the pool.
    pub(super) fn upload_whole(&mut self, ctx: &Context, texels: &[u8]) -> Result<()> {
        let vol = self.volume.as_mut().expect("set above");
        let pool = new_pool(ctx, vol, 1)?;
        upload_texture(&ctx.queue, &pool, texels, vol.layout.texel_bytes);
        vol.pool = Some(pool);
        vol.slots.place(&[0], |_| NOT_LATER, 1, 1);
        vol.page[0] = [0, 0];
        vol.layers = 1;
        self.finish_residency(ctx)
    }

    /// Makes the bricks `needed` names resident: each is read from the host's data into a
    /// free slot, the pool growing by layers of slots as it fills, or into the slot of the
    /// least recently used brick this frame does not need. Bricks stay resident across
    /// frames while the memory budget holds them, so a transfer-function change uploads only
    /// the bricks it adds and a frame needing what the last one held uploads none. A pool at
    /// least twice the layers this frame needs shrinks to one and a half times them. An
    /// error names the sizes when the bricks exceed the budget (only ray casting streams).
    pub fn ensure_resident(&mut self, ctx: &Context, needed: Needed<'_>) -> Result<()> {
        self.with_flags(needed, |res, flags| {
            res.plan_residency(ctx, flags, None).map(|_| ())
        })
    }

    /// [`Resources::ensure_resident`] for a pass that can stream, its rays confined to the
    /// bricks `in_view` marks (all without): when the bricks `needed` names exceed the memory
    /// budget, none is uploaded and the plan to stream them comes back instead, in passes
    /// the pool holds, front to back for the view `front` is of (`residency::passes`).
    pub fn plan_streaming(
        &mut self,
        ctx: &Context,
        needed: Needed<'_>,
        front: &FrontToBack,
        in_view: Option<&[bool]>,
    ) -> Result<Option<StreamPlan>> {
        self.with_flags(needed, |res, flags| {
            res.plan_residency(ctx, flags, Some((front, in_view)))
        })
    }

    /// Loads pass `g` of a streaming plan: its bricks resident (evicting first bricks this
    /// frame no longer needs, least recently used first), the plan's other bricks resident
    /// where they stayed, otherwise PAGE_MISSING (rays stop there and resume in a later
    /// pass), the rest empty.
    pub fn load_stream_group(&mut self, ctx: &Context, plan: &StreamPlan, g: usize) -> Result<()> {
        let vol = self.volume.as_mut().expect("a plan is for a volume");
        let host = vol.host.clone().expect("a plan is for a bricked volume");
        vol.slots.tick();
        let layer = vol.grid.layer_slots();
        let g32 = g as u32;
        let moves = vol.slots.place(
            &plan.groups[g],
            |b| match plan.pass_of[b] {
                p if p != NOT_LATER && p > g32 => plan.rank[b],
                _ => NOT_LATER,
            },
            layer,
            capacity(vol),
        );
        apply_moves(ctx, vol, &host, &moves, |b| plan.pass_of[b] != NOT_LATER)
            .inspect_err(|_| forget(vol))?;
        self.stats.brick_uploads += moves.len() as u32;
        self.finish_residency(ctx)
    }

    /// After group `g` of a streaming plan is submitted: counts the pass and tells the
    /// progress callback.
    pub fn streamed_pass(&mut self, plan: &StreamPlan, g: usize) {
        self.stats.streamed_passes += 1;
        if let Some(progress) = self.progress.as_mut() {
            progress(g as u32 + 1, plan.groups.len() as u32);
        }
    }

    /// Runs `f` with the block flags `needed` stands for (`None`: every brick).
    pub(super) fn with_flags<T>(
        &mut self,
        needed: Needed<'_>,
        f: impl FnOnce(&mut Resources, Option<&[u32]>) -> Result<T>,
    ) -> Result<T> {
        match needed {
            Needed::All => f(self, None),
            Needed::Blocks(flags) => f(self, Some(flags)),
            Needed::Occupied => {
                let occupancy = self.occupancy.take();
                let done = f(self, occupancy.as_ref().map(|o| &o.flags[..]));
                self.occupancy = occupancy;
                done
            }
        }
    }

    /// The bricks overlapping a block flagged in `flags` (all of them without), within the
    /// view where `stream` marks one, resident; or, past the budget with a streaming view
    /// (its front-to-back order), the plan to stream them.
    fn plan_residency(
        &mut self,
        ctx: &Context,
        flags: Option<&[u32]>,
        stream: Option<(&FrontToBack, Option<&[bool]>)>,
    ) -> Result<Option<StreamPlan>> {
        self.leave_lod();
        let vol = self.volume.as_mut().ok_or_else(super::no_volume)?;
        let Some(host) = vol.host.clone() else {
            return Ok(None);
        };
        let needed = needed_bricks(vol, flags, stream.and_then(|(_, in_view)| in_view));
        let count = needed.iter().filter(|&&n| n).count() as u32;
        let capacity = capacity(vol);
        if capacity == 0 {
            return Err(over_budget(vol, count));
        }
        let layer = vol.grid.layer_slots();
        if count > capacity {
            let Some((front, _)) = stream else {
                return Err(over_budget(vol, count));
            };
            let groups = residency::passes(
                &front.order,
                front,
                &needed,
                capacity,
                vol.slots.clone(),
                layer,
            );
            let mut pass_of = vec![NOT_LATER; needed.len()];
            for (p, group) in groups.iter().enumerate() {
                for &b in group {
                    pass_of[b] = p as u32;
                }
            }
            let mut rank = vec![0; needed.len()];
            for (r, &b) in front.order.iter().enumerate() {
                rank[b] = r as u32;
            }
            return Ok(Some(StreamPlan {
                groups,
                pass_of,
                rank,
            }));
        }
        vol.slots.tick();
        let need_layers = count.div_ceil(layer).max(1);
        if vol.layers >= 2 * need_layers {
            shrink(ctx, vol, (3 * need_layers).div_ceil(2), &needed);
        }
        let wanted: Vec<usize> = (0..needed.len()).filter(|&i| needed[i]).collect();
        let moves = vol.slots.place(&wanted, |_| NOT_LATER, layer, capacity);
        let pages_before = vol.page.clone();
        apply_moves(ctx, vol, &host, &moves, |_| false).inspect_err(|_| forget(vol))?;
        self.stats.brick_uploads += moves.len() as u32;
        if moves.is_empty() && vol.page == pages_before && vol.groups.is_some() {
            return Ok(None);
        }
        self.finish_residency(ctx)?;
        Ok(None)
    }

    /// After the pool changed: the page table, the pool's gradients, uniforms and bind
    /// groups.
    pub(super) fn finish_residency(&mut self, ctx: &Context) -> Result<()> {
        let vol = self.volume.as_mut().expect("a volume");
        upload_texture(
            &ctx.queue,
            &vol.page_table,
            bytemuck::cast_slice(&vol.page),
            8,
        );
        let pool = vol.pool.as_ref().expect("a pool");
        let view = pool.create_view(&Default::default());
        if vol.gradients {
            let pass = match self.gradient_pass.take() {
                Some(p) => p,
                None => GradientPass::new(ctx)?,
            };
            vol.gradient = Some(pass.build(ctx, &view, pool.size(), &vol.layout)?);
            self.gradient_pass = Some(pass);
        }
        let s = pool.size();
        let g = &vol.grid;
        let pu = PoolUniforms {
            brick: [
                g.brick_cells as f32,
                g.apron as f32,
                vol.lod.as_ref().is_some_and(|l| l.active) as u32 as f32,
                0.0,
            ],
            grid: [g.counts[0], g.counts[1], g.counts[2], 0],
            slot: [g.slot[0] as f32, g.slot[1] as f32, g.slot[2] as f32, 0.0],
            inv_size: [
                1.0 / s.width as f32,
                1.0 / s.height as f32,
                1.0 / s.depth_or_array_layers as f32,
                0.0,
            ],
        };
        ctx.queue
            .write_buffer(&vol.uniform, 0, bytemuck::bytes_of(&pu));
        let gradient_view = vol
            .gradient
            .as_ref()
            .map(|t| t.create_view(&Default::default()));
        let page_view = vol.page_table.create_view(&Default::default());
        let constants_view = vol.constants.create_view(&Default::default());
        let group = |s: &wgpu::Sampler| {
            ctx.device.create_bind_group(&wgpu::BindGroupDescriptor {
                label: Some("volume"),
                layout: &self.brick_bgl,
                entries: &[
                    bind(slots::POOL, vol.uniform.as_entire_binding()),
                    bind_view(slots::VOLUME, &view),
                    bind(slots::VOLUME_SAMPLER, wgpu::BindingResource::Sampler(s)),
                    bind(
                        slots::GRADIENTS,
                        wgpu::BindingResource::TextureView(gradient_view.as_ref().unwrap_or(&view)),
                    ),
                    bind_view(slots::PAGE_TABLE, &page_view),
                    bind_view(slots::BRICK_CONSTANTS, &constants_view),
                    bind(slots::BRICK_REQUESTS, vol.requests.as_entire_binding()),
                ],
            })
        };
        vol.groups = Some([group(&self.linear), group(&self.nearest)]);
        Ok(())
    }
}

/// A pool texture of `layers` layers of slots for `vol` (within its budget: the plan and
/// `capacity` see to that).
fn new_pool(ctx: &Context, vol: &GpuVolume, layers: u32) -> Result<wgpu::Texture> {
    let [w, h, d] = vol.grid.pool_size(layers);
    let descriptor = wgpu::TextureDescriptor {
        label: Some("brick pool"),
        size: wgpu::Extent3d {
            width: w,
            height: h,
            depth_or_array_layers: d,
        },
        mip_level_count: 1,
        sample_count: 1,
        dimension: wgpu::TextureDimension::D3,
        format: vol.layout.format,
        usage: wgpu::TextureUsages::TEXTURE_BINDING
            | wgpu::TextureUsages::COPY_DST
            | wgpu::TextureUsages::COPY_SRC,
        view_formats: &[],
    };
    ctx.checked("allocating the brick pool", || {
        ctx.device.create_texture(&descriptor)
    })
}

/// Streaming a frame: front to back, the passes of bricks the pool holds, one dispatch
/// each (`residency::passes`).
pub(crate) struct StreamPlan {
    pub groups: Vec<Vec<usize>>,
    /// Per brick: the pass it is needed in ([`NOT_LATER`]: none).
    pass_of: Vec<u32>,
    /// Per brick: its place in the front-to-back order.
    rank: Vec<u32>,
}

/// Per brick: whether it overlaps a block flagged in `flags` (all bricks without) and,
/// where `in_view` is given, is marked there.
pub(super) fn needed_bricks(
    vol: &GpuVolume,
    flags: Option<&[u32]>,
    in_view: Option<&[bool]>,
) -> Vec<bool> {
    let grid = vol.grid;
    let bd = vol.minmax.dims;
    (0..grid.len())
        .map(|i| {
            in_view.is_none_or(|v| v[i])
                && match flags {
                    None => true,
                    Some(flags) => grid.blocks_of(i, bd).any(|b| flags[b] != 0),
                }
        })
        .collect()
}

/// The bricks overlapping a block `flags` marks (all bricks without), and the slots the
/// memory budget holds.
pub(super) fn demand(vol: &GpuVolume, flags: Option<&[u32]>) -> (u32, u32) {
    let count = needed_bricks(vol, flags, None)
        .iter()
        .filter(|&&n| n)
        .count() as u32;
    (count, capacity(vol))
}

/// Bytes of one slot: its points, with any precomputed gradients.
pub(super) fn slot_bytes(vol: &GpuVolume) -> u64 {
    let point = vol.layout.texel_bytes as u64 + if vol.gradients { 8 } else { 0 };
    vol.grid.slot.iter().map(|&d| d as u64).product::<u64>() * point
}

/// Slots the memory budget holds: whole layers, at most the 3D texture limit's.
pub(super) fn capacity(vol: &GpuVolume) -> u32 {
    let layer = vol.grid.layer_slots() as u64 * slot_bytes(vol);
    let layers = (vol.max_bytes / layer).min(vol.grid.slots[2] as u64) as u32;
    layers * vol.grid.layer_slots()
}

fn over_budget(vol: &GpuVolume, count: u32) -> Error {
    let each = slot_bytes(vol);
    Error::Unsupported(format!(
        "this frame needs {count} bricks of {}³ points ({}) but the volume's memory budget \
         ({}) holds {}: raise the budget, or draw it by ray casting, which streams bricks",
        vol.grid.slot[0],
        size_text(count as u64 * each),
        size_text(vol.max_bytes),
        capacity(vol),
    ))
}

/// Bytes as MiB below a GiB, GiB above.
pub(super) fn size_text(bytes: u64) -> String {
    let mib = bytes as f64 / (1u64 << 20) as f64;
    if mib < 1024.0 {
        format!("{mib:.1} MiB")
    } else {
        format!("{:.2} GiB", mib / 1024.0)
    }
}

/// No brick resident and no pool (after a failed upload: the next frame starts again).
pub(super) fn forget(vol: &mut GpuVolume) {
    vol.slots = Slots::new(vol.grid.len());
    vol.page.fill([PAGE_EMPTY, 0]);
    if let Some(lod) = vol.lod.as_mut() {
        lod.active = false;
    }
    vol.pool = None;
    vol.layers = 0;
    vol.groups = None;
}

/// The page-table entry of a brick in slot `s`.
pub(super) fn slot_entry(grid: &BrickGrid, s: u32) -> u32 {
    let [sx, sy, sz] = slot_position(grid, s);
    sx | sy << PAGE_SLOT_BITS | sz << (2 * PAGE_SLOT_BITS)
}

/// Where slot `s` lies in the pool, in slots per axis.
fn slot_position(grid: &BrickGrid, s: u32) -> [u32; 3] {
    [
        s % grid.slots[0],
        s / grid.slots[0] % grid.slots[1],
        s / grid.layer_slots(),
    ]
}

/// Shrinks the pool to `layers` layers of slots, keeping the bricks `needed` names first,
/// then the most recently used (copied on the device, not read again).
fn shrink(ctx: &Context, vol: &mut GpuVolume, layers: u32, needed: &[bool]) {
    let grid = vol.grid;
    let moves = vol.slots.shrink(layers * grid.layer_slots(), needed);
    let (Some(old), Ok(pool)) = (vol.pool.as_ref(), new_pool(ctx, vol, layers)) else {
        // (no pool yet, or none allocated: the next upload starts from an empty one)
        forget(vol);
        return;
    };
    let mut enc = ctx.device.create_command_encoder(&Default::default());
    let corner = |s: u32| {
        let p = slot_position(&grid, s);
        wgpu::Origin3d {
            x: p[0] * grid.slot[0],
            y: p[1] * grid.slot[1],
            z: p[2] * grid.slot[2],
        }
    };
    for &(from, to) in &moves {
        enc.copy_texture_to_texture(
            wgpu::TexelCopyTextureInfo {
                origin: corner(from),
                ..old.as_image_copy()
            },
            wgpu::TexelCopyTextureInfo {
                origin: corner(to),
                ..pool.as_image_copy()
            },
            wgpu::Extent3d {
                width: grid.slot[0],
                height: grid.slot[1],
                depth_or_array_layers: grid.slot[2],
            },
        );
    }
    ctx.submit([enc.finish()]);
    vol.pool = Some(pool);
    vol.layers = layers;
    // (the page table follows in apply_moves)
    vol.groups = None;
}

/// Applies a placement: the pool grown to the slots allocated (the old pool copied), the
/// bricks `moves` names read from `host` into their slots, and the page table: resident
/// bricks at their slots, bricks `missing` marks PAGE_MISSING, the rest empty.
pub(super) fn apply_moves(
    ctx: &Context,
    vol: &mut GpuVolume,
    host: &VolumeData,
    moves: &[(usize, u32)],
    missing: impl Fn(usize) -> bool,
) -> Result<()> {
    let grid = vol.grid;
    let layers = vol.slots.allocated().div_ceil(grid.layer_slots()).max(1);
    if layers > vol.layers {
        let pool = new_pool(ctx, vol, layers)?;
        if let Some(old) = vol.pool.as_ref() {
            let mut enc = ctx.device.create_command_encoder(&Default::default());
            enc.copy_texture_to_texture(old.as_image_copy(), pool.as_image_copy(), old.size());
            ctx.submit([enc.finish()]);
        }
        vol.pool = Some(pool);
        vol.layers = layers;
        vol.groups = None;
    }
    let pool = vol.pool.as_ref().expect("allocated above");
    for &(i, slot) in moves {
        // (ids past the volume's bricks are a coarser level's, lod.rs)
        let (data, g, j) = match vol.lod.as_ref() {
            Some(l) if i >= grid.len() => (&*l.host, &l.grid, i - grid.len()),
            _ => (host, &grid, i),
        };
        let texels =
            bricks::brick_texels(data, &vol.layout, g.slot_origin_point(g.cell(j)), g.slot)?;
        let p = slot_position(&grid, slot);
        let origin = [
            p[0] * grid.slot[0],
            p[1] * grid.slot[1],
            p[2] * grid.slot[2],
        ];
        upload_region(
            &ctx.queue,
            pool,
            origin,
            grid.slot,
            &texels,
            vol.layout.texel_bytes,
        );
    }
    for (i, page) in vol.page.iter_mut().enumerate() {
        *page = match vol.slots.slot_of(i) {
            Some(s) => [slot_entry(&grid, s), 0],
            None if missing(i) => [PAGE_MISSING, 0],
            None => [PAGE_EMPTY, 0],
        };
    }
    Ok(())
}
