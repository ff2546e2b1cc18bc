"""build/regression/index.html: the regression suite's report (run.py writes it)."""
import html
import os
import time

CSS = """
body{font:14px/1.4 system-ui,sans-serif;margin:1.5em;color:#222;max-width:1800px}
h1{font-size:1.5em;margin:0 0 .3em} h2{font-size:1.15em;margin:1.6em 0 .3em}
table{border-collapse:collapse} td,th{border:1px solid #ccc;padding:2px 7px;text-align:right}
th{background:#f1f1f1} td.l,th.l{text-align:left}
.PASS{background:#c8efc8} .FAIL{background:#f7b7b7} .PENDING{background:#fde8a6}
.SKIP{background:#ddd} .bad{color:#b00;font-weight:bold}
.badge{padding:1px 7px;border-radius:3px;font-weight:bold}
.imgs{display:flex;flex-wrap:wrap;gap:8px;margin:.4em 0}
.imgs figure{margin:0} .imgs img{max-width:300px;max-height:300px;image-rendering:pixelated;
 border:1px solid #999;background:#000} figcaption{font-size:12px;color:#555}
.scene{border-top:2px solid #ddd;padding-top:.4em}
.note{color:#444;font-size:13px;max-width:1100px} .box{background:#f6f6f6;padding:.6em 1em;
 max-width:1100px;border-left:4px solid #888}
"""

COLS = (("ssim", "SSIM", "%.4f", "min"), ("psnr", "PSNR dB", "%.2f", "min"),
        ("flip", "FLIP", "%.4f", "max"), ("footprint", "ΔRGB", "%.2f", "max"))


def _e(s):
    return html.escape(str(s))


def _cell(m, t, key, fmtstr, kind):
    if not m or key not in m:
        return "<td>–</td>"
    v = m[key]
    bad = False
    if t and key in t:
        bad = v < t[key] if kind == "min" else v > t[key]
    return '<td class="%s">%s</td>' % ("bad" if bad else "", fmtstr % v)


def _thr(t, key, fmtstr, kind):
    if not t or key not in t:
        return "<td>–</td>"
    return "<td>%s %s</td>" % ("≥" if kind == "min" else "≤", fmtstr % t[key])


