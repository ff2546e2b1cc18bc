#!/usr/bin/python3
"""Equal-fidelity benchmark: time and image error together, in one run, for
vtkFerroVolumeMapper and vtkGPUVolumeRayCastMapper in a VTK window.

For each scene, each renderer first draws a converged reference in its own conventions:
the same scene at a sample distance of 1/16 of the smallest voxel spacing (AutoAdjust off,
no jittering). Every timed configuration is then measured twice: its image at the scene's
camera against its renderer's reference (PSNR, SSIM and mean FLIP), and its frame time
over --frames frames while the camera turns 1 degree per frame (the mean, after warm-up,
each frame waited for with WaitForCompletion). The configurations:

  ferrovol default   vtkFerroVolumeMapper as a script gets it
  ferrovol fast      SampleDistance twice the smallest spacing (AutoAdjust off)
  ferrovol half      SampleDistance half the smallest spacing (AutoAdjust off)
  pre-int default    the default with PreIntegration on
  pre-int fast       ferrovol fast with PreIntegration on
  midpoint default   the default with MidpointQuadrature on
  midpoint fast      ferrovol fast with MidpointQuadrature on
  adaptive default   the default with AdaptiveSampling on (midpoints, a step per block)
  vtk default        vtkGPUVolumeRayCastMapper as a script gets it

(ferrovol's reference is drawn without pre-integration and on VTK's lattice: every rule
converges to the same image; the midpoint one's own converged image is 57-71 dB from it)

and one more row says how far the two references are from each other (the two
renderers' conventions). Scenes: the wavelet benchmark (VTK's TestGPURayCastMapperBenchmark
functions) unshaded and shaded, the skull CT with bone and skin (build/data/cranium.vti,
scripts/fetch-data.sh; skipped without it), the wavelet under a transfer function of thin
opacity peaks (where sampling error is largest), and MIP.

    . build/env.sh && scripts/with-xvfb.sh /usr/bin/python3 bench/fidelity.py
"""
import argparse
import os
import sys
import time

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(HERE)
sys.path.insert(0, os.path.join(ROOT, "vtk_plugin", "tests"))
sys.path.insert(0, os.path.join(ROOT, "tests", "regression"))
sys.path.insert(0, os.path.join(ROOT, "tests"))

WARMUP = 2
LATTICE, MIDPOINT, ADAPTIVE = range(3)
REFERENCE_DIVISOR = 16


def scenes():
    """(name, data, make_property, blend mode, camera) of every benchmark scene."""
    import scenes as S
    from fvtest import tf_property, WAVELET_COLOR
    peaks = [(37.35, 0.0)]
    for centre in (110.0, 150.0, 190.0, 230.0):
        peaks += [(centre - 1.5, 0.0), (centre, 0.8), (centre + 1.5, 0.0)]
    peaks.append((276.83, 0.0))
    out = [
        ("wavelet", S.wavelet128, S.wavelet_tf(), "composite", S.orbit()),
        ("wavelet shaded", S.wavelet128, S.wavelet_tf(shade=True), "composite", S.orbit()),
        ("wavelet thin peaks", S.wavelet128,
         lambda: tf_property(color=WAVELET_COLOR, opacity=peaks, interpolation="linear"),
         "composite", S.orbit()),
        ("wavelet MIP", S.wavelet128, S.wavelet_tf(), "mip", S.orbit()),
        ("skull CT bone+skin", S.cranium, S.ct_tf(), "composite", S.ct_front()),
    ]
    return out


def make_mapper(kind):
    import vtk
    if kind == "ferrovol":
        import ferrovol
        return ferrovol.vtkFerroVolumeMapper()
    return vtk.vtkGPUVolumeRayCastMapper()


