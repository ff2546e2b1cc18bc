#!/usr/bin/env python3
"""ferrovol's regression suite against VTK's own volume rendering.

Every scene of scenes.py is rendered in the same VTK window setup by
vtkGPUVolumeRayCastMapper (the reference), vtkFixedPointVolumeRayCastMapper (a second
opinion, where it supports the scene) and vtkFerroVolumeMapper; an unstructured-grid scene
by vtkUnstructuredGridVolumeRayCastMapper (the reference), vtkUnstructuredGridVolumeZSweepMapper
and vtkProjectedTetrahedraMapper (second opinions) and vtkFerroUnstructuredVolumeMapper
(pending where the module `ferrovol` lacks it). ferrovol's image and the second opinions are each
compared with the reference (SSIM, PSNR, mean FLIP, mean colour
difference inside the volume's footprint) and ferrovol's figures are held against
thresholds.toml. Writes build/regression/index.html (images side by side, figures,
pass/fail), results.json and the images.

    make regression          # every scene
    make regression-quick    # the subset `make test` runs
    . build/env.sh; scripts/with-xvfb.sh /usr/bin/python3 tests/regression/run.py \
        [--quick] [--only NAME[,NAME...]] [--out DIR] [--no-fixed]

Exit status 0 when no scene failed (pending and skipped scenes do not fail), 1 otherwise.
"""
import argparse
import fnmatch
import json
import os
import platform
import sys
import time

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.abspath(os.path.join(HERE, "..", ".."))
sys.path.insert(0, os.path.join(ROOT, "vtk_plugin", "tests"))
sys.path.insert(0, os.path.join(ROOT, "tests"))
sys.path.insert(0, HERE)

import tomllib  # Python 3.11 (Debian bookworm's /usr/bin/python3)

ACCEPT_SSIM, ACCEPT_PSNR = 0.98, 35.0   # issue 4: every composite/MIP/MinIP scene
ACCEPT_BLENDS = {"composite", "maximum", "minimum"}
FIXED_BLENDS = {"composite", "maximum", "minimum", "additive"}
BLEND = {"composite": "Composite", "maximum": "MaximumIntensity",
         "minimum": "MinimumIntensity", "average": "AverageIntensity",
         "additive": "Additive", "isosurface": "IsoSurface", "slice": "Slice"}
# The mappers of a scene: the reference first, ferrovol, then the second opinions.
MAPPERS = ("vtk-gpu", "ferrovol", "vtk-fixed")
UGRID_MAPPERS = ("vtk-bunyk", "ferrovol", "vtk-zsweep", "vtk-pt")
LABELS = {"vtk-gpu": "vtkGPUVolumeRayCastMapper", "vtk-fixed": "vtkFixedPointVolumeRayCastMapper",
          "vtk-bunyk": "vtkUnstructuredGridVolumeRayCastMapper",
          "vtk-zsweep": "vtkUnstructuredGridVolumeZSweepMapper",
          "vtk-pt": "vtkProjectedTetrahedraMapper", "ferrovol": "vtkFerroVolumeMapper"}
UGRID_FERROVOL = "vtkFerroUnstructuredVolumeMapper"


def mappers_of(scene):
    return UGRID_MAPPERS if scene.unstructured else MAPPERS


def parse_args(argv):
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--quick", action="store_true", help="only the scenes marked quick")
    ap.add_argument("--only", default="", help="comma-separated scene names or globs")
    ap.add_argument("--out", default=os.path.join(ROOT, "build", "regression"))
    ap.add_argument("--no-fixed", action="store_true",
                    help="skip the second opinions (vtkFixedPointVolumeRayCastMapper; for "
                    "unstructured grids the Z-sweep and projected-tetrahedra mappers)")
    ap.add_argument("--thresholds", default=os.path.join(HERE, "thresholds.toml"))
    return ap.parse_args(argv)


ARGS = parse_args(sys.argv[1:])
IMG_DIR = os.path.join(ARGS.out, "img")
os.makedirs(IMG_DIR, exist_ok=True)
for _old in os.listdir(IMG_DIR):   # the report shows this run's images only
    if _old.endswith(".png"):
        os.remove(os.path.join(IMG_DIR, _old))
os.environ["FERROVOL_TEST_OUTPUT"] = IMG_DIR   # where fvtest.save writes

