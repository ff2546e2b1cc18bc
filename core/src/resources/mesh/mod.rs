//! An unstructured volume prepared for ray traversal (CPU side): every cell split into
//! tetrahedra, each tetrahedron's four neighbours across its faces, the boundary triangles
//! and a bounding volume hierarchy over them ([`bvh`]); [`gpu`] uploads it.
//!
//! # Rules
//!
//! * **Tetrahedra, conforming.** A tetra stays itself. Every quadrilateral face is split
//!   along its diagonal through its smallest global point index (the standard conforming
//!   rule: two cells sharing a quad split it alike, so neighbours' triangles match). A
//!   pyramid becomes two tetrahedra (its base so split, joined with the apex); a wedge three
//!   (Dompierre et al. 1999: turned so that its smallest point is first, the quad opposite
//!   split by the rule, both other quads then split through the smallest point); a
//!   hexahedron or voxel twelve: each face's two triangles joined with the cell's centroid,
//!   a point added per cell whose point scalars are the mean of its eight corners'. So
//!   scalars are piecewise linear in every cell: exact for tetrahedra, a stated
//!   approximation of the trilinear (hexahedron) and the wedge's and pyramid's own
//!   interpolants that agrees with them at the corners (and, for hexahedra, at the centre).
//! * **Degenerate tetrahedra.** A tetrahedron whose volume is at most [`FLAT`] times the
//!   cube of its longest edge is left out and counted ([`Tetrahedra::flat`]); its faces
//!   become boundary faces, which rays leave and re-enter through the boundary hierarchy
//!   (so do faces that do not conform, a quad against two triangles split the other way). A cell
//!   all of whose tetrahedra are left out (a flat cell) is refused, naming the cell.
//! * **Non-manifold faces.** A triangle shared by more than two tetrahedra is refused,
//!   naming the cells they come from.
//! * **Scalars.** Point scalars stay per point (the first component), cell scalars are
//!   copied to each of the cell's tetrahedra.
//! * **Coordinates.** Points are stored as `f32` relative to the centre of the mesh's
//!   bounds ([`TetMesh::origin`], kept in `f64`).
//! * **Gradients.** Each point carries the scalar's gradient, the volume-weighted mean of
//!   its tetrahedra's ([`gradients`]), which shaded frames interpolate.
//! * **Order.** Points and tetrahedra are stored in Z-order along the mesh's bounds
//!   ([`order`]), not in the cells' order: a walk's next tetrahedron is near in memory.

pub(crate) mod bvh;
pub(crate) mod gpu;
mod gradients;
mod order;

use std::collections::HashMap;

use crate::error::{Error, Result};
use crate::params::{CellType, ScalarLocation, UnstructuredVolume};
use bvh::Bvh;

/// A tetrahedron whose |volume| ≤ FLAT · (longest edge)³ counts as flat (a regular
/// tetrahedron's ratio is 0.118).
pub(crate) const FLAT: f64 = 1e-7;

/// No neighbour across a face: it is on the boundary.
pub(crate) const BOUNDARY: u32 = u32::MAX;

/// The prepared mesh.
#[derive(Clone, Debug)]
pub(crate) struct TetMesh {
    /// Where the stored coordinates are relative to.
    pub origin: [f64; 3],
    /// xyz relative to `origin`; w the point's scalar (point scalars), else 0. The cell
    /// centroids of hexahedra and voxels come after the mesh's own points.
    pub points: Vec<[f32; 4]>,
    /// Each tetrahedron's points, positively oriented (face i is opposite point i).
    pub tets: Vec<[u32; 4]>,
    /// Across face i of each tetrahedron: `4 · neighbour + its face`, or [`BOUNDARY`].
    pub neighbours: Vec<[u32; 4]>,
    /// Cell scalars: each tetrahedron's (empty for point scalars).
    pub cell_scalars: Vec<f32>,
    /// The scalar's gradient at each point (xyz; [`gradients`]), for shading.
    pub point_gradients: Vec<[f32; 4]>,
    /// The boundary triangles as `4 · tet + face`, in the hierarchy's order.
    pub boundary: Vec<u32>,
    pub bvh: Bvh,
    pub location: ScalarLocation,
    /// The mesh's scalar components (the first is drawn).
    pub components: u32,
    /// The mesh's bounds, `[xmin, xmax, ymin, ymax, zmin, zmax]`.
    pub bounds: [f64; 6],
}

