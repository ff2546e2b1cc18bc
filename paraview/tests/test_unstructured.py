"""(g) "Ferrovol Volume" on unstructured grids: tests/regression/meshes.py's tetrahedralised
wavelet (40 000 tetrahedra, made in memory) and a multiblock of its two halves, against
ParaView's own "Volume" of the same data, serial and under MPI.

  pvbatch test_unstructured.py serial
      the grid drawn by "Ferrovol Volume" and by "Volume" with each of its mappers
      (MAPPERS); the multiblock (its blocks merged by the representation, as "Volume" merges
      them) against the single grid; the mesh uploaded once for renders that change only the
      camera; Shade lights it (drawn, unlike the unshaded image) and Volumetric Scattering
      Blending shadows it (unlike the shaded image); Isosurface draws the
      Isosurface Values (drawn, unlike the composite image); Path Trace draws it as a
      scattering medium, every path in a still render; a three-component array
      refused (nothing drawn). Writes the references the
      distributed step compares with.
  mpiexec -n N pvbatch --symmetric test_unstructured.py distributed
      every rank's source holds interleaved slabs of the grid (cells by z, alternating between
      the ranks): ParaView redistributes the cells over the ranks by its k-d tree, each rank
      draws its region with ferrovol and IceT composites the images in visibility order.
      Rank 0 checks that the ranks draw disjoint regions and compares the result with the
      serial images, also from either side of the cut (the order flips), and the
      isosurfaces with the serial ones.
"""
import os
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import fvtest as T  # noqa: E402
from paraview.simple import Hide, ProgrammableSource, Render, Show  # noqa: E402

MODE = sys.argv[1] if len(sys.argv) > 1 else "serial"
SIZE = (300, 300)
BOUNDS = [-10.0, 10.0, -10.0, 10.0, -10.0, 10.0]
# The unstructured mappers' convention: opacity is attenuation per unit distance
# (tests/regression/UNSTRUCTURED.md), the VTK module's test_unstructured.py's functions.
RGB = [37.3531, 0.2, 0.29, 1.0, 157.091, 0.87, 0.87, 0.87, 276.829, 0.7, 0.015, 0.15]
OPACITY = [37.3531, 0.0, 0.5, 0.0, 276.829, 1.0, 0.5, 0.0]
UNIT_DISTANCE = 1.0
# +x and -x look across the cut ParaView's k-d tree makes for 2 ranks (x = 0): one rank's
# region lies behind the other's, and the compositing order flips between the two.
CAMERAS = {"oblique": [0.5, 0.34, 0.8], "plus-x": [1.0, 0.1, 0.15], "minus-x": [-1.0, 0.1, -0.15]}
# "Volume"'s mappers (its Select Mapper) and the floors of "Ferrovol Volume" against each
# (SSIM, PSNR dB on the volume's box): the bar against the ray caster (its default
# pre-integrated integrator), and under what was measured against projected tetrahedra
# (paraview/README.md, Tests, has the figures).
MAPPERS = {
    "Bunyk ray cast": (0.98, 35.0),
    "Projected tetra": (0.99, 41.0),
}
# The multiblock (merged by the representation) and the distributed image against the
# serial single grid drawn by ferrovol: the same mesh, cut (the cut is a face of both pieces).
SAME = (0.98, 35.0)

