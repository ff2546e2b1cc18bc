#!/usr/bin/python3
"""vtkFerroVolumeMapper against vtkGPUVolumeRayCastMapper inside a VTK window, in one run.

Runs bench/vtk_bench.py (VTK's TestGPURayCastMapperBenchmark scene: wavelet 256^3, 900x900,
azimuth and elevation +1 degree per frame) for vtkGPUVolumeRayCastMapper and for
vtkFerroVolumeMapper on its zero-copy shared path and on its readback path, alternating the
three for --rounds rounds so that machine noise hits all of them alike, and prints each
one's ms/frame (the median over rounds of each round's mean) and the ratios to VTK's.

Needs `. build/env.sh` (the ferrovol Python module) and an X display (scripts/with-xvfb.sh).
"""

import argparse
import os
import re
import statistics
import subprocess
import sys

HERE = os.path.dirname(os.path.abspath(__file__))
CONFIGS = [
    ("vtk_gpu", ["--mapper", "gpu"]),
    ("ferrovol_shared", ["--mapper", "ferrovol", "--output-path", "shared"]),
    ("ferrovol_readback", ["--mapper", "ferrovol", "--output-path", "readback"]),
]
LINE = re.compile(r"^(vtk_\S+) (\S+) ms_per_frame=([0-9.]+)")


def main(argv):
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--frames", type=int, default=10, help="timed frames per mode and run")
    p.add_argument("--rounds", type=int, default=3, help="alternating rounds (default 3)")
    p.add_argument("--size", default="900x900")
    p.add_argument("--extent", type=int, default=127)
    p.add_argument("--multisamples", type=int, metavar="N",
                   help="the window's MultiSamples (default VTK's: 8 on VTK 9.2)")
    args = p.parse_args(argv)

    results = {}  # (config, mode) -> [ms per round]
    for r in range(args.rounds):
        for name, extra in CONFIGS:
            cmd = [sys.executable, os.path.join(HERE, "vtk_bench.py"), "--frames",
                   str(args.frames), "--size", args.size, "--extent", str(args.extent)] + extra
            if args.multisamples is not None:
                cmd += ["--multisamples", str(args.multisamples)]
            out = subprocess.run(cmd, capture_output=True, text=True)
            if out.returncode != 0:
                sys.stderr.write(out.stdout + out.stderr)
                print("# error: %s failed (exit %d)" % (name, out.returncode))
                return 1
            for line in out.stdout.splitlines():
                if line.startswith("# ferrovol output path") and r == 0:
                    print(line)
                m = LINE.match(line)
                if m:
                    got = m.group(1)
                    if got != "vtk_" + name.replace("vtk_", ""):
                        print("# error: asked for %s, the mapper ran %s" % (name, got))
                        return 1
                    results.setdefault((name, m.group(2)), []).append(float(m.group(3)))
        print("# round %d of %d done" % (r + 1, args.rounds))
        sys.stdout.flush()

    print("# ms/frame: median over %d rounds of each round's mean (%d frames), %s, extent %d, "
          "MultiSamples %s" % (args.rounds, args.frames, args.size, args.extent,
                               "VTK's default" if args.multisamples is None else args.multisamples))
    for mode in ("unshaded", "shaded"):
        ref = statistics.median(results[("vtk_gpu", mode)])
        for name, _ in CONFIGS:
            ms = statistics.median(results[(name, mode)])
            rounds = " ".join("%.1f" % v for v in results[(name, mode)])
            print("%-18s %-8s ms_per_frame=%.1f ratio_to_vtk_gpu=%.2f rounds=[%s]"
                  % (name, mode, ms, ms / ref, rounds))
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
