use super::*;
use crate::params::Scalars;
use crate::synth;

#[test]
fn quads_split_through_their_smallest_point() {
    assert_eq!(split_quad([5, 2, 7, 9]), [[2, 7, 9], [2, 9, 5]]);
    assert_eq!(split_quad([1, 8, 3, 6]), [[1, 8, 3], [1, 3, 6]]);
}

#[test]
fn every_cell_type_splits_into_tetrahedra_of_its_volume() {
    // the house: a unit cube (12 tetrahedra around its centroid) and a pyramid (2)
    let t = tetrahedralize(&synth::house()).unwrap();
    assert_eq!(t.tets.len(), 14);
    assert_eq!(t.points.len(), 10, "the cube's centroid is added");
    assert_eq!(
        t.point_scalars[9], 0.5,
        "the centroid's scalar is the corners' mean"
    );
    let vol = |range: std::ops::Range<usize>| -> f64 {
        t.tets[range]
            .iter()
            .map(|q| signed_volume6(q.map(|i| t.points[i as usize])) / 6.0)
            .sum()
    };
    assert!((vol(0..12) - 1.0).abs() < 1e-12);
    assert!((vol(12..14) - 1.0 / 3.0).abs() < 1e-12);
    assert!(t
        .tets
        .iter()
        .all(|q| signed_volume6(q.map(|i| t.points[i as usize])) > 0.0));
}

/// Two prisms of `sides` sides (VTK_PENTAGONAL_PRISM or VTK_HEXAGONAL_PRISM), regular
/// polygons of circumradius 1 stacked along z (heights 0, 1, 2), sharing the middle
/// polygon. Each level's points are numbered turned by two, so no cell lists a shared
/// face's smallest point first.
fn stacked_prisms(sides: usize) -> UnstructuredVolume {
    let index = |level: usize, i: usize| (level * sides + (i + 2 * level) % sides) as u32;
    let mut points = vec![[0.0; 3]; 3 * sides];
    for level in 0..3 {
        for i in 0..sides {
            let a = std::f64::consts::TAU * i as f64 / sides as f64;
            points[index(level, i) as usize] = [a.cos(), a.sin(), level as f64];
        }
    }
    let connectivity: Vec<u32> = (0..2)
        .flat_map(|layer| (0..2 * sides).map(move |k| index(layer + k / sides, k % sides)))
        .collect();
    let scalars = points.iter().map(|p| (p[0] + p[2]) as f32).collect();
    UnstructuredVolume::from_vtk(
        points,
        connectivity,
        vec![0, 2 * sides as u32, 4 * sides as u32],
        vec![
            if sides == 5 {
                CellType::PentagonalPrism.vtk_code()
            } else {
                CellType::HexagonalPrism.vtk_code()
            };
            2
        ],
        ScalarLocation::Points,
        1,
        Scalars::F32(scalars),
    )
    .unwrap()
}

#[test]
fn prisms_split_into_tetrahedra_of_their_volume_around_their_centroids() {
    for (sides, per_cell) in [(5, 16), (6, 20)] {
        let v = stacked_prisms(sides);
        let t = tetrahedralize(&v).unwrap();
        assert_eq!(t.tets.len(), 2 * per_cell, "{sides} sides");
        assert_eq!(t.points.len(), 3 * sides + 2, "a centroid per prism");
        assert!((t.points[3 * sides][2] - 0.5).abs() < 1e-12);
        let area = sides as f64 / 2.0 * (std::f64::consts::TAU / sides as f64).sin();
        for cell in 0..2 {
            let vol: f64 = (0..t.tets.len())
                .filter(|&k| t.tet_cell[k] == cell)
                .map(|k| signed_volume6(t.tets[k].map(|i| t.points[i as usize])) / 6.0)
                .sum();
            assert!(
                (vol - area).abs() < 1e-12,
                "{sides} sides: {vol} against {area}"
            );
        }
        assert!(t
            .tets
            .iter()
            .all(|q| signed_volume6(q.map(|i| t.points[i as usize])) > 0.0));
        // the shared polygon is split alike from both sides: only the outer faces' triangles
        // are on the boundary (two end polygons, 2 × sides quads)
        let m = TetMesh::prepare(&v).unwrap();
        assert_eq!(
            m.boundary.len(),
            2 * (sides - 2) + 2 * sides * 2,
            "{sides} sides"
        );
    }
    assert_eq!(
        split_polygon(&[7, 3, 9, 4, 8]),
        [[3, 9, 4], [3, 4, 8], [3, 8, 7]]
    );
}

