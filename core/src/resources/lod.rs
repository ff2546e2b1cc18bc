//! Level of detail per brick, for preview frames of ray casting
//! ([`crate::params::RenderParams::preview_level`]): when the bricks in view exceed the memory
//! budget, the bricks of a coarser level stand in, in the same pool, for the fine bricks not
//! resident, so that the frame draws in one pass with whatever fine bricks it has. Rays mark
//! in the request buffer the bricks they read, from a stand-in or not; the frame copies it
//! into a readback ring, and the next preview frame takes the newest copy the device has
//! finished (without waiting: the last frame's when it is done, else an earlier one's),
//! keeps the bricks they read and brings some of those they read from a stand-in (nearest
//! first, a share of the pool per frame), evicting the least recently used. Frames of a
//! still camera thus converge to the fine image, and the bricks no ray reaches (behind
//! opaque matter, skipped as empty) are never brought. A still frame streams instead.

use super::bricks::{BrickGrid, FrontToBack};
use super::residency::NOT_LATER;
use super::volume::{self, BrickReads, GpuVolume, Lod, Needed};
use super::Resources;
use crate::error::Result;
use crate::gpu::context::lock;
use crate::gpu::readback::ReadbackRing;
use crate::gpu::uniforms::{PAGE_EMPTY, READ_STAND_IN};
use crate::gpu::Context;
use crate::params::downsample::{coarse_points, Reduction};
use std::sync::Arc;

/// A preview frame brings at most 1/UPLOAD_SHARE of the pool's slots of fine bricks.
const UPLOAD_SHARE: u32 = 4;
/// Preview frames whose requests can be on their way back at once (a frame finding every
/// copy still in flight reads none back).
const REQUEST_COPIES: usize = 3;

impl BrickReads {
    /// Takes the newest copy the device has finished, if any (the caller polled).
    fn update(&mut self) {
        if let Some((_, bytes)) = self.ring.as_mut().and_then(ReadbackRing::take_latest) {
            self.latest = bytemuck::cast_slice(&bytes).to_vec();
        }
    }

    /// Whether the newest frame read back read fine brick `i`.
    fn read(&self, i: usize) -> bool {
        self.latest.get(i).is_some_and(|&r| r != 0)
    }
}

impl GpuVolume {
    /// Fine bricks the newest preview frame whose requests came back read from a stand-in
    /// (0: no stand-in is in the pool, or that frame drew the volume itself).
    pub fn stand_ins_read(&self) -> u32 {
        if !self.lod.as_ref().is_some_and(|l| l.active) {
            return 0;
        }
        let mut reads = lock(&self.reads);
        reads.update();
        reads.latest.iter().filter(|&&r| r == READ_STAND_IN).count() as u32
    }
}

/// Of `grid`'s bricks, the one of the level 2^`shift` times coarser (`coarse`) holding fine
/// brick `i`.
fn stand_in(grid: &BrickGrid, coarse: &BrickGrid, shift: u32, i: usize) -> usize {
    let c = grid.cell(i);
    let k: [u32; 3] = std::array::from_fn(|a| (c[a] >> shift).min(coarse.counts[a] - 1));
    k[0] as usize
        + coarse.counts[0] as usize * (k[1] as usize + coarse.counts[1] as usize * k[2] as usize)
}

/// The bricks of the level 2^`shift` times coarser than a volume of `dims` points bricked
/// as `grid`.
fn level_grid(grid: &BrickGrid, dims: [u32; 3], shift: u32) -> BrickGrid {
    let cells = dims.map(|n| coarse_points(n, 1 << shift).saturating_sub(1).max(1));
    BrickGrid {
        counts: cells.map(|c| c.div_ceil(grid.brick_cells)),
        ..*grid
    }
}

