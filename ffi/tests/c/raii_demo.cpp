// Drives the C++ RAII wrapper (ferrovol.hpp): renders a small sphere volume, then a second
// one intermixed with it, then a hexahedral mesh, and checks that bad calls throw
// ferrovol::Error with the right status and a message.
// Built with -std=c++17 -Wall -Wextra -Werror -pedantic by ffi/tests/c_program.rs.
#include "ferrovol.hpp"

#include <cmath>
#include <cstdio>
#include <vector>

// Runs `call`, which must throw ferrovol::Error with `want`; prints "<what> refused: <message>".
template <class F> static bool refused(const char *what, FvStatus want, F call) {
  try {
    call();
  } catch (const ferrovol::Error &e) {
    std::printf("%s refused: %s\n", what, e.what());
    return e.status() == want;
  }
  std::fprintf(stderr, "%s accepted\n", what);
  return false;
}

int main(int argc, char **argv) {
  if (argc != 2) {
    std::fprintf(stderr, "usage: %s OUT.png\n", argv[0]);
    return 2;
  }
  try {
    ferrovol::Context ctx;
    ferrovol::Renderer renderer(ctx);
    const uint32_t n = 32;
    std::vector<uint8_t> data(n * n * n);
    for (uint32_t k = 0; k < n; ++k)
      for (uint32_t j = 0; j < n; ++j)
        for (uint32_t i = 0; i < n; ++i) {
          double x = i - 15.5, y = j - 15.5, z = k - 15.5;
          double r = std::sqrt(x * x + y * y + z * z);
          data[(k * n + j) * n + i] = static_cast<uint8_t>(r < 14 ? 255 - 16 * r : 0);
        }
    FvVolumeDesc desc{};
    desc.dims[0] = desc.dims[1] = desc.dims[2] = n;
    desc.components = 1;
    desc.scalar_type = FV_SCALAR_TYPE_U8;
    desc.spacing[0] = desc.spacing[1] = desc.spacing[2] = 1.0;
    desc.direction[0] = desc.direction[4] = desc.direction[8] = 1.0;
    ferrovol::Volume volume(desc, data.data(), data.size());
    renderer.set_volume(volume);
    ferrovol::TransferFunction tf;
    tf.set_color(0, {0, 1, 0.5, 0.2, 255, 1, 1, 0.9});
    tf.set_opacity(0, {0, 0, 255, 0.2});
    renderer.set_transfer_function(tf);
    FvCamera cam{};
    cam.focal_point[0] = cam.focal_point[1] = cam.focal_point[2] = 15.5;
    cam.position[0] = cam.position[1] = 15.5;
    cam.position[2] = 15.5 + 100;
    cam.view_up[1] = 1;
    cam.view_angle = 30;
    cam.parallel_scale = 1;
    cam.clipping_range[0] = 50;
    cam.clipping_range[1] = 150;
    renderer.set_camera(cam);
    renderer.set_params(ferrovol::Renderer::default_params());
    renderer.render(200, 150);
    ferrovol::Frame frame = renderer.read_frame();
    const uint8_t *centre = frame.rgba() + 4 * (75 * 200 + 100);
    std::printf("frame %ux%u, centre alpha %u\n", frame.width(), frame.height(), centre[3]);
    frame.write_png(argv[1]);
    if (centre[3] < 128) {
      std::fprintf(stderr, "the sphere is missing from the centre of the frame\n");
      return 1;
    }
    {
      // A second sphere, red, moved 8 points to +x and intermixed with the first; its
      // handles go before the frame (the renderer keeps what it needs).
      ferrovol::Volume second(desc, data.data(), data.size());
      ferrovol::TransferFunction red;
      red.set_color(0, {0, 1, 0, 0, 255, 1, 0, 0});
      red.set_opacity(0, {0, 0, 255, 0.2});
      FvIntermixedVolume iv{};
      iv.volume = second.get();
      iv.transfer_function = red.get();
      iv.matrix[0] = iv.matrix[5] = iv.matrix[10] = iv.matrix[15] = 1.0;
      iv.matrix[12] = 8.0;
      iv.interpolation = FV_INTERPOLATION_LINEAR;
      renderer.set_intermixed_volumes({iv});
      if (!refused("four intermixed volumes", FV_STATUS_UNSUPPORTED, [&] {
            renderer.set_intermixed_volumes(std::vector<FvIntermixedVolume>(4, iv));
          })) {
        return 1;
      }
    }
    renderer.render(200, 150);
    ferrovol::Frame mixed = renderer.read_frame();
    const uint8_t *right = mixed.rgba() + 4 * (75 * 200 + 100);
    std::printf("intermixed centre %u %u %u %u\n", right[0], right[1], right[2], right[3]);
    if (!(right[0] > right[1] && right[3] > centre[3])) {
      std::fprintf(stderr, "the red sphere does not show over the first\n");
      return 1;
    }
    renderer.set_intermixed_volumes({});
    if (!refused("invalid blend mode", FV_STATUS_INVALID_ARGUMENT, [&] {
          FvRenderParams bad = ferrovol::Renderer::default_params();
          bad.blend_mode = 42;
          renderer.set_params(bad);
        })) {
      return 1;
    }
    {
      // The same box as a mesh, in VTK's default arrays (double points, int64 cells): one
      // hexahedron with a scalar per corner.
      std::vector<double> points;
      std::vector<float> scalars;
      for (int k = 0; k < 2; ++k)
        for (int j = 0; j < 2; ++j)
          for (int i = 0; i < 2; ++i) {
            points.insert(points.end(), {31.0 * (i ^ j), 31.0 * j, 31.0 * k});
            scalars.push_back(static_cast<float>(255 * (i ^ j)));
          }
      std::vector<int64_t> connectivity = {0, 1, 2, 3, 4, 5, 6, 7}, offsets = {0, 8};
      uint8_t hexahedron = 12;
      FvUnstructuredVolumeDesc d = ferrovol::UnstructuredVolume::default_desc();
      d.points = points.data();
      d.point_count = 8;
      d.connectivity = connectivity.data();
      d.connectivity_count = connectivity.size();
      d.offsets = offsets.data();
      d.cell_types = &hexahedron;
      d.cell_count = 1;
      d.scalars = scalars.data();
      renderer.set_unstructured(ferrovol::UnstructuredVolume(d));
      renderer.render(200, 150);
      ferrovol::Frame mesh = renderer.read_frame();
      const uint8_t *c = mesh.rgba() + 4 * (75 * 200 + 100);
      std::printf("mesh centre %u %u %u %u\n", c[0], c[1], c[2], c[3]);
      if (c[3] < 128) {
        std::fprintf(stderr, "the hexahedron is missing from the centre of the frame\n");
        return 1;
      }
      connectivity[7] = 8;
      if (!refused("dangling index", FV_STATUS_INVALID_ARGUMENT,
                   [&] { ferrovol::UnstructuredVolume dangling(d); })) {
        return 1;
      }
    }
  } catch (const ferrovol::Error &e) {
    std::fprintf(stderr, "%s\n", e.what());
    return 1;
  }
  return 0;
}