/// The two triangles of quad `q` (global point indices, in cycle order), split along the
/// diagonal through its smallest point.
pub(crate) fn split_quad(q: [u32; 4]) -> [[u32; 3]; 2] {
    let k = (0..4).min_by_key(|&k| q[k]).expect("four points");
    if k % 2 == 0 {
        [[q[0], q[1], q[2]], [q[0], q[2], q[3]]]
    } else {
        [[q[1], q[2], q[3]], [q[1], q[3], q[0]]]
    }
}

/// The wedge's point order with its smallest point first: rotations and reflections of the
/// prism that keep (0, 1, 2) a triangle and i + 3 above i.
const WEDGE_TURNS: [[usize; 6]; 6] = [
    [0, 1, 2, 3, 4, 5],
    [1, 2, 0, 4, 5, 3],
    [2, 0, 1, 5, 3, 4],
    [3, 5, 4, 0, 2, 1],
    [4, 3, 5, 1, 0, 2],
    [5, 4, 3, 2, 1, 0],
];

/// The triangles of polygon `p` (global point indices, in cycle order): a fan from its
/// smallest point, so the two cells that share a face split it alike, whichever way each
/// goes round it (for a quad, [`split_quad`]'s diagonal).
fn split_polygon(p: &[u32]) -> Vec<[u32; 3]> {
    let n = p.len();
    let k = (0..n).min_by_key(|&k| p[k]).expect("a polygon has points");
    (1..n - 1)
        .map(|i| [p[k], p[(k + i) % n], p[(k + i + 1) % n]])
        .collect()
}

/// Whether a cell of type `ty` is split around a point added at its centroid.
fn splits_around_centroid(ty: CellType) -> bool {
    matches!(
        ty,
        CellType::Hexahedron
            | CellType::Voxel
            | CellType::PentagonalPrism
            | CellType::HexagonalPrism
    )
}

/// The tetrahedra of cell `c` of `cell` points (global indices), as the module's rules
/// split it; the centroid of a cell split around it ([`splits_around_centroid`]) is point
/// `centroid`.
pub(crate) fn cell_tets(ty: CellType, cell: &[u32], centroid: u32) -> Vec<[u32; 4]> {
    match ty {
        CellType::Tetra => vec![[cell[0], cell[1], cell[2], cell[3]]],
        CellType::Pyramid => split_quad([cell[0], cell[1], cell[2], cell[3]])
            .iter()
            .map(|t| [t[0], t[1], t[2], cell[4]])
            .collect(),
        CellType::Wedge => {
            let k = (0..6).min_by_key(|&k| cell[k]).expect("six points");
            let v = WEDGE_TURNS[k].map(|i| cell[i]);
            // the quad opposite v0: (1, 2, 5, 4)
            if v[1].min(v[5]) < v[2].min(v[4]) {
                vec![
                    [v[0], v[1], v[2], v[5]],
                    [v[0], v[1], v[5], v[4]],
                    [v[0], v[4], v[5], v[3]],
                ]
            } else {
                vec![
                    [v[0], v[1], v[2], v[4]],
                    [v[0], v[4], v[2], v[5]],
                    [v[0], v[4], v[5], v[3]],
                ]
            }
        }
        CellType::Hexahedron | CellType::Voxel => {
            let hex = if ty == CellType::Voxel {
                [0, 1, 3, 2, 4, 5, 7, 6].map(|i| cell[i])
            } else {
                [0, 1, 2, 3, 4, 5, 6, 7].map(|i| cell[i])
            };
            CellType::Hexahedron
                .faces()
                .iter()
                .flat_map(|f| split_quad([hex[f[0]], hex[f[1]], hex[f[2]], hex[f[3]]]))
                .map(|t| [t[0], t[1], t[2], centroid])
                .collect()
        }
        CellType::PentagonalPrism | CellType::HexagonalPrism => ty
            .faces()
            .iter()
            .flat_map(|f| split_polygon(&f.iter().map(|&i| cell[i]).collect::<Vec<_>>()))
            .map(|t| [t[0], t[1], t[2], centroid])
            .collect(),
    }
}

