//! Generated unstructured volumes (no data files): the wavelet on tetrahedra, a mixed mesh
//! of distorted cells of every linear type, a hollow cylinder (non-convex: rays leave and
//! re-enter it) and a tiny "house". Points are numbered x fastest (lexicographically), so
//! that the conforming split of quads (through their smallest point) agrees with the
//! tetrahedra generated here, which split every cube along the diagonals from each face's
//! lowest corner (Kuhn's six tetrahedra).

use super::{wavelet, wavelet_extent};
use crate::params::{CellType, ScalarLocation, Scalars, UnstructuredVolume};

/// The house's points: a unit cube's 8 corners in VTK hexahedron order, then the apex of
/// the pyramid roof on its top face.
pub const HOUSE_POINTS: [[f64; 3]; 9] = [
    [0.0, 0.0, 0.0],
    [1.0, 0.0, 0.0],
    [1.0, 1.0, 0.0],
    [0.0, 1.0, 0.0],
    [0.0, 0.0, 1.0],
    [1.0, 0.0, 1.0],
    [1.0, 1.0, 1.0],
    [0.0, 1.0, 1.0],
    [0.5, 0.5, 2.0],
];

/// A unit-cube hexahedron with a pyramid roof ([`HOUSE_POINTS`]); point scalars: each
/// point's height.
pub fn house() -> UnstructuredVolume {
    UnstructuredVolume {
        points: HOUSE_POINTS.to_vec(),
        connectivity: vec![0, 1, 2, 3, 4, 5, 6, 7, 4, 5, 6, 7, 8],
        offsets: vec![0, 8, 13],
        cell_types: vec![
            CellType::Hexahedron.vtk_code(),
            CellType::Pyramid.vtk_code(),
        ],
        location: ScalarLocation::Points,
        components: 1,
        scalars: Scalars::F32(HOUSE_POINTS.iter().map(|p| p[2] as f32).collect()),
    }
}

/// A cell list under construction.
#[derive(Default)]
struct Cells {
    connectivity: Vec<u32>,
    offsets: Vec<u32>,
    types: Vec<u8>,
}

impl Cells {
    fn push(&mut self, ty: CellType, points: &[u32]) {
        if self.offsets.is_empty() {
            self.offsets.push(0);
        }
        self.connectivity.extend_from_slice(points);
        self.offsets.push(self.connectivity.len() as u32);
        self.types.push(ty.vtk_code());
    }

    fn volume(
        self,
        points: Vec<[f64; 3]>,
        location: ScalarLocation,
        s: Vec<f32>,
    ) -> UnstructuredVolume {
        UnstructuredVolume {
            points,
            connectivity: self.connectivity,
            offsets: self.offsets,
            cell_types: self.types,
            location,
            components: 1,
            scalars: Scalars::F32(s),
        }
    }
}

/// The corners of cube (i, j, k) of a lattice of `n` points per axis (x fastest, VTK's
/// voxel order: bit 0 x, bit 1 y, bit 2 z), with a `wrap` of the y axis at `n[1]`.
fn corners(n: [u32; 3], i: u32, j: u32, k: u32, wrap: bool) -> [u32; 8] {
    let id = |a: u32, b: u32, c: u32| {
        let b = if wrap { b % n[1] } else { b };
        a + n[0] * (b + n[1] * c)
    };
    [0, 1, 2, 3, 4, 5, 6, 7].map(|v| id(i + (v & 1), j + ((v >> 1) & 1), k + (v >> 2)))
}

/// Kuhn's six tetrahedra of a cube (corners in voxel order), positively oriented.
fn kuhn(c: [u32; 8], cells: &mut Cells) {
    // the paths from corner 0 to corner 7 along x, y, z in every order, and their parity
    for (a, b, even) in [
        (1, 2, true),
        (1, 4, false),
        (2, 1, false),
        (2, 4, true),
        (4, 1, true),
        (4, 2, false),
    ] {
        let t = [c[0], c[a], c[a + b], c[7]];
        let t = if even { t } else { [t[0], t[2], t[1], t[3]] };
        cells.push(CellType::Tetra, &t);
    }
}

/// VTK's hexahedron order of a cube's corners in voxel order.
fn hex_order(c: [u32; 8]) -> [u32; 8] {
    [0, 1, 3, 2, 4, 5, 7, 6].map(|v| c[v])
}

/// The wavelet over `n` points per axis ([`wavelet_extent`]) on tetrahedra: each grid cube
/// split into Kuhn's six, point scalars the wavelet's. (n − 1)³ · 6 tetrahedra: 57 points
/// per axis give 1 053 696.
///
/// # Panics
/// If `n` < 2.
pub fn tet_wavelet(n: u32) -> UnstructuredVolume {
    assert!(n >= 2, "tet_wavelet: n = {n} points");
    let img = wavelet(wavelet_extent(n));
    let dims = [n; 3];
    let mut points = Vec::with_capacity((n * n * n) as usize);
    for k in 0..n {
        for j in 0..n {
            for i in 0..n {
                let ijk = [i, j, k];
                points.push([0, 1, 2].map(|a| img.origin[a] + img.spacing[a] * ijk[a] as f64));
            }
        }
    }
    let mut cells = Cells::default();
    for k in 0..n - 1 {
        for j in 0..n - 1 {
            for i in 0..n - 1 {
                kuhn(corners(dims, i, j, k, false), &mut cells);
            }
        }
    }
    let Scalars::F32(s) = img.scalars else {
        unreachable!("the wavelet is float32")
    };
    cells.volume(points, ScalarLocation::Points, s)
}

