"""The regression matrix: every scene is rendered in the same VTK window setup by
vtkGPUVolumeRayCastMapper (the reference), vtkFixedPointVolumeRayCastMapper (a second
opinion, where it supports the scene) and vtkFerroVolumeMapper; an unstructured-grid scene
(`unstructured=True`, the meshes of meshes.py) by vtkUnstructuredGridVolumeRayCastMapper
(the reference), vtkUnstructuredGridVolumeZSweepMapper and vtkProjectedTetrahedraMapper
(second opinions) and ferrovol's vtkFerroUnstructuredVolumeMapper.

A scene is data + volume property + blend mode + mapper settings + camera (+ actors, volume
matrix, viewports). Its thresholds live in thresholds.toml under the same name. Scenes with
`quick=True` form the subset `make test` runs.
"""
import os
from dataclasses import dataclass, field
from typing import Callable, Optional, Sequence

import numpy as np
import vtk

import fvtest  # vtk_plugin/tests/fvtest.py: windows, TF helpers, image_from_array, spheres
from fvtest import WAVELET_OPACITY, tf_property

# ---------------------------------------------------------------------------------------
# Data (each loaded once per process)

_CACHE = {}


def _cached(fn):
    def get():
        if fn.__name__ not in _CACHE:
            _CACHE[fn.__name__] = fn()
        return _CACHE[fn.__name__]
    get.__name__ = fn.__name__
    get.__doc__ = fn.__doc__
    return get


def _path(name):
    return os.path.join(fvtest.DATA, name)


class MissingData(Exception):
    pass


def _read(name, reader=vtk.vtkXMLImageDataReader):
    """The image in DATA/name, read with a VTK reader class (VTK's XML image format by
    default)."""
    p = _path(name)
    if not os.path.exists(p):
        raise MissingData("%s missing (scripts/fetch-data.sh makes it)" % p)
    r = reader()
    r.SetFileName(p)
    r.Update()
    img = vtk.vtkImageData()
    img.DeepCopy(r.GetOutput())
    return img


def _wavelet(lo, hi):
    """VTK's wavelet (vtkRTAnalyticSource, float32) with the extent lo..hi on every axis."""
    src = vtk.vtkRTAnalyticSource()
    src.SetWholeExtent(lo, hi, lo, hi, lo, hi)
    src.Update()
    return src.GetOutput()


@_cached
def wavelet128():
    """VTK's wavelet, extent -64..63: 128^3 float32."""
    return _wavelet(-64, 63)


@_cached
def wavelet21():
    """VTK's wavelet, extent -10..10: 21^3 float32."""
    return _wavelet(-10, 10)


@_cached
def marschner_lobb():
    """Marschner-Lobb (f_M = 6, alpha = 0.25) on 41^3 points over [-1, 1]^3, float32."""
    n, fm, alpha = 41, 6.0, 0.25
    t = np.linspace(-1.0, 1.0, n)
    z, y, x = np.meshgrid(t, t, t, indexing="ij")
    r = np.sqrt(x * x + y * y)
    rho = (1.0 - np.sin(np.pi * z / 2.0) + alpha * (1.0 + np.cos(2.0 * np.pi * fm
           * np.cos(np.pi * r / 2.0)))) / (2.0 * (1.0 + alpha))
    return fvtest.image_from_array(rho.astype(np.float32), spacing=(2.0 / (n - 1),) * 3,
                                   origin=(-1.0, -1.0, -1.0), name="rho")


@_cached
def cranium():
    """InVesalius skull CT: 256x256x108 int16 HU, spacing 0.957 x 0.957 x 1.5 mm."""
    return _read("cranium.vti")


@_cached
def colin27():
    """Colin27 T1 MRI (mricron-data): 181x217x181 uint8, 1 mm."""
    return _read("colin27.nii.gz", vtk.vtkNIFTIImageReader)


@_cached
def heart():
    """mayavi2's heart.vti: CT of a heart, 32x32x12 float32, spacing 1 x 1 x 4."""
    return _read("heart.vti")


# Label map: the skull CT classified into 4 tissues (air 0, soft tissue 1, bone 2, dense
# bone / metal 3) at half resolution in-plane: 128x128x108 uint8, spacing 1.914 x 1.914 x 1.5.
LABEL_EDGES = (-400.0, 250.0, 1200.0)
LABEL_COLORS = {1: (0.85, 0.55, 0.45), 2: (0.95, 0.92, 0.80), 3: (0.20, 0.45, 1.00)}
LABEL_OPACITY = {0: 0.0, 1: 0.03, 2: 0.5, 3: 1.0}


@_cached
def labels():
    """The skull CT thresholded into 4 labels (uint8), half resolution in-plane."""
    ct = cranium()
    from vtk.util.numpy_support import vtk_to_numpy
    nx, ny, nz = ct.GetDimensions()
    hu = vtk_to_numpy(ct.GetPointData().GetScalars()).reshape(nz, ny, nx)[:, ::2, ::2]
    lab = np.digitize(hu, LABEL_EDGES).astype(np.uint8)
    sx, sy, sz = ct.GetSpacing()
    return fvtest.image_from_array(lab, spacing=(2 * sx, 2 * sy, sz), name="labels")


@_cached
def wavelet128_blanked():
    """wavelet128 with ghost arrays (vtkUniformGrid-style blanking): the cells of an
    off-centre box marked HIDDENCELL, and the points of a slab marked HIDDENPOINT."""
    from vtk.util.numpy_support import numpy_to_vtk
    img = vtk.vtkImageData()
    img.DeepCopy(wavelet128())
    for dims, data, flag, region in (
            ([n - 1 for n in img.GetDimensions()], img.GetCellData(),
             vtk.vtkDataSetAttributes.HIDDENCELL,
             lambda x, y, z: (x < 70) & (y > 40) & (z > 30)),
            (img.GetDimensions(), img.GetPointData(), vtk.vtkDataSetAttributes.HIDDENPOINT,
             lambda x, y, z: (z < 20) & (x > 80))):
        z, y, x = np.mgrid[0:dims[2], 0:dims[1], 0:dims[0]]
        ghosts = numpy_to_vtk((region(x, y, z) * flag).astype(np.uint8).ravel(), deep=True)
        ghosts.SetName(vtk.vtkDataSetAttributes.GhostArrayName())
        data.AddArray(ghosts)
    return img


