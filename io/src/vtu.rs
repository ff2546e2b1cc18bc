//! VTK XML UnstructuredGrid (`.vtu`) reader.
//!
//! Reads, from every `<Piece>` of `<UnstructuredGrid>` (`NumberOfPoints`,
//! `NumberOfCells`): the `<Points>` array (3 components, any scalar type, kept as `f64`),
//! the `<Cells>` arrays `connectivity`, `offsets` and `types` (any 8- to 64-bit integer
//! type; values must fit the [`UnstructuredVolume`]'s `u32` indices and `u8` cell types),
//! and one scalar array:
//!
//! * from `<PointData>`: the array named by its `Scalars` attribute, else the first array;
//! * only if there is no point data array, from `<CellData>` the same way.
//!
//! Several pieces are merged into one mesh: each piece's point indices are offset by the
//! points of the pieces before it (points shared between pieces are not merged: a
//! parallel writer's duplicated boundary points stay two points), and their scalars must
//! have the same location, type and number of components. Pieces with no points and no
//! cells are skipped.
//!
//! Data formats are those of the `.vti` reader (see [`crate::vti`]): ascii, base64 binary
//! with UInt32 or UInt64 headers, appended raw or base64, zlib in one or several blocks,
//! both byte orders. The mesh then goes through [`UnstructuredVolume::from_vtk`]: quadratic
//! cells are linearised and bad meshes (dangling indices, unsupported cell types, repeated
//! points in a cell, faces shared by more than two cells…) are refused with an error naming
//! the cell (the rules: [`ferrovol_core::params::unstructured`]).

use ferrovol_core::{ScalarLocation, Scalars, UnstructuredVolume};

use crate::decode::{lookup_type, TypeNames};
use crate::error::Problem;
use crate::vtkxml::{appended_encoding, get, read_xml, ArrayDesc, Arrays, Piece, SUPPORTED_TYPES};
use crate::ReadError;

const FORMAT: &str = "VTK UnstructuredGrid (.vtu)";
const OTHER_TYPE_HINT: &str = "save the mesh as an unstructured grid (.vtu), e.g. after ParaView's Merge Blocks or Append Datasets";

fn bad(message: impl Into<String>) -> ReadError {
    ReadError::bad_header(FORMAT, message)
}

/// Parses a `.vtu` file from its bytes.
pub fn parse(bytes: &[u8]) -> Result<UnstructuredVolume, ReadError> {
    let (h, binary, xml_end) =
        read_xml(FORMAT, "UnstructuredGrid", ".vtu", OTHER_TYPE_HINT, bytes)?;
    let arrays = Arrays::new(
        FORMAT,
        bytes,
        binary,
        appended_encoding(FORMAT, &h)?,
        xml_end,
    );
    if h.pieces.is_empty() {
        return Err(bad("<UnstructuredGrid> has no <Piece> element"));
    }
    let npieces = h.pieces.len();
    let mut mesh: Option<Mesh> = None;
    for (i, piece) in h.pieces.into_iter().enumerate() {
        let name = if npieces == 1 {
            "the piece".to_string()
        } else {
            format!("piece {}", i + 1)
        };
        let Some(part) = read_piece(&arrays, &name, piece)? else {
            continue;
        };
        mesh = Some(match mesh {
            None => part,
            Some(m) => m.append(part, &name)?,
        });
    }
    let m = mesh.ok_or_else(|| bad("every <Piece> is empty (no points and no cells)"))?;
    UnstructuredVolume::from_vtk(
        m.points,
        m.connectivity,
        m.offsets,
        m.types,
        m.location,
        m.components,
        m.scalars,
    )
    .map_err(|e| Problem::InvalidVolume(e).into())
}

/// A piece as read, or several merged.
struct Mesh {
    points: Vec<[f64; 3]>,
    connectivity: Vec<u32>,
    /// With the leading 0.
    offsets: Vec<u32>,
    types: Vec<u8>,
    location: ScalarLocation,
    components: u32,
    scalars: Scalars,
}

impl Mesh {
    /// This mesh followed by `next` (called `name` in messages).
    fn append(mut self, next: Mesh, name: &str) -> Result<Mesh, ReadError> {
        if (next.location, next.components) != (self.location, self.components)
            || next.scalars.scalar_type() != self.scalars.scalar_type()
        {
            return Err(ReadError::unsupported(format!(
                "{name}'s scalars ({} {}, {} component(s)) differ from the first piece's ({} {}, {} component(s)); save the pieces with the same array (ParaView: Merge Blocks)",
                next.scalars.scalar_type().name(),
                noun(next.location),
                next.components,
                self.scalars.scalar_type().name(),
                noun(self.location),
                self.components
            )));
        }
        let too_many = || {
            ReadError::unsupported(format!(
                "with {name}, the mesh has 2^32 or more points or connectivity entries; ferrovol takes fewer"
            ))
        };
        let base = u32::try_from(self.points.len()).map_err(|_| too_many())?;
        let conn_base = u32::try_from(self.connectivity.len()).map_err(|_| too_many())?;
        for p in next.connectivity {
            self.connectivity
                .push(p.checked_add(base).ok_or_else(too_many)?);
        }
        for o in next.offsets.into_iter().skip(1) {
            self.offsets
                .push(o.checked_add(conn_base).ok_or_else(too_many)?);
        }
        self.points.extend(next.points);
        self.types.extend(next.types);
        self.scalars = concat(self.scalars, next.scalars);
        Ok(self)
    }
}

