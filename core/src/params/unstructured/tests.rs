use super::*;

/// A unit cube's 8 corners in VTK hexahedron order, and one more point (the apex of a
/// pyramid on top): the house of [`crate::synth`].
fn points() -> Vec<[f64; 3]> {
    crate::synth::HOUSE_POINTS.to_vec()
}

/// One tetra with point scalars.
fn tetra() -> UnstructuredVolume {
    UnstructuredVolume {
        points: points(),
        connectivity: vec![0, 1, 3, 4],
        offsets: vec![0, 4],
        cell_types: vec![10],
        location: ScalarLocation::Points,
        components: 1,
        scalars: Scalars::F32((0..9).map(|i| i as f32).collect()),
    }
}

fn err(v: &UnstructuredVolume) -> String {
    match v.validate() {
        Ok(()) => panic!("expected an error for {v:?}"),
        Err(e) => e.to_string(),
    }
}

#[track_caller]
fn refuses(v: UnstructuredVolume, words: &str) {
    let m = err(&v);
    assert!(m.contains(words), "wanted {words:?} in {m}");
}

#[test]
fn one_of_each_cell_type_is_valid() {
    // Each cell on its own copy of the points, 2 apart along x.
    let cells: [&[u32]; 5] = [
        &[0, 1, 3, 4],
        &[0, 1, 3, 2, 4, 5, 7, 6],
        &[0, 1, 2, 3, 4, 5, 6, 7],
        &[0, 1, 3, 4, 5, 7],
        &[4, 5, 6, 7, 8],
    ];
    let mut offsets = vec![0];
    let mut connectivity = vec![];
    for (k, cell) in cells.iter().enumerate() {
        connectivity.extend(cell.iter().map(|&p| p + 9 * k as u32));
        offsets.push(connectivity.len() as u32);
    }
    let v = UnstructuredVolume {
        points: (0..5)
            .flat_map(|k| {
                points()
                    .into_iter()
                    .map(move |p| [p[0] + 2.0 * k as f64, p[1], p[2]])
            })
            .collect(),
        connectivity,
        offsets,
        cell_types: vec![10, 11, 12, 13, 14],
        location: ScalarLocation::Cells,
        components: 2,
        scalars: Scalars::U8(vec![1; 10]),
    };
    v.validate().unwrap();
    assert_eq!(v.num_cells(), 5);
    assert_eq!(v.cell(4), &[40, 41, 42, 43, 44]);
    assert_eq!(v.cell_type(1), Some(CellType::Voxel));
    assert_eq!(v.bounds(), [0.0, 9.0, 0.0, 1.0, 0.0, 2.0]);
    for code in [0, 9, 17, 24, 255] {
        assert_eq!(CellType::from_vtk(code), None);
    }
    for ty in CellType::ALL {
        assert_eq!(CellType::from_vtk(ty.vtk_code()), Some(ty));
        assert_eq!(
            vtk_cell_type_name(ty.vtk_code()).replace('_', ""),
            format!("VTK{:?} ({})", ty, ty.vtk_code()).to_uppercase()
        );
        for f in ty.faces() {
            assert!(f.iter().all(|&i| i < ty.num_points()));
            assert!(f.len() <= CellType::MAX_FACE_POINTS);
        }
    }
}

#[test]
fn dangling_index() {
    let mut v = tetra();
    v.connectivity[2] = 9;
    refuses(
        v,
        "cell 0 (VTK_TETRA (10)) refers to point 9, but the mesh has 9 points",
    );
}

#[test]
fn offsets_must_increase_and_match() {
    let mut v = tetra();
    v.offsets = vec![0, 4, 4];
    v.cell_types = vec![10, 10];
    refuses(v, "offsets do not increase at cell 1: 4 then 4");
    let mut v = tetra();
    v.offsets = vec![0, 3];
    refuses(
        v,
        "the last offset is 3, but the connectivity has 4 entries",
    );
    let mut v = tetra();
    v.offsets = vec![1, 4];
    refuses(v, "the first offset is 1, not 0");
    let mut v = tetra();
    v.offsets = vec![4];
    refuses(v, "1 offsets for 1 cells: expected 2");
    let mut v = tetra();
    v.cell_types.clear();
    refuses(v, "no cells");
}

