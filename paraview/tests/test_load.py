"""(e) The plugin loads, and "Ferrovol Volume" is listed, in every way the README documents:

1. pvpython with PV_PLUGIN_PATH (build/env.sh): ParaView loads it at start-up;
2. pvpython with PV_PLUGIN_PATH, then LoadDistributedPlugin('Ferrovol') by name;
3. pvpython and pvbatch without PV_PLUGIN_PATH: LoadPlugin('<...>/Ferrovol.so');
4. the ParaView GUI (paraview --script, under the caller's X display) with PV_PLUGIN_PATH:
   the representation list of a Wavelet's display (the domain the GUI's representation
   combo box shows) and one frame drawn by ferrovol.
In 1-3 the properties panel's groups are checked too: with "Ferrovol Volume" the panel
shows the Ferrovol group and the standard volume properties ferrovol draws (Shade, opacity,
unit distance, cropping, Blend Mode and Ferrovol Blend Mode, isosurface values, Slice Type,
Use 2D Transfer Function), and not Volume Rendering Mode, which it warns about; "Volume"
keeps all of its own.

Run with any Python 3 (it starts pvpython, pvbatch and paraview itself):
    FERROVOL_PV_PLUGIN_DIR=build/paraview/lib/paraview-5.11/plugins/Ferrovol python3 test_load.py
"""
import os
import shutil
import subprocess
import sys
import tempfile
import time

HERE = os.path.dirname(os.path.abspath(__file__))
REPO = os.path.dirname(os.path.dirname(HERE))
PLUGIN_DIR = os.environ.get(
    "FERROVOL_PV_PLUGIN_DIR",
    os.path.join(REPO, "build", "paraview", "lib", "paraview-5.11", "plugins", "Ferrovol"))
PLUGIN = os.path.join(PLUGIN_DIR, "Ferrovol.so")

PROBE = r'''
import os, sys
from paraview.simple import *
how = sys.argv[1]
if how == "LoadPlugin":
    LoadPlugin(sys.argv[2], remote=False, ns=globals())
elif how == "LoadDistributedPlugin":
    LoadDistributedPlugin("Ferrovol", remote=False, ns=globals())
pm = servermanager.vtkSMProxyManager.GetProxyManager()
info = pm.GetPluginManager().GetLocalInformation()
loaded = [info.GetPluginName(i) for i in range(info.GetNumberOfPlugins()) if info.GetPluginLoaded(i)]
w = Wavelet()
d = Show(w)
reps = list(d.Representation.Available)

# The properties panel: which group shows each property, for which representations (the
# decorators' values). A property belongs to the last group naming it (pqProxyWidget).
def values(e):
    out = [e.GetAttribute("value")] if e is not None and e.GetAttribute("value") else []
    for i in range(e.GetNumberOfNestedElements() if e is not None else 0):
        out += values(e.GetNestedElement(i))
    return out
p = d.SMProxy
group = {}
for i in range(p.GetNumberOfPropertyGroups()):
    g = p.GetPropertyGroup(i)
    for k in range(g.GetNumberOfProperties()):
        if g.GetProperty(k) is not None:
            group[p.GetPropertyName(g.GetProperty(k))] = values(g.GetHints())
shown = ["Shade", "ScalarOpacityFunction", "ScalarOpacityUnitDistance", "UseCropping",
         "CroppingOrigin", "IsosurfaceValues", "BlendMode", "FerrovolBlendMode",
         "FerrovolSampleDistance", "FerrovolUseJittering", "FerrovolEnvironmentLighting",
         "FerrovolAmbientOcclusionSamples", "SliceFunction", "UseTransfer2D"]
hidden = ["VolumeRenderingMode"]
# Ferrovol Blend Mode sits in a group "Volume" shows too; its own hint shows it for
# "Ferrovol Volume" only.
fbm = p.GetProperty("FerrovolBlendMode")
own = values(fbm.GetHints()) if fbm is not None else []
panel = all("Ferrovol Volume" in group.get(n, []) for n in shown) and not any(
    "Ferrovol Volume" in group.get(n, []) for n in hidden) and all(
    "Volume" in group.get(n, []) for n in shown[:7] + hidden) and own == ["Ferrovol Volume"]
print("RESULT loaded=%s has_proxy=%s panel=%s reps=%s" % (
    "Ferrovol" in loaded,
    servermanager.ProxyManager().SMProxyManager.GetProxyDefinitionManager().HasDefinition(
        "representations", "FerrovolVolumeRepresentation"),
    panel, reps))
'''

