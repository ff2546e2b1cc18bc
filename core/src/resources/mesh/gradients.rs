//! The scalar's gradient at every point of a prepared mesh, which shaded frames interpolate
//! across each tetrahedron (unstructured.wgsl) for smooth lighting.
//!
//! Each tetrahedron has one gradient: that of its linear interpolant with point scalars,
//! Σ sᵢ ∇λᵢ over its barycentric coordinates λᵢ; with cell scalars (constant in each
//! tetrahedron), Green–Gauss over its faces, each face's value the mean of the cell's and
//! the neighbour's across it (the cell's own on the boundary), which is
//! Σ −(3/2)(s_nᵢ − s) ∇λᵢ, nᵢ the neighbour across the face opposite point i. A point's
//! gradient is the mean of its tetrahedra's weighted by their volumes. Gradients are in the
//! mesh's coordinates (scalar units per unit of length).

use super::BOUNDARY;
use glam::DVec3;

/// The gradients of the barycentric coordinates of the tetrahedron of points `p` and its
/// signed volume times six; `None` for a flat one.
fn barycentric_gradients(p: [DVec3; 4]) -> Option<([DVec3; 4], f64)> {
    let (e1, e2, e3) = (p[1] - p[0], p[2] - p[0], p[3] - p[0]);
    let c = [e2.cross(e3), e3.cross(e1), e1.cross(e2)];
    let det = e1.dot(c[0]);
    if det == 0.0 || !det.is_finite() {
        return None;
    }
    let g = c.map(|v| v / det);
    Some(([-(g[0] + g[1] + g[2]), g[0], g[1], g[2]], det))
}

/// Per point of `points` (xyz, w the point scalar), its gradient as xyz (w 0): of the point
/// scalars, or of `cell_scalars` (one per tetrahedron) when there are any.
pub(crate) fn point_gradients(
    points: &[[f32; 4]],
    tets: &[[u32; 4]],
    neighbours: &[[u32; 4]],
    cell_scalars: &[f32],
) -> Vec<[f32; 4]> {
    let mut sum = vec![(DVec3::ZERO, 0.0f64); points.len()];
    for (t, ids) in tets.iter().enumerate() {
        let p = ids.map(|i| {
            let q = points[i as usize];
            DVec3::new(q[0] as f64, q[1] as f64, q[2] as f64)
        });
        let Some((grads, det)) = barycentric_gradients(p) else {
            continue;
        };
        let weights: [f64; 4] = if cell_scalars.is_empty() {
            ids.map(|i| points[i as usize][3] as f64)
        } else {
            let s = cell_scalars[t] as f64;
            neighbours[t].map(|n| {
                let across = if n == BOUNDARY {
                    s
                } else {
                    cell_scalars[(n / 4) as usize] as f64
                };
                -1.5 * (across - s)
            })
        };
        let g: DVec3 = weights.iter().zip(&grads).map(|(w, gi)| *w * *gi).sum();
        let volume = det.abs();
        for &i in ids {
            let acc = &mut sum[i as usize];
            acc.0 += volume * g;
            acc.1 += volume;
        }
    }
    sum.iter()
        .map(|&(g, w)| {
            let g = if w > 0.0 { g / w } else { DVec3::ZERO };
            [g.x as f32, g.y as f32, g.z as f32, 0.0]
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A linear field's gradient is exact at every point, whichever tetrahedra meet there.
    #[test]
    fn a_linear_field_has_its_gradient_everywhere() {
        let f = |p: [f32; 3]| 2.0 * p[0] - 3.0 * p[1] + 0.5 * p[2] + 1.0;
        let corners = [
            [0.0, 0.0, 0.0],
            [1.0, 0.0, 0.0],
            [0.0, 1.0, 0.0],
            [0.0, 0.0, 1.0],
            [1.0, 1.0, 1.0],
        ];
        let points: Vec<[f32; 4]> = corners.iter().map(|&p| [p[0], p[1], p[2], f(p)]).collect();
        let tets = [[0, 1, 2, 3], [1, 2, 3, 4]];
        let none = [[BOUNDARY; 4]; 2];
        for g in point_gradients(&points, &tets, &none, &[]) {
            for (a, want) in [2.0, -3.0, 0.5].iter().enumerate() {
                assert!((g[a] - want).abs() < 1e-5, "{g:?}");
            }
        }
    }

    /// Cell scalars: two tetrahedra across a face, the second's scalar higher, give a
    /// gradient pointing across that face; equal scalars give none.
    #[test]
    fn cell_scalars_give_the_gradient_across_faces() {
        let points: Vec<[f32; 4]> = [
            [0.0, 0.0, 0.0],
            [1.0, 0.0, 0.0],
            [0.0, 1.0, 0.0],
            [0.0, 0.0, 1.0],
            [1.0, 1.0, 1.0],
        ]
        .iter()
        .map(|p| [p[0], p[1], p[2], 0.0])
        .collect();
        let tets = [[0, 1, 2, 3], [4, 1, 2, 3]];
        // face 0 of each (opposite its point 0) is the shared (1, 2, 3)
        let neighbours = [
            [4, BOUNDARY, BOUNDARY, BOUNDARY],
            [0, BOUNDARY, BOUNDARY, BOUNDARY],
        ];
        let g = point_gradients(&points, &tets, &neighbours, &[0.0, 1.0]);
        let along = |g: [f32; 4]| g[0] + g[1] + g[2];
        assert!(along(g[0]) > 0.0 && along(g[4]) > 0.0, "{g:?}");
        let flat = point_gradients(&points, &tets, &neighbours, &[1.0, 1.0]);
        assert!(flat.iter().all(|g| g.iter().all(|x| *x == 0.0)));
    }
}
