//! Volume upload: texture format choice, bricking, and the min–max grid for empty-space
//! skipping.
//!
//! Storage keeps the data's precision where a filterable format allows it: 8-bit data in
//! 8-bit normalised textures, 16-bit data in 16-bit normalised textures (signed types are
//! offset into the unsigned range so no value is lost), wider types as float32 where the
//! device filters it, otherwise as float16 normalised to the data range. The shader turns a
//! texel back into a scalar with a per-component `scale · texel + shift`.

use crate::gpu::DeviceInfo;
use crate::params::{ScalarType, VolumeData};

/// Points of overlap kept on each side of a brick: one for trilinear interpolation, one
/// more for central-difference gradients, so bricks meet without seams.
pub const BRICK_OVERLAP: u32 = 2;

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
    /// Cells per brick along each axis (the brick's core).
    pub brick_cells: u32,
}

/// One brick: the cells it owns and the points its texture holds.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct BrickExtent {
    /// Grid position of the brick.
    pub cell: [u32; 3],
    /// Owned index-space box [core_lo, core_hi].
    pub core_lo: [u32; 3],
    pub core_hi: [u32; 3],
    /// First point held by the texture, and the texture's size in points.
    pub tex_lo: [u32; 3],
    pub tex_size: [u32; 3],
}

pub(crate) fn channels_for(components: u32) -> u32 {
    if components >= 3 {
        4
    } else {
        components
    }
}

/// Picks the storage for a volume on a device.
pub fn choose_storage(
    v: &VolumeData,
    info: &DeviceInfo,
) -> (Storage, wgpu::TextureFormat, u32, [f32; 4], [f32; 4]) {
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
                let [lo, hi] = v.range(c);
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
    (storage, format, bytes * ch, scale, shift)
}

/// Splits the volume into bricks no larger than `max_points` per axis (overlap included)
/// and `max_bytes` per texture. A volume that fits is one brick with no overlap.
pub fn plan_bricks(
    dims: [u32; 3],
    texel_bytes: u32,
    max_points: u32,
    max_bytes: u64,
) -> (u32, Vec<BrickExtent>) {
    let fits = |n: [u32; 3]| {
        n.iter().all(|&d| d <= max_points)
            && n.iter().map(|&d| d as u64).product::<u64>() * texel_bytes as u64 <= max_bytes
    };
    let cells = dims.map(|d| d.saturating_sub(1).max(1));
    let max_cells = *cells.iter().max().unwrap_or(&1);
    let brick_cells = if fits(dims) {
        max_cells
    } else {
        // largest brick edge whose texture (core + overlap on both sides) fits
        let mut b = max_points
            .saturating_sub(2 * BRICK_OVERLAP + 1)
            .max(1)
            .min(max_cells);
        while b > 1 && !fits([b + 2 * BRICK_OVERLAP + 1; 3]) {
            b = (b * 7 / 8).max(1);
        }
        b
    };
    let counts = cells.map(|c| c.div_ceil(brick_cells));
    let mut bricks = Vec::new();
    for bz in 0..counts[2] {
        for by in 0..counts[1] {
            for bx in 0..counts[0] {
                let cell = [bx, by, bz];
                let mut core_lo = [0; 3];
                let mut core_hi = [0; 3];
                let mut tex_lo = [0; 3];
                let mut tex_size = [0; 3];
                for a in 0..3 {
                    core_lo[a] = cell[a] * brick_cells;
                    core_hi[a] = ((cell[a] + 1) * brick_cells).min(dims[a] - 1);
                    let single = counts[a] == 1;
                    let lo = if single {
                        0
                    } else {
                        core_lo[a].saturating_sub(BRICK_OVERLAP)
                    };
                    let hi = if single {
                        dims[a] - 1
                    } else {
                        (core_hi[a] + BRICK_OVERLAP).min(dims[a] - 1)
                    };
                    tex_lo[a] = lo;
                    tex_size[a] = hi - lo + 1;
                }
                bricks.push(BrickExtent {
                    cell,
                    core_lo,
                    core_hi,
                    tex_lo,
                    tex_size,
                });
            }
        }
    }
    (brick_cells, bricks)
}

