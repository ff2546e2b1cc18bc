//! Unstructured volumes on the CPU: points, cells as VTK stores them (connectivity,
//! offsets, VTK cell type codes) and scalars on the points or on the cells, held as
//! [`Scalars`] like a [`VolumeData`](super::VolumeData)'s.
//!
//! # Rules
//!
//! * **Cell types.** The renderer's cells are VTK's linear 3D cells [`CellType`]: tetra
//!   (10), voxel (11), hexahedron (12), wedge (13), pyramid (14), pentagonal prism (15)
//!   and hexagonal prism (16), with VTK's point order. [`UnstructuredVolume::from_vtk`]
//!   also takes VTK's quadratic 3D cells and linearises each by keeping its corner points (VTK lists them first) as the linear cell
//!   of the same shape: quadratic tetra (24) → tetra, quadratic (25), tri-quadratic (29)
//!   and bi-quadratic-quadratic (33) hexahedron → hexahedron, quadratic (26),
//!   quadratic-linear (31) and bi-quadratic-quadratic (32) wedge → wedge, quadratic (27)
//!   and tri-quadratic (37) pyramid → pyramid. One cell stays one cell, so cell scalars
//!   keep their meaning. Every other type (0D–2D cells, polyhedra, Lagrange and Bézier
//!   cells) is refused with an error naming the type and the first cell that has it.
//! * **Degenerate cells.** A cell that lists a point twice (a "collapsed" hexahedron
//!   standing in for a wedge, say) is refused, naming the cell and the point: the
//!   renderer's ray–face tests need cells with distinct corners. Cells whose distinct
//!   corners are coplanar (zero volume) are not looked for here; the renderer must
//!   tolerate them.
//! * **Non-manifold faces.** A face (the same set of points) shared by more than two cells
//!   is refused. Faces that match only partly (a hexahedron's quad against two tetra
//!   triangles: a non-conforming mesh) are not looked for.
//! * **Sizes.** Point indices, offsets and counts are `u32`: a mesh has fewer than 2^32
//!   points and 2^32 connectivity entries (far beyond what a GPU binds in one buffer).

use std::collections::HashMap;

use super::volume::{beyond_f32, ScalarType, Scalars};
use crate::error::{Error, Result};

/// A cell type the renderer takes. VTK numbers these seven consecutively, from VTK_TETRA
/// (10) to VTK_HEXAGONAL_PRISM (16), in the order the variants are declared.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum CellType {
    /// VTK_TETRA: 4 points.
    Tetra,
    /// VTK_VOXEL: 8 points of an axis-aligned box, x fastest (not a hexahedron's order).
    Voxel,
    /// VTK_HEXAHEDRON: 8 points, the bottom quad (0–3) then the top quad (4–7).
    Hexahedron,
    /// VTK_WEDGE: 6 points, two triangles (0–2, 3–5).
    Wedge,
    /// VTK_PYRAMID: 5 points, the base quad (0–3) and the apex (4).
    Pyramid,
    /// VTK_PENTAGONAL_PRISM: 10 points, two pentagons (0–4, 5–9), i + 5 above i.
    PentagonalPrism,
    /// VTK_HEXAGONAL_PRISM: 12 points, two hexagons (0–5, 6–11), i + 6 above i.
    HexagonalPrism,
}

/// VTK's code of the first type the renderer takes (VTK_TETRA).
const FIRST_VTK_CODE: u8 = 10;

impl CellType {
    /// Every type the renderer takes, in VTK's code order.
    pub const ALL: [CellType; 7] = [
        CellType::Tetra,
        CellType::Voxel,
        CellType::Hexahedron,
        CellType::Wedge,
        CellType::Pyramid,
        CellType::PentagonalPrism,
        CellType::HexagonalPrism,
    ];

    /// The type VTK calls `code`, if the renderer takes it.
    pub fn from_vtk(code: u8) -> Option<CellType> {
        let index = code.checked_sub(FIRST_VTK_CODE)?;
        Self::ALL.get(usize::from(index)).copied()
    }

