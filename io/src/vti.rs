//! VTK XML ImageData (`.vti`) reader.
//!
//! Reads `WholeExtent`, `Origin`, `Spacing` and the optional VTK 9 `Direction` of
//! `<ImageData>`, and one data array of its single `<Piece>`:
//!
//! * from `<PointData>`: the array named by its `Scalars` attribute, else the first array;
//! * only if there is no point data array, from `<CellData>` the same way. Cell values
//!   are then treated as point samples at the cell centres: the volume gets the cell
//!   dimensions (`max(extent span, 1)` per axis) and its origin moves half a spacing
//!   along every axis that has cells.
//!
//! The first point of the extent (which need not start at 0) becomes the volume's
//! origin: `origin + direction · (spacing ⊙ extent_min)`.
//!
//! Data formats: `format="ascii"`, `format="binary"` (base64 with a `UInt32` or `UInt64`
//! header, `header_type`) and `format="appended"` with `<AppendedData encoding="raw">` or
//! `encoding="base64"`; binary and appended data may be compressed with
//! `compressor="vtkZLibDataCompressor"`; both byte orders. The raw appended section is not
//! XML: only the part of the file before it goes to the XML parser, and the data is
//! located by byte offset after the `_` marker.

use ferrovol_core::{ScalarType, VolumeData};

use crate::decode::{lookup_type, numbers, Geometry, Layout, TypeNames};
use crate::vtkxml::{
    appended_array, appended_encoding, appended_section, get, read_xml, ArrayDesc, Arrays, Binary,
    Encoding, SUPPORTED_TYPES,
};
use crate::ReadError;

const FORMAT: &str = "VTK ImageData (.vti)";
const OTHER_TYPE_HINT: &str =
    "resample it to an image (e.g. ParaView's Resample To Image) and save as .vti";

fn bad(message: impl Into<String>) -> ReadError {
    ReadError::bad_header(FORMAT, message)
}

/// Whether the array is point or cell data.
#[derive(Clone, Copy, PartialEq, Eq)]
enum Which {
    Point,
    Cell,
}

/// Parses a `.vti` file from its bytes.
pub fn parse(bytes: &[u8]) -> Result<VolumeData, ReadError> {
    let h = describe(bytes)?;
    let arrays = Arrays::new(FORMAT, bytes, h.binary, h.appended_encoding, h.xml_end);
    let scalars = arrays.values(&h.array, &h.what, h.ty, h.layout.count)?;
    h.layout.volume(h.geometry, scalars)
}

/// Where the data of a `.vti` file whose XML part lies in `prefix` (its first bytes) is, when
/// it can be read in place: an uncompressed array in raw appended data whose byte-count
/// header (in `prefix`) matches the extent. `None` otherwise (the in-memory reader then
/// reads the file, and names any problem).
pub(crate) fn raw_data(prefix: &[u8]) -> Result<Option<crate::raw::RawData>, ReadError> {
    use crate::raw::{RawData, RawStart};
    let h = describe(prefix)?;
    if h.array.format != "appended" || h.binary.compressed {
        return Ok(None);
    }
    let (encoding, offset) = appended_array(FORMAT, &h.what, &h.array, h.appended_encoding)?;
    if !matches!(encoding, Encoding::Raw) {
        return Ok(None);
    }
    let data = appended_section(FORMAT, prefix, h.xml_end)?;
    // the section's first byte, as an offset in the file
    let section = data.as_ptr() as usize - prefix.as_ptr() as usize;
    let width = if h.binary.header_u64 { 8 } else { 4 };
    let Some(count) = data.get(offset..).and_then(|d| d.get(..width)) else {
        return Ok(None);
    };
    let count = if h.binary.big_endian {
        count.iter().fold(0u64, |v, &x| (v << 8) | x as u64)
    } else {
        count.iter().rev().fold(0u64, |v, &x| (v << 8) | x as u64)
    };
    if count != h.layout.nbytes as u64 {
        return Ok(None);
    }
    Ok(Some(RawData {
        format: FORMAT,
        layout: h.layout,
        geometry: h.geometry,
        big_endian: h.binary.big_endian,
        file: None,
        start: RawStart::At((section + offset + width) as u64),
    }))
}

/// What the XML part of a `.vti` file says: the chosen array, its layout and geometry, and
/// how its binary data is stored.
struct Described {
    layout: Layout,
    geometry: Geometry,
    array: ArrayDesc,
    /// "DataArray 'name'", for messages.
    what: String,
    ty: ScalarType,
    binary: Binary,
    appended_encoding: Option<Encoding>,
    /// The end of the XML part (after the `<AppendedData>` start tag, if there is one).
    xml_end: usize,
}

