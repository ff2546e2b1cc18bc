//! Volume upload: texture format choice, bricking into the pool, and the min–max grid for
//! empty-space skipping.
//!
//! Storage keeps the data's precision where a filterable format allows it: 8-bit data in
//! 8-bit normalised textures, 16-bit data in 16-bit normalised textures (signed types are
//! offset into the unsigned range so no value is lost), wider types as float32 where the
//! device filters it, otherwise as float16 normalised to the data range. The shader turns a
//! texel back into a scalar with a per-component `scale · texel + shift`.

use crate::error::{Error, Result};
use crate::gpu::uniforms::PAGE_SLOT_BITS;
use crate::gpu::DeviceInfo;
use crate::params::{ScalarType, VolumeData};

/// Points of overlap kept on each side of a brick: one for trilinear interpolation, one
/// more for central-difference gradients, so bricks meet without seams.
pub const BRICK_OVERLAP: u32 = 2;

/// Fewest slots the memory budget must hold (the slot edge shrinks to fit them).
const MIN_SLOTS: u64 = 8;

/// Edge of an occupancy block in cells.
pub const BLOCK_SIZE: u32 = 8;

#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Storage {
    /// 8-bit normalised; texel = (value + offset) / 255.
    Unorm8 { offset: f64 },
    /// 16-bit normalised; texel = (value + offset) / 65535.
    Unorm16 { offset: f64 },
    /// Raw float32.
    Float32,
    /// float16 holding (value − min) / (max − min) per component.
    Float16Normalized,
}

/// How a volume is laid out on the device.
#[derive(Clone, Debug)]
pub struct Layout {
    pub storage: Storage,
    pub format: wgpu::TextureFormat,
    pub texel_bytes: u32,
    pub channels: u32,
    /// scalar = scale · texel + shift, per component.
    pub scale: [f32; 4],
    pub shift: [f32; 4],
}

pub(crate) fn channels_for(components: u32) -> u32 {
    if components >= 3 {
        4
    } else {
        components
    }
}

/// Picks the storage for a volume on a device: its layout (the float16 fallback reads the
/// data range: an error if a source fails to read).
pub fn choose_storage(v: &VolumeData, info: &DeviceInfo) -> Result<Layout> {
    use wgpu::TextureFormat as F;
    let ch = channels_for(v.components);
    let pick = |f1: F, f2: F, f4: F| match ch {
        1 => f1,
        2 => f2,
        _ => f4,
    };
    let t = v.scalars.scalar_type();
    let mut scale = [1.0f32; 4];
    let mut shift = [0.0f32; 4];
    let (storage, format, bytes) = match t {
        ScalarType::U8 | ScalarType::I8 => {
            let offset = if t == ScalarType::I8 { 128.0 } else { 0.0 };
            scale = [255.0; 4];
            shift = [-offset as f32; 4];
            (
                Storage::Unorm8 { offset },
                pick(F::R8Unorm, F::Rg8Unorm, F::Rgba8Unorm),
                1,
            )
        }
        ScalarType::U16 | ScalarType::I16 if info.norm16 => {
            let offset = if t == ScalarType::I16 { 32768.0 } else { 0.0 };
            scale = [65535.0; 4];
            shift = [-offset as f32; 4];
            (
                Storage::Unorm16 { offset },
                pick(F::R16Unorm, F::Rg16Unorm, F::Rgba16Unorm),
                2,
            )
        }
        _ if info.float32_filterable => (
            Storage::Float32,
            pick(F::R32Float, F::Rg32Float, F::Rgba32Float),
            4,
        ),
        _ => {
            for c in 0..v.components {
                let [lo, hi] = v.try_range(c)?;
                let w = if hi > lo { hi - lo } else { 1.0 };
                scale[c as usize] = w as f32;
                shift[c as usize] = lo as f32;
            }
            (
                Storage::Float16Normalized,
                pick(F::R16Float, F::Rg16Float, F::Rgba16Float),
                2,
            )
        }
    };
    Ok(Layout {
        storage,
        format,
        texel_bytes: bytes * ch,
        channels: ch,
        scale,
        shift,
    })
}

