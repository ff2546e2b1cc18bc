//! The path API on real files: detached data files next to their headers, and messages
//! that start with the path of the file that was wrong.

use std::path::Path;

use ferrovol_core::{ScalarLocation, ScalarType, Scalars};
use ferrovol_io::{read_volume, Format, ReadError};

mod common;
use common::TempDir;

/// Checks that reading fails with a message that starts with `path` and `words`.
fn assert_fails(r: Result<ferrovol_core::VolumeData, ReadError>, path: &Path, words: &str) {
    let m = r.expect_err("an error").to_string();
    println!("{m}");
    let want = format!("{}: {words}", path.display());
    assert!(m.starts_with(&want), "wanted {want:?} in {m}");
}

const MHD: &str = "NDims = 3\nDimSize = 3 2 2\nElementType = MET_UCHAR\nElementDataFile = ";
const NHDR: &str = "NRRD0004\ntype: uchar\ndimension: 3\nsizes: 3 2 2\nencoding: raw\ndata file: ";

#[test]
fn detached_data_files_are_read_next_to_the_header() {
    let dir = TempDir::new("detached");
    let vals: Vec<u8> = (0..12).map(|i| i * 20).collect();
    dir.write("sub/vol data.raw", &vals);
    for (name, header) in [
        ("a.mhd", format!("{MHD}sub/vol data.raw\n")),
        ("a.nhdr", format!("{NHDR}sub/vol data.raw\n")),
    ] {
        let v = read_volume(&dir.write(name, header.as_bytes())).unwrap();
        assert_eq!(v.dims, [3, 2, 2], "{name}");
        assert_eq!(v.scalars, Scalars::U8(vals.clone()), "{name}");
    }
}

#[test]
fn messages_name_the_file_that_was_wrong() {
    let dir = TempDir::new("messages");
    dir.write("short.raw", &[1, 2, 3]);
    for (name, header, what) in [
        ("s.mhd", format!("{MHD}short.raw\n"), "MetaImage voxel data"),
        ("s.nhdr", format!("{NHDR}short.raw\n"), "NRRD data"),
    ] {
        // A short data file: its own path.
        let short = dir.0.join("short.raw");
        let words = format!("truncated {what}: expected 12 bytes, found 3");
        assert_fails(
            read_volume(&dir.write(name, header.as_bytes())),
            &short,
            &words,
        );
        // A missing data file: its path.
        let p = dir.write(name, header.replace("short.raw", "gone.raw").as_bytes());
        assert_fails(
            read_volume(&p),
            &dir.0.join("gone.raw"),
            "cannot read the file",
        );
        // A bad header: the header's path.
        let p = dir.write(name, header.replace("3 2 2", "3 0 2").as_bytes());
        assert_fails(read_volume(&p), &p, "bad ");
    }
    let p = dir.write("bad.vti", b"hello");
    assert_fails(read_volume(&p), &p, "bad VTK ImageData (.vti) header");
    for name in ["a.vti", "a.nii", "a.nii.gz", "a.mha", "a.nrrd"] {
        let p = dir.0.join("nothere").join(name);
        assert_fails(read_volume(&p), &p, "cannot read the file");
    }
}

#[test]
fn the_byte_api_reads_what_the_path_api_reads() {
    let dir = TempDir::new("bytes");
    let vals: Vec<u8> = (0..12).collect();
    dir.write("d.raw", &vals);
    let header = format!("{NHDR}d.raw\n");
    let p = dir.write("h.nhdr", header.as_bytes());
    let from_file = read_volume(&p).unwrap();
    let format = Format::from_path(&p).unwrap();
    let from_bytes = format
        .parse(header.as_bytes(), |name| {
            assert_eq!(name, "d.raw");
            Ok(vals.clone())
        })
        .unwrap();
    assert_eq!(from_file.dims, from_bytes.dims);
    assert_eq!(from_file.scalars, from_bytes.scalars);
}

