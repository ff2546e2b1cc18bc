//! Unstructured volumes through the C ABI: a mixed mesh made from a caller's arrays draws
//! what ferrovol-core draws for the same mesh; bad arrays and descriptor sizes are refused
//! with a status and a message naming the problem.

use super::*;
use ferrovol::{FvScalarLocation, FvUnstructuredVolumeDesc};
use ferrovol_core::{
    synth, ComponentTransfer, Context, Piecewise, RenderParams, Renderer, ScalarLocation, Scalars,
    TransferFunction, UnstructuredVolume, View,
};

type NewMesh = unsafe extern "C" fn(*const FvUnstructuredVolumeDesc, *mut H) -> FvStatus;
type DescDefault = unsafe extern "C" fn(*mut FvUnstructuredVolumeDesc, usize) -> FvStatus;

/// The colour (x, r, g, b) and opacity (x, a) points both sides of a comparison draw with.
const XRGB: [f64; 12] = [0.0, 0.1, 0.2, 0.9, 0.5, 0.2, 0.9, 0.3, 1.0, 1.0, 0.3, 0.1];
const XA: [f64; 6] = [0.0, 0.0, 0.3, 0.15, 1.0, 0.8];
const SIZE: u32 = 48;

/// The defaults, through the ABI.
fn default_desc(lib: &Lib) -> FvUnstructuredVolumeDesc {
    let mut d = std::mem::MaybeUninit::<FvUnstructuredVolumeDesc>::uninit();
    let size = std::mem::size_of::<FvUnstructuredVolumeDesc>();
    // SAFETY: `size` writable bytes; the call writes them all.
    unsafe {
        lib.ok(lib.f::<DescDefault>("fv_unstructured_volume_desc_default")(
            d.as_mut_ptr(),
            size,
        ));
        d.assume_init()
    }
}

/// A mesh's arrays as a C caller holds them: points and indices in the types asked for,
/// the scalars as the mesh has them (f32).
struct Arrays {
    points: Vec<u8>,
    connectivity: Vec<u8>,
    offsets: Vec<u8>,
    cell_types: Vec<u8>,
    scalars: Vec<f32>,
}

/// The bytes of `values` converted by `f` to a type of `N` bytes in native order.
fn bytes<T: Copy, const N: usize>(values: &[T], f: impl Fn(T) -> [u8; N]) -> Vec<u8> {
    values.iter().flat_map(|&v| f(v)).collect()
}

impl Arrays {
    fn of(v: &UnstructuredVolume, point_type: FvScalarType, index_type: FvScalarType) -> Self {
        let xyz: Vec<f64> = v.points.iter().flatten().copied().collect();
        let points = match point_type {
            FvScalarType::F64 => bytes(&xyz, f64::to_ne_bytes),
            FvScalarType::F32 => bytes(&xyz, |x| (x as f32).to_ne_bytes()),
            t => panic!("points of {t:?}"),
        };
        let index = |i: &[u32]| match index_type {
            FvScalarType::I64 => bytes(i, |i| (i as i64).to_ne_bytes()),
            FvScalarType::I32 => bytes(i, |i| (i as i32).to_ne_bytes()),
            FvScalarType::U32 => bytes(i, u32::to_ne_bytes),
            FvScalarType::U64 => bytes(i, |i| (i as u64).to_ne_bytes()),
            t => panic!("indices of {t:?}"),
        };
        let Scalars::F32(scalars) = &v.scalars else {
            panic!("the generated meshes have f32 scalars")
        };
        Arrays {
            points,
            connectivity: index(&v.connectivity),
            offsets: index(&v.offsets),
            cell_types: v.cell_types.clone(),
            scalars: scalars.clone(),
        }
    }

    /// A description of these arrays (they must outlive its use).
    fn desc(
        &self,
        lib: &Lib,
        v: &UnstructuredVolume,
        point_type: FvScalarType,
        index_type: FvScalarType,
    ) -> FvUnstructuredVolumeDesc {
        let mut d = default_desc(lib);
        d.points = self.points.as_ptr().cast();
        d.point_count = v.points.len();
        d.point_type = point_type as u32;
        d.index_type = index_type as u32;
        d.connectivity = self.connectivity.as_ptr().cast();
        d.connectivity_count = v.connectivity.len();
        d.offsets = self.offsets.as_ptr().cast();
        d.cell_types = self.cell_types.as_ptr();
        d.cell_count = v.num_cells();
        d.scalar_type = FvScalarType::F32 as u32;
        d.components = v.components;
        d.location = match v.location {
            ScalarLocation::Points => FvScalarLocation::Points,
            ScalarLocation::Cells => FvScalarLocation::Cells,
        } as u32;
        d.scalars = self.scalars.as_ptr().cast();
        d
    }
}

