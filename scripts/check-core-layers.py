#!/usr/bin/env python3
"""Checks core/src's module structure: no import cycle among core modules, and the layers
only depend downward (docs/ARCHITECTURE.md): error < gpu < params < resources < passes <
renderer; `impl Renderer` only in renderer.rs (file sizes: scripts/check-file-sizes.py).

Every `crate::…`, `super::…` and `self::…` path in a file (outside comments and its
#[cfg(test)] module) is an edge from that file's module to the module the path names;
a path through a `mod.rs` or lib.rs re-export (`pub use sub::Item`) is followed to `sub`.
Exit status 1 with the cycle or the offending edge printed.
"""
import os
import re
import sys

ROOT = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "core", "src")
LAYERS = ["error", "gpu", "params", "resources", "passes", "renderer"]


def modules():
    out = {}
    for d, _, files in os.walk(ROOT):
        for f in files:
            if f.endswith(".rs"):
                p = os.path.relpath(os.path.join(d, f), ROOT)
                parts = p[:-3].split(os.sep)
                if parts[-1] in ("mod", "lib"):
                    parts = parts[:-1]
                out[tuple(parts)] = os.path.join(d, f)
    return out


def code_of(path):
    src = open(path, encoding="utf-8").read()
    src = re.split(r"#\[cfg\(test\)\]\s*mod \w+", src)[0]
    return re.sub(r"//[^\n]*", "", src)


def reexports(code):
    """`pub use a::{B, C}` / `pub(crate) use a::B` → {name: first path segment}."""
    table = {}
    for m in re.finditer(r"pub(?:\(crate\))?\s+use\s+([\w:]+?)::(\{[^}]*\}|\w+|\*)\s*;", code):
        head, names = m.group(1), m.group(2)
        first = head.split("::")[0]
        for n in re.findall(r"\w+", names):
            table[n] = first
        if names == "*":
            table["*"] = first
    return table


def resolve(mods, exports, base, segs):
    """The module a path starting at module `base` with segments `segs` lands in."""
    cur = list(base)
    for s in segs:
        if tuple(cur + [s]) in mods:
            cur.append(s)
            continue
        via = exports.get(tuple(cur), {}).get(s) or exports.get(tuple(cur), {}).get("*")
        if via and via not in ("crate", "super", "self") and tuple(cur + [via]) in mods:
            cur.append(via)
            continue
        break
    return tuple(cur)


def main():
    mods = modules()
    codes = {m: code_of(p) for m, p in mods.items()}
    exports = {m: reexports(c) for m, c in codes.items()}
    edges = {m: set() for m in mods}
    failures = []
    for m, code in codes.items():
        for path in re.findall(r"\b((?:crate|super|self)(?:::\w+)+|(?:crate|super|self)::\{[^}]*\})", code):
            segs = path.split("::")
            start = {"crate": (), "self": m, "super": m[:-1]}[segs[0]]
            rest = [s for s in segs[1:] if re.fullmatch(r"\w+", s)]
            target = resolve(mods, exports, start, rest)
            if target != m and target not in ((),):
                edges[m].add(target)
        if m != ("renderer",) and re.search(r"\bimpl\s+Renderer\b", code):
            failures.append(f"impl Renderer outside renderer.rs: {mods[m]}")

    def layer(m):
        return LAYERS.index(m[0]) if m and m[0] in LAYERS else None

    for a, targets in edges.items():
        for b in targets:
            la, lb = layer(a), layer(b)
            if la is not None and lb is not None and lb > la:
                failures.append(f"{'::'.join(a)} uses {'::'.join(b)}: a higher layer")
    # cycles (Tarjan's strongly connected components)
    index, low, stack, on, sccs = {}, {}, [], set(), []

    def strong(v):
        index[v] = low[v] = len(index)
        stack.append(v)
        on.add(v)
        for w in edges.get(v, ()):
            if w not in index:
                strong(w)
                low[v] = min(low[v], low[w])
            elif w in on:
                low[v] = min(low[v], index[w])
        if low[v] == index[v]:
            comp = []
            while True:
                w = stack.pop()
                on.discard(w)
                comp.append(w)
                if w == v:
                    break
            if len(comp) > 1:
                sccs.append(comp)

    sys.setrecursionlimit(10000)
    for v in list(edges):
        if v not in index:
            strong(v)
    for comp in sccs:
        failures.append("import cycle: " + " ↔ ".join("::".join(c) or "crate" for c in comp))
    n_edges = sum(len(t) for t in edges.values())
    if failures:
        print("\n".join(failures))
        sys.exit(1)
    print(f"core layers: {len(mods)} modules, {n_edges} imports, no cycle, layers respected")


main()