impl Resources {
    /// Before a preview frame of ray casting, its rays confined to the bricks `in_view`
    /// marks: when the bricks `needed` names there exceed the memory budget, makes resident
    /// the bricks of the finest coarser level that stand in for them within a share of the
    /// pool, and in the rest the fine bricks the last preview frame read (nearest first,
    /// bringing at most a share of the pool); the page table points each other needed brick
    /// at its stand-in. Returns whether it did; otherwise nothing changed (the frame fits
    /// or, without a host copy, is one brick).
    pub fn enter_lod(
        &mut self,
        ctx: &Context,
        needed: Needed<'_>,
        front: &FrontToBack,
        in_view: &[bool],
        reduction: Reduction,
    ) -> Result<bool> {
        self.with_flags(needed, |res, flags| {
            res.place_lod(ctx, flags, front, in_view, reduction)
        })
    }

    fn place_lod(
        &mut self,
        ctx: &Context,
        flags: Option<&[u32]>,
        front: &FrontToBack,
        in_view: &[bool],
        reduction: Reduction,
    ) -> Result<bool> {
        let vol = self.volume.as_mut().ok_or_else(super::no_volume)?;
        let Some(host) = vol.host.clone() else {
            return Ok(false);
        };
        let needed = volume::needed_bricks(vol, flags, Some(in_view));
        let count = needed.iter().filter(|&&n| n).count() as u32;
        let capacity = volume::capacity(vol);
        if count <= capacity || capacity < 2 {
            return Ok(false);
        }
        let grid = vol.grid;
        let fine = grid.len();
        // The level: the finest whose bricks standing in for every needed brick fit the
        // pool, or a coarser one where that leaves room for every needed brick the last
        // frame read beside the stand-ins of the rest (the frames can then complete).
        // (the requests of the newest preview frame the device has finished)
        ctx.poll("reading back the brick requests")?;
        let reads = vol.reads.get_mut().unwrap_or_else(|e| e.into_inner());
        reads.update();
        let read: Vec<bool> = (0..fine).map(|i| needed[i] && reads.read(i)).collect();
        let reads = read.iter().filter(|&&r| r).count() as u32;
        let stand_ins = |shift: u32, coarse: &BrickGrid, except: &[bool]| {
            let mut s: Vec<usize> = (0..fine)
                .filter(|&i| needed[i] && !except[i])
                .map(|i| stand_in(&grid, coarse, shift, i))
                .collect();
            s.sort_unstable();
            s.dedup();
            s.len() as u32
        };
        let none = vec![false; fine];
        let (mut shift, mut base) = (1, None);
        let coarse = loop {
            let coarse = level_grid(&grid, vol.data_dims, shift);
            let last = coarse.len() == 1;
            if base.is_none() && (stand_ins(shift, &coarse, &none) <= capacity || last) {
                base = Some(shift);
            }
            let complete = reads > 0 && stand_ins(shift, &coarse, &read) + reads <= capacity;
            if (base.is_some() && complete) || last {
                break match complete {
                    true => coarse,
                    false => {
                        shift = base.expect("set at the last level at least");
                        level_grid(&grid, vol.data_dims, shift)
                    }
                };
            }
            shift += 1;
        };
        if vol
            .lod
            .as_ref()
            .is_none_or(|l| (l.shift, l.reduction) != (shift, reduction))
        {
            // (the last level's stand-ins leave first, and with them the page entries)
            self.leave_lod();
            let vol = self.volume.as_mut().expect("a volume");
            let mut built = vol.lod.take().map_or_else(Vec::new, |l| l.built);
            let data = match built.iter().find(|(k, _)| *k == (shift, reduction)) {
                Some((_, data)) => data.clone(),
                None => {
                    let data = Arc::new(host.downsampled_on_lattice(1 << shift, reduction)?);
                    built.push(((shift, reduction), data.clone()));
                    data
                }
            };
            vol.lod = Some(Lod {
                shift,
                reduction,
                grid: coarse,
                host: data,
                active: false,
                built,
            });
        }
        let vol = self.volume.as_mut().expect("a volume");
        let lod = vol.lod.as_mut().expect("set above");
        if !lod.active {
            vol.slots.set_bricks(fine + coarse.len());
            lod.active = true;
        }
        // Per stand-in, the needed bricks it stands in for; then, front to back, the
        // bricks the last frame read replace their stand-ins while the pool has room (a
        // stand-in leaves when every brick it stood in for is in), at most a share of the
        // pool brought.
        let parent = |i: usize| stand_in(&grid, &coarse, shift, i);
        let mut children = vec![0u32; coarse.len()];
        for i in (0..fine).filter(|&i| needed[i]) {
            children[parent(i)] += 1;
        }
        let mut free = capacity - children.iter().filter(|&&c| c > 0).count() as u32;
        let mut uploads = (capacity / UPLOAD_SHARE).max(1);
        let mut wanted = Vec::new();
        for &b in front.order.iter().filter(|&&b| read[b]) {
            let resident = vol.slots.slot_of(b).is_some();
            if free == 0 || (!resident && uploads == 0) {
                continue;
            }
            uploads -= !resident as u32;
            free -= 1;
            wanted.push(b);
            children[parent(b)] -= 1;
            free += (children[parent(b)] == 0) as u32;
        }
        wanted.extend(
            (0..coarse.len())
                .filter(|&j| children[j] > 0)
                .map(|j| fine + j),
        );
        vol.slots.tick();
        let moves = vol
            .slots
            .place(&wanted, |_| NOT_LATER, grid.layer_slots(), capacity);
        volume::apply_moves(ctx, vol, &host, &moves, |_| false)
            .inspect_err(|_| volume::forget(vol))?;
        self.stats.brick_uploads += moves.len() as u32;
        let vol = self.volume.as_mut().expect("a volume");
        for i in (0..fine).filter(|&i| needed[i] && vol.slots.slot_of(i).is_none()) {
            if let Some(s) = vol.slots.slot_of(fine + parent(i)) {
                vol.page[i] = [volume::slot_entry(&grid, s), shift];
            }
        }
        let mut enc = ctx.device.create_command_encoder(&Default::default());
        enc.clear_buffer(&vol.requests, 0, None);
        ctx.submit([enc.finish()]);
        self.finish_residency(ctx)?;
        Ok(true)
    }

