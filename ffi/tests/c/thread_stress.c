/* Uses ferrovol's handles from several threads exactly as the header's thread notes allow:
 * one FvContext and one FvVolume shared by every thread at once; a renderer and a transfer
 * function per thread (one thread at a time); FvFrames read by several threads at once; a
 * renderer moved to another thread; fv_last_error per thread.
 *
 * The main thread first renders one reference frame per camera. Then THREADS threads, each
 * with its own renderer on the shared context and volume, render ROUNDS frames, cycling
 * through the cameras, and compare every frame byte for byte with the reference frame of
 * its camera (read concurrently by all threads). Each round also makes a failing call with
 * a message of its own and checks that fv_last_error on that thread still names it after
 * the other threads' calls. Finally the main thread renders once more with every thread's
 * renderer (moved between threads) and compares again.
 *
 * Built with -std=c11 -Wall -Wextra -Werror -pedantic -pthread by ffi/tests/c_program.rs,
 * and under ThreadSanitizer / AddressSanitizer by scripts/sanitize.sh.
 * Usage: thread_stress [ROUNDS]   (default 8). Exit 0: every frame matched. */
#include "ferrovol.h"
#include "fv_report.h"

#include <pthread.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define THREADS 4
#define CAMERAS 3
#define N 24
#define W 40
#define H 32

static FvContext *ctx;
static FvVolume *volume;
static FvFrame *reference[CAMERAS];
static int rounds = 8;

struct worker {
  int index;
  FvRenderer *renderer;
  FvTransferFunction *tf;
  int frames_checked;
  int result;
};

/* The camera of index c: the volume seen from one of CAMERAS directions around y. */
static FvCamera camera(int c) {
  static const double dirs[CAMERAS][3] = {{0, 0, 1}, {1, 0, 0}, {0.6, 0.48, 0.64}};
  FvCamera cam;
  memset(&cam, 0, sizeof cam);
  const double centre = (N - 1) / 2.0, dist = 3.0 * N;
  for (int i = 0; i < 3; ++i) {
    cam.focal_point[i] = centre;
    cam.position[i] = centre + dist * dirs[c][i];
  }
  cam.view_up[1] = 1.0;
  cam.view_angle = 30.0;
  cam.parallel_scale = 1.0;
  cam.clipping_range[0] = dist - N;
  cam.clipping_range[1] = dist + N;
  return cam;
}

/* A renderer on the shared context and volume with its own transfer function. */
static int make_renderer(FvRenderer **renderer, FvTransferFunction **tf) {
  const double color[] = {0.0, 0.1, 0.2, 0.9, 128.0, 1.0, 0.6, 0.2, 255.0, 1.0, 1.0, 1.0};
  const double opacity[] = {0.0, 0.0, 60.0, 0.0, 255.0, 0.7};
  FV_TRY(fv_renderer_new(ctx, renderer));
  FV_TRY(fv_renderer_set_volume(*renderer, volume));
  FV_TRY(fv_transfer_function_new(1, true, tf));
  FV_TRY(fv_transfer_function_set_color(*tf, 0, color, 3));
  FV_TRY(fv_transfer_function_set_opacity(*tf, 0, opacity, 3));
  FV_TRY(fv_renderer_set_transfer_function(*renderer, *tf));
  FvRenderParams params;
  FV_TRY(fv_render_params_default(&params, sizeof params));
  params.shade = true;
  FV_TRY(fv_renderer_set_params(*renderer, &params));
  return 0;
}

/* Renders camera c with `renderer` into *frame. */
static int render(FvRenderer *renderer, int c, FvFrame **frame) {
  FvCamera cam = camera(c);
  FV_TRY(fv_renderer_set_camera(renderer, &cam));
  FV_TRY(fv_renderer_render(renderer, W, H, NULL, 0));
  FV_TRY(fv_renderer_read_frame(renderer, frame));
  return 0;
}

/* 0 when `frame` equals the reference frame of camera c (colour and depth), 1 otherwise. */
static int compare(const FvFrame *frame, int c, const char *who) {
  uint32_t w = 0, h = 0;
  fv_frame_size(frame, &w, &h);
  const uint8_t *a = fv_frame_rgba(frame), *b = fv_frame_rgba(reference[c]);
  const float *da = fv_frame_depth(frame), *db = fv_frame_depth(reference[c]);
  if (w != W || h != H || !a || !b || !da || !db) {
    fprintf(stderr, "%s: camera %d: a %ux%u frame without pixels\n", who, c, w, h);
    return 1;
  }
  size_t differ = 0;
  for (size_t i = 0; i < (size_t)W * H; ++i)
    differ += memcmp(a + 4 * i, b + 4 * i, 4) != 0 || memcmp(da + i, db + i, 4) != 0;
  if (differ) {
    fprintf(stderr, "%s: camera %d: %zu of %d pixels differ from the reference\n", who, c,
            differ, W * H);
    return 1;
  }
  return 0;
}