MESH = """
import sys
sys.path.insert(0, %r)
import meshes
from vtkmodules.vtkCommonExecutionModel import vtkStreamingDemandDrivenPipeline
try:
    from vtkmodules.vtkFiltersCore import vtkExtractCells
except ImportError:
    from vtkmodules.vtkFiltersExtraction import vtkExtractCells
from vtkmodules.vtkFiltersCore import vtkCellCenters
from vtkmodules.vtkCommonCore import vtkIdList
from vtkmodules.util.numpy_support import vtk_to_numpy
grid = meshes.tet_wavelet(10)
centres = vtkCellCenters()
centres.SetInputData(grid)
centres.Update()
c = vtk_to_numpy(centres.GetOutput().GetPoints().GetData())

def cells(keep):
    ids = vtkIdList()
    for i in keep.nonzero()[0]:
        ids.InsertNextId(int(i))
    ex = vtkExtractCells()
    ex.SetInputData(grid)
    ex.SetCellList(ids)
    ex.Update()
    return ex.GetOutput()
"""
# one grid; under MPI every piece a set of interleaved z slabs (4 units thick)
GRID = MESH + """
info = self.GetOutputInformation(0)
piece = info.Get(vtkStreamingDemandDrivenPipeline.UPDATE_PIECE_NUMBER())
pieces = info.Get(vtkStreamingDemandDrivenPipeline.UPDATE_NUMBER_OF_PIECES())
if pieces > 1:
    slab = ((c[:, 2] + 10.0) // 4.0).astype(int) %% pieces
    self.GetOutput().ShallowCopy(cells(slab == piece))
else:
    self.GetOutput().ShallowCopy(grid)
"""
# two blocks: the halves x < 0 and x >= 0 (under MPI each rank's blocks hold its slabs of
# them)
BLOCKS = MESH + """
info = self.GetOutputInformation(0)
piece = info.Get(vtkStreamingDemandDrivenPipeline.UPDATE_PIECE_NUMBER())
pieces = info.Get(vtkStreamingDemandDrivenPipeline.UPDATE_NUMBER_OF_PIECES())
mine = ((c[:, 2] + 10.0) // 4.0).astype(int) %% (pieces if pieces > 1 else 1) == piece
out = self.GetOutput()
out.SetNumberOfBlocks(2)
out.SetBlock(0, cells(mine & (c[:, 0] < 0.0)))
out.SetBlock(1, cells(mine & (c[:, 0] >= 0.0)))
"""

T.load_plugin(globals())


def mesh_source(script, kind):
    src = ProgrammableSource()
    src.OutputDataSetType = kind
    src.Script = script % os.path.join(T.REPO, "tests", "regression")
    # every rank executes for its own piece
    src.ScriptRequestInformation = (
        "from vtkmodules.vtkCommonExecutionModel import vtkAlgorithm\n"
        "self.GetOutputInformation(0).Set(vtkAlgorithm.CAN_HANDLE_PIECE_REQUEST(), 1)\n")
    return src


def show(view, src):
    disp = Show(src, view)
    lut, _ = T.color_by(disp, "RTData", rgb_points=RGB, opacity_points=OPACITY)
    # linear in RGB between the points (ParaView's default, Diverging, is not; VTK's
    # unstructured integrators read the points as linear in RGB)
    lut.ColorSpace = "RGB"
    disp.ScalarOpacityUnitDistance = UNIT_DISTANCE
    disp.Representation = "Ferrovol Volume"
    return disp


def shot(view, name, camera):
    T.set_camera(view, BOUNDS, direction=CAMERAS[camera])
    Render(view)
    img, _, dt = T.screenshot(view, name)
    if T.rank() == 0:
        T.log("  %-44s %.2f s, %.1f%% of the frame covered" % (
            name + ".png", dt, 100 * T.coverage(img)))
    return img


def ferrovol_info(disp):
    disp.UpdatePropertyInformation()
    return {p: disp.GetProperty(p).GetData() for p in (
        "FerrovolLastRenderDrew", "FerrovolVolumeUploadCount", "FerrovolTableUploadCount")}


def check_drawn(img, name, failures):
    if T.rank() == 0 and T.coverage(img) < 0.2:
        failures.append("%s: %.3f of the frame covered (nearly empty)" % (name, T.coverage(img)))


def make_view():
    view = T.make_view(SIZE)
    view.UseFXAA = 0
    return view


