//! A small VTK XML UnstructuredGrid (`.vtu`) writer for tests, in every encoding the
//! reader takes: ascii, base64 binary, appended raw and base64, zlib in one or several
//! blocks, UInt32 or UInt64 block headers, both byte orders. Used by io's unit tests
//! (through `#[path]`) and test binaries, so that the two share one writer.
#![allow(dead_code)]

use std::io::Write;

/// How the arrays are stored.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Enc {
    Ascii,
    Binary,
    AppendedRaw,
    AppendedBase64,
}

#[derive(Clone, Copy, Debug)]
pub struct Opts {
    pub enc: Enc,
    /// vtkZLibDataCompressor with this block size.
    pub zlib: Option<usize>,
    pub u64_header: bool,
    pub big_endian: bool,
}

impl Opts {
    pub const ASCII: Opts = Opts {
        enc: Enc::Ascii,
        zlib: None,
        u64_header: false,
        big_endian: false,
    };
    pub fn with(enc: Enc) -> Opts {
        Opts { enc, ..Opts::ASCII }
    }
}

/// A `<DataArray>`: name, VTK type name, components, values.
#[derive(Clone, Debug)]
pub struct Array {
    pub name: String,
    pub ty: String,
    pub components: u32,
    pub values: Vec<f64>,
}

pub fn array(name: &str, ty: &str, components: u32, values: Vec<f64>) -> Array {
    Array {
        name: name.into(),
        ty: ty.into(),
        components,
        values,
    }
}

/// A `<Piece>`: points, cells as a file stores them (offsets without the leading 0), and
/// point and cell data arrays.
#[derive(Clone, Debug, Default)]
pub struct Piece {
    pub points: Vec<[f64; 3]>,
    pub connectivity: Vec<i64>,
    pub offsets: Vec<i64>,
    pub types: Vec<u8>,
    pub point_data: Vec<Array>,
    pub cell_data: Vec<Array>,
    /// The type of the connectivity and offsets arrays (Int64 as VTK 9 writes).
    pub index_type: Option<String>,
}

impl Piece {
    /// Cells given as (type, points).
    pub fn cells(points: Vec<[f64; 3]>, cells: &[(u8, &[i64])]) -> Piece {
        let mut p = Piece {
            points,
            ..Piece::default()
        };
        for (t, c) in cells {
            p.connectivity.extend_from_slice(c);
            p.offsets.push(p.connectivity.len() as i64);
            p.types.push(*t);
        }
        p
    }
}

fn to_bytes(ty: &str, values: &[f64], be: bool) -> Vec<u8> {
    macro_rules! conv {
        ($t:ty) => {
            values
                .iter()
                .flat_map(|&v| {
                    let v = v as $t;
                    if be {
                        v.to_be_bytes().to_vec()
                    } else {
                        v.to_le_bytes().to_vec()
                    }
                })
                .collect()
        };
    }
    match ty {
        "Int8" => conv!(i8),
        "UInt8" => conv!(u8),
        "Int16" => conv!(i16),
        "UInt16" => conv!(u16),
        "Int32" => conv!(i32),
        "UInt32" => conv!(u32),
        "Int64" => conv!(i64),
        "UInt64" => conv!(u64),
        "Float32" => conv!(f32),
        "Float64" => conv!(f64),
        other => panic!("no type {other}"),
    }
}

fn uint(v: usize, o: &Opts) -> Vec<u8> {
    match (o.u64_header, o.big_endian) {
        (true, false) => (v as u64).to_le_bytes().to_vec(),
        (true, true) => (v as u64).to_be_bytes().to_vec(),
        (false, false) => (v as u32).to_le_bytes().to_vec(),
        (false, true) => (v as u32).to_be_bytes().to_vec(),
    }
}

pub fn zlib(data: &[u8]) -> Vec<u8> {
    let mut e = flate2::write::ZlibEncoder::new(Vec::new(), flate2::Compression::default());
    e.write_all(data).unwrap();
    e.finish().unwrap()
}

pub fn b64(d: &[u8]) -> String {
    use base64::Engine;
    base64::engine::general_purpose::STANDARD.encode(d)
}

