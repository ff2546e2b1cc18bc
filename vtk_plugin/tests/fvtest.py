"""Shared pieces of the vtkFerroVolumeMapper tests: scenes, image capture and the images
written for people to look at (FERROVOL_TEST_OUTPUT, default build/vtk/test-images). The
measures (SSIM, PSNR, coverage) come from tests/ferrovol_testing, shared with the ParaView
tests and the regression suite, and are re-exported here.

Run the suites with Debian's /usr/bin/python3 (VTK 9.2), after `. build/env.sh`, with an X
display:  scripts/with-xvfb.sh /usr/bin/python3 -m unittest -v test_vtk_reference
"""
import os
import sys

import numpy as np
import vtk
from vtk.util.numpy_support import numpy_to_vtk, vtk_to_numpy

import ferrovol

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.abspath(os.path.join(HERE, "..", ".."))
sys.path.insert(0, os.path.join(ROOT, "tests"))
from ferrovol_testing.metrics import (  # noqa: E402,F401  (re-exported for the suites)
    coverage, difference_image, luminance, psnr, ssim)
from ferrovol_testing.png import write_png  # noqa: E402
sys.path.append(os.path.join(ROOT, "vtk_plugin", "examples"))
from volume_scene import (  # noqa: E402,F401  (the function helpers re-exported for the suites)
    WAVELET_COLOR, WAVELET_OPACITY, color_function, opacity_function, volume_property)
# The VTK under test: (major, minor), for the thresholds that differ between VTK versions.
VTK_VERSION = (vtk.vtkVersion.GetVTKMajorVersion(), vtk.vtkVersion.GetVTKMinorVersion())
OUTPUT = os.environ.get("FERROVOL_TEST_OUTPUT", os.path.join(ROOT, "build", "vtk", "test-images"))
DATA = os.environ.get("FERROVOL_DATA_DIR", os.path.join(ROOT, "build", "data"))
os.makedirs(OUTPUT, exist_ok=True)


def log(*args):
    print(*args, file=sys.stderr, flush=True)


def wavelet(n=31, maximum=None):
    """vtkRTAnalyticSource with WholeExtent -n..n+1 per axis (float32 point scalars 'RTData')."""
    src = vtk.vtkRTAnalyticSource()
    src.SetWholeExtent(-n, n + 1, -n, n + 1, -n, n + 1)
    if maximum is not None:
        src.SetMaximum(maximum)
    src.Update()
    return src


def roughness(img):
    """Mean |pixel - mean of its 4 neighbours| inside the image (noise, in levels)."""
    c = img[1:-1, 1:-1]
    n = (img[:-2, 1:-1] + img[2:, 1:-1] + img[1:-1, :-2] + img[1:-1, 2:]) / 4.0
    return float(np.abs(c - n).mean())


def image_from_array(arr, spacing=(1.0, 1.0, 1.0), origin=(0.0, 0.0, 0.0), name="scalars",
                     cells=False, vtk_type=None):
    """vtkImageData from a numpy array indexed [z, y, x] or [z, y, x, component]."""
    a = np.asarray(arr)
    comps = a.shape[3] if a.ndim == 4 else 1
    nz, ny, nx = a.shape[:3]
    img = vtk.vtkImageData()
    img.SetDimensions(nx + 1, ny + 1, nz + 1) if cells else img.SetDimensions(nx, ny, nz)
    img.SetSpacing(*spacing)
    img.SetOrigin(*origin)
    flat = np.ascontiguousarray(a.reshape(-1, comps) if comps > 1 else a.reshape(-1))
    data = numpy_to_vtk(flat, deep=True, array_type=vtk_type)
    data.SetName(name)
    if cells:
        img.GetCellData().SetScalars(data)
    else:
        img.GetPointData().SetScalars(data)
    return img


def tf_property(color=WAVELET_COLOR, opacity=WAVELET_OPACITY, interpolation="nearest"):
    prop = volume_property(color, opacity)
    if interpolation == "linear":
        prop.SetInterpolationTypeToLinear()
    return prop


def component_property(colors, max_opacity, top=200.0, interpolation="nearest"):
    """A property with one flat colour per component (its index in colors) and opacity
    rising linearly from 0 at 0 to max_opacity at top."""
    p = vtk.vtkVolumeProperty()
    for c, rgb in enumerate(colors):
        ctf = vtk.vtkColorTransferFunction()
        ctf.AddRGBPoint(0, *rgb)
        ctf.AddRGBPoint(top, *rgb)
        otf = vtk.vtkPiecewiseFunction()
        otf.AddPoint(0, 0.0)
        otf.AddPoint(top, max_opacity)
        p.SetColor(c, ctf)
        p.SetScalarOpacity(c, otf)
    if interpolation == "linear":
        p.SetInterpolationTypeToLinear()
    return p


