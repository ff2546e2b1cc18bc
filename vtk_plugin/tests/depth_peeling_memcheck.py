"""test_scene's depth-peeling scene at 48x48 (the wavelet 15³, a translucent sphere inside
it, dual depth peeling of volumes), rendered twice, for valgrind (docs/RELIABILITY.md):

    . build/env.sh; MESA_SHADER_CACHE_DISABLE=true \
      scripts/with-xvfb.sh valgrind --error-limit=no /usr/bin/python3 \
      vtk_plugin/tests/depth_peeling_memcheck.py
"""
import numpy as np

import ferrovol
import fvtest
from fvtest import Scene, grab, tf_property, wavelet


def view(cam):
    cam.Azimuth(30.0)
    cam.Elevation(20.0)
    cam.OrthogonalizeViewUp()


mapper = ferrovol.vtkFerroVolumeMapper()
window = fvtest.new_window()
window.SetMultiSamples(0)
window.SetSize(48, 48)
inside = fvtest.sphere_actor((8, -4, 12), 7, (1.0, 0.3, 0.3), resolution=8)
inside.GetProperty().SetOpacity(0.5)
scene = Scene(mapper, wavelet(15), tf_property(opacity=[(37.3531, 0.0), (276.829, 0.25)]),
              camera=view, actors=[inside])
scene.window.RemoveRenderer(scene.renderer)
scene.renderer.SetUseDepthPeeling(1)
scene.renderer.SetUseDepthPeelingForVolumes(1)
window.AddRenderer(scene.renderer)
window.Render()
a = grab(window)
window.Render()
b = grab(window)
print("max", a.max(), "stable", np.abs(a - b).max(), flush=True)