import numpy as np  # noqa: E402
import vtk  # noqa: E402

import ferrovol  # noqa: E402
import fvtest  # noqa: E402
import meshes  # noqa: E402
import scenes as S  # noqa: E402
from ferrovol_testing import flip  # noqa: E402
from ferrovol_testing.metrics import (  # noqa: E402
    coverage, difference_image, footprint, luminance, psnr, ssim)


def log(*a):
    print(*a, flush=True)


# ---------------------------------------------------------------------------------------
# Rendering

def make_mapper(kind, unstructured=False):
    """A mapper of that kind; None for ferrovol on an unstructured grid while the module has
    no unstructured mapper."""
    if kind == "vtk-gpu":
        return vtk.vtkGPUVolumeRayCastMapper()
    if kind in ("vtk-bunyk", "vtk-zsweep"):
        m = (vtk.vtkUnstructuredGridVolumeRayCastMapper() if kind == "vtk-bunyk"
             else vtk.vtkUnstructuredGridVolumeZSweepMapper())
        # one ray per pixel, no time-driven coarsening
        m.AutoAdjustSampleDistancesOff()
        m.SetImageSampleDistance(1.0)
        return m
    if kind == "vtk-pt":
        return vtk.vtkProjectedTetrahedraMapper()   # VTK's factory: the OpenGL one
    if kind == "ferrovol" and unstructured:
        cls = getattr(ferrovol, UGRID_FERROVOL, None)
        return cls() if cls else None
    if kind == "ferrovol":
        m = ferrovol.vtkFerroVolumeMapper()
        path = os.environ.get("FERROVOL_OUTPUT_PATH")  # readback / shared: force one path
        if path:
            getattr(m, "SetOutputPathTo" + path.capitalize())()
        return m
    m = vtk.vtkFixedPointVolumeRayCastMapper()
    # full image resolution, no time-driven coarsening: the same pixels as the GPU mapper
    m.AutoAdjustSampleDistancesOff()
    m.SetImageSampleDistance(1.0)
    return m


def auto_sample_distance(data, volume):
    """What vtkGPUVolumeRayCastMapper picks under AutoAdjustSampleDistances (VTK 9.2,
    vtkOpenGLGPUVolumeRayCastMapper::UpdateSamplingDistance): the smallest spacing times the
    length of the vtkVolume matrix's column for that axis."""
    m = vtk.vtkMatrix4x4()
    volume.GetModelToWorldMatrix(m)
    sp = data.GetSpacing()
    return min(abs(sp[i]) * np.sqrt(sum(m.GetElement(r, i) ** 2 for r in range(3)))
               for i in range(3))