def sphere_actor(center, radius, color, resolution=32, unlit=False):
    """An opaque sphere (resolution segments around and along); unlit: its flat colour
    everywhere (ambient only)."""
    s = vtk.vtkSphereSource()
    s.SetCenter(*center)
    s.SetRadius(radius)
    s.SetThetaResolution(resolution)
    s.SetPhiResolution(resolution)
    m = vtk.vtkPolyDataMapper()
    m.SetInputConnection(s.GetOutputPort())
    a = vtk.vtkActor()
    a.SetMapper(m)
    a.GetProperty().SetColor(*color)
    if unlit:
        a.GetProperty().SetAmbient(1.0)
        a.GetProperty().SetDiffuse(0.0)
        a.GetProperty().SetSpecular(0.0)
    return a


_DISPLAY_OWNER = []


def new_window():
    """An offscreen vtkRenderWindow. All test windows share one X display connection: on
    these machines Xvfb resets a new connection now and then (~2% of XOpenDisplay calls under
    load), and VTK aborts when that happens, so a process opens only one."""
    if not _DISPLAY_OWNER:
        owner = vtk.vtkRenderWindow()
        owner.SetOffScreenRendering(1)
        owner.SetSize(4, 4)
        owner.Render()
        _DISPLAY_OWNER.append(owner)
    w = vtk.vtkRenderWindow()
    w.SetDisplayId(_DISPLAY_OWNER[0].GetGenericDisplayId())
    w.SetOffScreenRendering(1)
    return w


class Errors:
    """Collects the ErrorEvents (and WarningEvents) of a VTK object."""

    def __init__(self, obj):
        self.messages = []
        self.warnings = []

        @vtk.calldata_type(vtk.VTK_STRING)
        def on_error(_obj, _event, message):
            self.messages.append(message)

        @vtk.calldata_type(vtk.VTK_STRING)
        def on_warning(_obj, _event, message):
            self.warnings.append(message)

        self._cb = (on_error, on_warning)
        obj.AddObserver("ErrorEvent", on_error)
        obj.AddObserver("WarningEvent", on_warning)

    def last(self):
        return self.messages[-1] if self.messages else ""


class Scene:
    """A renderer and an offscreen window holding one volume (and optional actors)."""

    def __init__(self, mapper, data, prop, size=(160, 160), background=(0.0, 0.0, 0.0),
                 camera=None, actors=()):
        self.mapper = mapper
        path = os.environ.get("FERROVOL_OUTPUT_PATH")  # readback / shared: force one path
        if path and mapper.IsA("vtkFerroVolumeMapper"):
            getattr(mapper, "SetOutputPathTo" + path.capitalize())()
        if data is not None:
            if isinstance(data, vtk.vtkAlgorithm):
                mapper.SetInputConnection(data.GetOutputPort())
            else:
                mapper.SetInputData(data)
        self.volume = vtk.vtkVolume()
        self.volume.SetMapper(mapper)
        self.volume.SetProperty(prop)
        self.renderer = vtk.vtkRenderer()
        self.renderer.SetBackground(*background)
        self.renderer.AddVolume(self.volume)
        for a in actors:
            self.renderer.AddActor(a)
        self.window = new_window()
        self.window.SetSize(*size)
        self.window.AddRenderer(self.renderer)
        self.renderer.ResetCamera()
        if camera:
            camera(self.renderer.GetActiveCamera())
            self.renderer.ResetCameraClippingRange()

    def render(self):
        """Renders once and returns the window as float RGB, rows top to bottom."""
        self.window.Render()
        return grab(self.window, rerender=False)


def ferrovol_scene(data, prop, *configure, **scene_args):
    """A Scene around a new vtkFerroVolumeMapper, after each of configure (callables taking
    the mapper; None skipped) has set it up; returns the scene and the mapper's Errors."""
    mapper = ferrovol.vtkFerroVolumeMapper()
    errors = Errors(mapper)
    for c in configure:
        if c:
            c(mapper)
    return Scene(mapper, data, prop, **scene_args), errors