/// Six times the signed volume of the tetrahedron of points a, b, c, d.
pub(crate) fn signed_volume6(p: [[f64; 3]; 4]) -> f64 {
    let e = |i: usize| [0, 1, 2].map(|a| p[i][a] - p[0][a]);
    let (u, v, w) = (e(1), e(2), e(3));
    u[0] * (v[1] * w[2] - v[2] * w[1]) - u[1] * (v[0] * w[2] - v[2] * w[0])
        + u[2] * (v[0] * w[1] - v[1] * w[0])
}

/// Whether the tetrahedron is flat by the module's rule.
fn is_flat(p: [[f64; 3]; 4]) -> bool {
    let mut longest: f64 = 0.0;
    for i in 0..4 {
        for j in i + 1..4 {
            let d2: f64 = (0..3).map(|a| (p[i][a] - p[j][a]).powi(2)).sum();
            longest = longest.max(d2.sqrt());
        }
    }
    signed_volume6(p).abs() / 6.0 <= FLAT * longest.powi(3)
}

/// The points of face i of a tetrahedron (opposite its point i).
pub(crate) const TET_FACES: [[usize; 3]; 4] = [[1, 2, 3], [0, 3, 2], [0, 1, 3], [0, 2, 1]];

/// An unstructured volume split into tetrahedra ([`tetrahedralize`]), in the mesh's own
/// coordinates: what the renderer uploads, and what a CPU reference needs.
#[derive(Clone, Debug, PartialEq)]
pub struct Tetrahedra {
    /// The mesh's points, then one centroid per hexahedron, voxel or pentagonal or
    /// hexagonal prism.
    pub points: Vec<[f64; 3]>,
    /// Per point, the first component's scalar (point scalars; 0 for cell scalars).
    pub point_scalars: Vec<f64>,
    /// Positively oriented tetrahedra (face i is opposite point i).
    pub tets: Vec<[u32; 4]>,
    /// The cell each tetrahedron comes from.
    pub tet_cell: Vec<u32>,
    /// Tetrahedra left out as flat.
    pub flat: usize,
}

/// Splits a mesh into tetrahedra as the renderer does. Each quad face is split along its
/// diagonal through its smallest point index (neighbours' triangles match); a tetra stays
/// itself, a pyramid becomes 2 tetrahedra, a wedge 3, a hexahedron or voxel 12, a
/// pentagonal prism 16 and a hexagonal prism 20 around a point added at its centroid (its
/// point scalars the corners' mean; each pentagon or hexagon split into a fan from its
/// smallest point), so scalars are linear per tetrahedron: exact for tetrahedra, an approximation of the other cells'
/// interpolants that agrees at their corners. Tetrahedra with a volume of at most 1e-7
/// times the cube of their longest edge are left out ([`Tetrahedra::flat`] counts them);
/// every tetrahedron is positively oriented. An error for a mesh that does not validate,
/// or has a cell with no tetrahedron left (a flat cell), naming the cell.
pub fn tetrahedralize(v: &UnstructuredVolume) -> Result<Tetrahedra> {
    v.validate()?;
    let nc = v.components as usize;
    let point_scalar = |i: usize| match v.location {
        ScalarLocation::Points => v.scalars.get(i * nc),
        ScalarLocation::Cells => 0.0,
    };
    let mut out = Tetrahedra {
        points: v.points.clone(),
        point_scalars: (0..v.points.len()).map(point_scalar).collect(),
        tets: Vec::with_capacity(v.num_cells()),
        tet_cell: Vec::with_capacity(v.num_cells()),
        flat: 0,
    };
    for c in 0..v.num_cells() {
        let ty = v.cell_type(c).expect("validated");
        let cell = v.cell(c);
        let mut centroid = u32::MAX;
        if splits_around_centroid(ty) {
            let n = cell.len() as f64;
            let mut m = [0.0; 3];
            for &p in cell {
                for (a, x) in m.iter_mut().enumerate() {
                    *x += out.points[p as usize][a] / n;
                }
            }
            centroid = out.points.len() as u32;
            let s = cell
                .iter()
                .map(|&p| out.point_scalars[p as usize])
                .sum::<f64>();
            out.point_scalars.push(s / n);
            out.points.push(m);
        }
        let before = out.tets.len();
        for mut t in cell_tets(ty, cell, centroid) {
            let p = t.map(|i| out.points[i as usize]);
            if is_flat(p) {
                out.flat += 1;
                continue;
            }
            if signed_volume6(p) < 0.0 {
                t.swap(2, 3);
            }
            out.tets.push(t);
            out.tet_cell.push(c as u32);
        }
        if out.tets.len() == before {
            return Err(Error::InvalidVolume(format!(
                "cell {c} ({ty:?}) has no volume (its points are coplanar or collinear): a \
                 flat cell is not renderable; remove it"
            )));
        }
    }
    Ok(out)
}

