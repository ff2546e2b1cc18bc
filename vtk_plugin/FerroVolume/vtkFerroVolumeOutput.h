// vtkFerroVolumeOutput: how ferrovol's frames reach VTK's OpenGL framebuffer. A frame path
// takes VTK's opaque depth for the viewport, has ferrovol render, and leaves the frame in two
// textures: premultiplied RGBA and window depth, rows top to bottom. Two paths:
//   readback (vtkFerroVolumeOutput.cxx): depth in with glReadPixels, the frame out with
//     ferrovol's read_frame and glTexImage2D (a CPU copy each way);
//   shared (vtkFerroVolumeSharedOutput): ferrovol's images imported with
//     GL_EXT_memory_object_fd, no copy (when ferrovol.h has the shared output path).
// vtkFerroVolumeOutput picks the path (vtkFerroVolumeChooseOutput's rule), says once why
// frames go through the CPU, falls back to the readback for good when the shared one fails,
// and composites the frame: one full-screen quad, premultiplied blending, gl_FragDepth from
// the volume's depth. Internal to the FerroVolume module (not wrapped).
#ifndef vtkFerroVolumeOutput_h
#define vtkFerroVolumeOutput_h

#include "vtkWeakPointer.h"

#include "ferrovol.hpp"

#include <memory>
#include <string>

class vtkFerroVolumeReport;
class vtkMatrix4x4;
class vtkObject;
class vtkOpenGLQuadHelper;
class vtkOpenGLRenderWindow;
class vtkRenderer;
class vtkTextureObject;
class vtkVolume;
class vtkWindow;

// One frame request: the viewport in the framebuffer and the size ferrovol renders at.
struct vtkFerroVolumeFrameRequest
{
  vtkOpenGLRenderWindow* Window;
  int ViewportX, ViewportY, ViewportW, ViewportH;
  int RenderW, RenderH;
  // Whether opaque geometry may be in VTK's depth buffer; without any, the buffer holds only
  // its clear value and the frame is rendered without a depth input (no copy pass).
  bool UseDepth;
  // FinalColorWindow / FinalColorLevel as VTK's ray caster applies them to the final
  // premultiplied colour: rgb · ColorScale + ColorBias · alpha, ColorScale = 1 / window,
  // ColorBias = 1/2 − level / window (1 and 0 by default: unchanged).
  float ColorScale = 1.0f;
  float ColorBias = 0.0f;

  // The request for `ren`'s viewport in `win`, rendered at the viewport's size, with
  // UseDepth from the scene's props besides `vol`; false when the viewport is empty.
  bool ForViewport(vtkRenderer* ren, vtkVolume* vol, vtkOpenGLRenderWindow* win);
};

// Linear (colour) or nearest (depth) filtering, clamped to the edges.
// What a hardware-selection pass (vtkHardwareSelector, cell association) writes where the
// last frame shows the volume (accumulated opacity above 3/255, as vtkGPUVolumeRayCastMapper):
// the prop's colour id, or the index + 1 of the volume's point nearest the frame's depth
// there, its low or its high 24 bits.
struct vtkFerroVolumeSelection
{
  enum class Write
  {
    Prop,
    PointLow24,
    PointHigh24
  };
  Write What = Write::Prop;
  float PropColor[3] = { 0.0f, 0.0f, 0.0f };
  // Normalised device coordinates (x, y, window depth all in [-1, 1]) → the volume's point
  // index (relative to its extent), homogeneous.
  vtkMatrix4x4* DeviceToIndex = nullptr;
  int Dims[3] = { 1, 1, 1 };
};

void vtkFerroVolumeSetSampling(vtkTextureObject* texture, bool linear);

// A way for frames to travel from ferrovol to OpenGL.
class vtkFerroVolumeFramePath
{
public:
  virtual ~vtkFerroVolumeFramePath() = default;
  virtual const char* Name() const = 0;
  // Renders the frame into the two textures; `warning`: something this frame lacks (it is
  // still drawn).
  virtual bool Render(ferrovol::Renderer& renderer, const vtkFerroVolumeFrameRequest& req,
    vtkFerroVolumeReport& report, std::string& warning) = 0;
  virtual vtkTextureObject* ColorTexture() = 0;
  virtual vtkTextureObject* DepthTexture() = 0;
  // nullptr: the context is gone, GL names are forgotten rather than deleted.
  virtual void ReleaseGraphicsResources(vtkWindow* window) = 0;
};