/// How the volume is cut into bricks and where they live in the pool texture. One brick is
/// the volume's own texture (no apron); several are cubes of `brick_cells` cells stored
/// with an apron of [`BRICK_OVERLAP`] points on every side in equal slots of the pool, and
/// the page table maps each brick to its slot.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct BrickGrid {
    /// Cells per brick edge (the brick's core).
    pub brick_cells: u32,
    /// Points of apron around each brick's core in its slot.
    pub apron: u32,
    /// Bricks per axis.
    pub counts: [u32; 3],
    /// Points per slot, per axis.
    pub slot: [u32; 3],
    /// Slots per pool axis: x and y per layer of slots, and the most layers (the pool
    /// grows layer by layer as bricks become resident).
    pub slots: [u32; 3],
}

impl BrickGrid {
    /// Number of bricks.
    pub fn len(&self) -> usize {
        self.counts.iter().map(|&c| c as usize).product()
    }

    /// The size in points of a pool of `layers` layers of slots.
    pub fn pool_size(&self, layers: u32) -> [u32; 3] {
        [
            self.slot[0] * self.slots[0],
            self.slot[1] * self.slots[1],
            self.slot[2] * layers,
        ]
    }

    /// Slots per layer.
    pub fn layer_slots(&self) -> u32 {
        self.slots[0] * self.slots[1]
    }

    /// All bricks front to back for a camera at `eye` looking along `dir` (index space):
    /// along each axis, bricks on the camera's side of a brick boundary come first. A ray's
    /// brick coordinates change monotonically along each axis, away from the camera's brick
    /// (perspective) or along the view direction (parallel), so every brick a ray crosses
    /// before brick `i` is reached from `i` by steps of one brick toward the camera
    /// ([`FrontToBack::before`]); each such step lowers the key (perspective: the sum over
    /// the axes of the brick steps from the camera's brick; parallel: the sum of the cells
    /// signed by the view direction) by one, so along any ray a later brick has a strictly
    /// larger key and the order holds for every ray.
    pub fn front_to_back(&self, eye: glam::DVec3, dir: glam::DVec3, parallel: bool) -> FrontToBack {
        let b = self.brick_cells as f64;
        let toward: [Toward; 3] = std::array::from_fn(|a| {
            if parallel {
                Toward::Lower(dir[a] >= 0.0)
            } else {
                Toward::Cell((eye[a] / b).floor() as i64)
            }
        });
        let key = |i: usize| -> i64 {
            let cell = self.cell(i);
            (0..3)
                .map(|a| {
                    let c = cell[a] as i64;
                    match toward[a] {
                        Toward::Lower(true) => c,
                        Toward::Lower(false) => -c,
                        Toward::Cell(e) => (c - e).abs(),
                    }
                })
                .sum()
        };
        let mut order: Vec<usize> = (0..self.len()).collect();
        order.sort_by_key(|&i| key(i));
        FrontToBack {
            order,
            grid: *self,
            toward,
        }
    }

    /// The min–max blocks (of `block_dims`, [`BLOCK_SIZE`] cells each, x fastest) the core
    /// of brick `i` overlaps, by index.
    pub fn blocks_of(&self, i: usize, block_dims: [u32; 3]) -> impl Iterator<Item = usize> {
        let cell = self.cell(i);
        let [x, y, z] = [0, 1, 2].map(|a| {
            let lo = cell[a] * self.brick_cells / BLOCK_SIZE;
            let hi = (cell[a] + 1) * self.brick_cells / BLOCK_SIZE;
            lo.min(block_dims[a] - 1)..=hi.min(block_dims[a] - 1)
        });
        z.flat_map(move |k| {
            let x = x.clone();
            y.clone().flat_map(move |j| {
                x.clone()
                    .map(move |b| ((k * block_dims[1] + j) * block_dims[0] + b) as usize)
            })
        })
    }