    /// After a preview frame [`Resources::enter_lod`] prepared was submitted: copies what
    /// its rays read into the readback ring, for a later preview frame to take once the
    /// device has finished it (never waiting: with every copy still in flight, this frame's
    /// is skipped).
    pub fn read_lod_requests(&mut self, ctx: &Context) -> Result<()> {
        let vol = self.volume.as_mut().ok_or_else(super::no_volume)?;
        let size = vol.requests.size();
        let reads = vol.reads.get_mut().unwrap_or_else(|e| e.into_inner());
        let ring = reads.ring.get_or_insert_with(|| {
            ReadbackRing::new(ctx, "brick requests readback", size, REQUEST_COPIES)
        });
        let Some(slot) = ring.record() else {
            return Ok(());
        };
        let mut enc = ctx.device.create_command_encoder(&Default::default());
        enc.copy_buffer_to_buffer(&vol.requests, 0, ring.buffer(slot), 0, size);
        ctx.checked("reading back the brick requests", || {
            ctx.submit([enc.finish()]);
        })?;
        ring.submitted(slot, 0);
        Ok(())
    }

    /// Before a frame that is not a preview of ray casting: the coarser level's bricks
    /// leave the pool, and the page table no longer points at them.
    pub(super) fn leave_lod(&mut self) {
        let Some(vol) = self.volume.as_mut() else {
            return;
        };
        let Some(lod) = vol.lod.as_mut().filter(|l| l.active) else {
            return;
        };
        lod.active = false;
        vol.slots.set_bricks(vol.grid.len());
        for p in vol.page.iter_mut().filter(|p| p[1] != 0) {
            *p = [PAGE_EMPTY, 0];
        }
        // (the next placement writes the page table and the bind groups again)
        vol.groups = None;
    }
}