/// Reads the XML part of a `.vti` file (all of `bytes` up to any `<AppendedData>` start
/// tag) and checks what it describes.
fn describe(bytes: &[u8]) -> Result<Described, ReadError> {
    let (h, binary, xml_end) = read_xml(FORMAT, "ImageData", ".vti", OTHER_TYPE_HINT, bytes)?;

    // Geometry.
    let whole = get(&h.dataset, "WholeExtent");
    let whole = whole
        .as_deref()
        .ok_or_else(|| bad("<ImageData> has no WholeExtent attribute"))?;
    let extent = parse_extent("WholeExtent", whole)?;
    match h.pieces.len() {
        0 => return Err(bad("<ImageData> has no <Piece> element")),
        1 => {}
        n => {
            return Err(ReadError::unsupported(
                format!("{n} pieces in one file; save the image as a single piece (ParaView: Merge Blocks, then save as .vti)"),
            ))
        }
    }
    if let Some(piece) = h.pieces.first().and_then(|p| get(&p.attrs, "Extent")) {
        let pe = parse_extent("Piece Extent", &piece)?;
        if pe != extent {
            return Err(ReadError::unsupported(
                format!(
                    "the piece's Extent {pe:?} differs from the WholeExtent {extent:?} (part of a parallel .pvti dataset?); load the .pvti in ParaView and save it as one .vti"
                ),
            ));
        }
    }
    let mut geometry = Geometry::default();
    if let Some(s) = &get(&h.dataset, "Origin") {
        geometry.origin = vec3("Origin", s)?;
    }
    if let Some(s) = &get(&h.dataset, "Spacing") {
        geometry.spacing = vec3("Spacing", s)?;
    }
    if let Some(s) = &get(&h.dataset, "Direction") {
        let v: Vec<f64> = numbers(s, 9).ok_or_else(|| {
            bad(format!(
                "Direction=\"{s}\" is not 9 numbers (a row-major 3x3 matrix)"
            ))
        })?;
        geometry.direction = [[v[0], v[1], v[2]], [v[3], v[4], v[5]], [v[6], v[7], v[8]]];
    }

    let appended_encoding = appended_encoding(FORMAT, &h)?;

    // The array.
    let Some(piece) = h.pieces.into_iter().next() else {
        return Err(bad("<ImageData> has no <Piece> element"));
    };
    let (point, cell) = (piece.point, piece.cell);
    let (which, array) = match point.chosen() {
        Some(a) => (Which::Point, a),
        None => match cell.chosen() {
            Some(a) => (Which::Cell, a),
            None => {
                return Err(bad(
                    "the piece has no <DataArray> in <PointData> or <CellData>; there is nothing to render",
                ))
            }
        },
    };
    let what = format!("DataArray '{}'", array.name);
    let ty = lookup_type(TypeNames::Vti, &array.type_name)
        .ok_or_else(|| ReadError::unsupported_type(&array.type_name, SUPPORTED_TYPES))?;
    let components: u64 = if array.components.is_empty() {
        1
    } else {
        array.components.trim().parse().map_err(|_| {
            bad(format!(
                "{what}: NumberOfComponents=\"{}\" is not a number",
                array.components
            ))
        })?
    };
    if !(1..=4).contains(&components) {
        return Err(ReadError::unsupported(
            format!(
                "{what} has {components} components; ferrovol renders 1 to 4 (extract the components you need, e.g. with ParaView's Calculator)"
            ),
        ));
    }

    let mut dims = [0u64; 3];
    let mut first = [0.0f64; 3];
    for a in 0..3 {
        let span = (extent[2 * a + 1] as i128) - (extent[2 * a] as i128);
        let n = match which {
            Which::Point => span + 1,
            Which::Cell => span.max(1),
        };
        dims[a] = u64::try_from(n).unwrap_or(u64::MAX);
        let half = if which == Which::Cell && span > 0 {
            0.5
        } else {
            0.0
        };
        first[a] = geometry.spacing[a] * (extent[2 * a] as f64 + half);
    }
    let layout = Layout::new(FORMAT, dims, components, ty)?;
    let d = geometry.direction;
    for (r, o) in geometry.origin.iter_mut().enumerate() {
        *o += d[r][0] * first[0] + d[r][1] * first[1] + d[r][2] * first[2];
    }

    Ok(Described {
        layout,
        geometry,
        array,
        what,
        ty,
        binary,
        appended_encoding,
        xml_end,
    })
}

fn parse_extent(attr: &str, s: &str) -> Result<[i64; 6], ReadError> {
    let v: Vec<i64> = s
        .split_ascii_whitespace()
        .map(|t| t.parse::<i64>())
        .collect::<Result<_, _>>()
        .map_err(|_| bad(format!("{attr}=\"{s}\" is not 6 integers")))?;
    let e: [i64; 6] = v
        .try_into()
        .map_err(|_| bad(format!("{attr}=\"{s}\" is not 6 integers")))?;
    for a in 0..3 {
        if e[2 * a + 1] < e[2 * a] {
            return Err(bad(format!(
                "{attr}=\"{s}\" is empty along {} (max < min); the image has no points",
                ["x", "y", "z"][a]
            )));
        }
    }
    Ok(e)
}

fn vec3(attr: &str, s: &str) -> Result<[f64; 3], ReadError> {
    let v: Vec<f64> =
        numbers(s, 3).ok_or_else(|| bad(format!("{attr}=\"{s}\" is not 3 numbers")))?;
    Ok([v[0], v[1], v[2]])
}

#[cfg(test)]
mod tests;