    /// Grid position of brick `i` (x fastest).
    pub fn cell(&self, i: usize) -> [u32; 3] {
        let [nx, ny, _] = self.counts.map(|c| c as usize);
        [i % nx, (i / nx) % ny, i / (nx * ny)].map(|c| c as u32)
    }

    /// The first point (index space, may lie outside the volume) the slot of the brick at
    /// `cell` holds.
    pub fn slot_origin_point(&self, cell: [u32; 3]) -> [i64; 3] {
        cell.map(|c| c as i64 * self.brick_cells as i64 - self.apron as i64)
    }
}

/// Where rays come from along one axis of the brick grid.
#[derive(Clone, Copy, Debug)]
enum Toward {
    /// A parallel projection: rays go toward higher coordinates (true) or lower.
    Lower(bool),
    /// A perspective one: rays leave the camera's brick coordinate.
    Cell(i64),
}

/// The bricks front to back for one view ([`BrickGrid::front_to_back`]).
#[derive(Clone, Debug)]
pub struct FrontToBack {
    /// Every brick, front to back.
    pub order: Vec<usize>,
    grid: BrickGrid,
    toward: [Toward; 3],
}

impl super::residency::Before for FrontToBack {
    /// The bricks one step from `i` toward the camera along each axis, inside the grid.
    fn before(&self, i: usize) -> [Option<usize>; 3] {
        let cell = self.grid.cell(i);
        let counts = self.grid.counts;
        std::array::from_fn(|a| {
            let c = cell[a] as i64;
            let step = match self.toward[a] {
                Toward::Lower(up) => {
                    if up {
                        -1
                    } else {
                        1
                    }
                }
                Toward::Cell(e) => (e - c).signum(),
            };
            let to = c + step;
            if step == 0 || to < 0 || to >= counts[a] as i64 {
                return None;
            }
            let mut n = cell;
            n[a] = to as u32;
            Some(((n[2] * counts[1] + n[1]) * counts[0] + n[0]) as usize)
        })
    }
}