/// An array's binary block: its header and data, compressed if asked.
pub fn block(data: &[u8], o: &Opts) -> Vec<u8> {
    match o.zlib {
        None => {
            let mut v = uint(data.len(), o);
            v.extend_from_slice(data);
            v
        }
        Some(size) => {
            let chunks: Vec<&[u8]> = data.chunks(size).collect();
            let mut header = uint(chunks.len(), o);
            header.extend(uint(size, o));
            header.extend(uint(data.len() % size, o));
            let mut body = Vec::new();
            for c in chunks {
                let z = zlib(c);
                header.extend(uint(z.len(), o));
                body.extend(z);
            }
            header.extend(body);
            header
        }
    }
}

/// Writes one `<DataArray>`, appending its data to `appended` where the encoding says so.
fn data_array(out: &mut String, appended: &mut Vec<u8>, a: &Array, o: &Opts) {
    let head = format!(
        "<DataArray type=\"{}\" Name=\"{}\" NumberOfComponents=\"{}\"",
        a.ty, a.name, a.components
    );
    let bytes = || block(&to_bytes(&a.ty, &a.values, o.big_endian), o);
    match o.enc {
        Enc::Ascii => {
            let text: Vec<String> = a.values.iter().map(|v| format!("{v}")).collect();
            out.push_str(&format!(
                "{head} format=\"ascii\">{}</DataArray>\n",
                text.join(" ")
            ));
        }
        Enc::Binary => out.push_str(&format!(
            "{head} format=\"binary\">\n{}\n</DataArray>\n",
            b64(&bytes())
        )),
        Enc::AppendedRaw | Enc::AppendedBase64 => {
            out.push_str(&format!(
                "{head} format=\"appended\" offset=\"{}\"/>\n",
                appended.len()
            ));
            if o.enc == Enc::AppendedRaw {
                appended.extend(bytes());
            } else {
                appended.extend(b64(&bytes()).into_bytes());
            }
        }
    }
}

/// A `.vtu` file of these pieces.
pub fn write(pieces: &[Piece], o: &Opts) -> Vec<u8> {
    let mut s = format!(
        "<?xml version=\"1.0\"?>\n<VTKFile type=\"UnstructuredGrid\" version=\"1.0\" byte_order=\"{}\" header_type=\"{}\"{}>\n<UnstructuredGrid>\n",
        if o.big_endian { "BigEndian" } else { "LittleEndian" },
        if o.u64_header { "UInt64" } else { "UInt32" },
        if o.zlib.is_some() { " compressor=\"vtkZLibDataCompressor\"" } else { "" }
    );
    let mut appended = Vec::new();
    for p in pieces {
        s.push_str(&format!(
            "<Piece NumberOfPoints=\"{}\" NumberOfCells=\"{}\">\n",
            p.points.len(),
            p.types.len()
        ));
        for (tag, arrays) in [("PointData", &p.point_data), ("CellData", &p.cell_data)] {
            s.push_str(&format!("<{tag}>\n"));
            for a in arrays {
                data_array(&mut s, &mut appended, a, o);
            }
            s.push_str(&format!("</{tag}>\n"));
        }
        s.push_str("<Points>\n");
        let xyz = p.points.iter().flatten().copied().collect();
        data_array(
            &mut s,
            &mut appended,
            &array("Points", "Float64", 3, xyz),
            o,
        );
        s.push_str("</Points>\n<Cells>\n");
        let it = p.index_type.as_deref().unwrap_or("Int64");
        let ints = |v: &[i64]| v.iter().map(|&x| x as f64).collect();
        let types = p.types.iter().map(|&x| x as f64).collect();
        data_array(
            &mut s,
            &mut appended,
            &array("connectivity", it, 1, ints(&p.connectivity)),
            o,
        );
        data_array(
            &mut s,
            &mut appended,
            &array("offsets", it, 1, ints(&p.offsets)),
            o,
        );
        data_array(&mut s, &mut appended, &array("types", "UInt8", 1, types), o);
        s.push_str("</Cells>\n</Piece>\n");
    }
    s.push_str("</UnstructuredGrid>\n");
    let mut out = s.into_bytes();
    if matches!(o.enc, Enc::AppendedRaw | Enc::AppendedBase64) {
        let enc = if o.enc == Enc::AppendedRaw {
            "raw"
        } else {
            "base64"
        };
        out.extend(format!("<AppendedData encoding=\"{enc}\">\n   _").into_bytes());
        out.extend(appended);
        out.extend(b"\n</AppendedData>\n");
    }
    out.extend(b"</VTKFile>\n");
    out
}