    /// VTK's code for this type.
    pub fn vtk_code(self) -> u8 {
        FIRST_VTK_CODE + self as u8
    }

    /// The number of points of a cell of this type.
    pub fn num_points(self) -> usize {
        match self {
            CellType::Tetra => 4,
            CellType::Voxel | CellType::Hexahedron => 8,
            CellType::Wedge => 6,
            CellType::Pyramid => 5,
            CellType::PentagonalPrism => 10,
            CellType::HexagonalPrism => 12,
        }
    }

    /// The most points a face of any type has (a hexagonal prism's hexagons).
    pub const MAX_FACE_POINTS: usize = 6;

    /// The faces, as indices into the cell's points (VTK's face order), each of at most
    /// [`CellType::MAX_FACE_POINTS`] points.
    pub fn faces(self) -> &'static [&'static [usize]] {
        match self {
            CellType::Tetra => &[&[0, 1, 3], &[1, 2, 3], &[2, 0, 3], &[0, 2, 1]],
            CellType::Voxel => &[
                &[0, 4, 6, 2],
                &[1, 3, 7, 5],
                &[0, 1, 5, 4],
                &[2, 6, 7, 3],
                &[0, 2, 3, 1],
                &[4, 5, 7, 6],
            ],
            CellType::Hexahedron => &[
                &[0, 4, 7, 3],
                &[1, 2, 6, 5],
                &[0, 1, 5, 4],
                &[3, 7, 6, 2],
                &[0, 3, 2, 1],
                &[4, 5, 6, 7],
            ],
            CellType::Wedge => &[
                &[0, 1, 2],
                &[3, 5, 4],
                &[0, 3, 4, 1],
                &[1, 4, 5, 2],
                &[2, 5, 3, 0],
            ],
            CellType::Pyramid => &[
                &[0, 3, 2, 1],
                &[0, 1, 4],
                &[1, 2, 4],
                &[2, 3, 4],
                &[3, 0, 4],
            ],
            CellType::PentagonalPrism => &[
                &[0, 4, 3, 2, 1],
                &[5, 6, 7, 8, 9],
                &[0, 1, 6, 5],
                &[1, 2, 7, 6],
                &[2, 3, 8, 7],
                &[3, 4, 9, 8],
                &[4, 0, 5, 9],
            ],
            CellType::HexagonalPrism => &[
                &[0, 5, 4, 3, 2, 1],
                &[6, 7, 8, 9, 10, 11],
                &[0, 1, 7, 6],
                &[1, 2, 8, 7],
                &[2, 3, 9, 8],
                &[3, 4, 10, 9],
                &[4, 5, 11, 10],
                &[5, 0, 6, 11],
            ],
        }
    }
}

/// VTK's name for a cell type code, for messages ("VTK_TRIANGLE (5)").
pub fn vtk_cell_type_name(code: u8) -> String {
    let name = match code {
        0 => "VTK_EMPTY_CELL",
        1 => "VTK_VERTEX",
        2 => "VTK_POLY_VERTEX",
        3 => "VTK_LINE",
        4 => "VTK_POLY_LINE",
        5 => "VTK_TRIANGLE",
        6 => "VTK_TRIANGLE_STRIP",
        7 => "VTK_POLYGON",
        8 => "VTK_PIXEL",
        9 => "VTK_QUAD",
        10 => "VTK_TETRA",
        11 => "VTK_VOXEL",
        12 => "VTK_HEXAHEDRON",
        13 => "VTK_WEDGE",
        14 => "VTK_PYRAMID",
        15 => "VTK_PENTAGONAL_PRISM",
        16 => "VTK_HEXAGONAL_PRISM",
        21..=23 | 28 | 30 | 34..=36 => "a quadratic 1D/2D cell",
        24 => "VTK_QUADRATIC_TETRA",
        25 => "VTK_QUADRATIC_HEXAHEDRON",
        26 => "VTK_QUADRATIC_WEDGE",
        27 => "VTK_QUADRATIC_PYRAMID",
        29 => "VTK_TRIQUADRATIC_HEXAHEDRON",
        31 => "VTK_QUADRATIC_LINEAR_WEDGE",
        32 => "VTK_BIQUADRATIC_QUADRATIC_WEDGE",
        33 => "VTK_BIQUADRATIC_QUADRATIC_HEXAHEDRON",
        37 => "VTK_TRIQUADRATIC_PYRAMID",
        42 => "VTK_POLYHEDRON",
        68..=81 => "a Lagrange or Bezier cell",
        _ => "an unknown cell type",
    };
    format!("{name} ({code})")
}