/// A deterministic hash of an integer to [−1, 1).
fn jitter(v: u32) -> f64 {
    let mut s = v.wrapping_mul(747_796_405).wrapping_add(2_891_336_453);
    s = ((s >> ((s >> 28) + 4)) ^ s).wrapping_mul(277_803_737);
    s = (s >> 22) ^ s;
    (s >> 8) as f64 / 8_388_608.0 - 1.0
}

/// A smooth field over the generated meshes' coordinates.
fn field(p: [f64; 3]) -> f64 {
    (1.7 * p[0]).sin() * (1.3 * p[1]).cos() + 0.5 * p[2]
}

/// `n`³ unit cubes, their interior points moved by up to 0.15 of a cube per axis, each
/// cube by (i + j + k) mod 4 a hexahedron, two wedges, six pyramids around a point added
/// at its centre, or six tetrahedra. Scalars: a smooth field at the points, or (cell
/// scalars) at each cell's first point.
///
/// # Panics
/// If `n` is 0.
pub fn mixed_cells(n: u32, location: ScalarLocation) -> UnstructuredVolume {
    assert!(n >= 1, "mixed_cells: n = {n}");
    let m = n + 1;
    let mut points = Vec::new();
    for k in 0..m {
        for j in 0..m {
            for i in 0..m {
                let ijk = [i, j, k];
                let id = points.len() as u32;
                points.push([0, 1, 2].map(|a| {
                    let inside = ijk[a] > 0 && ijk[a] < n;
                    let d = if inside {
                        0.15 * jitter(3 * id + a as u32)
                    } else {
                        0.0
                    };
                    ijk[a] as f64 + d
                }));
            }
        }
    }
    let mut cells = Cells::default();
    for k in 0..n {
        for j in 0..n {
            for i in 0..n {
                let c = corners([m; 3], i, j, k, false);
                match (i + j + k) % 4 {
                    0 => cells.push(CellType::Hexahedron, &hex_order(c)),
                    1 => {
                        cells.push(CellType::Wedge, &[c[0], c[3], c[1], c[4], c[7], c[5]]);
                        cells.push(CellType::Wedge, &[c[0], c[2], c[3], c[4], c[6], c[7]]);
                    }
                    2 => {
                        let centre = points.len() as u32;
                        let mut mid = [0.0; 3];
                        for v in c {
                            for (a, x) in mid.iter_mut().enumerate() {
                                *x += points[v as usize][a] / 8.0;
                            }
                        }
                        points.push(mid);
                        let h = hex_order(c);
                        for f in CellType::Hexahedron.faces() {
                            // VTK's faces point outward; a pyramid's base points to its apex
                            cells.push(
                                CellType::Pyramid,
                                &[h[f[3]], h[f[2]], h[f[1]], h[f[0]], centre],
                            );
                        }
                    }
                    _ => kuhn(c, &mut cells),
                }
            }
        }
    }
    let s = match location {
        ScalarLocation::Points => points.iter().map(|&p| field(p) as f32).collect(),
        ScalarLocation::Cells => (0..cells.types.len())
            .map(|c| field(points[cells.connectivity[cells.offsets[c] as usize] as usize]) as f32)
            .collect(),
    };
    cells.volume(points, location, s)
}

/// A hollow cylinder about the z axis: radii 1 to 2, height 2, `nr` × `nt` × `nz`
/// hexahedra (around, the last joined to the first). Non-convex: a ray across it leaves
/// the wall into the hole and enters the wall again. Point scalars: a smooth field.
///
/// # Panics
/// If a count is 0 or `nt` < 3.
pub fn hollow_cylinder(nr: u32, nt: u32, nz: u32) -> UnstructuredVolume {
    assert!(
        nr >= 1 && nt >= 3 && nz >= 1,
        "hollow_cylinder: {nr} × {nt} × {nz}"
    );
    let dims = [nr + 1, nt, nz + 1];
    let mut points = Vec::new();
    for k in 0..dims[2] {
        for j in 0..dims[1] {
            for i in 0..dims[0] {
                let r = 1.0 + i as f64 / nr as f64;
                let th = std::f64::consts::TAU * j as f64 / nt as f64;
                points.push([r * th.cos(), r * th.sin(), 2.0 * k as f64 / nz as f64 - 1.0]);
            }
        }
    }
    let mut cells = Cells::default();
    for k in 0..nz {
        for j in 0..nt {
            for i in 0..nr {
                cells.push(
                    CellType::Hexahedron,
                    &hex_order(corners(dims, i, j, k, true)),
                );
            }
        }
    }
    let s = points.iter().map(|&p| field(p) as f32).collect();
    cells.volume(points, ScalarLocation::Points, s)
}
