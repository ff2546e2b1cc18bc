/* The zero-copy path as a C host uses it: OpenGL (EGL, Mesa's surfaceless platform, no
 * window) imports ferrovol's shared colour image with GL_EXT_memory_object_fd and must read
 * exactly the pixels that fv_renderer_read_frame returns. It shares under the VTK mapper's
 * rule (vtk_plugin/FerroVolume/vtkFerroVolumeOutputChoice.h), on a GPU as on a CPU device:
 * GL has GL_EXT_memory_object_fd, the device can export memory, the Vulkan device UUID is
 * one of GL's device UUIDs and the driver UUIDs are equal. Synchronised by CPU waits
 * (fv_renderer_finish, glFinish). Exit 0: identical; 77: no usable EGL/GL interop here;
 * anything else: failure.
 * Built with -std=c11 -Wall -Wextra -Werror -pedantic by ffi/tests/c_program.rs. */
#define EGL_EGLEXT_PROTOTYPES
#include <EGL/egl.h>
#include <EGL/eglext.h>
#define GL_GLEXT_PROTOTYPES
#include <GL/gl.h>
#include <GL/glext.h>

#include "ferrovol.h"
#include "fv_report.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#define W 97
#define H 61
#define SKIP 77

/* Loads a GL entry point through EGL (extension functions are not exported by libGL). */
#define LOAD(type, name) type name = (type)eglGetProcAddress(#name)

static int open_gl(void) {
  PFNEGLGETPLATFORMDISPLAYEXTPROC get_display =
      (PFNEGLGETPLATFORMDISPLAYEXTPROC)eglGetProcAddress("eglGetPlatformDisplayEXT");
  if (!get_display)
    return SKIP;
  EGLDisplay dpy = get_display(EGL_PLATFORM_SURFACELESS_MESA, EGL_DEFAULT_DISPLAY, NULL);
  if (dpy == EGL_NO_DISPLAY || !eglInitialize(dpy, NULL, NULL))
    return SKIP;
  if (!eglBindAPI(EGL_OPENGL_API))
    return SKIP;
  const EGLint attrs[] = {EGL_CONTEXT_MAJOR_VERSION, 4, EGL_CONTEXT_MINOR_VERSION, 5,
                          EGL_CONTEXT_OPENGL_PROFILE_MASK,
                          EGL_CONTEXT_OPENGL_CORE_PROFILE_BIT, EGL_NONE};
  EGLContext ctx = eglCreateContext(dpy, EGL_NO_CONFIG_KHR, EGL_NO_CONTEXT, attrs);
  if (ctx == EGL_NO_CONTEXT || !eglMakeCurrent(dpy, EGL_NO_SURFACE, EGL_NO_SURFACE, ctx))
    return SKIP;
  return 0;
}

static void print_uuid(const char *what, const uint8_t *uuid) {
  printf("%s ", what);
  for (int i = 0; i < 16; ++i)
    printf("%02x", uuid[i]);
  printf("\n");
}

static int has_extension(const char *name) {
  LOAD(PFNGLGETSTRINGIPROC, glGetStringi);
  GLint n = 0;
  glGetIntegerv(GL_NUM_EXTENSIONS, &n);
  for (GLint i = 0; i < n; ++i) {
    if (strcmp((const char *)glGetStringi(GL_EXTENSIONS, (GLuint)i), name) == 0)
      return 1;
  }
  return 0;
}