/// Texel bytes of one brick in the chosen storage.
pub fn brick_texels(v: &VolumeData, layout: &Layout, b: &BrickExtent) -> Vec<u8> {
    let nc = v.components as usize;
    let ch = layout.channels as usize;
    let n: usize = b.tex_size.iter().map(|&d| d as usize).product();
    let mut out = Vec::with_capacity(n * layout.texel_bytes as usize);
    let (nx, ny) = (v.dims[0] as usize, v.dims[1] as usize);
    for k in 0..b.tex_size[2] as usize {
        for j in 0..b.tex_size[1] as usize {
            let row = ((b.tex_lo[2] as usize + k) * ny + b.tex_lo[1] as usize + j) * nx
                + b.tex_lo[0] as usize;
            for i in 0..b.tex_size[0] as usize {
                let p = (row + i) * nc;
                for c in 0..ch {
                    let val = if c < nc { v.scalars.get(p + c) } else { 0.0 };
                    match layout.storage {
                        Storage::Unorm8 { offset } => {
                            out.push((val + offset).round().clamp(0.0, 255.0) as u8)
                        }
                        Storage::Unorm16 { offset } => out.extend_from_slice(
                            &((val + offset).round().clamp(0.0, 65535.0) as u16).to_le_bytes(),
                        ),
                        Storage::Float32 => out.extend_from_slice(&(val as f32).to_le_bytes()),
                        Storage::Float16Normalized => {
                            let t = (val - layout.shift[c] as f64) / layout.scale[c] as f64;
                            out.extend_from_slice(&half::f16::from_f64(t).to_le_bytes());
                        }
                    }
                }
            }
        }
    }
    out
}

/// Min–max of each component over occupancy blocks of [`BLOCK_SIZE`] cells: block b holds
/// the points b·S … b·S + S (inclusive), all a sample inside the block interpolates from.
pub struct MinMaxGrid {
    pub dims: [u32; 3],
    /// Per block, per component: (min, max).
    pub ranges: Vec<[f32; 2]>,
}

impl MinMaxGrid {
    pub fn new(v: &VolumeData) -> MinMaxGrid {
        let s = BLOCK_SIZE;
        let dims = v.dims.map(|d| d.saturating_sub(1).max(1).div_ceil(s));
        let nc = v.components;
        let nblocks = dims.iter().map(|&d| d as usize).product::<usize>();
        let mut ranges = vec![[f32::INFINITY, f32::NEG_INFINITY]; nblocks * nc as usize];
        // Reduce along x into per-(row, block) ranges first, then spread over y and z.
        let (nx, ny, nz) = (v.dims[0], v.dims[1], v.dims[2]);
        for k in 0..nz {
            let bz_lo = (k.saturating_sub(1) / s).min(dims[2] - 1);
            let bz_hi = (k / s).min(dims[2] - 1);
            for j in 0..ny {
                let by_lo = (j.saturating_sub(1) / s).min(dims[1] - 1);
                let by_hi = (j / s).min(dims[1] - 1);
                for bx in 0..dims[0] {
                    let i0 = bx * s;
                    let i1 = (bx * s + s).min(nx - 1);
                    for c in 0..nc {
                        let mut lo = f32::INFINITY;
                        let mut hi = f32::NEG_INFINITY;
                        for i in i0..=i1 {
                            let val = v.value(i, j, k, c) as f32;
                            lo = lo.min(val);
                            hi = hi.max(val);
                        }
                        for bz in bz_lo..=bz_hi {
                            for by in by_lo..=by_hi {
                                let b = ((bz * dims[1] + by) * dims[0] + bx) as usize;
                                let r = &mut ranges[b * nc as usize + c as usize];
                                r[0] = r[0].min(lo);
                                r[1] = r[1].max(hi);
                            }
                        }
                    }
                }
            }
        }
        MinMaxGrid { dims, ranges }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn one_brick_when_it_fits() {
        let (b, bricks) = plan_bricks([64, 32, 16], 4, 2048, 1 << 30);
        assert_eq!(b, 63);
        assert_eq!(bricks.len(), 1);
        assert_eq!(bricks[0].tex_size, [64, 32, 16]);
        assert_eq!(bricks[0].core_hi, [63, 31, 15]);
    }

    #[test]
    fn bricks_cover_every_cell_once_with_overlap() {
        let dims = [50, 33, 20];
        let (b, bricks) = plan_bricks(dims, 1, 20, u64::MAX);
        assert!(b + 2 * BRICK_OVERLAP < 20);
        // each cell (i, j, k) of the grid lies in exactly one core
        for k in 0..dims[2] - 1 {
            for j in 0..dims[1] - 1 {
                for i in 0..dims[0] - 1 {
                    let c = [i, j, k];
                    let n = bricks
                        .iter()
                        .filter(|br| (0..3).all(|a| c[a] >= br.core_lo[a] && c[a] < br.core_hi[a]))
                        .count();
                    assert_eq!(n, 1, "cell {c:?}");
                }
            }
        }
        for br in &bricks {
            for (a, &dim) in dims.iter().enumerate() {
                assert!(br.tex_size[a] <= 20);
                assert!(br.tex_lo[a] + 2 <= br.core_lo[a] || br.tex_lo[a] == 0);
                let tex_hi = br.tex_lo[a] + br.tex_size[a] - 1;
                assert!(tex_hi >= (br.core_hi[a] + 2).min(dim - 1));
            }
        }
    }
}