/// The linear cell a quadratic VTK cell `code` is linearised to (its corner points come
/// first), and the number of points the quadratic cell has.
fn quadratic(code: u8) -> Option<(CellType, usize)> {
    Some(match code {
        24 => (CellType::Tetra, 10),
        25 => (CellType::Hexahedron, 20),
        26 => (CellType::Wedge, 15),
        27 => (CellType::Pyramid, 13),
        29 => (CellType::Hexahedron, 27),
        31 => (CellType::Wedge, 12),
        32 => (CellType::Wedge, 18),
        33 => (CellType::Hexahedron, 24),
        37 => (CellType::Pyramid, 19),
        _ => return None,
    })
}

/// Where the scalars of an [`UnstructuredVolume`] live.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum ScalarLocation {
    /// One tuple per point, interpolated within cells.
    Points,
    /// One tuple per cell, constant within it.
    Cells,
}

impl ScalarLocation {
    fn noun(self) -> &'static str {
        match self {
            ScalarLocation::Points => "point",
            ScalarLocation::Cells => "cell",
        }
    }
}

/// A mesh of 3D cells with scalars: VTK's vtkUnstructuredGrid as the renderer takes it.
///
/// Points are `f64`: VTK files hold Float32 or Float64 points, and `f64` keeps both
/// exactly (as [`VolumeData`](super::VolumeData)'s geometry is `f64`); the renderer
/// converts to 32-bit floats relative to the mesh's bounds when it uploads, so large
/// georeferenced coordinates lose no precision before that. Cell `c` is of type
/// `cell_types[c]` (a VTK code) and has the points
/// `connectivity[offsets[c] .. offsets[c + 1]]`: `offsets` has one entry more than
/// there are cells and starts at 0, as vtkCellArray's offsets do (a `.vtu` file's
/// `offsets` array leaves out the leading 0). See the module's rules for the cell
/// types taken, degenerate cells and faces.
#[derive(Clone, Debug, PartialEq)]
pub struct UnstructuredVolume {
    pub points: Vec<[f64; 3]>,
    pub connectivity: Vec<u32>,
    pub offsets: Vec<u32>,
    /// VTK cell type codes, one per cell; only [`CellType`]'s after validation.
    pub cell_types: Vec<u8>,
    pub location: ScalarLocation,
    /// Number of components per point or cell, 1–4.
    pub components: u32,
    /// `components` values per point or cell, interleaved, in point or cell order.
    pub scalars: Scalars,
}

fn invalid(message: String) -> Error {
    Error::InvalidVolume(message)
}

impl UnstructuredVolume {
    /// A mesh from VTK's arrays, with quadratic cells linearised (the module's rules),
    /// validated.
    #[allow(clippy::too_many_arguments)]
    pub fn from_vtk(
        points: Vec<[f64; 3]>,
        connectivity: Vec<u32>,
        offsets: Vec<u32>,
        cell_types: Vec<u8>,
        location: ScalarLocation,
        components: u32,
        scalars: Scalars,
    ) -> Result<Self> {
        let mut v = UnstructuredVolume {
            points,
            connectivity,
            offsets,
            cell_types,
            location,
            components,
            scalars,
        };
        v.check_cell_array()?;
        if v.cell_types.iter().any(|&t| quadratic(t).is_some()) {
            v.linearise()?;
        }
        v.validate()?;
        Ok(v)
    }