int main(void) {
  if (open_gl() != 0 || !has_extension("GL_EXT_memory_object_fd")) {
    printf("skipped: no EGL surfaceless context with GL_EXT_memory_object_fd\n");
    return SKIP;
  }
  printf("GL: %s, %s\n", glGetString(GL_RENDERER), glGetString(GL_VERSION));
  LOAD(PFNGLGETUNSIGNEDBYTEI_VEXTPROC, glGetUnsignedBytei_vEXT);
  LOAD(PFNGLGETUNSIGNEDBYTEVEXTPROC, glGetUnsignedBytevEXT);
  LOAD(PFNGLCREATEMEMORYOBJECTSEXTPROC, glCreateMemoryObjectsEXT);
  LOAD(PFNGLMEMORYOBJECTPARAMETERIVEXTPROC, glMemoryObjectParameterivEXT);
  LOAD(PFNGLIMPORTMEMORYFDEXTPROC, glImportMemoryFdEXT);
  LOAD(PFNGLTEXSTORAGEMEM2DEXTPROC, glTexStorageMem2DEXT);
  LOAD(PFNGLGENFRAMEBUFFERSPROC, glGenFramebuffers);
  LOAD(PFNGLBINDFRAMEBUFFERPROC, glBindFramebuffer);
  LOAD(PFNGLFRAMEBUFFERTEXTURE2DPROC, glFramebufferTexture2D);
  LOAD(PFNGLCHECKFRAMEBUFFERSTATUSPROC, glCheckFramebufferStatus);

  FvContext *ctx = NULL;
  FvRenderer *r = NULL;
  /* Created while our GL context is current, as a VTK mapper does: must not disturb it. */
  FV_TRY(fv_context_new(&ctx));
  if (!fv_context_can_share(ctx)) {
    printf("skipped: the device cannot export memory: %s\n", fv_last_error());
    return SKIP;
  }
  uint8_t vk_device[16], vk_driver[16], gl_device[GL_UUID_SIZE_EXT], gl_driver[GL_UUID_SIZE_EXT];
  FV_TRY(fv_context_uuids(ctx, &vk_device, &vk_driver));
  print_uuid("Vulkan device UUID", vk_device);
  print_uuid("Vulkan driver UUID", vk_driver);
  glGetUnsignedBytevEXT(GL_DRIVER_UUID_EXT, gl_driver);
  print_uuid("GL driver UUID    ", gl_driver);
  GLint gl_devices = 0;
  glGetIntegerv(GL_NUM_DEVICE_UUIDS_EXT, &gl_devices);
  int same_device = 0;
  for (GLint i = 0; i < gl_devices; ++i) {
    glGetUnsignedBytei_vEXT(GL_DEVICE_UUID_EXT, (GLuint)i, gl_device);
    print_uuid("GL device UUID    ", gl_device);
    same_device |= memcmp(vk_device, gl_device, 16) == 0;
  }
  if (!same_device || memcmp(vk_driver, gl_driver, 16) != 0) {
    printf("skipped: GL and Vulkan are different devices or drivers\n");
    return SKIP;
  }
  FV_TRY(fv_renderer_new(ctx, &r));

  /* A 16^3 int16 volume: a bright ball in a dim box. */
  int16_t data[16 * 16 * 16];
  for (int i = 0; i < 16 * 16 * 16; ++i) {
    int x = i % 16 - 8, y = (i / 16) % 16 - 8, z = i / 256 - 8;
    data[i] = (int16_t)(x * x + y * y + z * z < 36 ? 1000 : -200 + 10 * x);
  }
  FvVolumeDesc desc;
  memset(&desc, 0, sizeof desc);
  desc.dims[0] = desc.dims[1] = desc.dims[2] = 16;
  desc.components = 1;
  desc.scalar_type = FV_SCALAR_TYPE_I16;
  desc.spacing[0] = desc.spacing[1] = desc.spacing[2] = 1.0;
  desc.direction[0] = desc.direction[4] = desc.direction[8] = 1.0;
  FvVolume *v = NULL;
  FV_TRY(fv_volume_new(&desc, data, sizeof data, &v));
  FV_TRY(fv_renderer_set_volume(r, v));
  FvTransferFunction *tf = NULL;
  FV_TRY(fv_transfer_function_new(1, true, &tf));
  const double color[] = {-300, 0.2, 0.3, 0.9, 1000, 1.0, 0.8, 0.3};
  const double opacity[] = {-300, 0.0, 1000, 0.6};
  FV_TRY(fv_transfer_function_set_color(tf, 0, color, 2));
  FV_TRY(fv_transfer_function_set_opacity(tf, 0, opacity, 2));
  FV_TRY(fv_renderer_set_transfer_function(r, tf));
  FvCamera cam;
  memset(&cam, 0, sizeof cam);
  cam.focal_point[0] = cam.focal_point[1] = cam.focal_point[2] = 7.5;
  cam.position[0] = 30;
  cam.position[1] = 20;
  cam.position[2] = 50;
  cam.view_up[1] = 1;
  cam.view_angle = 30;
  cam.parallel_scale = 1;
  cam.clipping_range[0] = 10;
  cam.clipping_range[1] = 100;
  FV_TRY(fv_renderer_set_camera(r, &cam));

  FV_TRY(fv_renderer_set_output_path(r, FV_OUTPUT_PATH_SHARED));
  FV_TRY(fv_renderer_prepare_targets(r, W, H));
  FvSharedImage img;
  FV_TRY(fv_renderer_shared_image(r, FV_TARGET_COLOR, &img));
  printf("shared colour: fd %d, %llu bytes, %ux%u, format 0x%x, generation %llu\n", img.fd,
         (unsigned long long)img.size, img.width, img.height, img.gl_internal_format,
         (unsigned long long)img.generation);

  GLuint mem = 0, tex = 0, fbo = 0;
  glCreateMemoryObjectsEXT(1, &mem);
  GLint dedicated = img.dedicated ? GL_TRUE : GL_FALSE;
  glMemoryObjectParameterivEXT(mem, GL_DEDICATED_MEMORY_OBJECT_EXT, &dedicated);
  glImportMemoryFdEXT(mem, img.size, GL_HANDLE_TYPE_OPAQUE_FD_EXT, img.fd);
  glGenTextures(1, &tex);
  glBindTexture(GL_TEXTURE_2D, tex);
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_TILING_EXT, GL_OPTIMAL_TILING_EXT);
  glTexStorageMem2DEXT(GL_TEXTURE_2D, 1, img.gl_internal_format, (GLsizei)img.width,
                       (GLsizei)img.height, mem, 0);
  glGenFramebuffers(1, &fbo);
  glBindFramebuffer(GL_FRAMEBUFFER, fbo);
  glFramebufferTexture2D(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_TEXTURE_2D, tex, 0);
  GLenum err = glGetError();
  if (err != GL_NO_ERROR || glCheckFramebufferStatus(GL_FRAMEBUFFER) != GL_FRAMEBUFFER_COMPLETE) {
    fprintf(stderr, "importing the shared image failed: GL error 0x%x\n", err);
    return 1;
  }

  FV_TRY(fv_renderer_render(r, W, H, NULL, 0));
  FV_TRY(fv_renderer_finish(r));
  static uint8_t gl_pixels[W * H * 4];
  glFinish();
  glReadPixels(0, 0, W, H, GL_RGBA, GL_UNSIGNED_BYTE, gl_pixels);

  FvFrame *frame = NULL;
  FV_TRY(fv_renderer_read_frame(r, &frame));
  const uint8_t *cpu = fv_frame_rgba(frame);
  size_t differ = 0, opaque = 0;
  for (size_t i = 0; i < sizeof gl_pixels; ++i) {
    differ += gl_pixels[i] != cpu[i];
    opaque += (i % 4 == 3) && cpu[i] > 0;
  }
  printf("GL read %zu bytes through the imported texture: %zu differ from the readback; "
         "%zu pixels with opacity\n",
         sizeof gl_pixels, differ, opaque);
  fv_frame_free(frame);
  fv_transfer_function_free(tf);
  fv_volume_free(v);
  fv_renderer_free(r);
  fv_context_free(ctx);
  return (differ == 0 && opaque > W * H / 10) ? 0 : 1;
}