/// `v` seen from an angle, the near plane through it.
fn view_of(v: &UnstructuredVolume) -> View {
    let mut view = View::fit(v.bounds(), SIZE, SIZE);
    view.camera.azimuth(30.0);
    view.camera.elevation(20.0);
    view
}

/// Makes the mesh `d` describes, gives it to the session's renderer, frees it and draws
/// `v`'s view with the transfer function over [lo, hi].
fn abi_frame(
    s: &mut Session,
    d: &FvUnstructuredVolumeDesc,
    view: &View,
    lo: f64,
    hi: f64,
) -> Vec<u8> {
    let lib = s.lib;
    let mut mesh: H = null_mut();
    // SAFETY: `d` describes live arrays; valid handles and out-pointer. The renderer keeps
    // what it uploaded, so the mesh is freed at once.
    unsafe {
        lib.ok(lib.f::<NewMesh>("fv_unstructured_volume_new")(d, &mut mesh));
        lib.ok(lib.f::<SetH>("fv_renderer_set_unstructured")(s.r, mesh));
        lib.f::<Free>("fv_unstructured_volume_free")(mesh);
    }
    let scale = |points: &[f64], n: usize| -> Vec<f64> {
        points
            .chunks(n)
            .flat_map(|p| {
                let mut p = p.to_vec();
                p[0] = lo + p[0] * (hi - lo);
                p
            })
            .collect()
    };
    s.set_transfer_function(&scale(&XRGB, 4), &scale(&XA, 2));
    let c = &view.camera;
    let mut cam = camera(
        c.position.to_array(),
        c.focal_point.to_array(),
        c.clipping_range,
    );
    cam.view_up = c.view_up.to_array();
    cam.view_angle = c.view_angle;
    s.set_camera(&cam);
    s.frame(SIZE, SIZE).to_vec()
}

/// The same frame from ferrovol-core's Renderer::set_unstructured.
fn core_frame(v: &UnstructuredVolume, view: &View, lo: f64, hi: f64) -> Vec<u8> {
    let piecewise = |p: &[f64], n: usize| {
        p.chunks(n)
            .map(|q| {
                (
                    lo + q[0] * (hi - lo),
                    q[1..].iter().map(|&x| x as f32).collect(),
                )
            })
            .collect::<Vec<(f64, Vec<f32>)>>()
    };
    let color = piecewise(&XRGB, 4)
        .into_iter()
        .map(|(x, c)| (x, [c[0], c[1], c[2]]))
        .collect();
    let opacity = piecewise(&XA, 2)
        .into_iter()
        .map(|(x, a)| (x, [a[0]]))
        .collect();
    let tf = TransferFunction::single(ComponentTransfer::new(
        Piecewise::new(color).unwrap(),
        Piecewise::new(opacity).unwrap(),
    ));
    let mut r = Renderer::new(Context::new().unwrap()).unwrap();
    r.set_unstructured(v).unwrap();
    r.set_transfer_function(&tf).unwrap();
    r.render_image(view, &RenderParams::default()).unwrap().rgba
}

