// A rectilinear grid (VolumeData::coordinates): rays march the uniform lattice over the
// grid's box, and each sample's lattice point is mapped to the grid's index space per axis
// through a lookup built on the host (Resources::set_volume): row a holds the index-space
// coordinate at evenly spaced lattice points, column j at j·(n_a − 1)/(width − 1), read
// linearly between columns. A uniform grid binds a placeholder and leaves it unread. Ray
// casting and isosurfaces read it.
#include "lib/common.wgsl"
#include "lib/volume.wgsl"
@group(0) @binding(SLOT_GRID_LOOKUP) var grid_lookup: texture_3d<f32>;
override RECTILINEAR: bool = false;

// The grid's index-space point for the lattice point p, and the rate it changes with p
// per axis in `index_slope` (world_gradient's scale). Without RECTILINEAR, p itself.
fn grid_point(p: vec3<f32>) -> vec3<f32> {
    if (!RECTILINEAR) {
        return p;
    }
    let w = f32(textureDimensions(grid_lookup).x) - 1.0;
    var q = p;
    for (var a = 0; a < 3; a = a + 1) {
        let span = max(frame.dims[a] - 1.0, 1.0);
        let x = clamp(p[a] / span, 0.0, 1.0) * w;
        let i = min(floor(x), w - 1.0);
        let f0 = textureLoad(grid_lookup, vec3<i32>(i32(i), a, 0), 0).x;
        let f1 = textureLoad(grid_lookup, vec3<i32>(i32(i) + 1, a, 0), 0).x;
        q[a] = mix(f0, f1, x - i);
        index_slope[a] = select(1.0, (f1 - f0) * w / span, frame.dims[a] > 1.0);
    }
    return q;
}