/// Splits a volume of `dims` points into bricks of at most `max_brick` points per axis
/// (apron included), their slots laid out for a pool texture of at most `max_pool` points
/// per axis. A volume that fits (and whose texture takes at most `max_bytes`) is one brick
/// with no apron; otherwise the bricks are cubes whose slots have an edge of `slot_points`
/// (at most `max_brick`), layers of slots stacked along z. An error names the sizes when
/// even a pool holding every brick would exceed the 3D texture limit.
pub fn plan_bricks(
    dims: [u32; 3],
    texel_bytes: u32,
    max_brick: u32,
    max_pool: u32,
    max_bytes: u64,
    slot_points: u32,
) -> Result<BrickGrid> {
    let bytes = |n: [u32; 3]| n.iter().map(|&d| d as u64).product::<u64>() * texel_bytes as u64;
    let cells = dims.map(|d| d.saturating_sub(1).max(1));
    let max_points = max_brick.min(max_pool);
    if dims.iter().all(|&d| d <= max_points) && bytes(dims) <= max_bytes {
        return Ok(BrickGrid {
            brick_cells: *cells.iter().max().unwrap_or(&1),
            apron: 0,
            counts: [1; 3],
            slot: dims,
            slots: [1; 3],
        });
    }
    let min_slot = 2 * BRICK_OVERLAP + 2;
    // Slots small enough that the budget holds at least MIN_SLOTS of them, so that a
    // streamed frame moves on by several bricks per pass.
    let budget_edge = ((max_bytes / (MIN_SLOTS * texel_bytes as u64)) as f64).cbrt() as u32;
    if budget_edge < min_slot {
        return Err(Error::InvalidParameter(format!(
            "a memory budget of {max_bytes} bytes is too small for this volume: it must hold \
             {MIN_SLOTS} bricks of {min_slot}³ points ({} bytes)",
            MIN_SLOTS * (min_slot as u64).pow(3) * texel_bytes as u64
        )));
    }
    let edge = slot_points.min(max_points).min(budget_edge);
    if edge < min_slot {
        return Err(Error::InvalidParameter(format!(
            "brick edge {edge} is too small (at least {min_slot})"
        )));
    }
    let b = edge - (2 * BRICK_OVERLAP + 1);
    let counts = cells.map(|c| c.div_ceil(b));
    let n: u64 = counts.iter().map(|&c| c as u64).product();
    // (the page table addresses PAGE_SLOT_BITS bits of slot per axis)
    let per_axis = ((max_pool / edge) as u64).min(1 << PAGE_SLOT_BITS);
    let per_layer = n.div_ceil(per_axis.max(1));
    let sx = per_layer.min(per_axis);
    let sy = per_layer.div_ceil(sx.max(1));
    let sz = n.div_ceil(sx * sy).min(per_axis);
    let slot_bytes = bytes([edge; 3]);
    if per_axis == 0 || sy > per_axis {
        return Err(Error::Unsupported(format!(
            "the volume ({} × {} × {} points, {} bytes per point) needs {n} bricks of {edge}³ \
             points, {:.2} GiB of texture; a pool holds at most {per_axis} slots per axis \
             (the device takes at most {max_pool} points per axis in one 3D texture, the page \
             table addresses {} slots per axis)",
            dims[0],
            dims[1],
            dims[2],
            texel_bytes,
            (n * slot_bytes) as f64 / (1u64 << 30) as f64,
            1u32 << PAGE_SLOT_BITS,
        )));
    }
    Ok(BrickGrid {
        brick_cells: b,
        apron: BRICK_OVERLAP,
        counts,
        slot: [edge; 3],
        slots: [sx, sy, sz].map(|s| s as u32),
    })
}

/// Texel bytes of the `size` points from `lo` (index space; points outside the volume take
/// the nearest edge point's value, as a clamping sampler reads them) in the chosen storage.
/// In-memory data is read value by value; a source in one run per x-row (the row's points
/// the brick covers), so that a file source makes one positioned read per row. Errors are
/// a source's read failures.
pub fn brick_texels(
    v: &VolumeData,
    layout: &Layout,
    lo: [i64; 3],
    size: [u32; 3],
) -> Result<Vec<u8>> {
    let nc = v.components as usize;
    let ch = layout.channels as usize;
    let n: usize = size.iter().map(|&d| d as usize).product();
    let mut out = Vec::with_capacity(n * layout.texel_bytes as usize);
    let (nx, ny) = (v.dims[0] as usize, v.dims[1] as usize);
    let at = |a: usize, i: u32| (lo[a] + i as i64).clamp(0, v.dims[a] as i64 - 1) as usize;
    let push = |out: &mut Vec<u8>, val: f64, c: usize| match layout.storage {
        Storage::Unorm8 { offset } => out.push((val + offset).round().clamp(0.0, 255.0) as u8),
        Storage::Unorm16 { offset } => out
            .extend_from_slice(&((val + offset).round().clamp(0.0, 65535.0) as u16).to_le_bytes()),
        Storage::Float32 => out.extend_from_slice(&(val as f32).to_le_bytes()),
        Storage::Float16Normalized => {
            let t = (val - layout.shift[c] as f64) / layout.scale[c] as f64;
            out.extend_from_slice(&half::f16::from_f64(t).to_le_bytes());
        }
    };
    if v.scalars.source().is_some() {
        // The x-run of points the brick reads on each row (clamped into the volume).
        let (x0, x1) = (at(0, 0), at(0, size[0] - 1));
        let mut row_vals = vec![0.0; (x1 - x0 + 1) * nc];
        for k in 0..size[2] {
            for j in 0..size[1] {
                let row = (at(2, k) * ny + at(1, j)) * nx;
                v.scalars.read_run((row + x0) * nc, &mut row_vals)?;
                for i in 0..size[0] {
                    let p = (at(0, i) - x0) * nc;
                    for c in 0..ch {
                        let val = if c < nc { row_vals[p + c] } else { 0.0 };
                        push(&mut out, val, c);
                    }
                }
            }
        }
        return Ok(out);
    }
    for k in 0..size[2] {
        for j in 0..size[1] {
            let row = (at(2, k) * ny + at(1, j)) * nx;
            for i in 0..size[0] {
                let p = (row + at(0, i)) * nc;
                for c in 0..ch {
                    let val = if c < nc { v.scalars.get(p + c) } else { 0.0 };
                    push(&mut out, val, c);
                }
            }
        }
    }
    Ok(out)
}