/// A mixed mesh (hexahedra, wedges, pyramids, tetrahedra; distorted) made through the ABI
/// from VTK's default arrays (double points, int64 indices) and from float points with
/// uint32 indices, with point and with cell scalars: each frame equals ferrovol-core's of
/// the same mesh.
#[test]
fn a_mixed_mesh_through_the_c_abi_draws_what_the_core_draws() {
    let lib = Lib::open();
    for (location, point_type, index_type) in [
        (ScalarLocation::Points, FvScalarType::F64, FvScalarType::I64),
        (ScalarLocation::Cells, FvScalarType::F32, FvScalarType::U32),
    ] {
        let mut v = synth::mixed_cells(3, location);
        if point_type == FvScalarType::F32 {
            for p in &mut v.points {
                *p = p.map(|x| x as f32 as f64);
            }
        }
        let (lo, hi) = (0..v.scalars.len())
            .map(|i| v.scalars.get(i))
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), x| {
                (a.min(x), b.max(x))
            });
        let view = view_of(&v);
        let arrays = Arrays::of(&v, point_type, index_type);
        let d = arrays.desc(&lib, &v, point_type, index_type);
        let mut s = Session::new(&lib);
        let abi = abi_frame(&mut s, &d, &view, lo, hi);
        let core = core_frame(&v, &view, lo, hi);
        let covered = abi.chunks(4).filter(|p| p[3] > 0).count();
        let max = abi
            .iter()
            .zip(&core)
            .map(|(a, b)| a.abs_diff(*b))
            .max()
            .unwrap();
        let differ = abi.iter().zip(&core).filter(|(a, b)| a != b).count();
        println!(
            "{location:?} scalars, {point_type:?} points, {index_type:?} indices: {covered} of \
             {} pixels drawn; {differ} bytes differ from the core's frame, by at most {max}",
            SIZE * SIZE
        );
        assert!(covered > (SIZE * SIZE / 4) as usize, "the mesh is drawn");
        assert!(max <= 1, "the ABI's frame is the core's within a level");
    }
}

/// A quadratic tetrahedron (VTK_QUADRATIC_TETRA, 10 points, int32 indices) is drawn as the
/// linear tetrahedron of its corners, the rule UnstructuredVolume::from_vtk states.
#[test]
fn quadratic_cells_are_linearised_through_the_c_abi() {
    let lib = Lib::open();
    let corners = [
        [0.0, 0.0, 0.0],
        [2.0, 0.0, 0.0],
        [0.0, 2.0, 0.0],
        [0.0, 0.0, 2.0],
    ];
    let mut points = corners.to_vec();
    for (a, b) in [(0, 1), (1, 2), (2, 0), (0, 3), (1, 3), (2, 3)] {
        points.push([0, 1, 2].map(|k| 0.5 * (corners[a][k] + corners[b][k])));
    }
    let scalars = points.iter().map(|p| (p[0] + 2.0 * p[1]) as f32).collect();
    let quadratic = UnstructuredVolume {
        points,
        connectivity: (0..10).collect(),
        offsets: vec![0, 10],
        cell_types: vec![24],
        location: ScalarLocation::Points,
        components: 1,
        scalars: Scalars::F32(scalars),
    };
    let linear = UnstructuredVolume {
        connectivity: vec![0, 1, 2, 3],
        offsets: vec![0, 4],
        cell_types: vec![10],
        ..quadratic.clone()
    };
    let view = view_of(&linear);
    let frames: Vec<Vec<u8>> = [&quadratic, &linear]
        .iter()
        .map(|v| {
            let arrays = Arrays::of(v, FvScalarType::F64, FvScalarType::I32);
            let d = arrays.desc(&lib, v, FvScalarType::F64, FvScalarType::I32);
            abi_frame(&mut Session::new(&lib), &d, &view, 0.0, 6.0)
        })
        .collect();
    let covered = frames[0].chunks(4).filter(|p| p[3] > 0).count();
    println!("quadratic tetra: {covered} pixels drawn");
    assert!(covered > 50, "the tetrahedron is drawn");
    assert!(
        frames[0] == frames[1],
        "the quadratic tetra draws as its linear one"
    );
}

/// Two tetrahedra sharing the face (0, 1, 2), point scalars: the mesh the error cases spoil.
struct Two {
    points: Vec<f64>,
    connectivity: Vec<i64>,
    offsets: Vec<i64>,
    cell_types: Vec<u8>,
    scalars: Vec<f32>,
}

impl Two {
    fn new() -> Two {
        Two {
            points: vec![
                0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, -1.0, 0.3,
                0.3, 1.0,
            ],
            connectivity: vec![0, 1, 2, 3, 0, 2, 1, 4],
            offsets: vec![0, 4, 8],
            cell_types: vec![10, 10],
            scalars: vec![0.0, 1.0, 2.0, 3.0, 4.0, 5.0],
        }
    }

