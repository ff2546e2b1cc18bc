//! The transfer-function tables and the occupancy of the min–max blocks they give.

use super::bricks::BLOCK_SIZE;
use super::Resources;
use crate::error::{Error, Result};
use crate::gpu::binding::{bind_view, texture_entry};
use crate::gpu::slots;
use crate::gpu::texture::{block_grid, texture_2d, upload_texture};
use crate::gpu::uniforms::TABLE_SIZE;
use crate::gpu::Context;
use crate::params::{
    build_preintegration, build_tables, build_tables_over, TransferFunction,
    ADAPTIVE_STEP_TOLERANCE,
};

/// The pre-integration tables' texel format.
pub(crate) const PREINTEGRATION_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rgba16Float;

/// Everything that decides the tables' contents; tables are rebuilt only when it changes.
#[derive(PartialEq)]
pub(crate) struct TableKey {
    tf: TransferFunction,
    step_bits: u64,
}

impl TableKey {
    fn new(tf: &TransferFunction, step: f64) -> TableKey {
        TableKey {
            tf: tf.clone(),
            step_bits: step.to_bits(),
        }
    }
}

/// The transfer-function tables as the shaders read them (lib/common.wgsl): one row of
/// `TABLE_SIZE` texels per table, two tables per component. A texture, not a storage
/// buffer: lavapipe reads a storage buffer at per-lane indices one lane at a time, a
/// texture with one gather.
pub(crate) struct Tables {
    texture: wgpu::Texture,
    pub view: wgpu::TextureView,
}

impl Tables {
    /// Tables of `size` texels: `TABLE_SIZE` × two rows per component.
    pub fn new(d: &wgpu::Device, size: [u32; 2]) -> Tables {
        Tables::with_format(d, size, wgpu::TextureFormat::Rgba32Float)
    }

    /// Tables of `size` texels of `format`.
    pub fn with_format(d: &wgpu::Device, size: [u32; 2], format: wgpu::TextureFormat) -> Tables {
        let texture = d.create_texture(&texture_2d(
            "transfer tables",
            size,
            format,
            wgpu::TextureUsages::TEXTURE_BINDING | wgpu::TextureUsages::COPY_DST,
        ));
        let view = texture.create_view(&Default::default());
        Tables { texture, view }
    }
}

/// Which min–max blocks hold something to draw (non-zero) and which can be skipped (0), as
/// the passes read it (lib/march.wgsl), for the contents `key` names. On the GPU an empty
/// block also holds how far the empty space around it reaches ([`leap_texels`]).
pub(crate) struct Occupancy<K> {
    pub key: K,
    pub grid: wgpu::TextureView,
    /// The same flags on the CPU, one per block.
    pub flags: Vec<u32>,
    /// The fraction of blocks occupied.
    pub fraction: f64,
    /// The share of an occupied block's samples adaptive rays save on average (from the
    /// step multipliers the ray-casting occupancy holds).
    pub saving: f64,
}

impl<K: PartialEq> Occupancy<K> {
    /// Whether `slot` already holds the occupancy for `key`.
    pub fn current(slot: &Option<Occupancy<K>>, key: &K) -> bool {
        slot.as_ref().is_some_and(|o| o.key == *key)
    }

    pub fn new(ctx: &Context, label: &str, key: K, dims: [u32; 3], occ: &[u32]) -> Self {
        let grid = block_grid(ctx, label, dims, &leap_texels(dims, occ));
        let occupied = occ.iter().filter(|&&o| o != 0).count();
        let fraction = occupied as f64 / occ.len().max(1) as f64;
        let saved: f64 = occ
            .iter()
            .filter(|&&m| m > 1)
            .map(|&m| 1.0 - 1.0 / m as f64)
            .sum();
        let saving = saved / occupied.max(1) as f64;
        Occupancy {
            key,
            grid,
            flags: occ.to_vec(),
            fraction,
            saving,
        }
    }
}

/// The farthest an empty block's leap reaches, in blocks ([`empty_distances`]' value where
/// no block is occupied).
const LEAP_MAX: u32 = (1 << 24) - 1;

/// The occupancy grid's texels: an occupied block's value as it is (1 to 255), an empty
/// block's [`empty_distances`] in bits 8–31 (lib/march.wgsl, `leap_exit`).
fn leap_texels(dims: [u32; 3], occ: &[u32]) -> Vec<u32> {
    let occupied: Vec<bool> = occ.iter().map(|&o| o != 0).collect();
    occ.iter()
        .zip(empty_distances(dims, &occupied))
        .map(|(&o, d)| if d == 0 { o } else { d << 8 })
        .collect()
}

