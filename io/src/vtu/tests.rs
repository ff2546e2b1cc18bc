//! Tests of the .vtu reader: every encoding and compression, both byte orders, several
//! pieces, bad meshes, and damaged or hostile files.

use super::parse;
use crate::test_util::{check_errors, msg, never_panics};
use ferrovol_core::{ScalarLocation, Scalars};

#[path = "../../tests/common/vtu.rs"]
mod writer;
use writer::*;

#[test]
fn readers_vtu_one_tetra_in_every_encoding() {
    for (name, o) in all_opts() {
        let v = parse(&write(&[one_tetra()], &o)).unwrap_or_else(|e| panic!("{name} {o:?}: {e}"));
        assert_eq!(v.points[2], [0.0, 0.0, 1.0], "{name}");
        assert_eq!(
            (v.connectivity, v.offsets, v.cell_types),
            (vec![0, 1, 3, 2], vec![0, 4], vec![10])
        );
        assert_eq!(v.location, ScalarLocation::Points);
        assert_eq!(
            v.scalars,
            Scalars::F32(vec![0.0, 0.5, 1.0, 1.5]),
            "{name} {o:?}"
        );
    }
}

#[test]
fn readers_vtu_each_cell_type_and_a_hex_grid() {
    for (name, o) in all_opts() {
        let v = parse(&write(&[each_cell_type()], &o)).unwrap();
        assert_eq!(v.cell_types, vec![10, 11, 12, 13, 14], "{name}");
        assert_eq!(v.cell(4), &[40, 41, 42, 43, 44]);
        assert_eq!(v.scalars, Scalars::U8(vec![10, 11, 12, 13, 14]));
        let v = parse(&write(&[hex_grid(3)], &o)).unwrap();
        assert_eq!((v.points.len(), v.num_cells(), v.components), (64, 27, 2));
        assert_eq!(v.location, ScalarLocation::Cells);
        assert_eq!(v.bounds(), [0.0, 3.0, 0.0, 3.0, 0.0, 1.5]);
        let Scalars::I16(s) = &v.scalars else {
            panic!("{:?}", v.scalars)
        };
        assert_eq!(&s[52..], &[4, -2]);
    }
}

#[test]
fn readers_vtu_index_types() {
    for ty in ["Int32", "UInt32", "Int64", "UInt64", "UInt16", "Int8"] {
        for be in [false, true] {
            let mut p = each_cell_type();
            p.index_type = Some(ty.into());
            let o = Opts {
                big_endian: be,
                ..Opts::with(Enc::AppendedRaw)
            };
            let v = parse(&write(&[p], &o)).unwrap_or_else(|e| panic!("{ty}: {e}"));
            assert_eq!(v.offsets.last(), Some(&31));
        }
    }
}

#[test]
fn readers_vtu_pieces_are_merged() {
    for (name, o) in all_opts() {
        let v = parse(&write(&[one_tetra(), Piece::default(), one_tetra()], &o)).unwrap();
        assert_eq!(v.connectivity, vec![0, 1, 3, 2, 4, 5, 7, 6], "{name}");
        assert_eq!(v.offsets, vec![0, 4, 8]);
        assert_eq!(v.points.len(), 8);
        assert_eq!(v.scalars.len(), 8);
    }
    let mut other = one_tetra();
    other.point_data[0].ty = "Float64".into();
    let m = msg(parse(&write(&[one_tetra(), other], &Opts::ASCII)));
    assert!(m.contains("piece 2's scalars (float64 point data"), "{m}");
}

#[test]
fn readers_vtu_quadratic_cells_are_linearised() {
    let mut p = one_tetra();
    p.points.extend((0..6).map(|i| [0.1 * i as f64, 0.1, 0.1]));
    p.connectivity.extend(4..10);
    p.offsets = vec![10];
    p.types = vec![24];
    p.point_data[0].values.extend([0.0; 6]);
    let v = parse(&write(&[p], &Opts::ASCII)).unwrap();
    assert_eq!((v.cell_types, v.connectivity), (vec![10], vec![0, 1, 3, 2]));
}

/// A tetra file changed by `f`.
fn tetra_with(f: impl FnOnce(&mut Piece)) -> Vec<u8> {
    let mut p = one_tetra();
    f(&mut p);
    write(&[p], &Opts::ASCII)
}