/// A unit cube's corners in VTK hexahedron order and an apex above it (the house of
/// ferrovol_core::synth).
pub fn cube_points() -> Vec<[f64; 3]> {
    ferrovol_core::synth::HOUSE_POINTS.to_vec()
}

/// One tetra with a Float32 point scalar.
pub fn one_tetra() -> Piece {
    let mut p = Piece::cells(cube_points()[..4].to_vec(), &[(10, &[0, 1, 3, 2])]);
    p.points[2] = [0.0, 0.0, 1.0];
    p.point_data
        .push(array("density", "Float32", 1, vec![0.0, 0.5, 1.0, 1.5]));
    p
}

/// An `n`×`n`×`n` grid of hexahedra, cell scalars `Int16` with 2 components.
pub fn hex_grid(n: usize) -> Piece {
    let m = n + 1;
    let id = |i: usize, j: usize, k: usize| (i + m * (j + m * k)) as i64;
    let mut points = Vec::new();
    for k in 0..m {
        for j in 0..m {
            for i in 0..m {
                points.push([i as f64, j as f64, 0.5 * k as f64]);
            }
        }
    }
    let mut p = Piece {
        points,
        ..Piece::default()
    };
    let mut values = Vec::new();
    for k in 0..n {
        for j in 0..n {
            for i in 0..n {
                p.connectivity.extend([
                    id(i, j, k),
                    id(i + 1, j, k),
                    id(i + 1, j + 1, k),
                    id(i, j + 1, k),
                    id(i, j, k + 1),
                    id(i + 1, j, k + 1),
                    id(i + 1, j + 1, k + 1),
                    id(i, j + 1, k + 1),
                ]);
                p.offsets.push(p.connectivity.len() as i64);
                p.types.push(12);
                values.extend([(i + j) as f64, -(k as f64)]);
            }
        }
    }
    p.cell_data.push(array("id", "Int16", 2, values));
    p
}

/// One cell of each type the renderer takes, each on its own copy of the points (2 apart
/// along x), with a UInt8 cell scalar.
pub fn each_cell_type() -> Piece {
    let cells: [(u8, &[i64]); 5] = [
        (10, &[0, 1, 3, 4]),
        (11, &[0, 1, 3, 2, 4, 5, 7, 6]),
        (12, &[0, 1, 2, 3, 4, 5, 6, 7]),
        (13, &[0, 1, 3, 4, 5, 7]),
        (14, &[4, 5, 6, 7, 8]),
    ];
    let mut p = Piece::default();
    for (k, (t, c)) in cells.iter().enumerate() {
        let base = p.points.len() as i64;
        p.points.extend(
            cube_points()
                .into_iter()
                .map(|q| [q[0] + 2.0 * k as f64, q[1], q[2]]),
        );
        p.connectivity.extend(c.iter().map(|&i| i + base));
        p.offsets.push(p.connectivity.len() as i64);
        p.types.push(*t);
    }
    p.cell_data.push(array(
        "kind",
        "UInt8",
        1,
        p.types.iter().map(|&t| t as f64).collect(),
    ));
    p
}

/// Every encoding the reader takes, with a name.
pub fn all_opts() -> Vec<(&'static str, Opts)> {
    let mut v = vec![("ascii", Opts::ASCII)];
    for (name, enc) in [
        ("binary", Enc::Binary),
        ("appended-raw", Enc::AppendedRaw),
        ("appended-base64", Enc::AppendedBase64),
    ] {
        v.push((name, Opts::with(enc)));
        v.push((
            name,
            Opts {
                zlib: Some(1 << 15),
                u64_header: true,
                ..Opts::with(enc)
            },
        ));
        v.push((
            name,
            Opts {
                zlib: Some(64),
                big_endian: true,
                ..Opts::with(enc)
            },
        ));
        v.push((
            name,
            Opts {
                u64_header: true,
                big_endian: true,
                ..Opts::with(enc)
            },
        ));
    }
    v
}
