// vtkFerroVolumeDepthReader: VTK's opaque depth for ferrovol's depth input. Reads the window
// depth (0 near … 1 far) of a rectangle of the framebuffer VTK is drawing into; a
// multisampled framebuffer (VTK's default render framebuffer has 8 samples) is first
// resolved into a single-sample depth renderbuffer of the same format. Internal to the
// FerroVolume module (not wrapped).
#ifndef vtkFerroVolumeDepthReader_h
#define vtkFerroVolumeDepthReader_h

#include "vtkFerroVolumeGL.h"

#include <string>
#include <vector>

class vtkFerroVolumeReport;
class vtkOpenGLRenderWindow;
class vtkRenderer;
class vtkVolume;

class vtkFerroVolumeDepthReader
{
public:
  vtkFerroVolumeDepthReader() = default;
  vtkFerroVolumeDepthReader(const vtkFerroVolumeDepthReader&) = delete;
  vtkFerroVolumeDepthReader& operator=(const vtkFerroVolumeDepthReader&) = delete;
  ~vtkFerroVolumeDepthReader() { this->ReleaseGraphicsResources(); }

  // Whether the renderer has visible props other than volumes that draw opaque geometry
  // before the volume pass. Without any, VTK's depth buffer holds only its clear value: the
  // frame then needs no depth input, which saves a full-viewport copy.
  static bool SceneHasOpaqueGeometry(vtkRenderer* ren, vtkVolume* volume);

  // The viewport pixel whose depth a rendered pixel takes when ferrovol renders at a reduced
  // size (ImageSampleDistance): the one under the rendered pixel's centre, in integers so
  // that the CPU (readback) and the GPU (shared path) pick the same one.
  static int SourcePixel(int i, int renderSize, int viewportSize)
  {
    return ((2 * i + 1) * viewportSize) / (2 * renderSize);
  }

  // The depth of the rectangle (x, y, w, h) of the framebuffer bound for reading: `out`
  // receives w·h floats, rows bottom to top (OpenGL order); 1 everywhere, with the reason in
  // `error`, when it cannot be read.
  bool Read(vtkOpenGLRenderWindow* win, int x, int y, int w, int h, std::vector<float>& out,
    vtkFerroVolumeReport& report);

  // The internal format of the depth buffer of framebuffer `fbo` (bound for reading), or
  // GL_NONE when it is not one this reader knows.
  static GLenum DepthFormatOf(GLint fbo);

  // Deletes the GL names (the window's context is current), or never allocated.
  void ReleaseGraphicsResources();

  // Forgets GL names without deleting them (their context is gone).
  void Forget();

private:
  void Prepare(GLenum format, int w, int h);

  GLuint Fbo = 0;
  GLuint Rbo = 0;
  GLenum Format = GL_NONE;
  int Width = 0;
  int Height = 0;
};

#endif