/// Per block of a grid of `dims` blocks: 0 where `occupied`, else the Chebyshev distance in
/// blocks to the nearest occupied block (at most [`LEAP_MAX`], which it is when none is),
/// so that every block less than that distance away along each axis is empty and a ray can
/// leap out of the whole cube of them. Two raster passes over the 26 neighbours with unit
/// weights, exact for the Chebyshev metric.
pub(crate) fn empty_distances(dims: [u32; 3], occupied: &[bool]) -> Vec<u32> {
    let [nx, ny, nz] = dims.map(|d| d as i64);
    let index = |x: i64, y: i64, z: i64| ((z * ny + y) * nx + x) as usize;
    let mut dist: Vec<u32> = occupied
        .iter()
        .map(|&o| if o { 0 } else { LEAP_MAX })
        .collect();
    // the neighbours before a block in raster order (z, then y, then x); the passes go
    // forwards with these offsets and backwards with their negatives
    let before: Vec<[i64; 3]> = (-1..=1)
        .flat_map(|z| (-1..=1).flat_map(move |y| (-1..=1).map(move |x| [x, y, z])))
        .filter(|&[x, y, z]| z < 0 || (z == 0 && (y < 0 || (y == 0 && x < 0))))
        .collect();
    for sign in [1i64, -1] {
        for zi in 0..nz {
            for yi in 0..ny {
                for xi in 0..nx {
                    let [x, y, z] = if sign > 0 {
                        [xi, yi, zi]
                    } else {
                        [nx - 1 - xi, ny - 1 - yi, nz - 1 - zi]
                    };
                    let here = index(x, y, z);
                    if dist[here] == 0 {
                        continue;
                    }
                    let mut d = dist[here];
                    for &[ox, oy, oz] in &before {
                        let [qx, qy, qz] = [x + sign * ox, y + sign * oy, z + sign * oz];
                        if (0..nx).contains(&qx) && (0..ny).contains(&qy) && (0..nz).contains(&qz) {
                            d = d.min(dist[index(qx, qy, qz)].saturating_add(1));
                        }
                    }
                    dist[here] = d.min(LEAP_MAX);
                }
            }
        }
    }
    dist
}

/// Keeps in `slot` the tables `build` makes of the transfer function of `key` (rows of
/// `TABLE_SIZE` texels of `format`): rebuilt only when the key changed, in the same texture
/// when its size is the same. Whether it rebuilt them.
fn ensure_rows<T: bytemuck::Pod>(
    ctx: &Context,
    slot: &mut Option<(TableKey, Tables)>,
    key: TableKey,
    format: wgpu::TextureFormat,
    build: impl Fn(&TransferFunction) -> Vec<T>,
) -> bool {
    if slot.as_ref().is_some_and(|(k, _)| *k == key) {
        return false;
    }
    let data = build(&key.tf);
    let size = [TABLE_SIZE as u32, (data.len() / TABLE_SIZE) as u32];
    let tables = match slot.take() {
        Some((_, t)) if [t.texture.width(), t.texture.height()] == size => t,
        _ => Tables::with_format(&ctx.device, size, format),
    };
    let texel = std::mem::size_of::<T>() as u32;
    upload_texture(
        &ctx.queue,
        &tables.texture,
        bytemuck::cast_slice(&data),
        texel,
    );
    *slot = Some((key, tables));
    true
}

/// The lookup tables of every component (two rows each, `build_tables`), then those of
/// labels 1 to the highest with functions of its own, over the labels' shared ranges (the
/// frame's `labels` uniform).
fn table_rows(tf: &TransferFunction, comps: usize, step: f64) -> Vec<[f32; 4]> {
    let mut data = Vec::with_capacity((comps + tf.max_label() as usize) * 2 * TABLE_SIZE);
    for c in 0..comps {
        data.extend(build_tables(tf.component(c), step));
    }
    let (range, gradient_range) = tf.label_ranges();
    for label in 1..=tf.max_label() {
        let t = tf.label_transfer(label);
        data.extend(build_tables_over(&t, step, range, gradient_range));
    }
    data
}