impl TetMesh {
    /// Prepares a mesh (see the module's rules).
    pub fn prepare(v: &UnstructuredVolume) -> Result<TetMesh> {
        let split = tetrahedralize(v)?;
        let bounds = v.bounds();
        let origin = [0, 1, 2].map(|a| 0.5 * (bounds[2 * a] + bounds[2 * a + 1]));
        let nc = v.components as usize;
        let Tetrahedra {
            mut points,
            mut point_scalars,
            mut tets,
            mut tet_cell,
            ..
        } = split;
        order::morton_order(
            &mut points,
            &mut point_scalars,
            &mut tets,
            &mut tet_cell,
            bounds,
        );
        let neighbours = adjacency(&tets, &tet_cell)?;
        let cell_scalars = match v.location {
            ScalarLocation::Cells => tet_cell
                .iter()
                .map(|&c| v.scalars.get(c as usize * nc) as f32)
                .collect(),
            ScalarLocation::Points => Vec::new(),
        };
        let points: Vec<[f32; 4]> = points
            .iter()
            .zip(&point_scalars)
            .map(|(p, s)| {
                [
                    (p[0] - origin[0]) as f32,
                    (p[1] - origin[1]) as f32,
                    (p[2] - origin[2]) as f32,
                    *s as f32,
                ]
            })
            .collect();
        let mut boundary: Vec<u32> = (0..tets.len() as u32)
            .flat_map(|t| (0..4u32).map(move |f| 4 * t + f))
            .filter(|&tf| neighbours[(tf / 4) as usize][(tf % 4) as usize] == BOUNDARY)
            .collect();
        let triangle = |tf: u32| {
            let t = tets[(tf / 4) as usize];
            TET_FACES[(tf % 4) as usize].map(|k| {
                let p = points[t[k] as usize];
                [p[0], p[1], p[2]]
            })
        };
        let bvh = Bvh::build(&mut boundary, triangle);
        let point_gradients =
            gradients::point_gradients(&points, &tets, &neighbours, &cell_scalars);
        Ok(TetMesh {
            origin,
            points,
            tets,
            neighbours,
            cell_scalars,
            point_gradients,
            boundary,
            bvh,
            location: v.location,
            components: v.components,
            bounds,
        })
    }
}

/// Each tetrahedron's neighbours across its faces (`4 · tet + face`), through a hash of
/// the faces' sorted points; a face shared by more than two tetrahedra is an error naming their cells.
fn adjacency(tets: &[[u32; 4]], tet_cell: &[u32]) -> Result<Vec<[u32; 4]>> {
    let mut neighbours = vec![[BOUNDARY; 4]; tets.len()];
    let mut faces: HashMap<[u32; 3], [u32; 2]> = HashMap::with_capacity(2 * tets.len() + 8);
    for (t, tet) in tets.iter().enumerate() {
        for (f, face) in TET_FACES.iter().enumerate() {
            let mut key = face.map(|k| tet[k]);
            key.sort_unstable();
            let tf = 4 * t as u32 + f as u32;
            let e = faces.entry(key).or_insert([BOUNDARY; 2]);
            if e[0] == BOUNDARY {
                e[0] = tf;
            } else if e[1] == BOUNDARY {
                e[1] = tf;
                let (a, b) = (e[0], tf);
                neighbours[(a / 4) as usize][(a % 4) as usize] = b;
                neighbours[(b / 4) as usize][(b % 4) as usize] = a;
            } else {
                let cells = [e[0], e[1], tf].map(|x| tet_cell[(x / 4) as usize]);
                return Err(Error::InvalidVolume(format!(
                    "the triangle with points {key:?} belongs to more than two tetrahedra (of \
                     cells {}, {} and {}): the mesh is not manifold there",
                    cells[0], cells[1], cells[2]
                )));
            }
        }
    }
    Ok(neighbours)
}

#[cfg(test)]
mod tests;