GUI = r'''
import os
from paraview.simple import *
w = Wavelet()
d = Show(w)
Render()
reps = list(d.Representation.Available)
d.Representation = "Ferrovol Volume"
ColorBy(d, ("POINTS", "RTData"))
Render()
d.UpdatePropertyInformation()
with open(os.environ["FERROVOL_GUI_OUT"], "w") as f:
    f.write("RESULT reps=%s drew=%s\n" % (reps, d.GetProperty("FerrovolLastRenderDrew").GetData()))
os._exit(0)  # leave the GUI
'''


def run(cmd, env, timeout=120):
    t0 = time.time()
    p = subprocess.run(cmd, env=env, stdout=subprocess.PIPE, stderr=subprocess.STDOUT,
                       universal_newlines=True, timeout=timeout)
    return p.returncode, p.stdout, time.time() - t0


def main():
    failures = []
    if not os.path.exists(PLUGIN):
        print("FAIL load: %s is missing (make paraview)" % PLUGIN)
        return 1
    tmp = tempfile.mkdtemp(prefix="ferrovol-pv-load-")
    probe = os.path.join(tmp, "probe.py")
    with open(probe, "w") as f:
        f.write(PROBE)
    base = dict(os.environ)
    base.pop("PV_PLUGIN_PATH", None)
    with_path = dict(base, PV_PLUGIN_PATH=PLUGIN_DIR)

    cases = [
        ("pvpython, PV_PLUGIN_PATH (loaded at start-up)", ["pvpython", probe, "none"], with_path),
        ("pvpython, PV_PLUGIN_PATH + LoadDistributedPlugin('Ferrovol')",
         ["pvpython", probe, "LoadDistributedPlugin"], with_path),
        ("pvpython, LoadPlugin(Ferrovol.so)", ["pvpython", probe, "LoadPlugin", PLUGIN], base),
        ("pvbatch, LoadPlugin(Ferrovol.so)", ["pvbatch", probe, "LoadPlugin", PLUGIN], base),
        ("pvpython, no plugin (control)", ["pvpython", probe, "none"], base),
    ]
    print("Loading the plugin (%s)" % PLUGIN)
    for name, cmd, env in cases:
        rc, out, dt = run(cmd, env)
        line = next((l for l in out.splitlines() if l.startswith("RESULT")), "")
        listed = "'Ferrovol Volume'" in line
        control = "control" in name
        ok = rc == 0 and bool(line) and (listed != control) and (
            control or ("loaded=True" in line and "has_proxy=True" in line
                        and "panel=True" in line))
        print("  %-62s %4.1f s  %s%s" % (name, dt, "listed" if listed else "not listed",
                                           "" if ok else "  FAIL"))
        if not ok:
            failures.append("%s: rc=%d %s\n%s" % (name, rc, line or "(no RESULT)", out[-2000:]))

    if shutil.which("paraview") and os.environ.get("DISPLAY"):
        gui = os.path.join(tmp, "gui.py")
        with open(gui, "w") as f:
            f.write(GUI)
        out_file = os.path.join(tmp, "gui.out")
        env = dict(with_path, FERROVOL_GUI_OUT=out_file)
        rc, out, dt = run(["paraview", "--dr", "--script=" + gui], env)
        line = open(out_file).read().strip() if os.path.exists(out_file) else ""
        ok = "'Ferrovol Volume'" in line and "drew=1" in line
        print("  %-62s %4.1f s  %s%s" % ("paraview GUI, PV_PLUGIN_PATH (--script)", dt,
                                           line[len("RESULT "):] if line else "(no result)",
                                           "" if ok else "  FAIL"))
        if not ok:
            failures.append("paraview GUI: rc=%d %s\n%s" % (rc, line or "(no RESULT)", out[-2000:]))
    else:
        print("  SKIP paraview GUI: %s" % ("no DISPLAY" if shutil.which("paraview")
                                           else "the paraview binary is not installed"))
    shutil.rmtree(tmp, ignore_errors=True)
    if failures:
        print("FAIL load:\n  " + "\n  ".join(failures))
        return 1
    print("PASS load: the plugin loads and lists \"Ferrovol Volume\"")
    return 0


if __name__ == "__main__":
    sys.exit(main())