def grab(window, rerender=False):
    w2i = vtk.vtkWindowToImageFilter()
    w2i.SetInput(window)
    w2i.ReadFrontBufferOff()
    if not rerender:
        w2i.ShouldRerenderOff()
    w2i.Update()
    img = w2i.GetOutput()
    nx, ny, _ = img.GetDimensions()
    a = vtk_to_numpy(img.GetPointData().GetScalars()).reshape(ny, nx, -1)[::-1, :, :3]
    return a.astype(np.float64)


def render_pair(data, prop_factory, size=(160, 160), camera=None, configure=None,
                actors_factory=None, background=(0.0, 0.0, 0.0)):
    """The same scene rendered by vtkFerroVolumeMapper and vtkGPUVolumeRayCastMapper."""
    images = []
    mappers = []
    for mapper in (ferrovol.vtkFerroVolumeMapper(), vtk.vtkGPUVolumeRayCastMapper()):
        if configure:
            configure(mapper)
        actors = actors_factory() if actors_factory else ()
        scene = Scene(mapper, data, prop_factory(), size=size, camera=camera, actors=actors,
                      background=background)
        images.append(scene.render())
        mappers.append(mapper)
    return images[0], images[1], mappers[0]


def assert_matches_vtk(test, name, data, prop_factory, floor, camera=None, configure=None):
    """Renders the scene with vtkFerroVolumeMapper and vtkGPUVolumeRayCastMapper; asserts that
    ferrovol raised no error, drew more than 5% of the frame and reached floor = (SSIM, PSNR)
    against VTK's image. Returns ferrovol's image."""
    errors = []

    def observed(m):
        if m.IsA("vtkFerroVolumeMapper"):
            errors.append(Errors(m))
        if configure:
            configure(m)
    ours, theirs, _ = render_pair(data, prop_factory, camera=camera, configure=observed)
    s, p = compare(name, ours, theirs)
    test.assertEqual(errors[0].messages, [])
    test.assertGreater(coverage(ours), 0.05)
    test.assertGreaterEqual(s, floor[0], name)
    test.assertGreaterEqual(p, floor[1], name)
    return ours


def wavelet_image(n=31, start=(0, 0, 0)):
    """The wavelet (fvtest.wavelet) as a vtkImageData whose extent starts at `start`."""
    source = wavelet(n)
    change = vtk.vtkImageChangeInformation()
    change.SetInputConnection(source.GetOutputPort())
    change.SetOutputExtentStart(*start)
    change.Update()
    img = vtk.vtkImageData()
    img.DeepCopy(change.GetOutput())
    return img


def save(name, *images):
    """Writes the images side by side (and their difference, when two) as a PNG."""
    imgs = list(images)
    if len(imgs) == 2:
        imgs.append(difference_image(*imgs))
    return write_png(os.path.join(OUTPUT, name + ".png"), np.concatenate(imgs, axis=1))


def compare(name, ours, theirs):
    """SSIM and PSNR of ferrovol's image against VTK's; prints them and saves the images."""
    s, p = ssim(ours, theirs), psnr(ours, theirs)
    path = save(name, ours, theirs)
    log("  %-28s SSIM %.4f  PSNR %5.1f dB  (%s: ferrovol | VTK | 4x difference)"
        % (name, s, p, os.path.basename(path)))
    return s, p


def timer_interactor(window):
    """A vtkGenericRenderWindowInteractor on `window` whose one-shot timers the test fires
    itself (as toolkit embeddings run them): returns it, initialised, and the set of its
    pending timers (fire them with fire_timers)."""
    iren = vtk.vtkGenericRenderWindowInteractor()
    iren.SetInteractorStyle(None)
    iren.SetRenderWindow(window)
    live = set()

    @vtk.calldata_type(vtk.VTK_INT)
    def created(_obj, _event, timer):
        live.add(timer)

    @vtk.calldata_type(vtk.VTK_INT)
    def destroyed(_obj, _event, timer):
        live.discard(timer)

    iren.AddObserver("CreateTimerEvent", created)
    iren.AddObserver("DestroyTimerEvent", destroyed)
    iren.Initialize()
    return iren, live


def fire_timers(iren, live, done):
    """Fires the pending timers, one at a time, until none is left or done() says to stop;
    returns the most that were pending at once."""
    most = 0
    while live and not done():
        most = max(most, len(live))
        iren.InvokeEvent("TimerEvent", live.pop())  # a one-shot timer fires once
    return most