/// Min–max of each component over occupancy blocks of [`BLOCK_SIZE`] cells: block b holds
/// the points b·S … b·S + S (inclusive), all a sample inside the block interpolates from;
/// and how far apart neighbouring points are there.
pub struct MinMaxGrid {
    pub dims: [u32; 3],
    /// Per block, per component: (min, max).
    pub ranges: Vec<[f32; 2]>,
    /// Per block, per component: the largest change between neighbouring points (along
    /// x, y or z), how rough the data is at the voxel scale, which its range does not tell.
    pub jumps: Vec<f32>,
}

impl MinMaxGrid {
    /// Reads every point once. In-memory data is read value by value; a source in runs of
    /// whole x-rows, whose values are checked here for NaN and infinity (the only time the
    /// upload reads them all; see [`crate::Scalars`]). Errors: such a value, or a source's
    /// read failure.
    pub fn new(v: &VolumeData) -> Result<MinMaxGrid> {
        let s = BLOCK_SIZE;
        let dims = v.dims.map(|d| d.saturating_sub(1).max(1).div_ceil(s));
        let nc = v.components;
        let nblocks = dims.iter().map(|&d| d as usize).product::<usize>();
        let mut ranges = vec![[f32::INFINITY, f32::NEG_INFINITY]; nblocks * nc as usize];
        let mut jumps = vec![0.0f32; nblocks * nc as usize];
        // Reduce along x into per-(row, block) ranges first, then spread over y and z.
        let (nx, ny, nz) = (v.dims[0], v.dims[1], v.dims[2]);
        let source = v.scalars.source().is_some();
        let mut row_vals = vec![0.0; if source { (nx * nc) as usize } else { 0 }];
        // A source's rows of the slice before (those not yet read of this one): the jumps
        // to a point's neighbours before it along y and z.
        let mut before = vec![
            0.0;
            if source {
                row_vals.len() * ny as usize
            } else {
                0
            }
        ];
        let apart = |a: f32, b: f64| (a as f64 - b).abs() as f32;
        for k in 0..nz {
            let bz_lo = (k.saturating_sub(1) / s).min(dims[2] - 1);
            let bz_hi = (k / s).min(dims[2] - 1);
            for j in 0..ny {
                let by_lo = (j.saturating_sub(1) / s).min(dims[1] - 1);
                let by_hi = (j / s).min(dims[1] - 1);
                let mut row = RowRanges {
                    dims,
                    nc,
                    x_last: nx - 1,
                    bz: [bz_lo, bz_hi],
                    by: [by_lo, by_hi],
                    ranges: &mut ranges,
                    jumps: &mut jumps,
                };
                if source {
                    let start = (k as usize * ny as usize + j as usize) * row_vals.len();
                    v.scalars.read_run(start, &mut row_vals)?;
                    if let Some(i) = row_vals.iter().position(|x| !x.is_finite()) {
                        return Err(v.non_finite(start + i, row_vals[i]));
                    }
                    let n = row_vals.len();
                    let (done, rest) = before.split_at_mut(j as usize * n);
                    let above = &mut rest[..n];
                    row.reduce(
                        |i, c| row_vals[(i * nc + c) as usize] as f32,
                        |i, c, val| {
                            let x = (i * nc + c) as usize;
                            let y = if j > 0 {
                                apart(val, done[done.len() - n + x])
                            } else {
                                0.0
                            };
                            let z = if k > 0 { apart(val, above[x]) } else { 0.0 };
                            y.max(z)
                        },
                    );
                    above.copy_from_slice(&row_vals);
                } else {
                    row.reduce(
                        |i, c| v.value(i, j, k, c) as f32,
                        |i, c, val| {
                            let y = if j > 0 {
                                apart(val, v.value(i, j - 1, k, c))
                            } else {
                                0.0
                            };
                            let z = if k > 0 {
                                apart(val, v.value(i, j, k - 1, c))
                            } else {
                                0.0
                            };
                            y.max(z)
                        },
                    );
                }
            }
        }
        Ok(MinMaxGrid {
            dims,
            ranges,
            jumps,
        })
    }