fn noun(location: ScalarLocation) -> &'static str {
    match location {
        ScalarLocation::Points => "point data",
        ScalarLocation::Cells => "cell data",
    }
}

/// `a` followed by `b` (of the same type; checked by the caller).
fn concat(a: Scalars, b: Scalars) -> Scalars {
    macro_rules! cat {
        ($($v:ident),*) => {
            match (a, b) {
                $((Scalars::$v(mut x), Scalars::$v(y)) => {
                    x.extend(y);
                    Scalars::$v(x)
                })*
                (a, _) => a,
            }
        };
    }
    cat!(U8, I8, U16, I16, U32, I32, F32, F64)
}

/// A `u64` attribute of a piece.
fn count_attr(piece: &Piece, name: &str, attr: &str) -> Result<u64, ReadError> {
    let v =
        get(&piece.attrs, attr).ok_or_else(|| bad(format!("{name} has no {attr} attribute")))?;
    v.trim().parse().map_err(|_| {
        bad(format!(
            "{name}: {attr}=\"{v}\" is not a non-negative integer"
        ))
    })
}

fn to_usize(what: &str, n: u64) -> Result<usize, ReadError> {
    usize::try_from(n).map_err(|_| {
        bad(format!(
            "{what} ({n}) is more than this machine can address"
        ))
    })
}

/// Reads one piece (`None` for an empty one).
fn read_piece(arrays: &Arrays, name: &str, mut piece: Piece) -> Result<Option<Mesh>, ReadError> {
    let npoints = count_attr(&piece, name, "NumberOfPoints")?;
    let ncells = count_attr(&piece, name, "NumberOfCells")?;
    if npoints == 0 && ncells == 0 {
        return Ok(None);
    }
    let npoints = to_usize("NumberOfPoints", npoints)?;
    let ncells = to_usize("NumberOfCells", ncells)?;

    // Points.
    let points_array = piece
        .points
        .kept
        .pop()
        .ok_or_else(|| bad(format!("{name} has no <Points> <DataArray>")))?;
    let what = format!("{name}'s <Points> DataArray '{}'", points_array.name);
    let ty = lookup_type(TypeNames::Vti, &points_array.type_name)
        .ok_or_else(|| ReadError::unsupported_type(&points_array.type_name, SUPPORTED_TYPES))?;
    if components(&what, &points_array)? != 3 {
        return Err(bad(format!(
            "{what} has NumberOfComponents=\"{}\"; points have 3",
            points_array.components
        )));
    }
    let count = npoints
        .checked_mul(3)
        .ok_or_else(|| bad(format!("{what}: NumberOfPoints={npoints} is too large")))?;
    let xyz = arrays.values(&points_array, &what, ty, count)?;
    let mut points = Vec::with_capacity(npoints);
    for p in 0..npoints {
        points.push([xyz.get(3 * p), xyz.get(3 * p + 1), xyz.get(3 * p + 2)]);
    }
    drop(xyz);

    // Cells.
    let mut cell_array = |array: &str| {
        piece.cells.take(array).ok_or_else(|| {
            bad(format!(
                "{name}'s <Cells> has no DataArray named '{array}' (a .vtu piece has connectivity, offsets and types)"
            ))
        })
    };
    let (offsets_array, types_array, connectivity_array) = (
        cell_array("offsets")?,
        cell_array("types")?,
        cell_array("connectivity")?,
    );
    let ends = indices(arrays, name, &offsets_array, ncells, u32::MAX as u64)?;
    let types = indices(arrays, name, &types_array, ncells, u8::MAX as u64)?;
    let nconn = ends.last().copied().unwrap_or(0) as usize;
    let connectivity = indices(arrays, name, &connectivity_array, nconn, u32::MAX as u64)?;
    let mut offsets = Vec::with_capacity(ncells + 1);
    offsets.push(0);
    offsets.extend(ends);

    // Scalars.
    let Piece { point, cell, .. } = piece;
    let (location, array, n) = match point.chosen() {
        Some(a) => (ScalarLocation::Points, a, npoints),
        None => match cell.chosen() {
            Some(a) => (ScalarLocation::Cells, a, ncells),
            None => {
                return Err(bad(format!(
                    "{name} has no <DataArray> in <PointData> or <CellData>; there is nothing to render"
                )))
            }
        },
    };
    let what = format!("{name}'s {} DataArray '{}'", noun(location), array.name);
    let ty = lookup_type(TypeNames::Vti, &array.type_name)
        .ok_or_else(|| ReadError::unsupported_type(&array.type_name, SUPPORTED_TYPES))?;
    let components = components(&what, &array)?;
    if !(1..=4).contains(&components) {
        return Err(ReadError::unsupported(format!(
            "{what} has {components} components; ferrovol renders 1 to 4 (extract the components you need, e.g. with ParaView's Calculator)"
        )));
    }
    let count = n
        .checked_mul(components as usize)
        .ok_or_else(|| bad(format!("{what}: too many values")))?;
    let scalars = arrays.values(&array, &what, ty, count)?;
    Ok(Some(Mesh {
        points,
        connectivity,
        offsets,
        types: types.into_iter().map(|t| t as u8).collect(),
        location,
        components: components as u32,
        scalars,
    }))
}