#[test]
fn readers_vtu_bad_meshes() {
    let tetra = String::from_utf8(write(&[one_tetra()], &Opts::ASCII)).unwrap();
    check_errors(
        parse,
        &[
            ("dangling", tetra_with(|p| p.connectivity[1] = 7), "refers to point 7, but the mesh has 4 points"),
            ("unknown type", tetra_with(|p| p.types[0] = 99), "cell 0 is an unknown cell type (99)"),
            ("triangle", tetra_with(|p| p.types[0] = 5), "cell 0 is VTK_TRIANGLE (5)"),
            ("degenerate", tetra_with(|p| p.connectivity[1] = 0), "lists point 0 twice"),
            ("count", tetra_with(|p| p.types[0] = 12), "has 4 points; that type has 8"),
            ("decreasing offsets", tetra_with(|p| {
                p.offsets = vec![4, 4];
                p.types = vec![10, 10];
            }), "offsets do not increase at cell 1: 4 then 4"),
            ("negative index", tetra_with(|p| p.connectivity[0] = -1), "value #1 is -1; it must be 0 to 4294967295"),
            ("type too big", tetra.replace(">10</DataArray>", ">300</DataArray>").into_bytes(), "'types': value #1 is 300; it must be 0 to 255"),
            ("nan point", tetra_with(|p| p.points[1][0] = f64::NAN), "point 1 is [NaN, 0.0, 0.0]"),
            ("inf point", tetra_with(|p| p.points[1][0] = f64::INFINITY), "point 1 is [inf, 0.0, 0.0]"),
            ("scalar count", tetra_with(|p| p.point_data[0].values.pop().map(|_| ()).unwrap()), "found 3 values, expected 4"),
            ("no scalars", tetra_with(|p| p.point_data.clear()), "the piece has no <DataArray> in <PointData> or <CellData>"),
            ("5 components", tetra_with(|p| {
                p.point_data[0].components = 5;
                p.point_data[0].values = vec![0.0; 20];
            }), "5 components; ferrovol renders 1 to 4"),
            ("short connectivity", tetra.replace(">0 1 3 2<", ">0 1 3<").into_bytes(), "found 3 values, expected 4"),
            ("no types", tetra.replace("Name=\"types\"", "Name=\"kinds\"").into_bytes(), "has no DataArray named 'types'"),
            ("no points", tetra.replace("Points>", "Pointz>").into_bytes(), "the piece has no <Points> <DataArray>"),
            ("2d points", tetra.replace("Name=\"Points\" NumberOfComponents=\"3\"", "Name=\"Points\" NumberOfComponents=\"2\"").into_bytes(), "points have 3"),
            ("NumberOfPoints", tetra.replace("NumberOfPoints=\"4\"", "NumberOfPoints=\"x\"").into_bytes(), "NumberOfPoints=\"x\" is not a non-negative integer"),
            ("image", tetra.replace("type=\"UnstructuredGrid\"", "type=\"ImageData\"").into_bytes(), "the file holds VTK ImageData data, not UnstructuredGrid"),
            ("no piece", b"<VTKFile type=\"UnstructuredGrid\"><UnstructuredGrid/></VTKFile>".to_vec(), "no <Piece>"),
            ("empty", b"<VTKFile type=\"UnstructuredGrid\"><UnstructuredGrid><Piece NumberOfPoints=\"0\" NumberOfCells=\"0\"/></UnstructuredGrid></VTKFile>".to_vec(), "every <Piece> is empty"),
            ("not xml", b"hello".to_vec(), "no <VTKFile> element"),
        ],
    );
}

#[test]
fn readers_vtu_non_manifold_face() {
    let p = Piece::cells(
        cube_points(),
        &[
            (10, &[0, 1, 3, 4]),
            (10, &[0, 1, 3, 2]),
            (10, &[3, 1, 0, 8]),
        ],
    );
    let mut p = p;
    p.cell_data.push(array("c", "UInt8", 1, vec![1.0; 3]));
    let m = msg(parse(&write(&[p], &Opts::ASCII)));
    assert!(m.contains("belongs to more than two cells"), "{m}");
}

#[test]
fn readers_vtu_absurd_sizes_fail_before_allocating() {
    let tetra = String::from_utf8(write(&[one_tetra()], &Opts::ASCII)).unwrap();
    let m = msg(parse(
        tetra
            .replace("NumberOfPoints=\"4\"", "NumberOfPoints=\"1000000000000\"")
            .as_bytes(),
    ));
    assert!(m.contains("found 12 values, expected 3000000000000"), "{m}");
    let m = msg(parse(
        tetra
            .replace(
                "NumberOfPoints=\"4\"",
                "NumberOfPoints=\"18446744073709551615\"",
            )
            .as_bytes(),
    ));
    assert!(m.contains("too large") || m.contains("address"), "{m}");
    // A last offset of 2^32 - 1.
    let m = msg(parse(
        tetra
            .replace(">4</DataArray>", ">4294967295</DataArray>")
            .as_bytes(),
    ));
    assert!(m.contains("found 4 values, expected 4294967295"), "{m}");
}

#[test]
fn readers_vtu_never_panics_on_damaged_files() {
    let o = Opts {
        zlib: Some(16),
        ..Opts::with(Enc::AppendedRaw)
    };
    never_panics(parse, &write(&[one_tetra()], &o), &[0, b'9', 0xff, b'<']);
    never_panics(parse, &write(&[one_tetra()], &Opts::ASCII), b"09\"");
}

#[test]
fn readers_vtu_many_pieces_take_linear_time() {
    // 20 000 tetra pieces in raw appended data (about 3 MB): each array is found in the
    // appended section without scanning the section again.
    let pieces = vec![one_tetra(); 20_000];
    let mut file = write(&pieces, &Opts::with(Enc::AppendedRaw));
    // Without its closing tags, as in a cut file, the section runs to the end.
    file.truncate(file.len() - b"\n</AppendedData>\n</VTKFile>\n".len());
    let start = std::time::Instant::now();
    let v = parse(&file).unwrap();
    assert_eq!(v.num_cells(), 20_000);
    let took = start.elapsed();
    assert!(took < std::time::Duration::from_secs(3), "took {took:?}");
}