/* One failing call whose message names `tag`; then fv_last_error must still name it. */
static int own_error(int tag, const char *who) {
  FvTransferFunction *tf = NULL;
  char want[64];
  FvStatus s = fv_transfer_function_new((uint32_t)(100 + tag), true, &tf);
  snprintf(want, sizeof want, "%d components", 100 + tag);
  if (s != FV_STATUS_INVALID_ARGUMENT || tf != NULL) {
    fprintf(stderr, "%s: fv_transfer_function_new(%d) returned %s\n", who, 100 + tag,
            fv_status_name(s));
    return 1;
  }
  if (!strstr(fv_last_error(), want)) {
    fprintf(stderr, "%s: fv_last_error() is '%s', wanted '%s'\n", who, fv_last_error(), want);
    return 1;
  }
  return 0;
}

static void *work(void *arg) {
  struct worker *w = arg;
  char who[32];
  snprintf(who, sizeof who, "thread %d", w->index);
  w->result = make_renderer(&w->renderer, &w->tf);
  for (int round = 0; round < rounds && w->result == 0; ++round) {
    int c = (w->index + round) % CAMERAS;
    FvFrame *frame = NULL;
    w->result = own_error(w->index * 1000 + round, who);
    if (w->result == 0)
      w->result = render(w->renderer, c, &frame);
    if (w->result == 0)
      w->result = compare(frame, c, who);
    if (w->result == 0)
      w->result = own_error(w->index * 1000 + round, who);
    fv_frame_free(frame);
    w->frames_checked += w->result == 0;
  }
  return NULL;
}

int main(int argc, char **argv) {
  if (argc > 2 || (argc == 2 && (rounds = atoi(argv[1])) < 1)) {
    fprintf(stderr, "usage: %s [ROUNDS >= 1]\n", argv[0]);
    return 2;
  }
  int code = 0;
  uint8_t data[N * N * N];
  for (int k = 0; k < N; ++k)
    for (int j = 0; j < N; ++j)
      for (int i = 0; i < N; ++i) {
        int x = 2 * i - N + 1, y = 2 * j - N + 1, z = 2 * k - N + 1;
        int r2 = x * x / 2 + y * y + 2 * z * z; /* an ellipsoid: each camera sees another shape */
        data[(k * N + j) * N + i] = (uint8_t)(r2 < N * N ? 255 - 255 * r2 / (N * N) : 0);
      }
  FvVolumeDesc desc;
  memset(&desc, 0, sizeof desc);
  desc.dims[0] = desc.dims[1] = desc.dims[2] = N;
  desc.components = 1;
  desc.scalar_type = FV_SCALAR_TYPE_U8;
  desc.spacing[0] = desc.spacing[1] = desc.spacing[2] = 1.0;
  desc.direction[0] = desc.direction[4] = desc.direction[8] = 1.0;
  FV_TRY(fv_context_new(&ctx));
  FV_TRY(fv_volume_new(&desc, data, sizeof data, &volume));

  FvRenderer *main_renderer = NULL;
  FvTransferFunction *main_tf = NULL;
  code = make_renderer(&main_renderer, &main_tf);
  for (int c = 0; c < CAMERAS && code == 0; ++c) {
    code = render(main_renderer, c, &reference[c]);
    if (code == 0) {
      size_t covered = 0;
      const uint8_t *rgba = fv_frame_rgba(reference[c]);
      for (size_t i = 0; i < (size_t)W * H; ++i)
        covered += rgba[4 * i + 3] > 0;
      printf("reference %d: %zu of %d pixels with opacity\n", c, covered, W * H);
      if (covered < (size_t)W * H / 10) {
        fprintf(stderr, "reference %d: the volume covers only %zu pixels\n", c, covered);
        code = 1;
      }
    }
  }

  struct worker workers[THREADS];
  pthread_t threads[THREADS];
  int started = 0;
  memset(workers, 0, sizeof workers);
  for (; started < THREADS && code == 0; ++started) {
    workers[started].index = started;
    if (pthread_create(&threads[started], NULL, work, &workers[started]) != 0) {
      fprintf(stderr, "pthread_create failed\n");
      code = 1;
    }
  }
  int checked = 0;
  for (int t = 0; t < started; ++t) {
    pthread_join(threads[t], NULL);
    code |= workers[t].result;
    checked += workers[t].frames_checked;
  }
  /* The renderers move to the main thread: one more frame each, a camera it has not used. */
  for (int t = 0; t < started && code == 0; ++t) {
    FvFrame *frame = NULL;
    int c = (t + rounds) % CAMERAS;
    code = render(workers[t].renderer, c, &frame);
    if (code == 0)
      code = compare(frame, c, "main thread");
    checked += code == 0;
    fv_frame_free(frame);
  }
  printf("%d threads x %d rounds: %d frames identical to the reference\n", started, rounds,
         checked);

  for (int t = 0; t < started; ++t) {
    fv_renderer_free(workers[t].renderer);
    fv_transfer_function_free(workers[t].tf);
  }
  for (int c = 0; c < CAMERAS; ++c)
    fv_frame_free(reference[c]);
  fv_renderer_free(main_renderer);
  fv_transfer_function_free(main_tf);
  fv_volume_free(volume);
  fv_context_free(ctx);
  return code;
}