class Bench:
    """One renderer's window for a scene."""

    def __init__(self, kind, data, make_property, blend, camera, size):
        import vtk
        from fvtest import new_window
        self.mapper = make_mapper(kind)
        self.mapper.SetInputData(data)
        if blend == "mip":
            self.mapper.SetBlendModeToMaximumIntensity()
        self.volume = vtk.vtkVolume()
        self.volume.SetMapper(self.mapper)
        self.volume.SetProperty(make_property())
        self.renderer = vtk.vtkRenderer()
        self.renderer.AddVolume(self.volume)
        self.window = new_window()
        self.window.SetSize(*size)
        self.window.SetMultiSamples(0)
        self.window.AddRenderer(self.renderer)
        self.renderer.ResetCamera()
        camera(self.renderer.GetActiveCamera())
        self.renderer.ResetCameraClippingRange()
        self.start = vtk.vtkCamera()
        self.start.DeepCopy(self.renderer.GetActiveCamera())
        self.spacing = min(data.GetSpacing())

    def configure(self, sample_distance=None, preintegration=False, quadrature=LATTICE):
        """Sample distance as a multiple of the smallest spacing; None: the defaults."""
        m = self.mapper
        if hasattr(m, "SetPreIntegration"):
            m.SetPreIntegration(preintegration)
            m.SetMidpointQuadrature(quadrature == MIDPOINT)
            m.SetAdaptiveSampling(quadrature == ADAPTIVE)
        if sample_distance is None:
            m.AutoAdjustSampleDistancesOn()
            m.SetSampleDistance(1.0)
        else:
            m.AutoAdjustSampleDistancesOff()
            m.SetSampleDistance(sample_distance * self.spacing)
        m.SetUseJittering(0)

    def image(self):
        """The frame at the scene's camera, float RGB on [0, 255]."""
        import numpy as np
        import vtk
        from vtk.util.numpy_support import vtk_to_numpy
        self.renderer.GetActiveCamera().DeepCopy(self.start)
        self.renderer.ResetCameraClippingRange()
        self.window.Render()
        self.window.WaitForCompletion()
        w, h = self.window.GetSize()
        px = vtk.vtkUnsignedCharArray()
        self.window.GetRGBACharPixelData(0, 0, w - 1, h - 1, 0, px)
        return vtk_to_numpy(px).reshape(h, w, 4)[::-1, :, :3].astype(np.float64)

    def ms_per_frame(self, frames):
        cam = self.renderer.GetActiveCamera()
        cam.DeepCopy(self.start)
        for i in range(WARMUP + frames):
            if i == WARMUP:
                t0 = time.perf_counter()
            cam.Azimuth(1.0)
            self.renderer.ResetCameraClippingRange()
            self.window.Render()
            self.window.WaitForCompletion()
        return (time.perf_counter() - t0) / frames * 1e3


def errors(reference, img):
    from ferrovol_testing.flip import mean_flip
    from ferrovol_testing.metrics import psnr, ssim
    return psnr(reference, img), ssim(reference, img), mean_flip(reference, img)


def main(argv):
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("--frames", type=int, default=10, help="timed frames per configuration")
    p.add_argument("--size", default="400x400", help="window size WxH (default 400x400)")
    p.add_argument("--scenes", help="only the scenes whose names contain this text")
    args = p.parse_args(argv)
    size = tuple(int(v) for v in args.size.lower().split("x"))

    import scenes as S
    print("# equal fidelity: error against each renderer's own reference (sample distance "
          "1/%d voxel), frame time over %d frames, %dx%d" % (
              REFERENCE_DIVISOR, args.frames, *size))
    print("%-20s %-17s %9s %9s %7s %7s %9s" % (
        "scene", "configuration", "ms/frame", "PSNR dB", "SSIM", "FLIP", "vs VTK"))
    for name, data, make_property, blend, camera in scenes():
        if args.scenes and args.scenes not in name:
            continue
        try:
            image = data()
        except S.MissingData as e:
            print("%-20s skipped: %s" % (name, e))
            continue
        benches = {k: Bench(k, image, make_property, blend, camera, size)
                   for k in ("ferrovol", "vtk")}
        refs = {}
        for kind, b in benches.items():
            b.configure(1.0 / REFERENCE_DIVISOR)
            refs[kind] = b.image()
        rows = []
        for label, kind, distance, pre, mid in (
                ("ferrovol default", "ferrovol", None, False, LATTICE),
                ("ferrovol fast", "ferrovol", 2.0, False, LATTICE),
                ("ferrovol half", "ferrovol", 0.5, False, LATTICE),
                ("pre-int default", "ferrovol", None, True, LATTICE),
                ("pre-int fast", "ferrovol", 2.0, True, LATTICE),
                ("midpoint default", "ferrovol", None, False, MIDPOINT),
                ("midpoint fast", "ferrovol", 2.0, False, MIDPOINT),
                ("adaptive default", "ferrovol", None, False, ADAPTIVE),
                ("vtk default", "vtk", None, False, LATTICE)):
            b = benches[kind]
            b.configure(distance, pre, mid)
            img = b.image()
            rows.append((label, b.ms_per_frame(args.frames)) + errors(refs[kind], img))
        vtk_ms = rows[-1][1]
        for label, ms, db, s, f in rows:
            print("%-20s %-17s %9.1f %9.2f %7.4f %7.4f %9.2f" % (
                name, label, ms, db, s, f, ms / vtk_ms), flush=True)
        db, s, f = errors(refs["vtk"], refs["ferrovol"])
        print("%-20s %-17s %9s %9.2f %7.4f %7.4f" % (name, "references", "", db, s, f))
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
