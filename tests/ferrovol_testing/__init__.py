"""ferrovol's Python test support: the image measures every Python test uses.

Used by the VTK module's tests (vtk_plugin/tests/fvtest.py), the ParaView plugin's tests
(paraview/tests/fvtest.py, under pvbatch and pvpython), the regression suite against VTK
(tests/regression) and the benchmarks (bench/). Those put this folder's parent (tests/) on
sys.path; everything here runs on Debian's /usr/bin/python3, the interpreter that VTK's
Python, pvpython and pvbatch share.

- metrics: SSIM, PSNR, luminance, the foreground mask / footprint / screen box of a volume;
- flip: LDR-FLIP (Andersson et al. 2020), the per-pixel map, its mean and a heat map;
- png: PNG files as numpy arrays (VTK's reader and writer).

One SSIM: Wang et al. 2004's Gaussian-window SSIM of the luminance (metrics.ssim). The
regression thresholds (tests/regression/thresholds.toml, the tightest in the tree: 0.996 on
most scenes) and the VTK module's tests were set with it; the ParaView tests, which averaged
SSIM over R, G and B, use it too now (their PSNR is over R, G and B and still catches a
change of hue that luminance hides).

FLIP: the project's own numpy port (flip.py), not NVIDIA's maintained package from PyPI
(flip-evaluator). Every consumer runs on Debian's /usr/bin/python3, which is externally
managed (PEP 668): a PyPI package would have to go into the system interpreter with
--break-system-packages, or into a virtual environment that pvbatch and pvpython (which embed
that interpreter) and CTest would all have to be pointed at; scripts/install-deps.sh would
gain pip and a download on every fresh machine beside its Debian packages, which it now only
checks. The port needs numpy and scipy (Debian's python3-numpy and python3-scipy), is written
from the paper with the reference's choices where the paper leaves them open, and agrees
with flip-evaluator per pixel (flip.py says how closely); keeping it in step with the
reference is the price.
"""