def serial(failures):
    view = make_view()
    src = mesh_source(GRID, "vtkUnstructuredGrid")
    disp = show(view, src)
    refs = {cam: shot(view, "ugrid-serial-ferrovol-%s" % cam, cam) for cam in CAMERAS}
    for cam, img in refs.items():
        check_drawn(img, "ferrovol " + cam, failures)
    uploads = ferrovol_info(disp)
    T.log("  after %d renders (camera changes only): %s" % (len(CAMERAS), uploads))
    if uploads["FerrovolLastRenderDrew"] != 1:
        failures.append("ferrovol did not draw the grid (%s)" % uploads)
    if uploads["FerrovolVolumeUploadCount"] != 1:
        failures.append("the mesh was uploaded %d times for %d camera changes"
                        % (uploads["FerrovolVolumeUploadCount"], len(CAMERAS)))
    disp.FerrovolBlendMode = "Maximum Intensity"
    mip = shot(view, "ugrid-serial-ferrovol-mip", "oblique")
    check_drawn(mip, "ferrovol MIP", failures)
    disp.FerrovolBlendMode = "Composite"
    # the thresholds can fail: another blend mode's image must fall under them
    T.compare("control: MIP vs composite", mip, refs["oblique"], *SAME, failures,
              expect_fail=True)
    # Shade (which "Volume"'s unstructured mappers ignore) lights the mesh: drawn, and not
    # the unshaded image
    disp.Shade = 1
    lit = shot(view, "ugrid-serial-ferrovol-shaded", "oblique")
    # Volumetric Scattering Blending (with Global Illumination Reach): shadows, drawn, and
    # not the image lit by gradients alone
    disp.VolumetricScatteringBlending = 1.0
    disp.GlobalIlluminationReach = 0.1
    shadowed = shot(view, "ugrid-serial-ferrovol-volumetric", "oblique")
    disp.VolumetricScatteringBlending = 0.0
    check_drawn(shadowed, "ferrovol volumetric shadows", failures)
    T.compare("control: volumetric vs shaded", shadowed, lit, *SAME, failures,
              expect_fail=True)
    disp.Shade = 0
    check_drawn(lit, "ferrovol shaded", failures)
    if ferrovol_info(disp)["FerrovolLastRenderDrew"] != 1:
        failures.append("ferrovol did not draw the shaded grid")
    T.compare("control: shaded vs unshaded", lit, refs["oblique"], *SAME, failures,
              expect_fail=True)
    # Isosurface (which "Volume" on unstructured grids lacks): the Isosurface Values, drawn,
    # and not the composite image
    disp.IsosurfaceValues = [150.0]
    disp.FerrovolBlendMode = "Isosurface"
    iso = shot(view, "ugrid-serial-ferrovol-isosurface", "oblique")
    disp.FerrovolBlendMode = "Composite"
    check_drawn(iso, "ferrovol isosurface", failures)
    if ferrovol_info(disp)["FerrovolLastRenderDrew"] != 1:
        failures.append("ferrovol did not draw the isosurface")
    T.compare("control: isosurface vs composite", iso, refs["oblique"], *SAME, failures,
              expect_fail=True)
    # Path Trace: the mesh as a scattering medium; pvbatch's still render traces every path
    # (two per pixel: drawn and lit, and not the ray-cast image)
    disp.FerrovolRenderMode = "Path Trace"
    disp.FerrovolSamplesPerPixel = 2
    traced = shot(view, "ugrid-serial-ferrovol-pathtrace", "oblique")
    disp.UpdatePropertyInformation()
    paths = disp.GetProperty("FerrovolAccumulatedSamples").GetData()
    disp.FerrovolRenderMode = "Ray Cast"
    T.log("  path traced: %s paths per pixel" % paths)
    check_drawn(traced, "ferrovol path traced", failures)
    if paths != 2:
        failures.append("path tracing accumulated %s paths per pixel, not 2" % paths)
    T.compare("control: path traced vs ray cast", traced, refs["oblique"], *SAME, failures,
              expect_fail=True)

    disp.Representation = "Volume"
    for mapper, floor in MAPPERS.items():
        disp.SelectMapper = mapper
        tag = mapper.split()[0].lower()
        img = shot(view, "ugrid-serial-volume-%s-oblique" % tag, "oblique")
        check_drawn(img, "Volume " + mapper, failures)
        T.compare("ferrovol vs Volume (%s)" % mapper, refs["oblique"], img,
                  floor[0] if floor else None, floor[1] if floor else None, failures)
    Hide(src, view)

    # the multiblock: "Volume" with the ray caster first; "Volume"'s Select Mapper does not
    # reach "Ferrovol Volume", which then draws the merged blocks with ferrovol
    blocks = mesh_source(BLOCKS, "vtkMultiblockDataSet")
    bdisp = show(view, blocks)
    bdisp.Representation = "Volume"
    bdisp.SelectMapper = "Bunyk ray cast"
    vimg = shot(view, "ugrid-serial-multiblock-volume-bunyk-oblique", "oblique")
    bdisp.Representation = "Ferrovol Volume"
    img = shot(view, "ugrid-serial-multiblock-ferrovol-oblique", "oblique")
    if ferrovol_info(bdisp)["FerrovolLastRenderDrew"] != 1:
        failures.append("ferrovol did not draw the multiblock")
    check_drawn(img, "multiblock", failures)
    T.compare("multiblock vs one grid", img, refs["oblique"], *SAME, failures)
    T.compare("multiblock: ferrovol vs Volume (Bunyk)", img, vimg, *MAPPERS["Bunyk ray cast"],
              failures)
    Hide(blocks, view)

    # a three-component array: refused by the mapper, nothing drawn
    vec = mesh_source(GRID + """
from vtkmodules.vtkCommonCore import vtkFloatArray
v = vtkFloatArray()
v.SetName("vec")
v.SetNumberOfComponents(3)
v.SetNumberOfTuples(self.GetOutput().GetNumberOfPoints())
v.Fill(100.0)
self.GetOutput().GetPointData().AddArray(v)
""", "vtkUnstructuredGrid")
    vdisp = show(view, vec)
    T.ColorBy(vdisp, ("POINTS", "vec", "Magnitude"))
    vimg = shot(view, "ugrid-serial-three-components", "oblique")
    drew = ferrovol_info(vdisp)["FerrovolLastRenderDrew"]
    T.log("  three components: drew %d, %.3f of the frame covered" % (drew, T.coverage(vimg)))
    if drew != 0 or T.coverage(vimg) > 0.01:
        failures.append("a three-component array was drawn (drew %d)" % drew)
    Hide(vec, view)


