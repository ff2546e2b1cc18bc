#!/usr/bin/python3
"""Path tracing convergence and preview cost, with the ferrovol CLI (target/release/ferrovol).

1. Time to converge: a reference of --ref-spp paths per pixel (seed 1, cached in --out), then
   images of 1, 2, 4, ... paths per pixel (seed 0, independent of the reference) until the
   mean LDR-FLIP against the reference falls below --target. The time of each is the CLI's
   own path tracing time (its "N paths per pixel in T s": from the first frame to the last,
   without start-up and upload). FLIP is tests/ferrovol_testing/flip.py (NVIDIA's LDR-FLIP,
   checked against their implementation), averaged over the pixels where the reference is
   not black (the footprint) and over the whole frame.
2. Preview cost: one path per pixel from a fresh accumulation (--repeat, as a moving camera
   does) against shaded ray casting of the same volume and view, frame times from --repeat.

Usage: /usr/bin/python3 bench/pathtrace_flip.py [--demo sphere] [--input FILE --tf PRESET]
       [--size 512] [--ref-spp 4096] [--target 0.05] [extra CLI flags after --]
"""

import argparse
import os
import re
import subprocess
import sys
import time

import numpy as np
from PIL import Image

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.abspath(os.path.join(HERE, ".."))
sys.path.insert(0, os.path.join(ROOT, "tests"))
from ferrovol_testing import flip  # noqa: E402

CLI = os.path.join(ROOT, "target", "release", "ferrovol")


def run(args):
    t0 = time.perf_counter()
    p = subprocess.run([CLI, "render"] + args, capture_output=True, text=True)
    wall = time.perf_counter() - t0
    if p.returncode != 0:
        sys.exit("ferrovol failed: %s\n%s" % (" ".join(args), p.stderr))
    return p.stderr + p.stdout, wall


def load(path):
    img = np.asarray(Image.open(path).convert("RGBA"), dtype=np.float64)
    return img[..., :3], img[..., 3]


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--demo", default="sphere")
    ap.add_argument("--input", help="a volume file instead of --demo")
    ap.add_argument("--tf", help="transfer function preset")
    ap.add_argument("--size", type=int, default=512)
    ap.add_argument("--ref-spp", type=int, default=4096)
    ap.add_argument("--target", type=float, default=0.05)
    ap.add_argument("--max-spp", type=int, default=4096)
    ap.add_argument("--repeat", type=int, default=5)
    ap.add_argument("--out", default=os.path.join(ROOT, "build", "bench-pt"))
    ap.add_argument("extra", nargs="*", help="more ferrovol render flags (after --)")
    a = ap.parse_args()
    os.makedirs(a.out, exist_ok=True)
    scene = ([a.input] if a.input else ["--demo", a.demo]) + (["--tf", a.tf] if a.tf else [])
    scene += ["--size", "%dx%d" % (a.size, a.size)] + a.extra
    name = (os.path.splitext(os.path.basename(a.input))[0] if a.input else a.demo)
    tag = "%s-%d%s" % (name, a.size, "".join("_" + re.sub(r"[^\w.]", "", e) for e in a.extra))
    ref_path = os.path.join(a.out, "%s-ref-%d.png" % (tag, a.ref_spp))
    if not os.path.exists(ref_path):
        print("reference: %d paths per pixel ..." % a.ref_spp, flush=True)
        err, _ = run(scene + ["--mode", "pathtrace", "--spp", str(a.ref_spp), "--seed", "1",
                              "--out", ref_path])
        print("  " + re.search(r"\d+ paths per pixel in [\d.]+ s", err).group(0), flush=True)
    ref, _ = load(ref_path)
    # (the CLI writes the image over the background, opaque: the footprint is what differs
    # from black)
    footprint = ref.max(axis=2) > 2
    print("scene: %s, %dx%d, reference %d paths per pixel (%s), footprint %.1f%% of the frame"
          % (" ".join(scene), a.size, a.size, a.ref_spp, ref_path, 100 * footprint.mean()))
    print("| paths per pixel | path tracing time (s) | mean FLIP (footprint) | mean FLIP (frame) |")
    print("|---:|---:|---:|---:|")
    n = 1
    reached = None
    while n <= a.max_spp:
        path = os.path.join(a.out, "%s-%d.png" % (tag, n))
        err, _ = run(scene + ["--mode", "pathtrace", "--spp", str(n), "--seed", "0",
                              "--out", path])
        m = re.search(r"(\d+) paths per pixel in ([\d.]+) s", err)
        secs = float(m.group(2))
        img, _ = load(path)
        fmap = flip.flip_map(ref, img)
        fp, frame = float(fmap[footprint].mean()), float(fmap.mean())
        print("| %d | %.2f | %.4f | %.4f |" % (n, secs, fp, frame), flush=True)
        if fp < a.target:
            reached = (n, secs)
            break
        n *= 2
    if reached:
        print("mean FLIP (footprint) < %.2f after %d paths per pixel, %.2f s"
              % (a.target, reached[0], reached[1]))
    else:
        print("mean FLIP (footprint) stayed above %.2f up to %d paths per pixel"
              % (a.target, a.max_spp))
    # Preview: 1 path per pixel from scratch, against shaded ray casting.
    rep = ["--repeat", str(a.repeat)]
    err_pt, _ = run(scene + ["--mode", "pathtrace", "--spp", "1", "--out",
                             os.path.join(a.out, "preview.png")] + rep)
    err_dvr, _ = run(scene + ["--shade", "--out", os.path.join(a.out, "dvr.png")] + rep)
    ms = [float(re.search(r"([\d.]+) ms/frame", e).group(1)) for e in (err_pt, err_dvr)]
    print("preview, 1 path per pixel: %.1f ms per frame; shaded ray casting %.1f ms (%.1fx)"
          % (ms[0], ms[1], ms[0] / ms[1]))


if __name__ == "__main__":
    main()