    fn desc(&self, lib: &Lib) -> FvUnstructuredVolumeDesc {
        let mut d = default_desc(lib);
        d.points = self.points.as_ptr().cast();
        d.point_count = self.points.len() / 3;
        d.connectivity = self.connectivity.as_ptr().cast();
        d.connectivity_count = self.connectivity.len();
        d.offsets = self.offsets.as_ptr().cast();
        d.cell_types = self.cell_types.as_ptr();
        d.cell_count = self.cell_types.len();
        d.scalars = self.scalars.as_ptr().cast();
        d
    }
}

/// `d` with `change` made to it.
fn changed(
    mut d: FvUnstructuredVolumeDesc,
    change: impl FnOnce(&mut FvUnstructuredVolumeDesc),
) -> FvUnstructuredVolumeDesc {
    change(&mut d);
    d
}

/// Every bad array gets its status and a message naming the problem (the core's validation
/// messages for the mesh itself), `*out` stays NULL, and the good mesh is then made.
#[test]
fn bad_meshes_are_refused_naming_the_problem() {
    let lib = Lib::open();
    let new = lib.f::<NewMesh>("fv_unstructured_volume_new");
    let good = Two::new();
    let base = good.desc(&lib);
    let mut mesh: H = null_mut();
    let mut dangling = Two::new();
    dangling.connectivity[7] = 6;
    let mut negative = Two::new();
    negative.connectivity[2] = -1;
    let mut polygon = Two::new();
    polygon.cell_types[1] = 7;
    let mut unknown = Two::new();
    unknown.cell_types[0] = 200;
    let mut decreasing = Two::new();
    decreasing.offsets = vec![0, 4, 4];
    let mut three = Two::new();
    // a third tetrahedron on the face (0, 1, 2), to point 5
    three.connectivity.extend([0, 1, 2, 5]);
    three.offsets.push(12);
    three.cell_types.push(10);
    let mut nan = Two::new();
    nan.points[4] = f64::NAN;
    let unaligned = [0f64; 19];
    // SAFETY: one byte into the vector: in bounds.
    let unaligned = unsafe { unaligned.as_ptr().cast::<u8>().add(1) };
    let cases: Vec<(FvUnstructuredVolumeDesc, FvStatus, &str)> = vec![
        (changed(base, |d| d.points = null()), Null, "points is NULL"),
        (changed(base, |d| d.connectivity = null()), Null, "connectivity is NULL"),
        (changed(base, |d| d.offsets = null()), Null, "offsets is NULL"),
        (changed(base, |d| d.cell_types = null()), Null, "cell_types is NULL"),
        (changed(base, |d| d.scalars = null()), Null, "scalars is NULL"),
        (dangling.desc(&lib), Invalid, "cell 1 (VTK_TETRA (10)) refers to point 6, but the mesh has 6 points (a dangling index)"),
        (negative.desc(&lib), Invalid, "connectivity[2] is -1: not an index"),
        (polygon.desc(&lib), Invalid, "cell 1 is VTK_POLYGON (7)"),
        (unknown.desc(&lib), Invalid, "cell 0 is an unknown cell type (200)"),
        (decreasing.desc(&lib), Invalid, "offsets do not increase at cell 1: 4 then 4"),
        (three.desc(&lib), Invalid, "the face with points [0, 1, 2] belongs to more than two cells"),
        (nan.desc(&lib), Invalid, "point 1 is [1.0, NaN, 0.0]"),
        (changed(base, |d| d.connectivity_count = 7), Invalid, "the last offset is 8, but the connectivity has 7 entries"),
        (changed(base, |d| d.cell_count = 0), Invalid, "the mesh has no cells"),
        (changed(base, |d| d.point_type = FvScalarType::I32 as u32), FvStatus::Unsupported, "point_type I32: points are F64 or F32"),
        (changed(base, |d| d.index_type = FvScalarType::F32 as u32), FvStatus::Unsupported, "index_type F32"),
        (changed(base, |d| d.index_type = 99), FvStatus::Unsupported, "index_type 99 is not an FvScalarType"),
        (changed(base, |d| d.scalar_type = 10), FvStatus::Unsupported, "scalar_type 10 is not an FvScalarType"),
        (changed(base, |d| d.location = 2), Invalid, "location 2 is not an FvScalarLocation"),
        (changed(base, |d| d.components = 5), Invalid, "components is 5; ferrovol renders 1 to 4"),
        (changed(base, |d| d.components = 0), Invalid, "components is 0"),
        (changed(base, |d| d.points = unaligned.cast()), Invalid, "points is not aligned to 8 bytes"),
        (changed(base, |d| d.point_count = usize::MAX), Invalid, "point_count: the count overflows"),
    ];
    // SAFETY (all calls below): every array a description points to holds the counts given
    // (or the call refuses it before reading past them); invalid arguments are the test.
    unsafe {
        for (d, want, needle) in &cases {
            mesh = null_mut();
            lib.expect(new(d, &mut mesh), *want, needle);
            assert!(
                mesh.is_null(),
                "a failed fv_unstructured_volume_new leaves *out NULL"
            );
        }
        lib.expect(new(null(), &mut mesh), Null, "desc is NULL");
        lib.expect(new(&base, null_mut()), Null, "out is NULL");
        lib.ok(new(&base, &mut mesh));
        let set = lib.f::<SetH>("fv_renderer_set_unstructured");
        let mut s = Session::new(&lib);
        lib.expect(set(null_mut(), mesh), Null, "renderer is NULL");
        lib.expect(set(s.r, null_mut()), Null, "volume is NULL");
        lib.ok(set(s.r, mesh));
        lib.f::<Free>("fv_unstructured_volume_free")(mesh);
        // two components per point: made, uploaded, and refused at render by the pass
        let pairs: Vec<f32> = good.scalars.iter().flat_map(|&x| [x, -x]).collect();
        let d = changed(base, |d| {
            d.components = 2;
            d.scalars = pairs.as_ptr().cast();
        });
        lib.ok(new(&d, &mut mesh));
        lib.ok(set(s.r, mesh));
        lib.f::<Free>("fv_unstructured_volume_free")(mesh);
        s.set_transfer_function(
            &[0.0, 1.0, 1.0, 1.0, 5.0, 1.0, 1.0, 1.0],
            &[0.0, 0.0, 5.0, 1.0],
        );
        s.set_camera(&camera([0.3, 0.3, 6.0], [0.3, 0.3, 0.0], [1.0, 20.0]));
        let render = lib.f::<Render>("fv_renderer_render");
        lib.expect(
            render(s.r, 8, 8, null(), 0),
            FvStatus::Unsupported,
            "drawn from one scalar component, and this mesh has 2",
        );
    }
}

