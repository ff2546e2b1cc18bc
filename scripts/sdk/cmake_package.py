"""Makes Debian's CMake packages of VTK (and ParaView) usable from an SDK folder that holds
only some of their files: scripts/vtk-sdk.sh and scripts/pv6-sdk.sh.

  cmake_package.py USR [--find NAME]... CMAKE_DIR...

In each CMAKE_DIR (e.g. USR/lib/x86_64-linux-gnu/cmake/vtk-9.6):
  - every file its targets name under the install prefix that is absent (libraries of
    packages not unpacked, Java tools, ...) becomes an empty file, which only a build that
    used it would notice;
  - every package its modules look for is skipped except the --find ones, and every imported
    target its targets name from the skipped ones (Qt, HDF5, TBB, Viskores, ...) is an empty
    INTERFACE stand-in, declared before the targets are included;
  - Python3 (when asked for) is found without the version Debian built for, so that the
    venv's Python serves whichever version PyPI's wheel is for.
"""
import argparse
import pathlib
import re

KEEP = ("VTK::", "ParaView::")


def find_macro(names):
    """_ferrovol_sdk_find_package: find_package for `names`, FOUND for any other."""
    lines = ["# ferrovol's SDK (scripts/sdk/cmake_package.py): only these packages are "
             "looked for.", "macro(_ferrovol_sdk_find_package name)"]
    others = [n for n in names if n != "Python3"]
    if "Python3" in names:
        lines += ['  if ("${name}" STREQUAL "Python3")',
                  "    set(_ferrovol_sdk_args ${ARGN})",
                  "    list(POP_FRONT _ferrovol_sdk_args)",
                  "    find_package(Python3 ${_ferrovol_sdk_args})"]
    if others:
        test = " OR ".join('"${name}" STREQUAL "%s"' % n for n in others)
        lines += ["  %s (%s)" % ("elseif" if "Python3" in names else "if", test),
                  "    find_package(${name} ${ARGN})"]
    lines += ["  else ()", "    set(${name}_FOUND 1)", "  endif ()", "endmacro ()", ""]
    return "\n".join(lines)


def patch(cmake, usr, names):
    keep = KEEP + tuple(n + "::" for n in names)
    external = set()
    for targets in cmake.glob("*-targets*.cmake"):
        text = targets.read_text()
        if targets.name.endswith("-targets.cmake"):  # (not the per-configuration files)
            external.update(n for n in re.findall(r"[A-Za-z0-9_]+::[A-Za-z0-9_:]+", text)
                            if not n.startswith(keep))
        for ref in set(re.findall(r'\$\{_IMPORT_PREFIX\}/([^";]*)', text)):
            path = usr / ref
            if not path.exists():
                path.parent.mkdir(parents=True, exist_ok=True)
                path.write_bytes(b"")
    for finds in cmake.glob("*-vtk-module-find-packages.cmake"):
        body = re.sub(r"(?m)^(\s*)find_package\(", r"\1_ferrovol_sdk_find_package(",
                      finds.read_text())
        finds.write_text(find_macro(names) + body)
    config = cmake / (cmake.name.rsplit("-", 1)[0] + "-config.cmake")
    text = config.read_text().replace('_HAS_VISKORES" "ON"', '_HAS_VISKORES" "OFF"')
    stubs = "".join("if (NOT TARGET %s)\n  add_library(%s INTERFACE IMPORTED)\nendif ()\n"
                    % (t, t) for t in sorted(external))
    first = re.search(r'(?m)^\s*include\("\$\{CMAKE_CURRENT_LIST_DIR\}/[^"]*-targets\.cmake"\)',
                      text)
    if not first:
        raise SystemExit("%s: no include of the targets file" % config)
    config.write_text(text[:first.start()] + "\n# ferrovol's SDK: stand-ins\n" + stubs +
                      text[first.start():])


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("usr", type=pathlib.Path)
    parser.add_argument("cmake", type=pathlib.Path, nargs="+")
    parser.add_argument("--find", action="append", required=True)
    args = parser.parse_args()
    for cmake in args.cmake:
        patch(cmake, args.usr, args.find)


if __name__ == "__main__":
    main()
