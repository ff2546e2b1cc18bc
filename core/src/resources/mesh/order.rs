//! The prepared mesh's memory order: points, then tetrahedra, sorted along a Z-order (Morton)
//! curve over the mesh's bounds. A ray walks from a tetrahedron to a neighbour, and rays of
//! neighbouring pixels through the same tetrahedra: in this order both are near in memory,
//! where the cells' own order (a grid's, slab after slab) puts a step across slabs
//! megabytes away, and the walk waits on memory.

/// Bits per axis of the curve's grid.
const BITS: u32 = 21;

/// The Morton code of a position in `[lo, hi]` (per axis; flat axes give 0).
fn morton(p: [f64; 3], lo: [f64; 3], hi: [f64; 3]) -> u64 {
    let cells = ((1u64 << BITS) - 1) as f64;
    let mut code = 0u64;
    for a in 0..3 {
        let span = hi[a] - lo[a];
        let u = if span > 0.0 {
            (p[a] - lo[a]) / span
        } else {
            0.0
        };
        let q = (u.clamp(0.0, 1.0) * cells) as u64;
        for b in 0..BITS as u64 {
            code |= ((q >> b) & 1) << (3 * b + a as u64);
        }
    }
    code
}

/// The indices of `keys` in ascending order of key (ties by index).
fn sorted_order(keys: &[u64]) -> Vec<u32> {
    let mut order: Vec<u32> = (0..keys.len() as u32).collect();
    order.sort_unstable_by_key(|&i| (keys[i as usize], i));
    order
}

/// Sorts the points (with their scalars) and the tetrahedra (with their cells) in Morton
/// order within `bounds` (`[xmin, xmax, ymin, ymax, zmin, zmax]`): points by position,
/// tetrahedra by centroid; each tetrahedron keeps its points' order (its orientation).
pub(crate) fn morton_order(
    points: &mut Vec<[f64; 3]>,
    point_scalars: &mut Vec<f64>,
    tets: &mut Vec<[u32; 4]>,
    tet_cell: &mut Vec<u32>,
    bounds: [f64; 6],
) {
    let lo = [bounds[0], bounds[2], bounds[4]];
    let hi = [bounds[1], bounds[3], bounds[5]];
    let keys: Vec<u64> = points.iter().map(|&p| morton(p, lo, hi)).collect();
    let order = sorted_order(&keys);
    let mut rank = vec![0u32; order.len()];
    for (new, &old) in order.iter().enumerate() {
        rank[old as usize] = new as u32;
    }
    *points = order.iter().map(|&i| points[i as usize]).collect();
    *point_scalars = order.iter().map(|&i| point_scalars[i as usize]).collect();
    for t in tets.iter_mut() {
        *t = t.map(|i| rank[i as usize]);
    }
    let keys: Vec<u64> = tets
        .iter()
        .map(|t| {
            let c = [0, 1, 2].map(|a| t.iter().map(|&i| points[i as usize][a]).sum::<f64>() / 4.0);
            morton(c, lo, hi)
        })
        .collect();
    let order = sorted_order(&keys);
    *tets = order.iter().map(|&i| tets[i as usize]).collect();
    *tet_cell = order.iter().map(|&i| tet_cell[i as usize]).collect();
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn morton_interleaves_the_axes() {
        let lo = [0.0; 3];
        let hi = [1.0; 3];
        assert_eq!(morton([0.0; 3], lo, hi), 0);
        assert_eq!(morton([1.0, 0.0, 0.0], lo, hi) & 0b111, 0b001);
        assert_eq!(morton([0.0, 1.0, 0.0], lo, hi) & 0b111, 0b010);
        assert_eq!(morton([0.0, 0.0, 1.0], lo, hi) & 0b111, 0b100);
        assert_eq!(morton([1.0, 1.0, 1.0], lo, hi), (1 << (3 * BITS)) - 1);
    }

    #[test]
    fn reordering_keeps_every_tetrahedron() {
        let mut points = vec![
            [1.0, 1.0, 1.0],
            [0.0, 0.0, 0.0],
            [1.0, 0.0, 0.0],
            [0.0, 1.0, 0.0],
            [0.0, 0.0, 1.0],
        ];
        let mut scalars: Vec<f64> = (0..5).map(|i| i as f64).collect();
        let before_points = points.clone();
        let mut tets = vec![[1, 2, 3, 4], [2, 3, 4, 0]];
        let before: Vec<[[f64; 3]; 4]> =
            tets.iter().map(|t| t.map(|i| points[i as usize])).collect();
        let mut cells = vec![7, 9];
        morton_order(
            &mut points,
            &mut scalars,
            &mut tets,
            &mut cells,
            [0.0, 1.0, 0.0, 1.0, 0.0, 1.0],
        );
        for (t, c) in tets.iter().zip(&cells) {
            let corners = t.map(|i| points[i as usize]);
            let was = if *c == 7 { before[0] } else { before[1] };
            assert_eq!(corners, was);
            for &i in t {
                let old = before_points
                    .iter()
                    .position(|p| *p == points[i as usize])
                    .unwrap();
                assert_eq!(scalars[i as usize], old as f64);
            }
        }
        assert_eq!(points[0], [0.0, 0.0, 0.0]);
    }
}
