//! Coarser levels of a bricked volume, for the frames whose rays go anywhere (path tracing,
//! volumetric shadows, ambient occlusion and scattering between isosurfaces): streaming
//! front to back cannot serve rays that leave the pixels' lines, so when the bricks such a
//! frame needs exceed the memory budget it draws the finest level, downsampled by a power of
//! two per axis, whose needed bricks fit. A level is built from the volume's host data (a
//! source is read once, slab by slab, never whole) and kept until the volume changes; only
//! one level holds a pool on the device at a time.

use super::tables::{Occupancy, TableKey};
use super::volume::{self, GpuVolume, HostVolume};
use super::Resources;
use crate::error::{Error, Result};
use crate::gpu::Context;
use crate::params::downsample::coarse_points;
use crate::params::RenderParams;
use std::sync::Arc;

/// A coarser level of the current volume, swapped with it while a frame draws it.
pub(crate) struct Level {
    /// Fine points per coarse point along each axis (a power of two).
    pub factor: u32,
    /// The level's volume; the fine volume while the level is swapped in.
    volume: Option<GpuVolume>,
    occupancy: Option<Occupancy<TableKey>>,
    /// Whether the level is the resources' volume now.
    active: bool,
}

/// The bricks a frame that draws a coarser level past the budget needs resident, at
/// whatever level it draws.
pub(crate) enum LevelDemand {
    /// Those the transfer function makes visible (path tracing, volumetric shadows).
    Visible,
    /// Those where component `component` takes one of `values` (ambient occlusion around
    /// isosurfaces), and the visible ones too where `visible` (scattering between the
    /// surfaces reads the opacity between them).
    Surfaces {
        values: Vec<f32>,
        component: u32,
        visible: bool,
    },
}

impl Resources {
    /// Before a frame that cannot stream (`what` names it in errors): leaves the volume as
    /// it is when the bricks `demand` names fit the memory budget, dropping any coarser
    /// level's pool; otherwise swaps in
    /// the finest coarser level whose needed bricks fit, building it if needed, and drops
    /// the fine level's pool. [`Resources::leave_level`] swaps back after the frame.
    pub fn enter_level(
        &mut self,
        ctx: &Context,
        params: &RenderParams,
        demand: &LevelDemand,
        what: &str,
    ) -> Result<()> {
        self.drawn_level = 1;
        if self.fits(ctx, params, demand)? {
            self.release_level();
            return Ok(());
        }
        if self.mask.is_some() || self.blanking.is_some() {
            return Err(Error::Unsupported(format!(
                "the bricks {what} needs exceed the volume's memory budget, so it would draw \
                 a coarser level of the volume, and masks and blanking are not downsampled: \
                 raise the budget or clear the mask and the blanking"
            )));
        }
        // The first level tried: the finest whose occupied share of its points fits
        // (without the bricks' aprons, so it may not; the next is tried then).
        let (needed, _) = self.demand(ctx, params, demand)?;
        let fine = self.volume()?;
        let share = needed as f64 / fine.grid.len() as f64;
        let point = fine.layout.texel_bytes as f64 + if fine.gradients { 8.0 } else { 0.0 };
        let budget = fine.max_bytes;
        let level_bytes = |f: u32| {
            let points: f64 = fine
                .data_dims
                .iter()
                .map(|&n| coarse_points(n, f) as f64)
                .product();
            points * point * share
        };
        let mut factor = 2;
        while level_bytes(factor) > budget as f64 && fine.data_dims.iter().any(|&n| n > factor) {
            factor *= 2;
        }
        let dims = fine.data_dims;
        volume::forget(self.volume.as_mut().expect("checked above"));
        loop {
            if self.level.as_ref().is_none_or(|l| l.factor < factor) {
                self.build_level(ctx, factor)?;
            }
            self.swap_level();
            if self.fits(ctx, params, demand)? {
                self.drawn_level = self.level.as_ref().expect("swapped in").factor;
                return Ok(());
            }
            self.swap_level();
            factor = self.level.as_ref().expect("built above").factor * 2;
            if dims.iter().all(|&n| n <= 2 * factor) {
                // (a level of 2 or 3 points per axis that does not fit: the budget is below
                // what bricking itself needs, which building the level reports first)
                return Err(Error::Unsupported(format!(
                    "even a level of the volume {factor}x coarser per axis exceeds its memory \
                     budget ({}): raise the budget",
                    volume::size_text(budget)
                )));
            }
        }
    }

