// vtkFerroVolumeRenderToImage: vtkGPUVolumeRayCastMapper's RenderToImage. Instead of
// compositing into the window, the frame (the frame path's colour and depth textures) is
// drawn into two textures of the mapper's own, in the form vtkOpenGLGPUVolumeRayCastMapper
// leaves them (measured): colour RGBA8, the premultiplied colour after
// FinalColorWindow/Level where rays meet the volume's box and transparent white elsewhere;
// depth as one component of DepthImageScalarType; rows bottom to top. GetColorImage /
// GetDepthImage copy them into vtkImageData. Internal to the FerroVolume module (not
// wrapped).
#ifndef vtkFerroVolumeRenderToImage_h
#define vtkFerroVolumeRenderToImage_h

#include "vtkSmartPointer.h"
#include "vtkWeakPointer.h"

#include <memory>
#include <string>

class vtkFerroVolumeReport;
class vtkImageData;
class vtkMatrix4x4;
class vtkOpenGLFramebufferObject;
class vtkOpenGLQuadHelper;
class vtkOpenGLRenderWindow;
class vtkRenderer;
class vtkTextureObject;
class vtkVolume;
struct vtkFerroVolumeFrameRequest;

class vtkFerroVolumeRenderToImage
{
public:
  vtkFerroVolumeRenderToImage();
  vtkFerroVolumeRenderToImage(const vtkFerroVolumeRenderToImage&) = delete;
  vtkFerroVolumeRenderToImage& operator=(const vtkFerroVolumeRenderToImage&) = delete;
  ~vtkFerroVolumeRenderToImage();

  // Whether the depth image can have this scalar type (VTK_UNSIGNED_CHAR,
  // VTK_UNSIGNED_SHORT, VTK_FLOAT: the types vtkOpenGLGPUVolumeRayCastMapper documents).
  static bool IsDepthType(int vtkType);

  // The matrix from the volume's box ([0, 1]³ over the input's point extent; an axis with
  // one point spans half a spacing either side, as ferrovol's slab) to the camera's clip
  // space for this renderer: where rays meet the box and enter it.
  static void BoxToClip(vtkRenderer* ren, vtkVolume* vol, vtkImageData* input, vtkMatrix4x4* out);

  // Draws the frame of `req` (`color`: premultiplied RGBA, `depth`: window depth, 1 where
  // transparent; rows top to bottom) into the two textures, sized as the frame: where rays
  // meet the box (`boxToClip`, see BoxToClip), the colour after req's FinalColorWindow/Level
  // and the depth, which with `clampDepth` (ClampDepthToBackface) is, without a visible
  // sample, where the ray enters the box; elsewhere (1, 1, 1, 0) and depth 1. The depth
  // texture has `depthType` (IsDepthType).
  bool Capture(const vtkFerroVolumeFrameRequest& req, vtkTextureObject* color,
    vtkTextureObject* depth, int depthType, vtkMatrix4x4* boxToClip, bool clampDepth,
    vtkFerroVolumeReport& report);

  // The textures of the last capture; nullptr before one.
  vtkTextureObject* ColorTexture() const;
  vtkTextureObject* DepthTexture() const;

  // Copies `texture` (its window's context is made current) into `image`: width × height × 1
  // points from the origin, unit spacing, the texture's components and scalar type, rows
  // bottom to top. Nothing happens without a texture, as in vtkOpenGLGPUVolumeRayCastMapper.
  static void ToImage(vtkTextureObject* texture, vtkImageData* image);

  // Frees the textures, the framebuffer and the shader (each in its window's context).
  void ReleaseGraphicsResources();

private:
  vtkSmartPointer<vtkTextureObject> Color;
  vtkSmartPointer<vtkTextureObject> Depth;
  vtkSmartPointer<vtkOpenGLFramebufferObject> Fbo;
  std::unique_ptr<vtkOpenGLQuadHelper> Quad;
  vtkWeakPointer<vtkOpenGLRenderWindow> Window;
};

#endif