    /// Keeps the corner points of each quadratic cell (the cell array is well formed).
    fn linearise(&mut self) -> Result<()> {
        let mut connectivity = Vec::with_capacity(self.connectivity.len());
        let mut offsets = Vec::with_capacity(self.offsets.len());
        offsets.push(0);
        for (c, code) in self.cell_types.iter_mut().enumerate() {
            let cell = &self.connectivity[self.offsets[c] as usize..self.offsets[c + 1] as usize];
            let keep = match quadratic(*code) {
                Some((linear, n)) => {
                    if cell.len() != n {
                        return Err(wrong_count(c, *code, cell.len(), n));
                    }
                    *code = linear.vtk_code();
                    linear.num_points()
                }
                None => cell.len(),
            };
            connectivity.extend_from_slice(&cell[..keep]);
            offsets.push(connectivity.len() as u32);
        }
        self.connectivity = connectivity;
        self.offsets = offsets;
        Ok(())
    }

    /// The number of cells.
    pub fn num_cells(&self) -> usize {
        self.cell_types.len()
    }

    /// The point indices of cell `c`.
    ///
    /// # Panics
    /// If `c` is out of range or the mesh has not passed [`UnstructuredVolume::validate`].
    pub fn cell(&self, c: usize) -> &[u32] {
        &self.connectivity[self.offsets[c] as usize..self.offsets[c + 1] as usize]
    }

    /// The type of cell `c` (of a validated mesh; `None` for a type it would refuse).
    pub fn cell_type(&self, c: usize) -> Option<CellType> {
        self.cell_types.get(c).and_then(|&t| CellType::from_vtk(t))
    }

    /// The scalar type of the values.
    pub fn scalar_type(&self) -> ScalarType {
        self.scalars.scalar_type()
    }

    /// `[xmin, xmax, ymin, ymax, zmin, zmax]` over all points (empty: infinities).
    pub fn bounds(&self) -> [f64; 6] {
        let mut b = [f64::INFINITY, f64::NEG_INFINITY].repeat(3);
        for p in &self.points {
            for a in 0..3 {
                b[2 * a] = b[2 * a].min(p[a]);
                b[2 * a + 1] = b[2 * a + 1].max(p[a]);
            }
        }
        [b[0], b[1], b[2], b[3], b[4], b[5]]
    }

    /// The offsets, types and connectivity agree with each other.
    fn check_cell_array(&self) -> Result<()> {
        let cells = self.cell_types.len();
        if cells == 0 {
            return Err(invalid(
                "the mesh has no cells; there is nothing to render".into(),
            ));
        }
        if self.offsets.len() != cells + 1 {
            return Err(invalid(format!(
                "{} offsets for {cells} cells: expected {} (one per cell and a leading 0)",
                self.offsets.len(),
                cells + 1
            )));
        }
        if self.offsets[0] != 0 {
            return Err(invalid(format!(
                "the first offset is {}, not 0",
                self.offsets[0]
            )));
        }
        for (c, w) in self.offsets.windows(2).enumerate() {
            if w[1] <= w[0] {
                return Err(invalid(format!(
                    "offsets do not increase at cell {c}: {} then {} (each cell has at least one point)",
                    w[0], w[1]
                )));
            }
        }
        let last = self.offsets[cells] as usize;
        if last != self.connectivity.len() {
            return Err(invalid(format!(
                "the last offset is {last}, but the connectivity has {} entries",
                self.connectivity.len()
            )));
        }
        Ok(())
    }