#[test]
fn vtu_files_are_read_as_meshes() {
    use common::vtu::{hex_grid, write, Enc, Opts};
    let dir = TempDir::new("vtu");
    let bytes = write(&[hex_grid(2)], &Opts::with(Enc::AppendedRaw));
    let p = dir.write("grid.VTU", &bytes);
    let mesh = ferrovol_io::read_unstructured(&p).unwrap();
    assert_eq!(mesh, ferrovol_io::vtu::parse(&bytes).unwrap());
    assert_eq!((mesh.points.len(), mesh.num_cells()), (27, 8));
    // read_volume points to read_unstructured.
    let m = read_volume(&p).unwrap_err().to_string();
    assert!(
        m.starts_with(&format!(
            "{}: not supported: this is an unstructured grid",
            p.display()
        )) && m.contains("read_unstructured"),
        "{m}"
    );
    // Errors name the file.
    let p = dir.write("bad.vtu", b"<VTKFile type=\"UnstructuredGrid\"/>");
    let m = ferrovol_io::read_unstructured(&p).unwrap_err().to_string();
    assert!(
        m.starts_with(&format!(
            "{}: bad VTK UnstructuredGrid (.vtu) header",
            p.display()
        )),
        "{m}"
    );
    let p = dir.0.join("nothere.vtu");
    let m = ferrovol_io::read_unstructured(&p).unwrap_err().to_string();
    assert!(m.contains("cannot read the file"), "{m}");
}

/// The seeds fuzz/make-corpus.py writes with VTK 9.2's vtkXMLUnstructuredGridWriter, in
/// every data mode: the reader reads what VTK writes.
#[test]
fn vtu_files_written_by_vtk() {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("../fuzz/corpus/vtu");
    let read = |name: &str| ferrovol_io::read_unstructured(&dir.join(name)).unwrap();
    for (name, location, components, scalars) in [
        (
            "binary-uint8-cells.vtu",
            ScalarLocation::Cells,
            1,
            ScalarType::U8,
        ),
        (
            "binary-zlib-int16-2c.vtu",
            ScalarLocation::Points,
            2,
            ScalarType::I16,
        ),
        (
            "appended-raw-float64.vtu",
            ScalarLocation::Points,
            1,
            ScalarType::F64,
        ),
        (
            "appended-raw-zlib-uint16-bigheader-pieces.vtu",
            ScalarLocation::Points,
            1,
            ScalarType::U16,
        ),
        (
            "appended-base64-int32-cells-4c.vtu",
            ScalarLocation::Cells,
            4,
            ScalarType::I32,
        ),
    ] {
        let m = read(name);
        // A hexahedron with a pyramid on its top face. VTK writes a data set that is not
        // split into pieces whole into each piece: the two-piece file holds the mesh
        // twice, merged here into 18 points and 4 cells.
        let copies = if name.contains("pieces") { 2 } else { 1 };
        assert_eq!(m.cell_types, [12, 14].repeat(copies), "{name}");
        assert_eq!(m.cell(1), &[4, 5, 6, 7, 8], "{name}");
        assert_eq!(
            (m.location, m.components, m.scalar_type()),
            (location, components, scalars),
            "{name}"
        );
        assert_eq!(m.points.len(), 9 * copies, "{name}");
        assert_eq!(m.bounds(), [0.0, 1.0, 0.0, 1.0, 0.0, 2.0], "{name}");
        // The ramp make-corpus.py writes: value i is 7 i mod 120.
        assert_eq!(m.scalars.get(1), 7.0, "{name}");
    }
    let m = read("ascii-float32-each-type.vtu");
    assert_eq!(m.cell_types, [10, 11, 12, 13, 14]);
    assert_eq!(m.cell(4), &[40, 41, 42, 43, 44]);
    assert_eq!(m.scalars.get(44), (44 * 7 % 120) as f64);
    let m = read("ascii-quadratic-tetra.vtu");
    assert_eq!((m.cell_types, m.connectivity), (vec![10], vec![0, 1, 3, 4]));
}