/// The 2D tables of every component (params::Table2D), each resampled (nearest texel) to the
/// largest width and height among them and stacked by component, opacity corrected for the
/// step as the 1D tables are; a component without one is zeros. (rgba, [width, height]).
fn table_2d_rows(tf: &TransferFunction, comps: usize) -> (Vec<[f32; 4]>, [u32; 2]) {
    let tables: Vec<_> = (0..comps)
        .map(|c| tf.component(c).table_2d.as_ref())
        .collect();
    let w = tables.iter().flatten().map(|t| t.width).max().unwrap_or(1);
    let h = tables.iter().flatten().map(|t| t.height).max().unwrap_or(1);
    let mut data = Vec::with_capacity(comps * (w * h) as usize);
    for t in &tables {
        for y in 0..h {
            for x in 0..w {
                data.push(match t {
                    Some(t) => {
                        let sx = ((x as u64 * 2 + 1) * t.width as u64 / (2 * w as u64)) as usize;
                        let sy = ((y as u64 * 2 + 1) * t.height as u64 / (2 * h as u64)) as usize;
                        t.rgba[sy * t.width as usize + sx]
                    }
                    None => [0.0; 4],
                });
            }
        }
    }
    (data, [w, h * comps as u32])
}

/// The 2D tables' layout entry (lib/table2d.wgsl).
pub(crate) fn tables_2d_layout_entry() -> wgpu::BindGroupLayoutEntry {
    texture_entry(slots::TABLES_2D, false, wgpu::TextureViewDimension::D2)
}

impl Resources {
    /// The 2D tables' bind group entry: the tables [`Resources::ensure_tables_2d`] built
    /// when `used`, else `none`.
    pub fn tables_2d_entry<'a>(&'a self, used: bool, none: &'a Tables) -> wgpu::BindGroupEntry<'a> {
        let view = match &self.tables_2d {
            Some((_, t)) if used => &t.view,
            _ => &none.view,
        };
        bind_view(slots::TABLES_2D, view)
    }

    /// Builds the 2D tables for the transfer function, unless they are current (a transfer
    /// function without 2D tables needs none). Their opacities are per sample, whatever the
    /// sample distance, as VTK 9.2 uploads its 2D table.
    pub fn ensure_tables_2d(&mut self, ctx: &Context) -> Result<()> {
        let key = TableKey::new(self.transfer_function()?, 0.0);
        if self.tables_2d.as_ref().is_some_and(|(k, _)| *k == key) {
            return Ok(());
        }
        let comps = self.volume.as_ref().map_or(1, |v| v.components) as usize;
        let (data, size) = table_2d_rows(&key.tf, comps);
        let tables = Tables::with_format(&ctx.device, size, wgpu::TextureFormat::Rgba32Float);
        upload_texture(&ctx.queue, &tables.texture, bytemuck::cast_slice(&data), 16);
        self.tables_2d = Some((key, tables));
        Ok(())
    }

    /// Builds the tables for the transfer function at sample distance `step`, unless they are
    /// current.
    pub fn ensure_tables(&mut self, ctx: &Context, step: f64) -> Result<()> {
        let key = TableKey::new(self.transfer_function()?, step);
        let comps = self.volume.as_ref().map_or(1, |v| v.components) as usize;
        let format = wgpu::TextureFormat::Rgba32Float;
        if ensure_rows(ctx, &mut self.tables, key, format, |tf| {
            table_rows(tf, comps, step)
        }) {
            self.stats.table_uploads += 1;
        }
        Ok(())
    }

    /// Builds the pre-integration tables (one `TABLE_SIZE`² block of rows per component,
    /// front sample's entry by row, back sample's by column; params::transfer's
    /// build_preintegration) for the transfer function at sample distance `step`, unless
    /// they are current. Half floats, filterable: the shader reads them with one bilinear
    /// fetch (the volume's sampler) where four loads of 32-bit floats would take longer on
    /// lavapipe; their 11-bit precision is below the 8-bit output's.
    pub fn ensure_preintegration(&mut self, ctx: &Context, step: f64) -> Result<()> {
        let key = TableKey::new(self.transfer_function()?, step);
        let comps = self.volume.as_ref().map_or(1, |v| v.components) as usize;
        let half = |tf: &TransferFunction| -> Vec<[half::f16; 4]> {
            (0..comps)
                .flat_map(|c| build_preintegration(tf.component(c), step))
                .map(|e| e.map(half::f16::from_f32))
                .collect()
        };
        let format = PREINTEGRATION_FORMAT;
        if ensure_rows(ctx, &mut self.preintegration, key, format, half) {
            self.stats.preintegration_builds += 1;
        }
        Ok(())
    }