    /// Checks everything a renderer relies on; the error names the problem and, for a
    /// cell, its index. See the module's rules.
    pub fn validate(&self) -> Result<()> {
        if self.points.is_empty() {
            return Err(invalid("the mesh has no points".into()));
        }
        if self.points.len() > u32::MAX as usize {
            return Err(invalid(format!(
                "{} points; ferrovol takes fewer than 2^32",
                self.points.len()
            )));
        }
        if let Some((i, p)) = self
            .points
            .iter()
            .enumerate()
            .find(|(_, p)| p.iter().any(|x| !x.is_finite()))
        {
            return Err(invalid(format!(
                "point {i} is {p:?} (NaN and infinite coordinates are not renderable)"
            )));
        }
        if let Some(beyond) = beyond_f32(self.bounds()) {
            return Err(invalid(format!("the mesh's {beyond}")));
        }
        self.check_cell_array()?;
        let np = self.points.len();
        for c in 0..self.num_cells() {
            let code = self.cell_types[c];
            let Some(ty) = CellType::from_vtk(code) else {
                return Err(invalid(format!(
                    "cell {c} is {}; ferrovol renders VTK_TETRA (10), VTK_VOXEL (11), VTK_HEXAHEDRON (12), VTK_WEDGE (13), VTK_PYRAMID (14) and linearises quadratic 3D cells (tetrahedralize other cells, e.g. with ParaView's Tetrahedralize filter)",
                    vtk_cell_type_name(code)
                )));
            };
            let cell = self.cell(c);
            if cell.len() != ty.num_points() {
                return Err(wrong_count(c, code, cell.len(), ty.num_points()));
            }
            for (k, &p) in cell.iter().enumerate() {
                if p as usize >= np {
                    return Err(invalid(format!(
                        "cell {c} ({}) refers to point {p}, but the mesh has {np} points (a dangling index)",
                        vtk_cell_type_name(code)
                    )));
                }
                if cell[..k].contains(&p) {
                    return Err(invalid(format!(
                        "cell {c} ({}) lists point {p} twice: a degenerate cell (store collapsed cells as the tetra, wedge or pyramid they are)",
                        vtk_cell_type_name(code)
                    )));
                }
            }
        }
        self.check_faces()?;
        self.check_scalars()
    }

    /// No face is shared by more than two cells (the cells are valid).
    fn check_faces(&self) -> Result<()> {
        // Each face as its sorted points (padded with u32::MAX), and the first cell seen
        // with it and how many have it.
        let mut seen: HashMap<[u32; CellType::MAX_FACE_POINTS], (usize, u8)> = HashMap::new();
        for c in 0..self.num_cells() {
            let cell = self.cell(c);
            let Some(ty) = self.cell_type(c) else {
                continue;
            };
            for face in ty.faces() {
                let mut key = [u32::MAX; CellType::MAX_FACE_POINTS];
                for (k, &i) in face.iter().enumerate() {
                    key[k] = cell[i];
                }
                key.sort_unstable();
                let e = seen.entry(key).or_insert((c, 0));
                e.1 += 1;
                if e.1 > 2 {
                    let points: Vec<u32> = key.into_iter().filter(|&p| p != u32::MAX).collect();
                    return Err(invalid(format!(
                        "the face with points {points:?} belongs to more than two cells (cells {} and {c}, among others): the mesh is not manifold there",
                        e.0
                    )));
                }
            }
        }
        Ok(())
    }

    fn check_scalars(&self) -> Result<()> {
        if !(1..=4).contains(&self.components) {
            return Err(invalid(format!(
                "{} components per {}; ferrovol renders 1 to 4",
                self.components,
                self.location.noun()
            )));
        }
        let n = match self.location {
            ScalarLocation::Points => self.points.len(),
            ScalarLocation::Cells => self.num_cells(),
        };
        let expected = n * self.components as usize;
        if self.scalars.len() != expected {
            return Err(invalid(format!(
                "{} scalar values for {n} {}s with {} component(s): expected {expected}",
                self.scalars.len(),
                self.location.noun(),
                self.components
            )));
        }
        let bad = match &self.scalars {
            Scalars::F32(v) => v.iter().position(|x| !x.is_finite()),
            Scalars::F64(v) => v.iter().position(|x| !x.is_finite()),
            _ => None,
        };
        if let Some(i) = bad {
            let c = self.components as usize;
            return Err(invalid(format!(
                "scalar of {} {} component {} is {} (NaN and infinite values are not renderable)",
                self.location.noun(),
                i / c,
                i % c,
                self.scalars.get(i)
            )));
        }
        Ok(())
    }
}

fn wrong_count(c: usize, code: u8, found: usize, expected: usize) -> Error {
    invalid(format!(
        "cell {c} ({}) has {found} points; that type has {expected}",
        vtk_cell_type_name(code)
    ))
}

#[cfg(test)]
mod tests;