def render(scene, kind):
    """Renders the scene with one kind of mapper; returns (rgb float image, info), or
    (None, info) where there is no such mapper yet."""
    data = S.DATA[scene.data]()
    if scene.unstructured and kind != "ferrovol":
        data = meshes.tetrahedralised(data)   # VTK's unstructured mappers: tetrahedra only
    if kind == "ferrovol" and scene.unstructured and not hasattr(ferrovol, UGRID_FERROVOL):
        return None, {"ms": None, "errors": [], "warnings": [], "drew": False,
                      "missing": "the module ferrovol has no %s yet" % UGRID_FERROVOL}
    w, h = scene.size
    win = fvtest.new_window()
    win.SetSize(w, h)
    if scene.multisamples is not None:
        win.SetMultiSamples(scene.multisamples)
    mappers, errors, keep = [], [], []
    for view in scene.views:
        m = make_mapper(kind, scene.unstructured)
        errors.append(fvtest.Errors(m))
        getattr(m, "SetBlendModeTo" + BLEND[view.blend])()
        prop = scene.prop()
        for i, v in enumerate(scene.iso_values):
            prop.GetIsoSurfaceValues().SetValue(i, v)
        vol = vtk.vtkVolume()
        vol.SetProperty(prop)
        if scene.volume:
            scene.volume(vol)
        if scene.intermix:
            # vtkMultiVolume: one mapper, an input and a vtkVolume per port
            multi = vtk.vtkMultiVolume()
            multi.SetMapper(m)
            ports = [(data, vol)]
            for key, make_prop, place in scene.intermix():
                v = vtk.vtkVolume()
                v.SetProperty(make_prop())
                if place:
                    place(v)
                ports.append((S.DATA[key](), v))
            for port, (image, v) in enumerate(ports):
                producer = vtk.vtkTrivialProducer()
                producer.SetOutput(image)
                m.SetInputConnection(port, producer.GetOutputPort())
                multi.SetVolume(v, port)
                keep.extend((producer, v))
            vol = multi
        else:
            m.SetInputData(data)
            vol.SetMapper(m)
        if kind == "vtk-fixed":
            m.SetSampleDistance(auto_sample_distance(data, vol))
        if scene.configure:
            scene.configure(m)
        ren = vtk.vtkRenderer()
        ren.SetViewport(*view.viewport)
        ren.SetBackground(0.0, 0.0, 0.0)
        ren.AddVolume(vol)
        for a in (scene.actors() if scene.actors else []):
            ren.AddActor(a)
        if scene.lights:
            scene.lights(ren)
        win.AddRenderer(ren)
        ren.ResetCamera()
        if view.camera:
            view.camera(ren.GetActiveCamera())
        ren.ResetCameraClippingRange()
        mappers.append(m)
    t0 = time.perf_counter()
    win.Render()
    img = fvtest.grab(win, rerender=False)
    ms = (time.perf_counter() - t0) * 1e3
    info = {"ms": round(ms, 1),
            "errors": [e for c in errors for e in c.messages],
            "warnings": [e for c in errors for e in c.warnings]}
    if kind == "ferrovol":
        info["drew"] = all(m.GetLastRenderDrew() if hasattr(m, "GetLastRenderDrew")
                           else not info["errors"] for m in mappers)
        if hasattr(mappers[0], "GetOutputPathName"):
            info["output_path"] = mappers[0].GetOutputPathName()
    win.Finalize()
    return img, info


# ---------------------------------------------------------------------------------------
# Metrics

def measure(img, ref):
    fmap = flip.flip_map(ref, img)
    fp = footprint(img, ref, tol=2.0)   # pixels where either image shows something
    d = np.abs(img - ref).mean(axis=2)
    out = {"ssim": ssim(img, ref), "psnr": psnr(img, ref),
           "flip": float(fmap.mean()),
           "footprint": float(d[fp].mean()) if fp.any() else 0.0,
           "dlum": float((luminance(img) - luminance(ref))[fp].mean())
           if fp.any() else 0.0,
           "coverage": float(fp.mean()),
           "silhouette": ssim(silhouette(img), silhouette(ref))}
    return out, fmap


def silhouette(img):
    """The image's coverage mask (pixels that differ from the black background by more than
    8 levels) as a black and white image: SSIM of two of them compares outlines alone."""
    mask = footprint(img, tol=8.0)
    return np.repeat(mask[..., None] * 255.0, 3, axis=2)


def save_png(name, img):
    fvtest.save(name, np.clip(img, 0, 255))
    return "img/%s.png" % name


# ---------------------------------------------------------------------------------------
# Thresholds

def load_thresholds(path, version=None):
    """The scenes' thresholds for this VTK: a scene's sub-table `vtk_M_N` (VTK M.N's own
    mapper draws the scene differently from 9.2's) replaces its figures, reason and
    below_acceptance line for VTK M.N and later, the latest such that applies."""
    with open(path, "rb") as f:
        table = tomllib.load(f)
    if version is None:
        version = (vtk.vtkVersion.GetVTKMajorVersion(), vtk.vtkVersion.GetVTKMinorVersion())
    for name, t in table.items():
        since = sorted((tuple(int(x) for x in key[4:].split("_")), key)
                       for key in t if key.startswith("vtk_"))
        applying = [key for v, key in since if v <= version]
        base = {k: v for k, v in t.items() if not k.startswith("vtk_")}
        if applying:
            base.pop("below_acceptance", None)
            base.update(t[applying[-1]])
        table[name] = base
    return table