def distributed(failures):
    view = make_view()
    src = mesh_source(GRID, "vtkUnstructuredGrid")
    disp = show(view, src)
    imgs, uploads = {}, []
    for cam in CAMERAS:
        imgs[cam] = shot(view, "ugrid-n%d-ferrovol-%s" % (T.nranks(), cam), cam)
        uploads.append(ferrovol_info(disp)["FerrovolVolumeUploadCount"])
    local = mesh_source_cells(src)
    drawn = drawn_piece(disp)
    T.print_in_rank_order(
        "  rank %d/%d: the source's piece %d of 40000 cells; drawn after redistribution: %d "
        "cells in %s; mesh uploads after each render %s" % (
            T.rank(), T.nranks(), local, drawn[0], [round(b, 2) for b in drawn[1]], uploads))
    if ferrovol_info(disp)["FerrovolLastRenderDrew"] != 1:
        failures.append("rank %d: ferrovol did not draw its piece" % T.rank())
    if uploads[-1] != uploads[0]:
        failures.append("rank %d: the mesh was uploaded again for camera changes (%s)"
                        % (T.rank(), uploads))
    # isosurfaces: each rank's layers lie within its region, composited in visibility order
    disp.IsosurfaceValues = [150.0]
    disp.FerrovolBlendMode = "Isosurface"
    iso = shot(view, "ugrid-n%d-ferrovol-isosurface" % T.nranks(), "oblique")
    disp.FerrovolBlendMode = "Composite"
    # the regions the ranks draw: the k-d tree's, which overlap at most in a layer of cells
    # (the source's pieces are interleaved slabs, overlapping over the whole z range)
    boxes = gather_boxes(drawn[1])
    if T.rank() == 0:
        overlap = overlap_fraction(boxes)
        T.log("  the drawn pieces' boxes overlap in %.1f%% of the whole's volume" % (100 * overlap))
        if overlap > 0.1:
            failures.append("the ranks draw overlapping regions (%.2f): not redistributed"
                            % overlap)
    blocks = mesh_source(BLOCKS, "vtkMultiblockDataSet")
    Hide(src, view)
    show(view, blocks)
    mb = shot(view, "ugrid-n%d-multiblock-ferrovol-oblique" % T.nranks(), "oblique")
    if T.rank() != 0:
        return
    for cam, img in imgs.items():
        check_drawn(img, "ferrovol " + cam, failures)
        ref = read_ref("ugrid-serial-ferrovol-%s" % cam, failures)
        if ref is not None:
            T.compare("mpi -n %d %s vs serial" % (T.nranks(), cam), img, ref, *SAME, failures)
    check_drawn(iso, "ferrovol isosurface", failures)
    ref = read_ref("ugrid-serial-ferrovol-isosurface", failures)
    if ref is not None:
        T.compare("mpi -n %d isosurface vs serial" % T.nranks(), iso, ref, *SAME, failures)
    ref = read_ref("ugrid-serial-volume-bunyk-oblique", failures)
    if ref is not None:
        T.compare("mpi -n %d vs serial Volume (Bunyk)" % T.nranks(), imgs["oblique"], ref,
                  *MAPPERS["Bunyk ray cast"], failures)
    check_drawn(mb, "multiblock", failures)
    ref = read_ref("ugrid-serial-ferrovol-oblique", failures)
    if ref is not None:
        T.compare("mpi -n %d multiblock vs serial grid" % T.nranks(), mb, ref, *SAME, failures)