class vtkFerroVolumeOutput
{
public:
  vtkFerroVolumeOutput();
  vtkFerroVolumeOutput(const vtkFerroVolumeOutput&) = delete;
  vtkFerroVolumeOutput& operator=(const vtkFerroVolumeOutput&) = delete;
  ~vtkFerroVolumeOutput();

  // Renders the frame through the path for this window and `preference` (an
  // vtkFerroVolumeEnums::OutputPaths value; the path is chosen again when either changed).
  // The warnings go to `report`; `warning` is something this frame lacks (said by the
  // caller once the frame is drawn).
  bool Render(int preference, ferrovol::Renderer& renderer,
    const vtkFerroVolumeFrameRequest& req, vtkFerroVolumeReport& report, std::string& warning);

  enum class Composited
  {
    Failed,
    OffScreen, // the volume is entirely off screen: nothing to composite
    Drawn
  };
  // Draws the last frame over the viewport, scissored to `rect` (x, y, w, h relative to the
  // viewport), its colour scaled by req's ColorScale and ColorBias.
  Composited Composite(
    const vtkFerroVolumeFrameRequest& req, const int rect[4], vtkFerroVolumeReport& report);
  // Draws the last frame's selection ids (`select`) over the viewport instead, scissored
  // to `rect`, where the volume shows; elsewhere what is there stays.
  Composited Select(const vtkFerroVolumeFrameRequest& req, const int rect[4],
    const vtkFerroVolumeSelection& select, vtkFerroVolumeReport& report);

  // The viewport pixels (x, y, w, h relative to the viewport) the volume's world bounding
  // box, grown by `pad` world units on every side, can cover (a volume one point thick
  // renders as a slab one spacing thick, beyond VTK's flat bounds); the whole viewport when
  // a corner is behind the camera. Outside them ferrovol's frame is empty, so the
  // compositing pass is scissored to them (it is a full-viewport fragment pass otherwise).
  static void ProjectedRect(
    vtkRenderer* ren, vtkVolume* vol, double pad, int vw, int vh, int rect[4]);

  // "shared", "readback", or "none" before the first frame.
  const char* Name() const;
  const std::string& Reason() const { return this->PathReason; }

  // The last frame's colour (premultiplied RGBA) and depth textures, rows top to bottom;
  // nullptr before the first frame.
  vtkTextureObject* ColorTexture() const;
  vtkTextureObject* DepthTexture() const;

  // Frees the GL resources with `window`'s context current; a window other than the one
  // drawn into, or nullptr, forgets the GL names instead.
  void ReleaseGraphicsResources(vtkWindow* window);

private:
  void Choose(int preference, ferrovol::Renderer& renderer, vtkOpenGLRenderWindow* win,
    vtkFerroVolumeReport& report);
  void UseReadback(ferrovol::Renderer& renderer);
  // Says why frames go through the CPU: with `warn`, a warning in `report`, once per mapper
  // for each reason; otherwise an INFO line in VTK's log, once per process for each reason
  // (the reason names the device and the OpenGL renderer, so another OpenGL is said again).
  void AnnounceReadback(const std::string& reason, bool warn, vtkFerroVolumeReport& report);

  std::unique_ptr<vtkFerroVolumeFramePath> Path;
  int Preference = -1;
  // weak: a window destroyed behind our back reads as null, and its GL names are forgotten
  vtkWeakPointer<vtkOpenGLRenderWindow> PathWindow;
  std::string PathReason;
  // Draws `quad` (made from `shader` for `req`'s window when missing) over the viewport,
  // scissored to `rect`, after `uniforms` set its own uniforms beside fvColor and fvDepth.
  template <typename Uniforms>
  Composited DrawQuad(std::unique_ptr<vtkOpenGLQuadHelper>& quad, const char* shader,
    const vtkFerroVolumeFrameRequest& req, const int rect[4], bool blend,
    vtkFerroVolumeReport& report, Uniforms uniforms);

  std::unique_ptr<vtkOpenGLQuadHelper> Quad;
  std::unique_ptr<vtkOpenGLQuadHelper> SelectQuad;
  vtkWeakPointer<vtkOpenGLRenderWindow> QuadWindow;
};

#endif