/// An array's `NumberOfComponents` (1 if missing).
fn components(what: &str, array: &ArrayDesc) -> Result<u64, ReadError> {
    if array.components.is_empty() {
        return Ok(1);
    }
    array.components.trim().parse().map_err(|_| {
        bad(format!(
            "{what}: NumberOfComponents=\"{}\" is not a number",
            array.components
        ))
    })
}

/// VTK's integer types: (names, size in bytes, signed).
const INDEX_TYPES: [(&str, usize, bool); 8] = [
    ("Int8,char,signed_char", 1, true),
    ("UInt8,unsigned_char", 1, false),
    ("Int16,short", 2, true),
    ("UInt16,unsigned_short", 2, false),
    ("Int32,int", 4, true),
    ("UInt32,unsigned_int", 4, false),
    ("Int64,long_long,vtkIdType", 8, true),
    ("UInt64,unsigned_long_long", 8, false),
];

/// Exactly `count` integers from a `<Cells>` array, each 0 to `max`.
fn indices(
    arrays: &Arrays,
    name: &str,
    array: &ArrayDesc,
    count: usize,
    max: u64,
) -> Result<Vec<u32>, ReadError> {
    let what = format!("{name}'s <Cells> DataArray '{}'", array.name);
    let &(_, size, signed) = INDEX_TYPES
        .iter()
        .find(|(names, _, _)| names.split(',').any(|n| n == array.type_name))
        .ok_or_else(|| {
            ReadError::unsupported(format!(
                "{what} has type=\"{}\"; cell arrays are Int8 to Int64 or UInt8 to UInt64",
                array.type_name
            ))
        })?;
    let range = |i: usize, v: i128| -> Result<u32, ReadError> {
        if (0..=max as i128).contains(&v) {
            Ok(v as u32)
        } else {
            Err(ReadError::corrupt(
                &what,
                format!("value #{} is {v}; it must be 0 to {max}", i + 1),
            ))
        }
    };
    // `count` comes from the header: reserve no more than the data can hold.
    let mut out = Vec::new();
    if array.format == "ascii" {
        let what = format!("ascii {what}");
        out.reserve(count.min(array.text.len() / 2 + 1));
        for (i, token) in array.text.split_ascii_whitespace().enumerate() {
            if i >= count {
                return Err(ReadError::corrupt(
                    &what,
                    format!("more than the {count} values the piece's sizes call for"),
                ));
            }
            let v: i128 = token.parse().map_err(|_| {
                ReadError::corrupt(
                    &what,
                    format!(
                        "value #{} '{}' is not an integer",
                        i + 1,
                        token.chars().take(40).collect::<String>()
                    ),
                )
            })?;
            out.push(range(i, v)?);
        }
        if out.len() != count {
            return Err(ReadError::corrupt(
                &what,
                format!(
                    "found {} values, expected {count} (the data is incomplete or the piece's sizes are wrong)",
                    out.len()
                ),
            ));
        }
        return Ok(out);
    }
    let nbytes = count
        .checked_mul(size)
        .ok_or_else(|| bad(format!("{what}: {count} values are too many")))?;
    let bytes = arrays.bytes(array, &what, nbytes)?;
    out.reserve(count);
    for (i, chunk) in bytes.chunks_exact(size).enumerate() {
        let mut b = [0u8; 8];
        if arrays.binary.big_endian {
            b[8 - size..].copy_from_slice(chunk);
            b.reverse();
        } else {
            b[..size].copy_from_slice(chunk);
        }
        let raw = u64::from_le_bytes(b);
        let v = if signed {
            let shift = 64 - 8 * size as u32;
            (((raw << shift) as i64) >> shift) as i128
        } else {
            raw as i128
        };
        out.push(range(i, v)?);
    }
    Ok(out)
}

#[cfg(test)]
mod tests;