    /// Per block, 1 where component `c` (of `nc`) takes one of `values` (an isosurface of it
    /// may lie there), else 0.
    pub fn blocks_holding(&self, values: &[f32], c: usize, nc: usize) -> Vec<u32> {
        self.ranges
            .iter()
            .skip(c)
            .step_by(nc)
            .map(|&[lo, hi]| values.iter().any(|&v| v >= lo && v <= hi) as u32)
            .collect()
    }

    /// Component `c`'s range per block as the device samples it: the data's own values
    /// where the storage keeps them exactly (8/16-bit normalised, float32), widened by the
    /// storage's rounding where it does not (float16 keeps 11 bits of the normalised value).
    /// MIP and MinIP skip a block only when this range cannot move the ray's extremum
    /// (shaders/dvr.wgsl, RANGE_SKIP).
    pub fn sample_bounds(&self, c: usize, nc: usize, layout: &Layout) -> Vec<[f32; 2]> {
        let margin = match layout.storage {
            Storage::Float16Normalized => layout.scale[c].abs() as f64 / 1024.0,
            _ => 0.0,
        };
        self.ranges
            .iter()
            .skip(c)
            .step_by(nc)
            .map(|&[lo, hi]| {
                if margin == 0.0 {
                    [lo, hi]
                } else {
                    [(lo as f64 - margin) as f32, (hi as f64 + margin) as f32]
                }
            })
            .collect()
    }
}

/// One x-row's share of the min–max grid: the blocks its points belong to.
struct RowRanges<'a> {
    dims: [u32; 3],
    nc: u32,
    x_last: u32,
    bz: [u32; 2],
    by: [u32; 2],
    ranges: &'a mut [[f32; 2]],
    jumps: &'a mut [f32],
}

