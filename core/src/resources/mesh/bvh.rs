//! A bounding volume hierarchy over the boundary triangles: where rays enter the mesh and,
//! in non-convex meshes, enter it again. Built by median splits along the longest axis of
//! the triangles' centroids, leaves of at most [`LEAF`] triangles, nodes in depth-first
//! order (an inner node's first child follows it, and holds the lower half). Rays visit the
//! nearer child first, taken along the node's longest side.

/// Triangles per leaf at most.
pub(crate) const LEAF: usize = 4;

/// One node as the shader reads it (32 bytes): the box, and in `a` the first triangle of a
/// leaf (`count` > 0) or the second child of an inner node (`count` = 0).
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, bytemuck::Pod, bytemuck::Zeroable)]
pub(crate) struct BvhNode {
    pub lo: [f32; 3],
    pub a: u32,
    pub hi: [f32; 3],
    pub count: u32,
}

#[derive(Clone, Debug, Default)]
pub(crate) struct Bvh {
    pub nodes: Vec<BvhNode>,
    /// The longest path from the root to a leaf, in nodes.
    pub depth: usize,
}

type Tri = [[f32; 3]; 3];

fn bounds(tris: &[Tri]) -> ([f32; 3], [f32; 3]) {
    let mut lo = [f32::INFINITY; 3];
    let mut hi = [f32::NEG_INFINITY; 3];
    for t in tris {
        for p in t {
            for a in 0..3 {
                lo[a] = lo[a].min(p[a]);
                hi[a] = hi[a].max(p[a]);
            }
        }
    }
    (lo, hi)
}

impl Bvh {
    /// The hierarchy over `items` (reordered to the leaves' order), each the triangle
    /// `triangle(item)`.
    pub fn build(items: &mut [u32], triangle: impl Fn(u32) -> Tri) -> Bvh {
        let mut tris: Vec<(u32, Tri)> = items.iter().map(|&i| (i, triangle(i))).collect();
        let mut bvh = Bvh::default();
        if !tris.is_empty() {
            bvh.depth = bvh.node(&mut tris, 0);
        }
        for (slot, (i, _)) in items.iter_mut().zip(&tris) {
            *slot = *i;
        }
        bvh
    }

    /// Appends the subtree over `tris` (starting at triangle `first`); its depth.
    fn node(&mut self, tris: &mut [(u32, Tri)], first: usize) -> usize {
        let only: Vec<Tri> = tris.iter().map(|t| t.1).collect();
        let (lo, hi) = bounds(&only);
        let me = self.nodes.len();
        self.nodes.push(BvhNode {
            lo,
            a: first as u32,
            hi,
            count: tris.len() as u32,
        });
        if tris.len() <= LEAF {
            return 1;
        }
        let centre = |t: &Tri, a: usize| t[0][a] + t[1][a] + t[2][a];
        let (mut clo, mut chi) = ([f32::INFINITY; 3], [f32::NEG_INFINITY; 3]);
        for (_, t) in tris.iter() {
            for a in 0..3 {
                clo[a] = clo[a].min(centre(t, a));
                chi[a] = chi[a].max(centre(t, a));
            }
        }
        let axis = (0..3)
            .max_by(|&x, &y| (chi[x] - clo[x]).total_cmp(&(chi[y] - clo[y])))
            .expect("three axes");
        let mid = tris.len() / 2;
        tris.select_nth_unstable_by(mid, |x, y| {
            centre(&x.1, axis).total_cmp(&centre(&y.1, axis))
        });
        self.nodes[me].count = 0;
        let (left, right) = tris.split_at_mut(mid);
        let dl = self.node(left, first);
        self.nodes[me].a = self.nodes.len() as u32;
        let dr = self.node(right, first + mid);
        1 + dl.max(dr)
    }
}
