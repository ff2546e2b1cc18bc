#!/usr/bin/env python3
"""Checks that docs/ARCHITECTURE.md names only things that exist: every file name and path
it mentions is in the tree, every CamelCase name is a type, enum variant or C++ method
defined in our sources (VTK, Vulkan and GL names excepted), and every `Type::function` and
`function` in code spans is defined.
Exit status 1 with the missing names listed."""
import os
import re
import subprocess
import sys

ROOT = os.path.abspath(os.path.join(os.path.dirname(os.path.abspath(__file__)), ".."))
DOC = os.path.join(ROOT, "docs", "ARCHITECTURE.md")
SOURCE_EXT = (".rs", ".wgsl", ".cxx", ".h", ".hpp", ".py", ".c", ".cpp")
# Names of other projects' APIs the page refers to.
EXTERNAL = re.compile(
    r"^(vtk(?!Ferro)\w*|GL_\w+|Vk\w*|VkImages|IceT|MPI|ParaView|PERFORMANCE|CHANGELOG|"
    r"MinIP|MIP|NIfTI|MetaImage|NRRD|Marschner|Lobb|FLIP|SSIM|PSNR|CTest|CamelCase|"
    r"Rezk|Salama|Mesa|RAII|OpenGL|R32Float|Henyey|Greenstein|Blinn|Phong|BSDF|AO|Schlick|"
    r"FERROVOL_BACKEND|GPU|CPU|UUIDs?|RGBA\w*|Monte|Carlo|JIT|Xvfb|Vulkan|EGL|WGSL|VTK|"
    r"README|ARCHITECTURE|DATA|SAMPLING|MAX_LIGHTS|TABLE_N|MAX_ISO|VOLUMETRIC|NVIDIA|GL|"
    r"Debian|Rust|Python|LLVM|ABI|Variant)$"
)


def tracked_files():
    out = subprocess.run(
        ["git", "ls-files", "--cached", "--others", "--exclude-standard"],
        cwd=ROOT, capture_output=True, text=True, check=True,
    ).stdout.split()
    return [f for f in out if os.path.exists(os.path.join(ROOT, f))]


def main():
    doc = open(DOC, encoding="utf-8").read()
    files = tracked_files()
    basenames = {os.path.basename(f) for f in files}
    dirs = {os.path.dirname(f) for f in files}
    dirs |= {d.rsplit("/", 1)[-1] for d in dirs}
    sources = "\n".join(
        open(os.path.join(ROOT, f), encoding="utf-8", errors="replace").read()
        for f in files if f.endswith(SOURCE_EXT)
    )
    missing = []

    # File names and paths.
    for m in set(re.findall(r"[\w./-]*\w\.(?:rs|wgsl|cxx|hpp|h|py|md|sh|toml|xml|txt)\b", doc)):
        p = m.lstrip("./")
        if not (os.path.exists(os.path.join(ROOT, p)) or os.path.basename(p) in basenames
                or any(f.endswith("/" + p) for f in files)):
            missing.append(f"file {m}")
    for m in set(re.findall(r"\b([\w-]+(?:/[\w-]+)*)/(?=[\s)|,.]|$)", doc, re.M)):
        if not (m in dirs or os.path.isdir(os.path.join(ROOT, m))
                or any(d.endswith("/" + m) for d in dirs)):
            missing.append(f"folder {m}/")

    # What the sources declare and use, word by word, collected once.
    def words(pattern):
        return set(re.findall(pattern, sources, re.M))
    types = words(r"\b(?:struct|enum|trait|class|type)\s+(\w+)")
    functions = words(r"\bfn\s+(\w+)")
    declared = types | functions | words(r"\b(?:const|mod|union)\s+(\w+)")
    called = words(r"\b(\w+)\s*\(")
    used = called | words(r"\b(\w+)\s*[={]")
    # Variants and methods: called after `::`, or a line's first word before ( , = {.
    variants = words(r"::(\w+)\s*\(") | words(r"^\s*(\w+)\s*[(,={]")
    before_colon = words(r"(\w+):")

    # Defined: declared, called, assigned, opening a block or followed by a colon (the end of
    # a longer word counts there, as in `self.name:` or `x_name:`).

    def defined(name):
        return (name in declared or name in used
                or any(w.endswith(name) for w in before_colon))

    # Types: CamelCase words.
    for name in set(re.findall(r"\b([A-Z][a-z0-9]+(?:[A-Z][a-z0-9]*)+|vtkFerro\w+|Fv[A-Z]\w*)\b(?!\.(?:rs|wgsl|cxx|hpp|h|py)\b)", doc)):
        if EXTERNAL.match(name):
            continue
        if not (name in types or name in variants or name in dirs):
            missing.append(f"type, variant or method {name}")
    # Type::function.
    for t, f in set(re.findall(r"\b(\w+)::(\w+)\b", doc)):
        if EXTERNAL.match(t) or t in ("frame",):
            if t == "frame" and f not in functions:
                missing.append(f"function {t}::{f}")
            continue
        if not (f in functions or f in called):
            missing.append(f"function {t}::{f}")
    # snake_case names in code spans and in the layout tree.
    spans = re.findall(r"`([a-z_][a-z0-9_]*)`", doc)
    tree = re.findall(r"^ {20,}([a-z_][a-z0-9_]*(?:, [a-z_][a-z0-9_]*)*)\s*$", doc, re.M)
    for name in set(spans) | {n for line in tree for n in line.split(", ")}:
        if not defined(name) and name not in basenames:
            missing.append(f"name {name}")
    if missing:
        print("docs/ARCHITECTURE.md names what does not exist:\n  " + "\n  ".join(sorted(missing)))
        sys.exit(1)
    print("docs/ARCHITECTURE.md: every file, type and function it names exists")


main()