#[test]
fn neighbours_agree_and_the_boundary_is_closed() {
    for v in [
        synth::house(),
        synth::mixed_cells(3, ScalarLocation::Points),
        synth::hollow_cylinder(2, 8, 2),
        stacked_prisms(5),
        stacked_prisms(6),
    ] {
        let m = TetMesh::prepare(&v).unwrap();
        let mut boundary = 0;
        for (t, nb) in m.neighbours.iter().enumerate() {
            for (f, &n) in nb.iter().enumerate() {
                if n == BOUNDARY {
                    boundary += 1;
                    continue;
                }
                let back = m.neighbours[(n / 4) as usize][(n % 4) as usize];
                assert_eq!(back, 4 * t as u32 + f as u32, "neighbours point back");
            }
        }
        assert_eq!(boundary, m.boundary.len());
        // every boundary edge is shared by two boundary triangles: a closed surface, so
        // the split conforms (matching triangles across every shared quad)
        let mut edges = HashMap::<[u32; 2], u32>::new();
        for &tf in &m.boundary {
            let t = m.tets[(tf / 4) as usize];
            let f = TET_FACES[(tf % 4) as usize].map(|k| t[k]);
            for e in [[f[0], f[1]], [f[1], f[2]], [f[2], f[0]]] {
                *edges.entry([e[0].min(e[1]), e[0].max(e[1])]).or_default() += 1;
            }
        }
        assert!(edges.values().all(|&c| c == 2), "an open boundary");
        // the hierarchy holds every boundary triangle once, each leaf within its box
        let mut seen = vec![0; m.boundary.len()];
        for n in m.bvh.nodes.iter().filter(|n| n.count > 0) {
            for i in n.a..n.a + n.count {
                seen[i as usize] += 1;
            }
        }
        assert!(seen.iter().all(|&c| c == 1));
        let leaves = m.boundary.len().div_ceil(bvh::LEAF) as f64;
        assert!(
            m.bvh.depth <= leaves.log2().ceil() as usize + 2,
            "median splits"
        );
    }
}

#[test]
fn a_triangle_of_three_tetrahedra_is_refused_naming_the_cells() {
    // a quad's triangle shared by two tetrahedra: the cells' own check sees a quad and two
    // triangles, the tetrahedra's check a triangle of three (core/tests/unstructured.rs
    // has three tetrahedra on one face, which the cells' check refuses)
    let hex_and_tets = UnstructuredVolume {
        points: synth::HOUSE_POINTS
            .iter()
            .copied()
            .chain([[0.5, 0.5, -1.0], [0.2, 0.2, -2.0]])
            .collect(),
        connectivity: vec![0, 1, 2, 3, 4, 5, 6, 7, 0, 2, 1, 9, 0, 2, 1, 10],
        offsets: vec![0, 8, 12, 16],
        cell_types: vec![12, 10, 10],
        location: ScalarLocation::Cells,
        components: 1,
        scalars: Scalars::F32(vec![1.0, 2.0, 3.0]),
    };
    let e = TetMesh::prepare(&hex_and_tets).unwrap_err().to_string();
    assert!(
        e.contains("cells 0, 1 and 2") || e.contains("more than two"),
        "{e}"
    );
}

#[test]
fn flat_tetrahedra_are_left_out_and_flat_cells_refused() {
    let mut v = synth::house();
    // the roof's apex down onto the top face: the pyramid is flat
    v.points[8] = [0.5, 0.5, 1.0];
    let e = TetMesh::prepare(&v).unwrap_err().to_string();
    assert!(e.contains("cell 1") && e.contains("no volume"), "{e}");
    // a cube with its top face collapsed onto a plane tilted through it keeps volume in
    // some tetrahedra: those without are counted
    let mut w = synth::house();
    w.points[8] = [0.5, 0.5, 1.5];
    w.points[6] = [1.0, 1.0, 0.0 + 1e-12];
    let t = tetrahedralize(&w).unwrap();
    assert!(t.flat > 0 && t.tets.len() + t.flat == 14, "{} flat", t.flat);
}

#[test]
fn the_mixed_mesh_splits_into_its_whole_volume() {
    // n³ unit cubes whose boundary points stay in place: hexahedra, wedges, pyramids and
    // tetrahedra, distorted inside, fill the n³ box exactly
    let t = tetrahedralize(&synth::mixed_cells(3, ScalarLocation::Cells)).unwrap();
    let total: f64 = t
        .tets
        .iter()
        .map(|q| signed_volume6(q.map(|i| t.points[i as usize])) / 6.0)
        .sum();
    assert!((total - 27.0).abs() < 1e-9, "{total}");
    assert_eq!(t.flat, 0);
}

#[test]
fn a_mesh_past_the_binding_size_is_refused_with_the_sizes() {
    let e = gpu::check_binding_size("tetrahedra", 200, 128)
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("200 bytes") && e.contains("at most 128 bytes"),
        "{e}"
    );
    assert!(gpu::check_binding_size("tetrahedra", 128, 128).is_ok());
}

#[test]
fn tetrahedra_past_one_binding_split_over_two_and_past_two_are_refused() {
    // 16 bytes each: a binding of 160 bytes holds 10
    assert_eq!(gpu::first_half(7, 160).unwrap(), 7);
    assert_eq!(gpu::first_half(10, 160).unwrap(), 10);
    assert_eq!(gpu::first_half(11, 160).unwrap(), 10);
    assert_eq!(gpu::first_half(20, 160).unwrap(), 10);
    let e = gpu::first_half(21, 160).unwrap_err().to_string();
    assert!(
        e.contains("336 bytes") && e.contains("two storage buffers of 160 bytes"),
        "{e}"
    );
}
