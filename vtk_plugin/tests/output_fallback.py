"""Run by test_output_paths.ReadbackFallback in a process of its own, whose OpenGL Mesa is
told to hide GL_EXT_memory_object_fd (MESA_EXTENSION_OVERRIDE): two mappers on the
automatic output path and one forced to the shared path render a few frames, the forced one
choosing its path again in between. Prints one JSON line: the OpenGL vendor, and per mapper
the path, the reason and the warnings and errors it raised."""
import json

import fvtest
from fvtest import tf_property, wavelet


def main():
    src = wavelet(4)
    report = {}
    for name, path in (("automatic", "Automatic"), ("automatic2", "Automatic"),
                       ("forced", "Shared")):
        scene, errors = fvtest.ferrovol_scene(
            src, tf_property(), lambda m, p=path: getattr(m, "SetOutputPathTo" + p)(),
            size=(24, 24))
        m = scene.mapper
        scene.render()
        scene.render()
        if path == "Shared":
            m.SetOutputPathToReadback()
            scene.render()
            m.SetOutputPathToShared()
            scene.render()
        vendor = [line.split(":", 1)[1].strip()
                  for line in scene.window.ReportCapabilities().splitlines()
                  if line.startswith("OpenGL vendor string:")]
        report["vendor"] = vendor[0] if vendor else ""
        report[name] = {"path": m.GetOutputPathName(), "reason": m.GetOutputPathReason(),
                        "warnings": errors.warnings, "errors": errors.messages}
    print(json.dumps(report))


if __name__ == "__main__":
    main()