def check(scene, t, m):
    """The failed checks of ferrovol's figures m against the scene's thresholds t."""
    bad = []
    if m["ssim"] < t["ssim"]:
        bad.append("SSIM %.4f < %.4f" % (m["ssim"], t["ssim"]))
    if m["psnr"] < t["psnr"]:
        bad.append("PSNR %.2f < %.2f dB" % (m["psnr"], t["psnr"]))
    if m["flip"] > t["flip"]:
        bad.append("FLIP %.4f > %.4f" % (m["flip"], t["flip"]))
    if "silhouette" in t and m["silhouette"] < t["silhouette"]:
        bad.append("silhouette SSIM %.4f < %.4f" % (m["silhouette"], t["silhouette"]))
    if m["footprint"] > t["footprint"]:
        bad.append("footprint diff %.2f > %.2f" % (m["footprint"], t["footprint"]))
    return bad


def table_problems(scene, t):
    """A threshold entry that is missing a field, or that lets a composite/MIP/MinIP scene
    below the issue's acceptance line without saying so."""
    if t is None:
        return ["no entry in thresholds.toml"]
    if "pending" in t:
        return []
    missing = [k for k in ("ssim", "psnr", "flip", "footprint", "reason") if k not in t]
    if missing:
        return ["thresholds.toml entry lacks " + ", ".join(missing)]
    if set(scene.blends) <= ACCEPT_BLENDS and (t["ssim"] < ACCEPT_SSIM or t["psnr"] < ACCEPT_PSNR) \
            and "below_acceptance" not in t:
        return ["composite/MIP/MinIP thresholds below SSIM %.2f / PSNR %.0f dB need a "
                "below_acceptance line" % (ACCEPT_SSIM, ACCEPT_PSNR)]
    return []


# ---------------------------------------------------------------------------------------

def run_scene(scene, table):
    t = table.get(scene.name)
    res = {"name": scene.name, "title": scene.title, "size": list(scene.size),
           "blends": scene.blends, "note": scene.note, "quick": scene.quick,
           "thresholds": t or {}, "images": {}, "renders": {}, "metrics": {}}
    try:
        S.DATA[scene.data]()
    except S.MissingData as e:
        res.update(status="SKIP", why=[str(e)])
        return res
    fixed_ok = set(scene.blends) <= FIXED_BLENDS and scene.fixed and not ARGS.no_fixed
    kinds = mappers_of(scene)
    res["reference"] = kinds[0]
    res["opinions"] = [k for k in kinds[2:] if fixed_ok]
    res["labels"] = {k: LABELS[k] for k in kinds}
    if scene.unstructured:
        res["labels"]["ferrovol"] = UGRID_FERROVOL
    imgs = {}
    for kind in kinds:
        if kind in kinds[2:] and not fixed_ok:
            continue
        img, info = render(scene, kind)
        res["renders"][kind] = info
        if img is None:
            continue
        imgs[kind] = img
        res["images"][kind] = save_png("%s-%s" % (scene.name, kind), img)
    ref = imgs[kinds[0]]
    fv = res["renders"]["ferrovol"]
    why = table_problems(scene, t)
    pending = t is not None and "pending" in t
    if coverage(ref) < 0.01:
        why.append("VTK's image is empty: bad scene")
    for kind in kinds[1:]:
        if kind not in imgs or (kind == "ferrovol" and pending and not fv["drew"]):
            continue
        m, fmap = measure(imgs[kind], ref)
        res["metrics"][kind] = m
        res["images"][kind + "-diff"] = save_png("%s-%s-diff" % (scene.name, kind),
                                                 difference_image(imgs[kind], ref))
        res["images"][kind + "-flip"] = save_png("%s-%s-flip" % (scene.name, kind),
                                                 flip.heat(fmap))
    if pending:
        res["status"] = "PENDING"
        why.insert(0, t["pending"])
        if fv["drew"]:
            why.append("ferrovol draws this scene now: measure it and replace `pending` "
                       "with thresholds")
        elif fv.get("missing"):
            why.append(fv["missing"])
        elif not fv["errors"]:
            why.append("ferrovol drew nothing and reported no error")
    else:
        if fv["errors"]:
            why.append("ferrovol reported: " + " | ".join(fv["errors"]))
        if not fv.get("drew"):
            why.append("ferrovol drew nothing" + (": " + fv["missing"] if fv.get("missing")
                                                  else ""))
        if "ferrovol" in res["metrics"] and t is not None and not table_problems(scene, t):
            why += check(scene, t, res["metrics"]["ferrovol"])
        res["status"] = "FAIL" if why else "PASS"
        m = res["metrics"].get("ferrovol")
        if t and "below_acceptance" in t and m and m["ssim"] >= ACCEPT_SSIM \
                and m["psnr"] >= ACCEPT_PSNR:
            res["info"] = ("now meets the acceptance line (SSIM %.2f, %.0f dB): raise its "
                           "thresholds and drop below_acceptance" % (ACCEPT_SSIM, ACCEPT_PSNR))
    res["why"] = why
    return res