/// FvUnstructuredVolumeDesc.size: its defaults written for the caller's size, sizes below
/// the first layout's or above this library's refused naming the struct, by both the
/// defaults function and fv_unstructured_volume_new. (An older, smaller layout read with
/// the later fields' defaults: sized.rs's tests, over every versioned struct.)
#[test]
fn unstructured_descriptor_sizes_are_checked() {
    let lib = Lib::open();
    let default = lib.f::<DescDefault>("fv_unstructured_volume_desc_default");
    let new = lib.f::<NewMesh>("fv_unstructured_volume_new");
    let own = std::mem::size_of::<FvUnstructuredVolumeDesc>();
    let d = default_desc(&lib);
    assert_eq!(d.size, own);
    assert_eq!(d.point_type, FvScalarType::F64 as u32);
    assert_eq!(d.index_type, FvScalarType::I64 as u32);
    assert_eq!(d.location, FvScalarLocation::Points as u32);
    assert_eq!(d.components, 1);
    assert!(d.points.is_null() && d.scalars.is_null() && d.cell_count == 0);
    let two = Two::new();
    let mut mesh: H = null_mut();
    // SAFETY: valid descriptions and out-pointers; bad sizes are the test (a size larger
    // than the struct is refused before anything past `size` is read or written).
    unsafe {
        lib.expect(default(null_mut(), own), Null, "desc is NULL");
        for bad in [0, 8, own - 8, own + 8] {
            let mut q = default_desc(&lib);
            let needle = format!("FvUnstructuredVolumeDesc.size is {bad}");
            lib.expect(default(&mut q, bad), Invalid, &needle);
            let mut desc = two.desc(&lib);
            desc.size = bad;
            lib.expect(new(&desc, &mut mesh), Invalid, &needle);
            assert!(mesh.is_null());
        }
        let msg = lib.last_error();
        assert!(
            msg.contains("fv_*_default") && msg.contains(&format!("{own} to {own}")),
            "{msg}"
        );
    }
}