impl RowRanges<'_> {
    /// Folds the row's values (`value(i, c)`) into the ranges of the blocks holding them, and
    /// their jumps to their neighbours along x and (`across(i, c, value)`) along y and z
    /// into the blocks' jumps.
    #[inline]
    fn reduce(&mut self, value: impl Fn(u32, u32) -> f32, across: impl Fn(u32, u32, f32) -> f32) {
        let (s, dims, nc) = (BLOCK_SIZE, self.dims, self.nc);
        for bx in 0..dims[0] {
            let i0 = bx * s;
            let i1 = (bx * s + s).min(self.x_last);
            for c in 0..nc {
                let mut lo = f32::INFINITY;
                let mut hi = f32::NEG_INFINITY;
                let mut jump = 0.0f32;
                let mut prev = value(i0, c);
                for i in i0..=i1 {
                    let val = value(i, c);
                    lo = lo.min(val);
                    hi = hi.max(val);
                    jump = jump.max((val - prev).abs()).max(across(i, c, val));
                    prev = val;
                }
                for bz in self.bz[0]..=self.bz[1] {
                    for by in self.by[0]..=self.by[1] {
                        let b = ((bz * dims[1] + by) * dims[0] + bx) as usize;
                        let r = &mut self.ranges[b * nc as usize + c as usize];
                        r[0] = r[0].min(lo);
                        r[1] = r[1].max(hi);
                        let j = &mut self.jumps[b * nc as usize + c as usize];
                        *j = j.max(jump);
                    }
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn one_brick_when_it_fits() {
        let g = plan_bricks([64, 32, 16], 4, 2048, 2048, 1 << 30, 128).unwrap();
        assert_eq!(g.brick_cells, 63);
        assert_eq!(g.len(), 1);
        assert_eq!(g.apron, 0);
        assert_eq!(g.pool_size(1), [64, 32, 16]);
    }

    #[test]
    fn bricks_cover_every_cell_with_an_apron() {
        let dims = [50, 33, 20];
        let g = plan_bricks(dims, 1, 20, 2048, u64::MAX, 128).unwrap();
        assert_eq!(g.slot, [20; 3]);
        assert_eq!(g.brick_cells, 15);
        assert_eq!(g.counts, [4, 3, 2]);
        // every cell lies in the core of the brick floor(cell / B) selects
        for (n, d) in g.counts.into_iter().zip(dims) {
            assert!(n * g.brick_cells >= d - 1);
            assert!((n - 1) * g.brick_cells < d - 1);
        }
        // the slots fit the pool and the core plus apron fits a slot
        assert!(g.pool_size(g.slots[2]).iter().all(|&p| p <= 2048));
        assert!(g.slots.iter().product::<u32>() as usize >= g.len());
        // a layer of slots is a fraction of the bricks: the pool grows in small steps
        assert_eq!(g.layer_slots(), 1);
        // brick (1, 0, 0): blocks x 1..=3, y 0..=1, z 0..=1 of a 7 × 5 × 3 grid
        let blocks: Vec<usize> = g.blocks_of(1, [7, 5, 3]).collect();
        assert_eq!(blocks.len(), 12);
        assert_eq!((blocks[0], blocks[11]), (1, 35 + 7 + 3));
        assert_eq!(g.brick_cells + 1 + 2 * g.apron, 20);
        assert_eq!(g.slot_origin_point([1, 0, 0]), [13, -2, -2]);
    }

    #[test]
    fn slots_per_axis_stay_within_the_page_tables_bits() {
        // 15996 one-cell bricks in 6³ slots on a device taking 16384 points per axis: 2730
        // slots would fit the texture along an axis, the page table addresses 1024.
        let g = plan_bricks([4000, 3, 3], 1, 6, 16384, u64::MAX, 6).unwrap();
        assert_eq!(g.len(), 15996);
        assert!(
            g.slots.iter().all(|&s| s <= 1 << PAGE_SLOT_BITS),
            "{:?}",
            g.slots
        );
        assert!(g.slots.iter().map(|&s| s as usize).product::<usize>() >= g.len());
    }

    #[test]
    fn a_pool_too_large_names_the_sizes() {
        let e = plan_bricks([5000, 5000, 5000], 4, 4096, 4096, 1 << 31, 128).unwrap_err();
        let msg = e.to_string();
        assert!(
            msg.contains("5000 × 5000 × 5000") && msg.contains("4096"),
            "{msg}"
        );
    }

    #[test]
    fn apron_points_outside_take_the_edge() {
        use crate::params::Scalars;
        let v = VolumeData::new([3, 1, 1], 1, Scalars::U8(vec![10, 20, 30])).unwrap();
        let layout = Layout {
            storage: Storage::Unorm8 { offset: 0.0 },
            format: wgpu::TextureFormat::R8Unorm,
            texel_bytes: 1,
            channels: 1,
            scale: [255.0; 4],
            shift: [0.0; 4],
        };
        assert_eq!(
            brick_texels(&v, &layout, [-2, 0, 0], [7, 1, 1]).unwrap(),
            vec![10, 10, 10, 20, 30, 30, 30]
        );
    }
}