    /// Classifies the min–max grid against the transfer function: 0 for blocks where no
    /// value in the block's range has non-zero opacity, else the step multiplier an
    /// adaptive ray may take there: 1, 2 or 4 sample distances, as many as keep the change
    /// of the classified function per step within [`crate::ADAPTIVE_STEP_TOLERANCE`].
    pub fn ensure_occupancy(&mut self, ctx: &Context, step: f64) -> Result<()> {
        let (Some(tf), Some(vol)) = (self.tf.as_ref(), self.volume.as_ref()) else {
            return Err(Error::InvalidParameter(
                "a volume and a transfer function are needed".into(),
            ));
        };
        let key = TableKey::new(tf, step);
        if Occupancy::current(&self.occupancy, &key) {
            return Ok(());
        }
        let nc = vol.components as usize;
        // Which components drive opacity, and prefix counts of non-zero table entries.
        let opacity_comps: Vec<usize> = if tf.independent {
            (0..nc).collect()
        } else {
            vec![nc - 1]
        };
        let counts = |tables: &[[f32; 4]], visible: bool| {
            let mut p = vec![0u32; TABLE_SIZE + 1];
            for i in 0..TABLE_SIZE {
                p[i + 1] = p[i] + (tables[i][3] > 0.0 && visible) as u32;
            }
            p
        };
        // Dependent components take their colour from the others, a label map classifies
        // labelled samples with other functions: their rays take every step.
        let adaptive = (nc == 1 || tf.independent) && (nc > 1 || tf.max_label() == 0);
        let mut functions: Vec<Classified> = opacity_comps
            .iter()
            .map(|&c| {
                let ct = tf.component(if tf.independent { c } else { 0 });
                let visible = !tf.independent || ct.weight > 0.0;
                let tables = build_tables(ct, step);
                Classified {
                    component: c,
                    range: ct.table_range(),
                    prefix: counts(&tables, visible),
                    spread: (adaptive && visible).then(|| Spread::new(&tables[..TABLE_SIZE])),
                }
            })
            .collect();
        // A label map classifies a one-component volume's labelled samples with their
        // labels' functions: a block may hold what one of those shows.
        if nc == 1 {
            let (range, gradient_range) = tf.label_ranges();
            for label in 1..=tf.max_label() {
                let t = tf.label_transfer(label);
                let tables = build_tables_over(&t, step, range, gradient_range);
                functions.push(Classified {
                    component: 0,
                    range,
                    prefix: counts(&tables, true),
                    spread: None,
                });
            }
        }
        // A sample distance in voxels (along the shortest edge): a block's spread of the
        // classified function times the fraction of its range one voxel can cross (its
        // largest jump between neighbours, at least the range over the block's width: data
        // smooth at the block's scale) bounds how much it changes per sample distance.
        let m = vol.index_to_data;
        let edge = [m.x_axis, m.y_axis, m.z_axis]
            .map(|a| a.truncate().length())
            .into_iter()
            .fold(f64::INFINITY, f64::min);
        let voxels = (step / edge) as f32;
        let nblocks = vol.minmax.ranges.len() / nc;
        let mut occ = vec![0u32; nblocks];
        let last = (TABLE_SIZE - 1) as f64;
        for (b, o) in occ.iter_mut().enumerate() {
            let mut change = if adaptive { 0.0 } else { f32::INFINITY };
            for f in &functions {
                let [lo, hi] = f.range;
                let [mn, mx] = vol.minmax.ranges[b * nc + f.component];
                let jump = vol.minmax.jumps[b * nc + f.component];
                let crossed = (jump / (mx - mn)).max(1.0 / BLOCK_SIZE as f32).min(1.0);
                let x0 = ((mn as f64 - lo) / (hi - lo) * last)
                    .floor()
                    .clamp(0.0, last) as usize;
                let x1 = ((mx as f64 - lo) / (hi - lo) * last)
                    .ceil()
                    .clamp(0.0, last) as usize;
                if f.prefix[x1 + 1] > f.prefix[x0] {
                    *o = 1;
                    if !adaptive {
                        break;
                    }
                }
                if let Some(s) = &f.spread {
                    change = change.max(s.over(x0, x1) * crossed * voxels);
                }
            }
            if *o != 0 {
                *o = match change {
                    c if 4.0 * c <= ADAPTIVE_STEP_TOLERANCE => 4,
                    c if 2.0 * c <= ADAPTIVE_STEP_TOLERANCE => 2,
                    _ => 1,
                };
            }
        }
        self.occupancy = Some(Occupancy::new(ctx, "occupancy", key, vol.minmax.dims, &occ));
        self.stats.occupancy_updates += 1;
        Ok(())
    }
}

