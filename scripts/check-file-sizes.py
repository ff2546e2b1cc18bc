#!/usr/bin/env python3
"""No hand-written source file over 900 lines: every file git tracks with a source
extension (Rust, C, C++, Python, WGSL, shell), except the header cbindgen generates.
Exit status 1 with each file over the limit printed."""
import os
import subprocess
import sys

MAX_LINES = 900
EXTENSIONS = (".rs", ".c", ".h", ".cxx", ".cpp", ".hpp", ".py", ".wgsl", ".sh")
GENERATED = {"ffi/include/ferrovol.h"}

root = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..")
files = subprocess.run(["git", "ls-files", "-z"], cwd=root, check=True,
                       capture_output=True).stdout.decode().split("\0")
over = []
checked = 0
for f in files:
    if not f.endswith(EXTENSIONS) or f in GENERATED or not os.path.exists(os.path.join(root, f)):
        continue
    checked += 1
    with open(os.path.join(root, f), encoding="utf-8", errors="replace") as fh:
        n = sum(1 for _ in fh)
    if n > MAX_LINES:
        over.append(f"{f}: {n} lines (at most {MAX_LINES}: split it by concern)")
if over:
    print("\n".join(over))
    sys.exit(1)
print(f"file sizes: {checked} source files, none over {MAX_LINES} lines")