#[test]
fn wrong_number_of_points() {
    let mut v = tetra();
    v.cell_types = vec![12];
    refuses(
        v,
        "cell 0 (VTK_HEXAHEDRON (12)) has 4 points; that type has 8",
    );
}

#[test]
fn unsupported_cell_types_are_named() {
    for (code, name) in [
        (5, "VTK_TRIANGLE (5)"),
        (42, "VTK_POLYHEDRON (42)"),
        (200, "an unknown cell type (200)"),
    ] {
        let mut v = tetra();
        v.cell_types = vec![code];
        refuses(v, &format!("cell 0 is {name}"));
    }
}

#[test]
fn non_finite_points() {
    let mut v = tetra();
    v.points[3][1] = f64::NAN;
    refuses(v, "point 3 is [0.0, NaN, 0.0]");
    let mut v = tetra();
    v.points[8][2] = 1e300;
    refuses(v, "bounds along z");
    let mut v = tetra();
    v.points.clear();
    refuses(v, "no points");
}

#[test]
fn scalar_length_and_values() {
    let mut v = tetra();
    v.scalars = Scalars::F32(vec![0.0; 8]);
    refuses(
        v,
        "8 scalar values for 9 points with 1 component(s): expected 9",
    );
    let mut v = tetra();
    v.location = ScalarLocation::Cells;
    refuses(v, "9 scalar values for 1 cells");
    let mut v = tetra();
    v.components = 5;
    refuses(v, "5 components per point");
    let mut v = tetra();
    v.scalars = Scalars::F64(vec![0.0, 1.0, f64::INFINITY, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0]);
    refuses(v, "scalar of point 2 component 0 is inf");
}

#[test]
fn degenerate_cells() {
    let mut v = tetra();
    v.connectivity = vec![0, 1, 1, 4];
    refuses(v, "cell 0 (VTK_TETRA (10)) lists point 1 twice");
}

#[test]
fn non_manifold_faces() {
    // Three tetras on the face 0-1-3.
    let mut v = tetra();
    v.connectivity = vec![0, 1, 3, 4, 0, 1, 3, 2, 3, 1, 0, 8];
    v.offsets = vec![0, 4, 8, 12];
    v.cell_types = vec![10; 3];
    refuses(
        v,
        "the face with points [0, 1, 3] belongs to more than two cells (cells 0 and 2",
    );
    // Two are fine.
    let mut v = tetra();
    v.connectivity = vec![0, 1, 3, 4, 0, 1, 3, 2];
    v.offsets = vec![0, 4, 8];
    v.cell_types = vec![10; 2];
    v.validate().unwrap();
}

#[test]
fn quadratic_cells_keep_their_corners() {
    let mut pts = points();
    pts.extend((0..20).map(|i| [0.1 * i as f64, 0.5, 0.5]));
    let quad_tet: Vec<u32> = [0, 1, 3, 4].into_iter().chain(9..15).collect();
    let quad_hex: Vec<u32> = (0..8).chain(9..21).collect();
    let v = UnstructuredVolume::from_vtk(
        pts,
        [quad_tet, quad_hex].concat(),
        vec![0, 10, 30],
        vec![24, 25],
        ScalarLocation::Cells,
        1,
        Scalars::I16(vec![1, 2]),
    )
    .unwrap();
    assert_eq!(v.cell_types, vec![10, 12]);
    assert_eq!(v.offsets, vec![0, 4, 12]);
    assert_eq!(v.cell(0), &[0, 1, 3, 4]);
    assert_eq!(v.cell(1), &[0, 1, 2, 3, 4, 5, 6, 7]);
    // A quadratic cell with the wrong count is named as it was.
    let e = UnstructuredVolume::from_vtk(
        points(),
        vec![0, 1, 3, 4],
        vec![0, 4],
        vec![24],
        ScalarLocation::Cells,
        1,
        Scalars::I16(vec![1]),
    )
    .unwrap_err()
    .to_string();
    assert!(
        e.contains("cell 0 (VTK_QUADRATIC_TETRA (24)) has 4 points; that type has 10"),
        "{e}"
    );
}