/// One function that classifies a component's samples, as the occupancy reads it.
struct Classified {
    component: usize,
    /// The scalar range its table spans.
    range: [f64; 2],
    /// Prefix counts of its table's entries with non-zero opacity.
    prefix: Vec<u32>,
    /// How much it varies over runs of entries (`None`: not for adaptive steps).
    spread: Option<Spread>,
}

/// Range queries of how much a table varies: the largest spread (max − min) of its
/// opacity and its opacity-weighted colour over a run of entries, from a sparse table of
/// their minima and maxima over runs of 2^l entries.
struct Spread {
    levels: Vec<Vec<[[f32; 4]; 2]>>,
}

impl Spread {
    fn new(entries: &[[f32; 4]]) -> Spread {
        let merge = |a: [[f32; 4]; 2], b: [[f32; 4]; 2]| {
            [
                std::array::from_fn(|i| a[0][i].min(b[0][i])),
                std::array::from_fn(|i| a[1][i].max(b[1][i])),
            ]
        };
        let first: Vec<[[f32; 4]; 2]> = entries
            .iter()
            .map(|e| {
                let q = [e[0] * e[3], e[1] * e[3], e[2] * e[3], e[3]];
                [q, q]
            })
            .collect();
        let mut levels = vec![first];
        let mut w = 1;
        while 2 * w <= entries.len() {
            let prev = &levels[levels.len() - 1];
            let next = (0..=entries.len() - 2 * w)
                .map(|i| merge(prev[i], prev[i + w]))
                .collect();
            levels.push(next);
            w *= 2;
        }
        Spread { levels }
    }

    /// The largest spread of one quantity over entries `x0..=x1`.
    fn over(&self, x0: usize, x1: usize) -> f32 {
        let l = (x1 - x0 + 1).ilog2() as usize;
        let (a, b) = (self.levels[l][x0], self.levels[l][x1 + 1 - (1 << l)]);
        (0..4)
            .map(|i| a[1][i].max(b[1][i]) - a[0][i].min(b[0][i]))
            .fold(0.0, f32::max)
    }
}

#[cfg(test)]
mod tests {
    use super::{leap_texels, LEAP_MAX};

    /// The leap distances equal the brute-force Chebyshev distance to the nearest occupied
    /// block, on grids of several shapes and densities; occupied blocks keep their values.
    #[test]
    fn leap_texels_hold_the_chebyshev_distance() {
        let mut seed = 0x9e37_79b9u32;
        let mut rand = move || {
            seed ^= seed << 13;
            seed ^= seed >> 17;
            seed ^= seed << 5;
            seed
        };
        for (dims, every) in [
            ([7u32, 5, 3], 9u32),
            ([1, 1, 12], 5),
            ([9, 9, 9], 60),
            ([6, 4, 8], 1_000_000),
            ([5, 5, 5], 1),
        ] {
            let n = (dims[0] * dims[1] * dims[2]) as usize;
            let occ: Vec<u32> = (0..n)
                .map(|_| {
                    if rand() % every == 0 {
                        [1, 2, 4][rand() as usize % 3]
                    } else {
                        0
                    }
                })
                .collect();
            let texels = leap_texels(dims, &occ);
            let at = |i: usize| {
                let x = i % dims[0] as usize;
                let y = i / dims[0] as usize % dims[1] as usize;
                let z = i / (dims[0] * dims[1]) as usize;
                [x as i64, y as i64, z as i64]
            };
            for i in 0..n {
                if occ[i] != 0 {
                    assert_eq!(texels[i], occ[i], "{dims:?}: occupied block {i}");
                    continue;
                }
                let p = at(i);
                let brute = (0..n)
                    .filter(|&j| occ[j] != 0)
                    .map(|j| {
                        let q = at(j);
                        (0..3).map(|a| (p[a] - q[a]).unsigned_abs()).max().unwrap() as u32
                    })
                    .min()
                    .unwrap_or(LEAP_MAX);
                assert_eq!(
                    texels[i] & 0xff,
                    0,
                    "{dims:?}: empty block {i} reads as occupied"
                );
                assert_eq!(texels[i] >> 8, brute, "{dims:?}: block {i}");
            }
        }
    }
}