@_cached
def frog():
    """pyvista's frog tissue label map: 500x470x136 uint8 labels 0-29, spacing 1 x 1 x 1.5."""
    return _read("frog_tissues.vti")


def _mask_of(image, values):
    """A mask image on `image`'s grid holding `values` ([z, y, x] uint8)."""
    m = fvtest.image_from_array(values.astype(np.uint8), spacing=image.GetSpacing(),
                                origin=image.GetOrigin(), name="mask")
    m.SetExtent(image.GetExtent())
    return m


@_cached
def cranium_cutaway_mask():
    """A binary mask of the skull CT: 0 in the quarter x < half, y < half (a cutaway)."""
    nx, ny, nz = cranium().GetDimensions()
    z, y, x = np.mgrid[0:nz, 0:ny, 0:nx]
    return _mask_of(cranium(), ~((x < nx // 2) & (y < ny // 2)))


@_cached
def frog_mask():
    """The frog's labels as a label-map mask of itself."""
    m = vtk.vtkImageData()
    m.DeepCopy(frog())
    return m


def _rectilinear(cells):
    """VTK's wavelet, extent -32..31 (64^3 float32), on a vtkRectilinearGrid whose x steps
    grow from 1 to 2.26 along the axis (y and z: steps of 1.5, float32 and int32
    coordinates), as point scalars or, on one point more per axis, as cell scalars."""
    from vtk.util.numpy_support import numpy_to_vtk
    n = 64
    values = _wavelet(-32, 31).GetPointData().GetScalars()
    m = n + 1 if cells else n
    xs = np.concatenate([[0.0], np.cumsum(1.0 + 0.02 * np.arange(m - 1))])
    ys = 1.5 * np.arange(m)
    grid = vtk.vtkRectilinearGrid()
    grid.SetDimensions(m, m, m)
    grid.SetXCoordinates(numpy_to_vtk(xs, deep=True))
    grid.SetYCoordinates(numpy_to_vtk(ys.astype(np.float32), deep=True))
    grid.SetZCoordinates(numpy_to_vtk(ys.astype(np.int32), deep=True))
    (grid.GetCellData() if cells else grid.GetPointData()).SetScalars(values)
    return grid


@_cached
def wavelet_rectilinear_points():
    return _rectilinear(cells=False)


@_cached
def wavelet_rectilinear_cells():
    return _rectilinear(cells=True)


DATA = {f.__name__: f for f in (wavelet128, wavelet128_blanked, wavelet21, marschner_lobb,
                                 cranium, colin27, heart, labels, frog,
                                 wavelet_rectilinear_points, wavelet_rectilinear_cells)}

# ---------------------------------------------------------------------------------------
# Volume properties


def wavelet_tf(interpolation="nearest", shade=False, unit_distance=1.0, opacity=None):
    def make():
        p = tf_property(opacity=opacity or WAVELET_OPACITY, interpolation=interpolation)
        if shade:
            p.ShadeOn()
        p.SetScalarOpacityUnitDistance(unit_distance)
        return p
    return make


# An opacity peak about the wavelet's middle values: the opacity's gradient turns over at
# the peak, where the scalar's does not.
WAVELET_PEAK_OPACITY = [(37.3531, 0.0), (130.0, 0.0), (160.0, 0.8), (190.0, 0.0),
                        (276.829, 0.0)]


def wavelet_gradient_opacity():
    p = wavelet_tf("linear")()
    g = vtk.vtkPiecewiseFunction()
    g.AddPoint(0.0, 0.0)   # VTK's units: |grad| x mean spacing
    g.AddPoint(10.0, 1.0)
    p.SetGradientOpacity(g)
    return p


def slice_tf(shade=False, normal=(0.3, 0.4, 1.0)):
    """The slice blend mode's property: its SliceFunction an oblique plane through the
    wavelet's centre; an opacity ramp over the whole range (the slice shows the opacity as
    given, so a low one would leave it faint)."""
    def make():
        p = wavelet_tf("linear", shade=shade, opacity=[(37.3531, 0.3), (276.829, 1.0)])()
        plane = vtk.vtkPlane()
        plane.SetOrigin(0.0, 0.0, 0.0)
        plane.SetNormal(*normal)
        p.SetSliceFunction(plane)
        return p
    return make


def minip_tf(interpolation="nearest"):
    # MinIP shows low values: opaque at the bottom of the range
    return wavelet_tf(interpolation, opacity=[(37.3531, 1.0), (276.829, 0.2)])


def additive_tf():
    return wavelet_tf("linear", opacity=[(37.3531, 0.0), (276.829, 0.01)])()


def ml_tf(shade=True):
    def make():
        p = tf_property(color=[(0.0, 1.0, 0.6, 0.2), (0.5, 1.0, 0.85, 0.6), (1.0, 1.0, 1.0, 1.0)],
                        opacity=[(0.0, 0.0), (0.42, 0.0), (0.5, 0.9), (0.58, 0.0), (1.0, 0.0)],
                        interpolation="linear")
        p.SetScalarOpacityUnitDistance(0.05)   # one voxel
        if shade:
            p.ShadeOn()
        return p
    return make


def ct_tf(shade=True, interpolation="linear"):
    """Bone and skin of the skull CT (VTK's CT-Bone-like preset, as the reference test)."""
    def make():
        p = tf_property(
            color=[(-3024, 0, 0, 0), (-16.4458, 0.729412, 0.254902, 0.301961),
                   (641.385, 0.905882, 0.815686, 0.552941), (3071, 1, 1, 1)],
            opacity=[(-3024, 0), (-16.4458, 0), (641.385, 0.715686), (3071, 0.705882)],
            interpolation=interpolation)
        if shade:
            p.ShadeOn()
        p.SetScalarOpacityUnitDistance(1.2)
        return p
    return make


def ct_mip_tf():
    return tf_property(color=[(-1024, 0, 0, 0), (3000, 1, 1, 1)],
                       opacity=[(-1024, 0.0), (3000, 1.0)], interpolation="linear")


def mri_tf(shade=False):
    def make():
        p = tf_property(color=[(0, 0, 0, 0), (60, 0.55, 0.35, 0.30), (100, 0.9, 0.8, 0.7),
                               (160, 1.0, 0.95, 0.9), (255, 1, 1, 1)],
                        opacity=[(0, 0.0), (40, 0.0), (80, 0.05), (120, 0.25), (255, 0.6)],
                        interpolation="linear")
        if shade:
            p.ShadeOn()
        return p
    return make


def mri_mip_tf():
    return tf_property(color=[(0, 0, 0, 0), (255, 1, 1, 1)], opacity=[(0, 0.0), (255, 1.0)],
                       interpolation="linear")


def heart_tf(interpolation="linear"):
    def make():
        p = tf_property(color=[(0, 0.1, 0.1, 0.4), (80, 0.9, 0.3, 0.2), (200, 1.0, 0.9, 0.6),
                               (255, 1, 1, 1)],
                        opacity=[(0, 0.0), (60, 0.0), (120, 0.3), (255, 0.8)],
                        interpolation=interpolation)
        p.SetScalarOpacityUnitDistance(2.0)
        return p
    return make


def label_tf():
    """Categorical: each label a flat colour and opacity (steps half-way between labels),
    nearest interpolation so that no in-between value is ever classified."""
    ctf = vtk.vtkColorTransferFunction()
    otf = vtk.vtkPiecewiseFunction()
    for lab in range(4):
        rgb = LABEL_COLORS.get(lab, (0.0, 0.0, 0.0))
        for x in (lab - 0.49, lab + 0.49):
            ctf.AddRGBPoint(x, *rgb)
            otf.AddPoint(x, LABEL_OPACITY[lab])
    p = vtk.vtkVolumeProperty()
    p.SetColor(ctf)
    p.SetScalarOpacity(otf)
    p.SetInterpolationTypeToNearest()
    p.SetScalarOpacityUnitDistance(1.9)
    return p


# The frog's tissues drawn through a label map of themselves: every tissue a faint grey
# (the property's own functions), five of them their own colour and opacity
# (vtkVolumeProperty::SetLabelColor / SetLabelScalarOpacity). Label 29, the mask's highest,
# has functions too (the property's grey): VTK 9.2 reads label L's row at floor(L·N/M), N the
# highest label with functions and M the mask's highest value, right only where N = M.
FROG_LABELS = {3: ((0.9, 0.2, 0.2), 0.35), 9: ((0.2, 0.8, 0.3), 0.35),
               10: ((0.95, 0.85, 0.4), 0.08), 13: ((0.3, 0.5, 1.0), 0.04),
               15: ((0.9, 0.5, 0.9), 0.25), 29: ((0.7, 0.7, 0.7), 0.02)}


def frog_tf(shade=False):
    def make():
        p = fvtest.volume_property([(0.0, 0.0, 0.0, 0.0), (29.0, 0.7, 0.7, 0.7)],
                                   [(0.49, 0.0), (0.51, 0.02), (29.0, 0.02)])
        p.SetInterpolationTypeToNearest()
        for label, (rgb, alpha) in FROG_LABELS.items():
            p.SetLabelColor(label, fvtest.color_function([(0.0, *rgb), (29.0, *rgb)]))
            p.SetLabelScalarOpacity(label, fvtest.opacity_function([(0.0, alpha), (29.0, alpha)]))
        if shade:
            p.ShadeOn()
        return p
    return make


def ct_tf_2d(shade=True):
    """The skull CT through a 2D transfer function: skin where the scalar is around -300 HU
    and bone above 300 HU, each more opaque where the gradient is steep (their boundaries)."""
    def make():
        from vtk.util.numpy_support import numpy_to_vtk
        p = ct_tf(shade=shade)()
        lo, hi = cranium().GetPointData().GetScalars().GetRange()
        nx, ny = 256, 128
        s = lo + (np.arange(nx) + 0.5) / nx * (hi - lo)
        g = (np.arange(ny) + 0.5) / ny
        ss, gg = np.meshgrid(s, g)
        skin = np.exp(-((ss + 300.0) / 120.0) ** 2)
        bone = np.clip((ss - 300.0) / 400.0, 0.0, 1.0)
        rgba = np.zeros((ny, nx, 4), np.float32)
        rgba[..., 0] = 0.9 * skin + 1.0 * bone
        rgba[..., 1] = 0.6 * skin + 0.95 * bone
        rgba[..., 2] = 0.5 * skin + 0.85 * bone
        rgba[..., 3] = (0.15 * skin + 0.8 * bone) * np.clip(0.2 + 4.0 * gg, 0.0, 1.0)
        img = vtk.vtkImageData()
        img.SetDimensions(nx, ny, 1)
        img.GetPointData().SetScalars(
            numpy_to_vtk(rgba.reshape(-1, 4), deep=True, array_type=vtk.VTK_FLOAT))
        p.SetTransferFunction2D(img)
        p.SetTransferFunctionMode(vtk.vtkVolumeProperty.TF_2D)
        return p
    return make


# ---------------------------------------------------------------------------------------
# Cameras, actors, mapper settings

def orbit(az=30.0, el=20.0, zoom=1.0, parallel=False):
    def f(cam):
        cam.Azimuth(az)
        cam.Elevation(el)
        cam.OrthogonalizeViewUp()
        cam.Zoom(zoom)
        if parallel:
            cam.ParallelProjectionOn()
    return f


def ct_front(az=0.0, el=0.0, zoom=1.4, parallel=False):
    """orbit() starting in front of the skull CT's face (its -y side), head up (+z)."""
    then = orbit(az, el, zoom, parallel)

    def f(cam):
        cam.Elevation(-90.0)
        cam.SetViewUp(0, 0, 1)
        cam.OrthogonalizeViewUp()
        then(cam)
    return f


def inside_wavelet(cam):
    # from 25 voxels off the centre, looking out through the +z half, wide angle
    cam.SetPosition(5.0, -4.0, 25.0)
    cam.SetFocalPoint(-15.0, 10.0, -60.0)
    cam.SetViewUp(0.0, 1.0, 0.0)
    cam.SetViewAngle(70.0)


def sphere_actor(center, radius, color=(0.2, 0.9, 0.3)):
    def make():
        return [fvtest.sphere_actor(center, radius, color, resolution=64)]
    return make


def sample_distance(d):
    def f(m):
        m.AutoAdjustSampleDistancesOff()
        m.SetSampleDistance(d)
    return f


def crop(planes, flags):
    def f(m):
        m.CroppingOn()
        m.SetCroppingRegionPlanes(*planes)
        getattr(m, "SetCroppingRegionFlagsTo" + flags)()
    return f


def clip_planes(*planes):
    def f(m):
        for origin, normal in planes:
            p = vtk.vtkPlane()
            p.SetOrigin(*origin)
            p.SetNormal(*normal)
            m.AddClippingPlane(p)
    return f


def crop_vtk_placed(planes, flags, n, center):
    """Cropping as crop(), except that ferrovol gets the planes where VTK 9.2's GPU mapper
    effectively puts them (every axis here has n points about `center`)."""
    moved = tuple(center + (p - center) * n / (n - 1.0) for p in planes)

    def f(m):
        crop(moved if m.IsA("vtkFerroVolumeMapper") else planes, flags)(m)
    return f


def clip_planes_vtk_placed(planes, n, center):
    """Clipping planes as clip_planes(), except that ferrovol gets them where VTK 9.2's GPU
    mapper effectively puts them (every axis here has n points about `center`)."""
    moved = tuple((tuple(center + (o - center) * n / (n - 1.0) for o in origin), normal)
                  for origin, normal in planes)

    def f(m):
        clip_planes(*(moved if m.IsA("vtkFerroVolumeMapper") else planes))(m)
    return f


# Eight planes (the most vtkGPUVolumeRayCastMapper takes), each cutting one corner of the
# wavelet 128^3 off.
EIGHT_CORNER_PLANES = tuple(((30 * sx, 28 * sy, 26 * sz), (-sx, -sy, -sz))
                            for sx in (-1, 1) for sy in (-1, 1) for sz in (-1, 1))


def average_range(lo, hi):
    def f(m):
        m.SetAverageIPScalarRange(lo, hi)
    return f


def volumetric(blending, reach):
    """VTK 9.2's volumetric shadows (the fixed-point mapper has none and ignores this)."""
    def f(m):
        if hasattr(m, "SetVolumetricScatteringBlending"):
            m.SetVolumetricScatteringBlending(blending)
            m.SetGlobalIlluminationReach(reach)
    return f


def clipped_voxel_intensity(make_prop, value):
    """make_prop's property with UseClippedVoxelIntensity on at `value`."""
    def make():
        p = make_prop()
        p.UseClippedVoxelIntensityOn()
        p.SetClippedVoxelIntensity(value)
        return p
    return make


def mask(make_mask, label_map=False, blend_factor=1.0):
    """The mapper's MaskInput (vtkGPUVolumeRayCastMapper's binary mask or label map)."""
    def f(m):
        m.SetMaskInput(make_mask())
        m.SetMaskType(m.LabelMapMaskType if label_map else m.BinaryMaskType)
        m.SetMaskBlendFactor(blend_factor)
    return f


def both(*configures):
    def f(m):
        for c in configures:
            c(m)
    return f


# A clipping plane through the wavelet's centre facing the default orbit camera: the cut face
# fills the view.
FACING_PLANE = ((0, 0, 0), (-0.47, -0.34, -0.81))


def shaded(make_prop):
    def make():
        p = make_prop()
        p.ShadeOn()
        return p
    return make


def normal_from_opacity(*more):
    """vtkVolumeMapper::ComputeNormalFromOpacity on, then each of `more` (mapper settings)."""
    def f(m):
        m.ComputeNormalFromOpacityOn()
        for g in more:
            g(m)
    return f


def anisotropic(make_prop, g):
    def make():
        p = make_prop()
        p.SetScatteringAnisotropy(g)
        return p
    return make


def side_light(ren):
    """One directional scene light from the upper left (VTK takes its light-kit path)."""
    light = vtk.vtkLight()
    light.SetLightTypeToSceneLight()
    light.SetPositional(0)
    light.SetPosition(-1.0, 1.0, 0.6)
    light.SetFocalPoint(0.0, 0.0, 0.0)
    ren.AddLight(light)


def ml_in_wavelet(vol):
    """Marschner-Lobb ([-1, 1]^3) grown to 70 units, turned and moved off the wavelet's
    centre: it overlaps the wavelet's box in part and leaves it on one side."""
    vol.SetScale(35.0, 35.0, 35.0)
    vol.RotateZ(30.0)
    vol.RotateX(20.0)
    vol.SetPosition(60.0, 10.0, 0.0)


def ml_intermixed(shade=False):
    def make():
        p = ml_tf(shade=shade)()
        p.SetScalarOpacityUnitDistance(2.0)
        return p
    return make


def rotate_scale(vol):
    vol.SetPosition(15.0, -5.0, 0.0)
    vol.RotateZ(30.0)
    vol.RotateX(20.0)
    vol.SetScale(1.0, 1.4, 0.8)


# ---------------------------------------------------------------------------------------
# Scenes

@dataclass
class View:
    """One renderer of a scene: a viewport of the window with its own camera and mapper."""
    blend: str = "composite"   # composite maximum minimum average additive isosurface
    camera: Optional[Callable] = None
    viewport: Sequence[float] = (0.0, 0.0, 1.0, 1.0)


@dataclass
class Scene:
    name: str
    title: str                       # one line: what the scene exercises
    data: str                        # key of DATA
    prop: Callable                   # () -> vtkVolumeProperty
    views: list = field(default_factory=lambda: [View(camera=orbit())])
    size: tuple = (300, 300)
    configure: Optional[Callable] = None   # mapper settings, applied to all three mappers
    volume: Optional[Callable] = None      # vtkVolume transform
    actors: Optional[Callable] = None      # () -> [vtkActor], opaque geometry
    lights: Optional[Callable] = None      # (vtkRenderer) -> None: scene lights
    iso_values: tuple = ()
    multisamples: Optional[int] = None     # window MSAA; None: VTK's default (8)
    # further volumes on the mapper's ports 1, 2, ... drawn through a vtkMultiVolume with the
    # scene's (port 0): () -> [(data key, prop, vtkVolume transform or None)]
    intermix: Optional[Callable] = None
    fixed: bool = True                     # False: the fixed-point mapper lacks a setting used
    # True: the data is a vtkUnstructuredGrid, drawn by vtkUnstructuredGridVolumeRayCastMapper
    # (the reference), vtkUnstructuredGridVolumeZSweepMapper and vtkProjectedTetrahedraMapper
    # (second opinions) and ferrovol's vtkFerroUnstructuredVolumeMapper
    unstructured: bool = False
    quick: bool = False
    note: str = ""                   # known, understood differences shown next to the images

    @property
    def blends(self):
        return sorted({v.blend for v in self.views})


def one(blend="composite", camera=None):
    return [View(blend=blend, camera=camera or orbit())]


OUTLINE_NOTE = ("Outline: VTK rasterises its proxy box into the 8x multisampled framebuffer, so "
                "the box's silhouette pixels are partly covered; ferrovol's full-screen "
                "composite covers a pixel fully or not at all, and VTK also takes one sample "
                "on rays that graze an edge by less than a step.")

SAMPLING_NOTE = ("Sample placement: ferrovol samples on VTK 9.2's lattice (first sample one "
                 "step inside the box, the exit-face sample kept), adopted after this suite "
                 "found the difference; what remains is listed in SAMPLING.md.")

SCENES = [
    # --- wavelet 128^3: blend modes
    Scene("wavelet-composite-nearest", "wavelet 128^3, composite, nearest (VTK's defaults), "
          "benchmark transfer function", "wavelet128", wavelet_tf("nearest"), quick=True,
          note=SAMPLING_NOTE),
    Scene("wavelet-composite-linear", "wavelet 128^3, composite, linear interpolation",
          "wavelet128", wavelet_tf("linear"), note=SAMPLING_NOTE),
    Scene("wavelet-composite-linear-fine", "wavelet 128^3, composite, linear, sample distance "
          "0.25 on every mapper (control: the lattice difference shrinks 4x)", "wavelet128",
          wavelet_tf("linear"), configure=sample_distance(0.25)),
    Scene("wavelet-composite-shaded", "wavelet 128^3, composite, linear, Phong shading "
          "(headlight)", "wavelet128", wavelet_tf("linear", shade=True), quick=True,
          note=SAMPLING_NOTE + " Gradients: VTK's central difference spans N/(N-1) voxels, "
          "ferrovol's exactly one."),
    Scene("wavelet-gradient-opacity", "wavelet 128^3, composite, linear, gradient opacity "
          "0..10 (VTK units)", "wavelet128", wavelet_gradient_opacity,
          note=SAMPLING_NOTE),
    Scene("wavelet-gradient-opacity-normal-from-opacity", "wavelet 128^3, composite, linear, "
          "gradient opacity 0..10 (VTK units), shaded with normals from the gradient of "
          "opacity x gradient opacity (ComputeNormalFromOpacity)", "wavelet128",
          shaded(wavelet_gradient_opacity), configure=normal_from_opacity(),
          note=SAMPLING_NOTE),
    Scene("wavelet-volumetric-normal-from-opacity", "wavelet 128^3, composite, linear, "
          "volumetric shadows blended with gradient shading (VolumetricScatteringBlending "
          "0.7, GlobalIlluminationReach 0.5), normals and the blending's gradient from the "
          "opacity (ComputeNormalFromOpacity), opacity peak at 160", "wavelet128",
          wavelet_tf("linear", shade=True, opacity=WAVELET_PEAK_OPACITY),
          configure=normal_from_opacity(volumetric(0.7, 0.5)), note=SAMPLING_NOTE),
    Scene("wavelet-volumetric-headlight", "wavelet 128^3, composite, linear, volumetric "
          "shadows only (VolumetricScatteringBlending 2, GlobalIlluminationReach 0.5, "
          "anisotropy 0.3), headlight", "wavelet128",
          anisotropic(wavelet_tf("linear", shade=True), 0.3), configure=volumetric(2.0, 0.5),
          quick=True, note=SAMPLING_NOTE),
    Scene("wavelet-volumetric-blend", "wavelet 128^3, composite, linear, volumetric shadows "
          "blended by the gradient (VolumetricScatteringBlending 1, reach 0.3), side light",
          "wavelet128", wavelet_tf("linear", shade=True), configure=volumetric(1.0, 0.3),
          lights=side_light, note=SAMPLING_NOTE + " The blend weight depends on VTK's "
          "gradient magnitude of the normalised scalar, which ferrovol normalises by the "
          "data range."),
    Scene("wavelet-mip", "wavelet 128^3, maximum intensity", "wavelet128", wavelet_tf("nearest"),
          views=one("maximum"), quick=True, note=OUTLINE_NOTE),
    Scene("wavelet-minip", "wavelet 128^3, minimum intensity", "wavelet128", minip_tf(),
          views=one("minimum"), quick=True, note=OUTLINE_NOTE + " " + SAMPLING_NOTE),
    Scene("wavelet-average", "wavelet 128^3, average intensity, AverageIPScalarRange 100..300",
          "wavelet128", wavelet_tf("linear"), views=one("average"),
          configure=average_range(100.0, 300.0)),
    Scene("wavelet-additive", "wavelet 128^3, additive", "wavelet128", additive_tf,
          views=one("additive"), quick=True),
    Scene("wavelet-isosurface", "wavelet 128^3, isosurface blend, iso-values 150 and 220",
          "wavelet128", wavelet_tf("linear", shade=True), views=one("isosurface"),
          iso_values=(150.0, 220.0), quick=True),
    Scene("wavelet-slice", "wavelet 128^3, slice blend, an oblique vtkPlane through the centre",
          "wavelet128", slice_tf(), views=one("slice"), quick=True),
    Scene("wavelet-slice-shaded", "wavelet 128^3, slice blend, shaded (headlight), another "
          "oblique plane", "wavelet128", slice_tf(shade=True, normal=(1.0, 0.2, 0.5)),
          views=one("slice"), note="Gradients: VTK's central difference spans N/(N-1) "
          "voxels, ferrovol's exactly one; a slice shows each pixel's shading unaveraged."),
    Scene("wavelet-slice-shaded-scaled", "as wavelet-slice-shaded, the vtkVolume rotated and "
          "scaled (1, 1.4, 0.8): VTK's plane mapping under a non-uniform scale", "wavelet128",
          slice_tf(shade=True, normal=(1.0, 0.2, 0.5)), views=one("slice"),
          volume=rotate_scale, note="VTK 9.2 shades in the volume's data coordinates (light "
          "and view directions taken back through the vtkVolume's matrix), ferrovol in world "
          "coordinates: under the non-uniform scale the lighting differs (ferrovol 7 levels "
          "brighter on average); the slice's outline is identical."),
    # --- wavelet 128^3: mapper settings and scene
    Scene("wavelet-crop-subvolume", "wavelet 128^3, cropping SubVolume "
          "(-30..35, -40..25, -35..30)", "wavelet128", wavelet_tf("nearest"), quick=True,
          configure=crop((-30, 35, -40, 25, -35, 30), "SubVolume"), note=SAMPLING_NOTE),
    Scene("wavelet-crop-subvolume-vtk-planes", "control: as wavelet-crop-subvolume, but "
          "ferrovol is given the planes where VTK 9.2 actually crops (c + (p - c) N/(N-1))",
          "wavelet128", wavelet_tf("nearest"),
          configure=crop_vtk_placed((-30, 35, -40, 25, -35, 30), "SubVolume", 128, -0.5),
          note="VTK 9.2 converts cropping planes with the texture matrix that maps the point "
          "bounds onto [0, 1] but compares them with coordinates that map them onto "
          "[0.5/N, 1 - 0.5/N]: its planes sit N/(N-1) times farther from the volume's centre "
          "than asked (here 128/127). ferrovol crops where asked; with the planes moved, the "
          "two agree."),
    Scene("wavelet-crop-fence", "wavelet 128^3, cropping Fence (-20..20 on each axis)",
          "wavelet128", wavelet_tf("nearest"), configure=crop((-20, 20) * 3, "Fence"),
          note=SAMPLING_NOTE),
    Scene("wavelet-clip-two-planes", "wavelet 128^3, two clipping planes (a wedge cut away)",
          "wavelet128", wavelet_tf("linear"), quick=True,
          configure=clip_planes(((0, 0, 0), (1, 0.3, 0)), ((0, 15, 0), (0.2, -1, 0.4))),
          note=SAMPLING_NOTE),
    Scene("wavelet-clip-eight-planes", "wavelet 128^3, eight clipping planes (the most "
          "vtkGPUVolumeRayCastMapper takes): every corner of the cube cut off",
          "wavelet128", wavelet_tf("linear"), quick=True,
          configure=clip_planes(*EIGHT_CORNER_PLANES),
          note=SAMPLING_NOTE + " VTK 9.2 maps clipping planes through the texture matrix "
          "that also misplaces its cropping planes: they sit N/(N-1) farther from the "
          "volume's centre than asked (here 128/127, about 0.4 voxel); ferrovol clips where "
          "asked (control: -vtk-planes)."),
    Scene("wavelet-clip-eight-planes-vtk-planes", "control: as wavelet-clip-eight-planes, but "
          "ferrovol is given the planes where VTK 9.2 actually clips (c + (o - c) N/(N-1))",
          "wavelet128", wavelet_tf("linear"), quick=True,
          configure=clip_planes_vtk_placed(EIGHT_CORNER_PLANES, 128, -0.5),
          note=SAMPLING_NOTE),
    Scene("wavelet-clip-clipped-voxel-intensity", "wavelet 128^3, shaded, a clipping plane "
          "facing the camera, UseClippedVoxelIntensity at 40 (gradients see a low wall "
          "beyond the plane: a lit cut face), sample distance 0.25", "wavelet128",
          clipped_voxel_intensity(wavelet_tf("linear", shade=True), 40.0), quick=True,
          configure=both(clip_planes(FACING_PLANE), sample_distance(0.25)),
          note=SAMPLING_NOTE + " The first sample lies a step beyond the plane: at a "
          "quarter voxel the gradients' neighbours reach across it."),
    Scene("wavelet-clip-clipped-voxel-intensity-gradient-opacity", "as "
          "wavelet-clip-clipped-voxel-intensity, unshaded, with gradient opacity 0..10 (VTK "
          "units) reading the value beyond the plane", "wavelet128",
          clipped_voxel_intensity(wavelet_gradient_opacity, 40.0),
          configure=both(clip_planes(FACING_PLANE), sample_distance(0.25)),
          note=SAMPLING_NOTE),
    Scene("wavelet-ghost-blanking", "wavelet 128^3 with ghost arrays: a box of hidden cells "
          "and a slab of hidden points left out (vtkUniformGrid blanking)",
          "wavelet128_blanked", wavelet_tf("linear", shade=True), quick=True,
          note=SAMPLING_NOTE + " Both mappers skip a sample whose nearest point, or a point "
          "around it along an axis, is hidden."),
    Scene("wavelet-sphere", "wavelet 128^3 with an opaque sphere intersecting it (depth "
          "in and out)", "wavelet128", wavelet_tf("linear"), quick=True,
          actors=sphere_actor((20, -20, 40), 28), views=one(camera=orbit(20, 10)),
          note=SAMPLING_NOTE + " VTK also samples up to one step behind the opaque "
          "surface (its loop tests the depth after stepping)."),
    Scene("wavelet-parallel", "wavelet 128^3, composite, parallel projection", "wavelet128",
          wavelet_tf("nearest"), views=one(camera=orbit(parallel=True)), note=SAMPLING_NOTE),
    Scene("wavelet-camera-inside", "wavelet 128^3, camera inside the volume (70 degree "
          "view angle), translucent", "wavelet128", wavelet_tf("linear", unit_distance=12.0), quick=True,
          views=one(camera=inside_wavelet),
          note=SAMPLING_NOTE + " Inside, VTK starts rays on the near plane moved "
          "0.001 x (far - near) further (its clipped proxy box), ferrovol on the near plane."),
    Scene("wavelet-volume-matrix", "wavelet 128^3 in a rotated (z 30, x 20) and scaled "
          "(1, 1.4, 0.8) vtkVolume", "wavelet128", wavelet_tf("nearest"), quick=True, volume=rotate_scale,
          note=SAMPLING_NOTE + " VTK steps in the volume's data space (unit direction before "
          "the vtkVolume matrix), ferrovol in world space: with a scale the steps differ."),
    Scene("wavelet-two-viewports", "wavelet 128^3 in two viewports of one window: composite "
          "(left) and MIP from another side (right)", "wavelet128", wavelet_tf("nearest"), quick=True,
          views=[View("composite", orbit(30, 20), (0.0, 0.0, 0.5, 1.0)),
                 View("maximum", orbit(-50, -15), (0.5, 0.0, 1.0, 1.0))],
          size=(600, 300), note=SAMPLING_NOTE),
    Scene("wavelet-minip-no-msaa", "control: wavelet-minip in a window without multisampling",
          "wavelet128", minip_tf(), views=one("minimum"), multisamples=0,
          note="Without MSAA VTK's proxy box has no partially covered silhouette pixels: "
          "what remains is the sample lattice alone."),
    Scene("wavelet-900", "wavelet 128^3, composite, nearest, 900x900", "wavelet128",
          wavelet_tf("nearest"), size=(900, 900), views=one(camera=orbit(1, 1)),
          note=SAMPLING_NOTE),
    Scene("wavelet21-minip-perspective", "wavelet 21^3, minimum intensity, perspective: the "
          "view of the MinIP triangle next to the back corner, linear", "wavelet21",
          minip_tf("linear"),
          quick=True, views=one("minimum", orbit(30, 20)),
          note="The triangle left of the centre is in VTK's image too: both lattices start at "
          "the box entry, and in perspective the chord length through opposite faces crosses "
          "a whole number of steps there (SAMPLING.md). " + OUTLINE_NOTE + " " + SAMPLING_NOTE),
    Scene("wavelet21-minip-parallel", "wavelet 21^3, minimum intensity, parallel projection "
          "(no triangle: chords through opposite faces all have one length), linear", "wavelet21",
          minip_tf("linear"), views=one("minimum", orbit(30, 20, parallel=True)),
          note=OUTLINE_NOTE + " " + SAMPLING_NOTE),
    # --- Marschner-Lobb 41^3
    Scene("ml-composite-shaded", "Marschner-Lobb 41^3, narrow opacity peak at 0.5, shaded "
          "(reconstruction and gradient quality)", "marschner_lobb", ml_tf(), quick=True,
          views=one(camera=orbit(0, 30)),
          note=SAMPLING_NOTE + " Gradients: VTK's central difference spans N/(N-1) voxels "
          "(41/40 here), ferrovol's exactly one."),
    Scene("ml-composite-shaded-normal-from-opacity", "Marschner-Lobb 41^3, narrow opacity "
          "peak at 0.5, shaded with normals from the opacity gradient "
          "(ComputeNormalFromOpacity: they turn over past the peak)", "marschner_lobb",
          ml_tf(), quick=True, views=one(camera=orbit(0, 30)), configure=normal_from_opacity(),
          note=SAMPLING_NOTE + " Gradients: VTK's central difference spans N/(N-1) voxels "
          "(41/40 here), ferrovol's exactly one."),
    Scene("ml-mip", "Marschner-Lobb 41^3, maximum intensity", "marschner_lobb",
          ml_tf(shade=False), views=one("maximum", orbit(0, 30)), note=OUTLINE_NOTE),
    Scene("ml-isosurface", "Marschner-Lobb 41^3, isosurface blend, iso-values 0.3 and 0.5",
          "marschner_lobb", ml_tf(), quick=True, views=one("isosurface", orbit(0, 30)),
          iso_values=(0.3, 0.5)),
    # --- skull CT (anisotropic spacing 0.957 x 0.957 x 1.5)
    Scene("ct-composite-shaded", "skull CT 256x256x108 int16 (anisotropic spacing), bone "
          "and skin, shaded, front", "cranium", ct_tf(), views=one(camera=ct_front()),
          quick=True),
    Scene("ct-volumetric-shadows", "skull CT (anisotropic spacing), bone and skin, volumetric "
          "shadows blended by the gradient (VolumetricScatteringBlending 1, reach 0.3), side "
          "light", "cranium", ct_tf(), views=one(camera=ct_front()), size=(240, 240),
          configure=volumetric(1.0, 0.3), lights=side_light),
    Scene("ct-composite-641x379", "skull CT, shaded, oblique, odd window 641x379",
          "cranium", ct_tf(), size=(641, 379), views=one(camera=ct_front(35, 15, 1.1))),
    Scene("ct-composite-nearest-parallel", "skull CT, unshaded, nearest, parallel projection, "
          "from the side", "cranium", ct_tf(shade=False, interpolation="nearest"),
          views=one(camera=ct_front(90, 0, 1.2, parallel=True))),
    Scene("ct-mip", "skull CT, maximum intensity", "cranium", ct_mip_tf,
          views=one("maximum", ct_front(20, 10)), note=OUTLINE_NOTE),
    Scene("ct-isosurface", "skull CT, isosurface blend, skin (-300 HU) and bone (400 HU)",
          "cranium", ct_tf(), views=one("isosurface", ct_front()), iso_values=(-300.0, 400.0)),
    # --- Colin27 MRI
    Scene("mri-composite", "Colin27 T1 MRI 181x217x181 uint8, scalp and brain, composite, "
          "linear", "colin27", mri_tf(), views=one(camera=orbit(-60, 10, 1.2))),
    Scene("mri-composite-shaded", "Colin27 T1 MRI, shaded", "colin27", mri_tf(shade=True),
          views=one(camera=orbit(120, 20, 1.2))),
    Scene("mri-mip", "Colin27 T1 MRI, maximum intensity", "colin27", mri_mip_tf,
          views=one("maximum", orbit(90, 0, 1.2))),
    # --- heart (small float volume, spacing 1 x 1 x 4, note=OUTLINE_NOTE)
    Scene("heart-composite", "heart.vti 32x32x12 float32 (spacing 1 x 1 x 4), composite, "
          "linear", "heart", heart_tf(), quick=True, views=one(camera=orbit(30, 30))),
    Scene("heart-composite-nearest", "heart.vti, composite, nearest (blocks of 1x1x4)",
          "heart", heart_tf("nearest"), views=one(camera=orbit(30, 30))),
    Scene("heart-mip", "heart.vti, maximum intensity", "heart", heart_tf(),
          views=one("maximum", orbit(-30, 40)), note=OUTLINE_NOTE),
    # --- label map
    # --- masks (vtkGPUVolumeRayCastMapper's MaskInput)
    Scene("ct-binary-mask", "skull CT, bone and skin, shaded, a binary mask cutting a quarter "
          "away", "cranium", ct_tf(), views=one(camera=ct_front(35, 15, 1.1)),
          configure=mask(cranium_cutaway_mask), fixed=False, quick=True),
    Scene("ct-binary-mask-mip", "skull CT, maximum intensity, the binary cutaway mask",
          "cranium", ct_mip_tf, views=one("maximum", ct_front(35, 15, 1.1)),
          configure=mask(cranium_cutaway_mask), fixed=False),
    Scene("ct-binary-mask-isosurface", "skull CT, isosurfaces -300 and 400 HU, the binary "
          "cutaway mask (surfaces capped where the mask ends, as VTK)", "cranium", ct_tf(),
          views=one("isosurface", ct_front(35, 15, 1.1)), iso_values=(-300.0, 400.0),
          configure=mask(cranium_cutaway_mask), fixed=False),
    Scene("ct-transfer-2d", "skull CT through a 2D transfer function (scalar x gradient "
          "magnitude: skin and bone boundaries), shaded", "cranium", ct_tf_2d(),
          views=one(camera=ct_front(35, 15, 1.1)), fixed=False),
    Scene("frog-label-map", "frog tissues 500x470x136 uint8 as a label map of themselves: "
          "five labels their own colour and opacity, nearest", "frog", frog_tf(),
          views=one(camera=orbit(30, 20, 1.3)), configure=mask(frog_mask, label_map=True),
          fixed=False, quick=True),
    Scene("frog-label-map-blend", "frog label map, MaskBlendFactor 0.5, shaded", "frog",
          frog_tf(shade=True), views=one(camera=orbit(30, 20, 1.3)),
          configure=mask(frog_mask, label_map=True, blend_factor=0.5), fixed=False),
    Scene("rectilinear-points", "wavelet 64^3 point data on a vtkRectilinearGrid whose x "
          "spacing grows from 1 to 2.26", "wavelet_rectilinear_points", wavelet_tf("linear"),
          fixed=False, quick=True),
    Scene("rectilinear-cells", "wavelet 64^3 as cell data of a vtkRectilinearGrid whose x "
          "spacing grows from 1 to 2.28", "wavelet_rectilinear_cells", wavelet_tf("linear"),
          fixed=False),
    Scene("intermix-wavelet-ml", "two volumes intermixed per sample (vtkMultiVolume): wavelet "
          "128^3 on port 0, Marschner-Lobb 41^3 on port 1 scaled, turned and moved to overlap "
          "it in part, each its own transfer function", "wavelet128", wavelet_tf("linear"),
          intermix=lambda: [("marschner_lobb", ml_intermixed(), ml_in_wavelet)],
          views=one(camera=orbit(30, 20, 1.1)), fixed=False, quick=True),
    Scene("intermix-wavelet-ml-shaded", "intermix-wavelet-ml with shading on (port 0's "
          "property turns it on for both, as VTK)", "wavelet128", wavelet_tf("linear", True),
          intermix=lambda: [("marschner_lobb", ml_intermixed(True), ml_in_wavelet)],
          views=one(camera=orbit(30, 20, 1.1)), fixed=False),
    Scene("labels-composite", "label map 128x128x108 uint8 (skull CT in 4 tissues), "
          "categorical TF, nearest", "labels", label_tf, quick=True,
          views=one(camera=ct_front(30, 10))),
]

# The unstructured grids' data and scenes (ugrid_scenes.py builds them from the pieces above;
# import this module, not that one, first).
import ugrid_scenes  # noqa: E402

DATA.update(ugrid_scenes.DATA)
SCENES += ugrid_scenes.SCENES

BY_NAME = {s.name: s for s in SCENES}