def fmt(m, k):
    if m is None or k not in m:
        return "–"
    v = m[k]
    return {"ssim": "%.4f", "psnr": "%.2f", "flip": "%.4f", "footprint": "%.2f",
            "dlum": "%+.2f", "silhouette": "%.4f"}[k] % v


def print_row(r):
    m = r["metrics"].get("ferrovol")
    line = "%-7s %-32s" % (r["status"], r["name"])
    if m:
        line += " SSIM %s  PSNR %6s dB  FLIP %s  dRGB %5s" % (
            fmt(m, "ssim"), fmt(m, "psnr"), fmt(m, "flip"), fmt(m, "footprint"))
    if m and "isosurface" in r["blends"]:
        line += "  silhouette SSIM %s" % fmt(m, "silhouette")
    for kind in r.get("opinions", []):
        f = r["metrics"].get(kind)
        if f:
            line += "   | %s: SSIM %s PSNR %s" % (kind[4:], fmt(f, "ssim"), fmt(f, "psnr"))
    log(line)
    for w in r.get("why", []):
        log("        " + w)
    if r.get("info"):
        log("        note: " + r["info"])


def main():
    table = load_thresholds(ARGS.thresholds)
    chosen = S.SCENES
    if ARGS.quick:
        chosen = [s for s in chosen if s.quick]
    if ARGS.only:
        pats = [p.strip() for p in ARGS.only.split(",") if p.strip()]
        chosen = [s for s in chosen if any(fnmatch.fnmatch(s.name, p) for p in pats)]
    unknown = sorted(set(table) - set(S.BY_NAME))
    t0 = time.perf_counter()
    results = []
    log("ferrovol regression: %d scenes against vtkGPUVolumeRayCastMapper (unstructured "
        "grids: vtkUnstructuredGridVolumeRayCastMapper), VTK %s"
        % (len(chosen), vtk.vtkVersion.GetVTKVersion()))
    for scene in chosen:
        ts = time.perf_counter()
        r = run_scene(scene, table)
        r["seconds"] = round(time.perf_counter() - ts, 1)
        results.append(r)
        print_row(r)
    total = time.perf_counter() - t0
    counts = {k: sum(r["status"] == k for r in results) for k in ("PASS", "FAIL", "PENDING",
                                                                     "SKIP")}
    summary = {"counts": counts, "seconds": round(total, 1), "quick": ARGS.quick,
               "vtk": vtk.vtkVersion.GetVTKVersion(), "python": platform.python_version(),
               "unknown_threshold_entries": unknown, "host": platform.node()}
    with open(os.path.join(ARGS.out, "results.json"), "w") as f:
        json.dump({"summary": summary, "scenes": results}, f, indent=1)
    import report
    path = report.write(ARGS.out, summary, results, table)
    measured = [r for r in results if "ferrovol" in r["metrics"] and r["status"] != "PENDING"]
    low = sorted(measured, key=lambda r: r["metrics"]["ferrovol"]["ssim"])[:3]
    log("lowest SSIM: " + ", ".join("%s %.4f" % (r["name"], r["metrics"]["ferrovol"]["ssim"])
                                    for r in low))
    if unknown:
        log("thresholds.toml names scenes that do not exist: " + ", ".join(unknown))
    log("report: %s" % path)
    log("%d pending (not supported by ferrovol yet), %d skipped (data missing), %.0f s"
        % (counts["PENDING"], counts["SKIP"], total))
    # the closing line test harnesses read: pending and skipped scenes count as skipped
    log("regression: %d passed, %d failed, %d skipped"
        % (counts["PASS"], counts["FAIL"], counts["PENDING"] + counts["SKIP"]))
    return 1 if counts["FAIL"] or unknown else 0


if __name__ == "__main__":
    sys.exit(main())
