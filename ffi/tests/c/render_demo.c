/* Renders the Marschner-Lobb test volume through ferrovol's C ABI alone and writes a PNG.
 * Built with -std=c11 -Wall -Wextra -Werror -pedantic by ffi/tests/c_program.rs.
 * Usage: render_demo OUT.png [SIZE [N]]: a SIZE x SIZE image (default 320) of an N^3 volume
 * (default 41); scripts/sanitize.sh runs it small under valgrind. */
#include "ferrovol.h"
#include "fv_report.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define CHECK(call)                                                            \
  do {                                                                         \
    FvStatus s_ = (call);                                                      \
    if (s_ != FV_STATUS_OK) {                                                  \
      code = fv_report(#call, s_);                                             \
      goto done;                                                               \
    }                                                                          \
  } while (0)

/* Marschner & Lobb (1994), f_M = 6, alpha = 0.25, on [-1, 1]^3. */
static float marschner_lobb(double x, double y, double z) {
  const double pi = 3.14159265358979323846;
  double r = sqrt(x * x + y * y);
  double rho = cos(2.0 * pi * 6.0 * cos(pi * r / 2.0));
  return (float)((1.0 - sin(pi * z / 2.0) + 0.25 * (1.0 + rho)) / (2.0 * 1.25));
}

int main(int argc, char **argv) {
  int code = 0;
  FvContext *ctx = NULL;
  FvRenderer *renderer = NULL;
  FvVolume *volume = NULL;
  FvTransferFunction *tf = NULL;
  FvFrame *frame = NULL;
  float *data = NULL;
  int size = 320, n = 41;
  if (argc < 2 || argc > 4 || (argc > 2 && (size = atoi(argv[2])) < 1) ||
      (argc > 3 && (n = atoi(argv[3])) < 2)) {
    fprintf(stderr, "usage: %s OUT.png [SIZE >= 1 [N >= 2]]\n", argv[0]);
    return 2;
  }
  if (fv_version_major() != FV_VERSION_MAJOR) {
    fprintf(stderr, "header version %d but library %s\n", FV_VERSION_MAJOR, fv_version());
    return 1;
  }

  const size_t points = (size_t)n * n * n;
  data = malloc(sizeof(float) * points);
  if (!data) {
    return 1;
  }
  for (int k = 0; k < n; ++k) {
    for (int j = 0; j < n; ++j) {
      for (int i = 0; i < n; ++i) {
        double s = 2.0 / (n - 1);
        data[((size_t)k * n + j) * n + i] = marschner_lobb(-1 + i * s, -1 + j * s, -1 + k * s);
      }
    }
  }

  CHECK(fv_context_new(&ctx));
  FvAdapterInfo info;
  CHECK(fv_context_info(ctx, &info));
  printf("ferrovol %s on %s (%s)\n", fv_version(), info.name, info.backend);
  CHECK(fv_renderer_new(ctx, &renderer));

  FvVolumeDesc desc;
  memset(&desc, 0, sizeof desc);
  desc.dims[0] = desc.dims[1] = desc.dims[2] = (uint32_t)n;
  desc.components = 1;
  desc.scalar_type = FV_SCALAR_TYPE_F32;
  desc.spacing[0] = desc.spacing[1] = desc.spacing[2] = 1.0;
  desc.direction[0] = desc.direction[4] = desc.direction[8] = 1.0;
  CHECK(fv_volume_new(&desc, data, sizeof(float) * points, &volume));
  CHECK(fv_renderer_set_volume(renderer, volume));

  CHECK(fv_transfer_function_new(1, true, &tf));
  const double color[] = {0.0, 0.1, 0.2, 0.6, 0.5, 0.9, 0.8, 0.6, 1.0, 1.0, 1.0, 0.9};
  const double opacity[] = {0.0, 0.0, 0.45, 0.0, 0.55, 0.6, 1.0, 0.8};
  CHECK(fv_transfer_function_set_color(tf, 0, color, 3));
  CHECK(fv_transfer_function_set_opacity(tf, 0, opacity, 4));
  CHECK(fv_renderer_set_transfer_function(renderer, tf));

  FvCamera cam;
  memset(&cam, 0, sizeof cam);
  const double c = (n - 1) / 2.0;
  const double elevation = 30.0 * 3.14159265358979323846 / 180.0;
  const double dist = 6.0 * c;
  cam.focal_point[0] = cam.focal_point[1] = cam.focal_point[2] = c;
  cam.position[0] = c;
  cam.position[1] = c + dist * sin(elevation);
  cam.position[2] = c + dist * cos(elevation);
  cam.view_up[1] = 1.0;
  cam.view_angle = 30.0;
  cam.parallel_scale = 1.0;
  cam.clipping_range[0] = dist - 2 * c;
  cam.clipping_range[1] = dist + 2 * c;
  CHECK(fv_renderer_set_camera(renderer, &cam));

  FvLight headlight;
  memset(&headlight, 0, sizeof headlight);
  headlight.space = FV_LIGHT_SPACE_HEADLIGHT;
  for (int i = 0; i < 3; ++i) {
    headlight.ambient[i] = headlight.diffuse[i] = headlight.specular[i] = 1.0f;
  }
  headlight.intensity = 1.0f;
  headlight.attenuation[0] = 1.0f;
  headlight.cone_angle = 180.0f;
  headlight.exponent = 1.0f;
  CHECK(fv_renderer_set_lights(renderer, &headlight, 1));

  FvRenderParams params;
  CHECK(fv_render_params_default(&params, sizeof params));
  params.shade = true;
  CHECK(fv_renderer_set_params(renderer, &params));

  CHECK(fv_renderer_render(renderer, (uint32_t)size, (uint32_t)size, NULL, 0));
  CHECK(fv_renderer_read_frame(renderer, &frame));
  uint32_t w = 0, h = 0;
  fv_frame_size(frame, &w, &h);
  const uint8_t *rgba = fv_frame_rgba(frame);
  size_t covered = 0;
  for (size_t i = 0; i < (size_t)w * h; ++i) {
    covered += rgba[4 * i + 3] > 0;
  }
  printf("frame %ux%u, %zu pixels with opacity\n", w, h, covered);
  const float background[3] = {0.1f, 0.1f, 0.15f};
  CHECK(fv_frame_write_png(frame, argv[1], &background));
  if (covered < (size_t)w * h / 10) {
    fprintf(stderr, "the volume covers only %zu pixels\n", covered);
    code = 1;
  }

done:
  fv_frame_free(frame);
  fv_transfer_function_free(tf);
  fv_volume_free(volume);
  fv_renderer_free(renderer);
  fv_context_free(ctx);
  free(data);
  return code;
}