    /// After a frame [`Resources::enter_level`] prepared: the fine volume back in place.
    pub fn leave_level(&mut self) {
        if self.level.as_ref().is_some_and(|l| l.active) {
            self.swap_level();
        }
    }

    /// Before a frame that draws the volume itself: any coarser level's pool is dropped, so
    /// that the memory budget holds.
    pub fn release_level(&mut self) {
        self.drawn_level = 1;
        if let Some(v) = self.level.as_mut().and_then(|l| l.volume.as_mut()) {
            volume::forget(v);
        }
    }

    /// Whether the bricks `demand` names at the current level fit the memory budget.
    fn fits(&mut self, ctx: &Context, params: &RenderParams, demand: &LevelDemand) -> Result<bool> {
        let (needed, capacity) = self.demand(ctx, params, demand)?;
        Ok(self.volume()?.host.is_none() || needed <= capacity)
    }

    /// The bricks `demand` names at the current level, and the slots the budget holds.
    fn demand(
        &mut self,
        ctx: &Context,
        params: &RenderParams,
        demand: &LevelDemand,
    ) -> Result<(u32, u32)> {
        let visible = match demand {
            LevelDemand::Visible => true,
            LevelDemand::Surfaces { visible, .. } => *visible,
        };
        if visible {
            let step = self.sample_distance(params)?;
            self.ensure_occupancy(ctx, step)?;
        }
        let vol = self.volume()?;
        let occupied = self.occupancy.as_ref().map(|o| &o.flags[..]);
        let flags = match demand {
            LevelDemand::Visible => occupied.map(<[u32]>::to_vec),
            LevelDemand::Surfaces {
                values, component, ..
            } => {
                let nc = vol.components as usize;
                let mut flags = vol.minmax.blocks_holding(values, *component as usize, nc);
                if let Some(occupied) = occupied.filter(|_| visible) {
                    for (f, o) in flags.iter_mut().zip(occupied) {
                        *f |= o;
                    }
                }
                Some(flags)
            }
        };
        Ok(volume::demand(vol, flags.as_deref()))
    }

    /// Builds the level `factor` times coarser than the (fine, swapped-out) volume.
    fn build_level(&mut self, ctx: &Context, factor: u32) -> Result<()> {
        let fine = self.volume()?;
        let host = fine
            .host
            .clone()
            .expect("only a bricked volume exceeds its budget");
        let opts = fine.opts;
        self.level = None;
        let data = host.downsampled(factor)?;
        let (coarse, whole) = volume::new_volume(ctx, HostVolume::Shared(Arc::new(data)), opts)?;
        self.level = Some(Level {
            factor,
            volume: Some(coarse),
            occupancy: None,
            active: false,
        });
        if let Some(texels) = whole {
            self.swap_level();
            let uploaded = self.upload_whole(ctx, &texels);
            self.swap_level();
            if uploaded.is_err() {
                self.level = None;
            }
            uploaded?;
        }
        Ok(())
    }

    /// The points per axis of the level the last frame drew, and the bytes of a coarser
    /// level's pool.
    pub fn level_residency(&self) -> ([u32; 3], u64) {
        let fine = self.volume.as_ref().map_or([0; 3], |v| v.data_dims);
        match self.level.as_ref().and_then(|l| l.volume.as_ref()) {
            Some(v) => {
                let dims = if self.drawn_level > 1 {
                    v.data_dims
                } else {
                    fine
                };
                (dims, v.residency().pool_bytes)
            }
            None => (fine, 0),
        }
    }

    /// The volume itself, also while a coarser level is swapped in for a frame (whose
    /// default sample distance stays the volume's, so the level changes the data only).
    pub(super) fn fine_volume(&self) -> Result<&GpuVolume> {
        match self.level.as_ref().filter(|l| l.active) {
            Some(l) => Ok(l
                .volume
                .as_ref()
                .expect("the fine volume while a level is in")),
            None => self.volume(),
        }
    }

    fn swap_level(&mut self) {
        let l = self.level.as_mut().expect("a level");
        std::mem::swap(&mut self.volume, &mut l.volume);
        std::mem::swap(&mut self.occupancy, &mut l.occupancy);
        l.active = !l.active;
    }
}
