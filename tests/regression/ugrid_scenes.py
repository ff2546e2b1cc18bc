"""The regression suite's unstructured-grid scenes (issue 40): the meshes of meshes.py drawn
by vtkUnstructuredGridVolumeRayCastMapper (the reference), vtkUnstructuredGridVolumeZSweepMapper
and vtkProjectedTetrahedraMapper (second opinions) and ferrovol's
vtkFerroUnstructuredVolumeMapper (pending where the module `ferrovol` lacks it). scenes.py
adds DATA and SCENES to its own (import scenes, not this module, first); UNSTRUCTURED.md
has VTK's conventions and the figures.
"""
import vtk

import meshes  # tests/regression/meshes.py: the unstructured grids
from scenes import Scene, _cached, one, orbit, wavelet_tf

# Data (each made once per process). VTK's unstructured mappers take tetrahedra only and get
# the mixed mesh through vtkDataSetTriangleFilter (run.py's render); ferrovol gets each mesh
# as it is.


@_cached
def ugrid_wavelet():
    """VTK's wavelet on -10..10 (wavelet21's points), 5 tetrahedra per voxel: 40 000
    tetrahedra, point scalars RTData."""
    return meshes.tet_wavelet(10)


@_cached
def ugrid_wavelet_cells():
    """ugrid_wavelet with cell scalars instead: each tetrahedron the mean of its 4 points."""
    f = vtk.vtkPointDataToCellData()
    f.SetInputData(ugrid_wavelet())
    f.Update()
    ug = vtk.vtkUnstructuredGrid()
    ug.ShallowCopy(f.GetOutput())
    ug.GetPointData().Initialize()
    ug.GetCellData().SetActiveScalars("RTData")
    return ug


@_cached
def ugrid_mixed():
    """meshes.mixed(): 768 hexahedra, 1152 wedges, 800 pyramids and 3008 tetrahedra,
    distorted, over [-10, 10]^3, point scalars."""
    return meshes.mixed()


@_cached
def ugrid_mixed_tets():
    """ugrid_mixed split into tetrahedra by vtkDataSetTriangleFilter (what VTK's mappers
    draw of it), for every mapper: matched interpolation."""
    return meshes.tetrahedralised(ugrid_mixed())


@_cached
def ugrid_torus():
    """meshes.torus(): a torus about z (major radius 6.5) with a hollow tube (radii 1.5 to
    3.5), 36 864 tetrahedra, point scalars."""
    return meshes.torus()


DATA = {f.__name__: f for f in (ugrid_wavelet, ugrid_wavelet_cells, ugrid_mixed,
                                 ugrid_mixed_tets, ugrid_torus)}


def ray_integrator(name):
    """The unstructured ray integrator vtkUnstructuredGrid<name> on the mappers that take one
    (the ray caster and the Z-sweep mapper; projected tetrahedra has none)."""
    def f(m):
        if hasattr(m, "SetRayIntegrator"):
            m.SetRayIntegrator(getattr(vtk, "vtkUnstructuredGrid" + name)())
    return f


UGRID_NOTE = ("Reference: vtkUnstructuredGridVolumeRayCastMapper (Bunyk et al.'s cell-to-cell "
              "ray caster, one ray per pixel: ImageSampleDistance 1, no auto-adjustment) with "
              "its default integrator for one-component point scalars, "
              "vtkUnstructuredGridPreIntegration (a 128 x 128 x 256 table of "
              "vtkUnstructuredGridPartialPreIntegration), unless the title names another. "
              "VTK's unstructured mappers read the transfer function's opacity as an "
              "attenuation coefficient per ScalarOpacityUnitDistance (exp(-length x opacity / "
              "unit distance)), not as the opacity of a unit step (UNSTRUCTURED.md).")

SCENES = [
    Scene("ugrid-wavelet", "wavelet 21^3 as 40 000 tetrahedra (vtkDataSetTriangleFilter), "
          "point scalars, composite, default integrator (pre-integration table)",
          "ugrid_wavelet", wavelet_tf("linear"), unstructured=True, note=UGRID_NOTE),
    Scene("ugrid-wavelet-linear-integrator", "wavelet 21^3 as 40 000 tetrahedra, point "
          "scalars, composite, vtkUnstructuredGridLinearRayIntegrator (exact for a "
          "piecewise-linear transfer function: splits segments at its control points)",
          "ugrid_wavelet", wavelet_tf("linear"),
          configure=ray_integrator("LinearRayIntegrator"), unstructured=True,
          note=UGRID_NOTE + " Projected tetrahedra has no integrator to choose."),
    Scene("ugrid-wavelet-cells", "wavelet 21^3 as 40 000 tetrahedra, cell scalars (each the "
          "mean of its points), composite (VTK's homogeneous integrator: constant colour and "
          "attenuation per cell)", "ugrid_wavelet_cells", wavelet_tf("linear"),
          unstructured=True, note=UGRID_NOTE),
    Scene("ugrid-mixed", "mixed mesh: 768 hexahedra, 1152 wedges, 800 pyramids, 3008 "
          "tetrahedra, distorted (non-planar faces), point scalars, composite; VTK draws it "
          "split into tetrahedra, ferrovol as it is", "ugrid_mixed", wavelet_tf("linear"),
          views=one(camera=orbit(35, 25)), unstructured=True,
          note=UGRID_NOTE + " VTK's unstructured mappers draw tetrahedra only (the ray "
          "caster skips other cells with a warning, projected tetrahedra stops with an "
          "error): they get vtkDataSetTriangleFilter's split of the mesh, whose linear "
          "tetrahedra differ from a hexahedron's trilinear field (ugrid-mixed-tets is the "
          "matched control)."),
    Scene("ugrid-mixed-tets", "control: the mixed mesh split into tetrahedra by "
          "vtkDataSetTriangleFilter for every mapper (matched interpolation)",
          "ugrid_mixed_tets", wavelet_tf("linear"), views=one(camera=orbit(35, 25)),
          unstructured=True, note=UGRID_NOTE),
    Scene("ugrid-torus", "hollow torus (annular tube), 36 864 tetrahedra, seen at 60 degrees "
          "from its axis: rays leave and re-enter the mesh", "ugrid_torus",
          wavelet_tf("linear", unit_distance=4.0), views=one(camera=orbit(30, 60)),
          unstructured=True,
          note=UGRID_NOTE),
    Scene("ugrid-torus-edge", "hollow torus seen nearly edge-on (80 degrees from its axis): "
          "rays cross up to four walls, where projected tetrahedra's cell-centre depth sort "
          "shows", "ugrid_torus", wavelet_tf("linear", unit_distance=4.0),
          views=one(camera=orbit(20, 80, 1.2)), unstructured=True, note=UGRID_NOTE),
]
