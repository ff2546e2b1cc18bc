"""(e) Path tracing refines by itself in a view with an interactor, and screenshots are
converged images.

    pvpython paraview/tests/test_progressive.py   the view's interactor (an X interactor in
        pvpython) runs timers: renders trace within the time budget, and while the
        interactor's event loop runs (here 4 s, ended by a timer) the view renders again by
        itself, without any property change: the accumulation grows and the estimated error
        of the image falls; SaveScreenshot then traces the whole budget, and its image equals
        a render with progressive mode off.
    pvbatch paraview/tests/test_progressive.py    no interactor that runs timers: one Render()
        traces the whole budget, and SaveScreenshot shows that image.
"""
import os
import sys
import time

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import fvtest as T  # noqa: E402
from paraview.simple import Render, Show, Wavelet, servermanager  # noqa: E402

T.load_plugin(globals())
SPP = 48
PM = servermanager.vtkProcessModule
BATCH = PM.GetProcessType() == PM.PROCESS_BATCH


def scene(progressive="Automatic"):
    view = T.make_view((160, 160))
    src = Wavelet()
    disp = Show(src, view)
    T.color_by(disp, "RTData",
               rgb_points=[37.35, 0.23, 0.30, 0.75, 157.1, 0.87, 0.87, 0.87, 276.8, 0.71, 0.02, 0.15],
               opacity_points=[37.35, 0.0, 0.5, 0.0, 276.8, 0.8, 0.5, 0.0])
    disp.Representation = "Ferrovol Volume"
    disp.ScalarOpacityUnitDistance = 3.0
    disp.FerrovolRenderMode = "Path Trace"
    disp.FerrovolSamplesPerPixel = SPP
    disp.FerrovolPathTracingTimeBudget = 0.05
    disp.FerrovolPathTracingDenoiseUntil = 0
    disp.FerrovolProgressiveMode = progressive
    T.set_camera(view, src.GetDataInformation().GetBounds(), azimuth=30, elevation=20)
    return view, disp


def state(disp):
    disp.UpdatePropertyInformation()
    return (disp.GetProperty("FerrovolAccumulatedSamples").GetData(),
            disp.GetProperty("FerrovolMeanAccumulatedSamples").GetData(),
            disp.GetProperty("FerrovolPathTracingError").GetData())


failures = []
view, disp = scene()
Render(view)
n1, mean1, err1 = state(disp)
T.log("  after the first render: %d complete passes, %.2f paths per pixel on average, "
      "estimated error %.3f" % (n1, mean1, err1))
if BATCH:
    if n1 != SPP:
        failures.append("pvbatch: a render traced %d paths per pixel, not the budget %d"
                        % (n1, SPP))
    shot, _, _ = T.screenshot(view, "progressive-pvbatch")
    again, _, _ = T.screenshot(view, "progressive-pvbatch-again")
    if (shot != again).any():
        failures.append("pvbatch: a second screenshot differs from the first")
    T.finish(failures, "pvbatch: a render traces the whole budget")
else:
    if mean1 >= SPP:
        failures.append("the first render traced the whole budget (%.1f paths per pixel): it "
                        "should stop at the time budget" % mean1)
    iren = view.GetRenderWindow().GetInteractor()
    started = time.time()
    seen = []


    def on_timer(obj, event):
        # (read while the loop runs: ending it closes the window, which frees the renderer)
        seen.append((time.time() - started,) + state(disp))
        if seen[-1][0] >= 4.0:
            obj.TerminateApp()


    iren.AddObserver("TimerEvent", on_timer)
    iren.CreateRepeatingTimer(200)
    iren.Start()
    for second in (1, 2, 3, 4):
        t, n, mean, err = next(x for x in seen if x[0] >= second - 0.1)
        T.log("  %.1f s into the interactor's event loop, nothing else called: %d complete passes, "
              "%.2f paths per pixel on average, estimated error %.3f" % (t, n, mean, err))
    _, n2, mean2, err2 = seen[-1]
    if not mean2 > mean1 + 1:
        failures.append("the view did not refine by itself (%.2f then %.2f paths per pixel)"
                        % (mean1, mean2))
    if not 0 <= err2 < 0.8 * max(err for _, _, _, err in seen if err >= 0):
        failures.append("the estimated error did not fall (%s)" % [round(x[3], 3) for x in seen])
    shot, _, _ = T.screenshot(view, "progressive-pvpython-screenshot")
    n3, _, _ = state(disp)
    T.log("  SaveScreenshot: %d paths per pixel" % n3)
    if n3 != SPP:
        failures.append("SaveScreenshot traced %d paths per pixel, not the budget %d" % (n3, SPP))
    T.Delete(disp)
    T.Delete(view)
    view, disp = scene("Off")
    Render(view)
    off, _, _ = T.screenshot(view, "progressive-pvpython-off")
    differ = int((shot != off).any(axis=-1).sum())
    T.log("  the screenshot against a render with Progressive Mode Off: %d pixels differ" % differ)
    if differ:
        failures.append("the progressive view's screenshot differs from a full still render in "
                        "%d pixels" % differ)
    T.finish(failures, "pvpython: the view refines by itself; screenshots are converged")
