//! End-to-end accuracy tests of the ray caster on a real wgpu device (see
//! common/gpu.rs for what is expected of each device class), by topic: the composite
//! integral and the other blend modes, silhouettes and the cleared outside, the GPU image
//! against the f64 CPU reference, renderer state (bricks, uploads, errors, volumetric
//! shadows, precomputed gradients), and bricking in every mode (ray casting, isosurfaces,
//! path tracing).
//!
//! Every test prints what it measured and asserts a tolerance with the reason for it.
//! Images of the interesting cases go to `target/test-images/*.png` for inspection.

use ferrovol_core::*;
use glam::DVec3;

mod adaptive;
mod bricks;
#[path = "../common/mod.rs"]
mod common;
mod compositing;
mod intermix;
mod lod;
mod masks;
mod pipelining;
mod preintegration;
mod quadrature;
mod rectilinear;
mod reference;
mod residency;
mod segments;
mod silhouettes;
mod skipping;
mod sources;
mod state;
mod tables_2d;

use common::raycast::to_pixel;

/// The eight corners of the box [lo, hi].
pub fn box_corners(lo: DVec3, hi: DVec3) -> [DVec3; 8] {
    std::array::from_fn(|c| {
        DVec3::new(
            if c & 1 != 0 { hi.x } else { lo.x },
            if c & 2 != 0 { hi.y } else { lo.y },
            if c & 4 != 0 { hi.z } else { lo.z },
        )
    })
}

/// First and last column, first and last row of the pixels whose centres fall inside the
/// bounding box of the projected points (world).
pub fn projected_extents(view: &View, points: [DVec3; 8]) -> [f64; 4] {
    let (mut x0, mut x1, mut y0, mut y1) = (
        f64::INFINITY,
        f64::NEG_INFINITY,
        f64::INFINITY,
        f64::NEG_INFINITY,
    );
    for p in points {
        let (px, py) = to_pixel(view, p);
        x0 = x0.min(px);
        x1 = x1.max(px);
        y0 = y0.min(py);
        y1 = y1.max(py);
    }
    [
        (x0 - 0.5).ceil(),
        (x1 - 0.5).floor(),
        (y0 - 0.5).ceil(),
        (y1 - 0.5).floor(),
    ]
}

/// First and last column, first and last row of a mask's set pixels.
pub fn mask_extents(mask: &[bool], w: u32, h: u32) -> Option<[f64; 4]> {
    let cols: Vec<u32> = (0..w)
        .filter(|&x| (0..h).any(|y| mask[(y * w + x) as usize]))
        .collect();
    let rows: Vec<u32> = (0..h)
        .filter(|&y| (0..w).any(|x| mask[(y * w + x) as usize]))
        .collect();
    Some([*cols.first()?, *cols.last()?, *rows.first()?, *rows.last()?].map(|v| v as f64))
}