def mesh_source_cells(src):
    return src.GetClientSideObject().GetOutputDataObject(0).GetNumberOfCells()


def drawn_piece(disp):
    """This rank's ferrovol mapper input (after ParaView's redistribution): cells, bounds."""
    rep = disp.GetClientSideObject().GetActiveRepresentation()
    grid = rep.GetActiveVolumeMapper().GetInput()
    if grid is None or grid.GetNumberOfCells() == 0:
        return 0, [0.0] * 6
    return grid.GetNumberOfCells(), list(grid.GetBounds())


def gather_boxes(bounds):
    """Every rank's bounds, on rank 0 (rank order)."""
    import numpy as np
    from vtkmodules.vtkCommonCore import vtkDoubleArray
    from vtkmodules.vtkParallelCore import vtkMultiProcessController
    ctrl = vtkMultiProcessController.GetGlobalController()
    mine, every = vtkDoubleArray(), vtkDoubleArray()
    for b in bounds:
        mine.InsertNextValue(b)
    ctrl.Gather(mine, every, 0)
    if T.rank() != 0:
        return None
    return np.array([every.GetValue(i) for i in range(every.GetNumberOfValues())]).reshape(-1, 6)


def overlap_fraction(boxes):
    """The largest volume two boxes share, over the whole grid's volume."""
    import numpy as np
    worst = 0.0
    for i in range(len(boxes)):
        for j in range(i + 1, len(boxes)):
            lo = np.maximum(boxes[i][0::2], boxes[j][0::2])
            hi = np.minimum(boxes[i][1::2], boxes[j][1::2])
            worst = np.maximum(worst, np.prod(np.clip(hi - lo, 0.0, None)) / 20.0 ** 3)
    return float(worst)


def read_ref(name, failures):
    path = os.path.join(T.OUT_DIR, name + ".png")
    if not os.path.exists(path):
        failures.append("no serial reference %s: run 'pvbatch test_unstructured.py serial' "
                        "first" % path)
        return None
    return T.read_png(path)


failures = []
if MODE == "serial":
    T.log("Unstructured grids, serial (%dx%d): Ferrovol Volume vs Volume" % SIZE)
    serial(failures)
    T.finish(failures, "unstructured, serial")
else:
    T.log("Unstructured grids, mpiexec -n %d (%dx%d) against the serial images"
          % ((T.nranks(),) + SIZE))
    if T.nranks() < 2:
        failures.append("run me with mpiexec -n 2 (or more) pvbatch --symmetric")
    else:
        distributed(failures)
    T.finish(failures, "unstructured, distributed")