def write(out, summary, results, table):
    c = summary["counts"]
    p = []
    p.append("<!doctype html><meta charset=utf-8><title>ferrovol regression</title>")
    p.append("<style>%s</style>" % CSS)
    p.append("<h1>ferrovol against VTK's volume rendering</h1>")
    fv_paths = sorted({r["renders"]["ferrovol"].get("output_path", "?") for r in results
                       if "ferrovol" in r.get("renders", {})})
    p.append("<p><span class='badge PASS'>%d passed</span> <span class='badge FAIL'>%d failed"
             "</span> <span class='badge PENDING'>%d pending</span> <span class='badge SKIP'>"
             "%d skipped</span> &nbsp; %s%.0f s &nbsp; VTK %s (Debian ParaView 5.11), "
             "ferrovol output path: %s &nbsp; %s</p>"
             % (c["PASS"], c["FAIL"], c["PENDING"], c["SKIP"],
                "quick subset, " if summary["quick"] else "", summary["seconds"],
                _e(summary["vtk"]), _e(", ".join(fv_paths)),
                time.strftime("%Y-%m-%d %H:%M")))
    p.append("""<div class=box><b>Reading this.</b> Each scene is rendered in the same VTK
window setup (size, camera, lights, property) by <b>vtkGPUVolumeRayCastMapper</b> (the
reference), by <b>vtkFerroVolumeMapper</b> and, where it supports the scene, by
<b>vtkFixedPointVolumeRayCastMapper</b> (a second opinion: how far VTK's own mappers agree).
Unstructured grids (<code>ugrid-*</code>) have <b>vtkUnstructuredGridVolumeRayCastMapper</b>
as the reference, <b>vtkUnstructuredGridVolumeZSweepMapper</b> and
<b>vtkProjectedTetrahedraMapper</b> as second opinions, and ferrovol's
vtkFerroUnstructuredVolumeMapper
(<a href="../../tests/regression/UNSTRUCTURED.md">UNSTRUCTURED.md</a>).
Figures against the reference: SSIM (luminance, 11×11 Gaussian window), PSNR over RGB, mean
<a href="https://research.nvidia.com/publication/2020-07_FLIP">FLIP</a> (Andersson et al.,
HPG 2020; 67 pixels per degree) and ΔRGB, the mean absolute colour difference in 8-bit levels
inside the volume's footprint (pixels where either image is not background). ferrovol's
figures are held against <code>tests/regression/thresholds.toml</code> (each with its reason);
the second opinions' figures are shown, not judged. Difference images are
|image − reference| × 4; FLIP maps are black (no visible difference) to light yellow (1).
<br><b>Sample placement</b>: ferrovol samples where VTK 9.2 does: the first sample one
full step inside the volume's box (<code>g_rayOrigin += g_dirStep</code> when jittering is
off), always taken, the exit-face sample kept, and up to one step past opaque depth and
clipping planes. This suite found the difference (ferrovol sampled the entry face); adopting
VTK's lattice took the composite scenes from ~37 to ~48 dB. The remaining differences
(vtkVolume scale, camera inside, cropping/clipping plane placement, the N/(N−1) gradient
span, VTK's multisampled outline) are in
<a href="../../tests/regression/SAMPLING.md">tests/regression/SAMPLING.md</a>.</div>""")

    # summary table
    p.append("<h2>Scenes</h2><table><tr><th class=l>scene</th><th>status</th><th class=l>"
             "blend</th><th>size</th>")
    for _, name, _, _ in COLS:
        p.append("<th>%s</th>" % name)
    p.append("<th>thresholds (SSIM / PSNR / FLIP / ΔRGB)</th>")
    p.append("<th class=l>second opinions: SSIM / PSNR dB</th>")
    p.append("<th>ms reference / ferrovol / second opinions</th></tr>")
    for r in results:
        t = r.get("thresholds") or {}
        m = r["metrics"].get("ferrovol")
        p.append("<tr><td class=l><a href='#%s'>%s</a></td><td class='%s'>%s</td>"
                 "<td class=l>%s</td><td>%d×%d</td>"
                 % (_e(r["name"]), _e(r["name"]), r["status"], r["status"],
                    _e(", ".join(r["blends"])), r["size"][0], r["size"][1]))
        for key, _, fs, kind in COLS:
            p.append(_cell(m, t, key, fs, kind))
        if "pending" in t:
            p.append("<td class=l>pending</td>")
        elif t:
            p.append("<td>%.3f / %.1f / %.3f / %.1f</td>"
                     % (t.get("ssim", 0), t.get("psnr", 0), t.get("flip", 0),
                        t.get("footprint", 0)))
        else:
            p.append("<td>–</td>")
        opinions = [(k, r["metrics"][k]) for k in r.get("opinions", []) if k in r["metrics"]]
        p.append("<td class=l>%s</td>" % ("<br>".join(
            "%s %.4f / %.2f" % (_e(k[4:]), f["ssim"], f["psnr"]) for k, f in opinions) or "–"))
        rd = r.get("renders", {})
        order = [r.get("reference", "vtk-gpu"), "ferrovol"] + r.get("opinions", [])
        p.append("<td>%s</td></tr>" % " / ".join(
            "%.0f" % rd[k]["ms"] if rd.get(k, {}).get("ms") is not None else "–"
            for k in order))
    p.append("</table>")
    measured = [r for r in results if "ferrovol" in r["metrics"] and r["status"] != "PENDING"]
    low = sorted(measured, key=lambda r: r["metrics"]["ferrovol"]["ssim"])[:3]
    if low:
        p.append("<p>Lowest SSIM: %s.</p>" % ", ".join(
            "<a href='#%s'>%s</a> %.4f" % (_e(r["name"]), _e(r["name"]),
                                           r["metrics"]["ferrovol"]["ssim"]) for r in low))

    # per scene
    for r in results:
        t = r.get("thresholds") or {}
        p.append("<div class=scene id='%s'><h2>%s <span class='badge %s'>%s</span></h2>"
                 % (_e(r["name"]), _e(r["name"]), r["status"], r["status"]))
        p.append("<div>%s — %d×%d, %s</div>" % (_e(r["title"]), r["size"][0], r["size"][1],
                                               _e(", ".join(r["blends"]))))
        for w in r.get("why", []):
            p.append("<div class=bad>%s</div>" % _e(w))
        if r.get("info"):
            p.append("<div><b>%s</b></div>" % _e(r["info"]))
        im = r.get("images", {})
        ref = r.get("reference", "vtk-gpu")
        labels = r.get("labels", {})
        figs = [(ref, "%s (reference)" % labels.get(ref, ref))]
        for k in ["ferrovol"] + r.get("opinions", []):
            short = "ferrovol" if k == "ferrovol" else k[4:]
            figs += [(k, labels.get(k, k)), (k + "-diff", "|%s − reference| × 4" % short),
                     (k + "-flip", "FLIP map, %s" % short)]
        p.append("<div class=imgs>")
        for key, cap in figs:
            if key in im:
                p.append("<figure><a href='%s'><img src='%s' loading=lazy></a><figcaption>%s"
                         "</figcaption></figure>" % (_e(im[key]), _e(im[key]), _e(cap)))
        p.append("</div>")
        if r["metrics"]:
            p.append("<table><tr><th class=l>against the reference</th>")
            for _, name, _, _ in COLS:
                p.append("<th>%s</th>" % name)
            p.append("<th>mean ΔL (signed)</th><th>footprint</th><th>render ms</th></tr>")
            rows = [(k, labels.get(k, k), t if k == "ferrovol" else None)
                    for k in ["ferrovol"] + r.get("opinions", [])]
            for key, label, th in rows:
                m = r["metrics"].get(key)
                if not m:
                    continue
                p.append("<tr><td class=l>%s</td>" % label)
                for k, _, fs, kind in COLS:
                    p.append(_cell(m, th if "pending" not in t else None, k, fs, kind))
                p.append("<td>%+.2f</td><td>%.1f%%</td><td>%.0f</td></tr>"
                         % (m["dlum"], 100 * m["coverage"], r["renders"][key]["ms"]))
            if t and "pending" not in t:
                p.append("<tr><td class=l>ferrovol thresholds</td>")
                for k, _, fs, kind in COLS:
                    p.append(_thr(t, k, fs, kind))
                p.append("<td colspan=3></td></tr>")
            p.append("</table>")
        if t.get("reason"):
            p.append("<p class=note><b>Thresholds:</b> %s</p>" % _e(t["reason"]))
        if t.get("below_acceptance"):
            p.append("<p class='note bad'>Below the acceptance line (SSIM 0.98, 35 dB): %s</p>"
                     % _e(t["below_acceptance"]))
        if r.get("note"):
            p.append("<p class=note><b>Known difference:</b> %s</p>" % _e(r["note"]))
        fv = r.get("renders", {}).get("ferrovol", {})
        if fv.get("warnings"):
            p.append("<p class=note>ferrovol warnings: %s</p>" % _e(" | ".join(fv["warnings"])))
        p.append("</div>")
    path = os.path.join(out, "index.html")
    with open(path, "w") as f:
        f.write("\n".join(p))
    return path
