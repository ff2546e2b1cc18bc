// vtkFerroVolumeDepthPeeling: the volume inside vtkDualDepthPeelingPass's volumetric peels
// (vtkRenderer UseDepthPeeling + UseDepthPeelingForVolumes with translucent geometry; on by
// default in ParaView). At each stage the pass hands a volume mapper its depth textures and
// expects the volume between the translucent layers they bound, written into its targets:
//   outside  (before the peels): the volume in front of the nearest layer and behind the
//            farthest one (up to opaque geometry), into the front and back accumulators;
//   peel     (each peel): the volume between the layers peeled last and the ones peeled
//            now, under-blended into the front accumulator and into the back peel;
//   blend    (after the last peel): the rest, between the remaining layers, into the back
//            accumulator.
// ferrovol renders each range with Renderer::render_between, on the depths read from the
// pass's textures, and one full-screen quad writes the stage's targets as VTK's ray caster
// does. Internal to the FerroVolume module (not wrapped).
#ifndef vtkFerroVolumeDepthPeeling_h
#define vtkFerroVolumeDepthPeeling_h

#include "vtkSmartPointer.h"
#include "vtkWeakPointer.h"

#include "ferrovol.hpp"

#include <memory>
#include <string>
#include <vector>

class vtkAbstractVolumeMapper;
class vtkFerroVolumeReport;
class vtkOpenGLQuadHelper;
class vtkOpenGLRenderWindow;
class vtkRenderPass;
class vtkTextureObject;
class vtkVolume;
class vtkWindow;
struct vtkFerroVolumeFrameRequest;

class vtkFerroVolumeDepthPeeling
{
public:
  vtkFerroVolumeDepthPeeling();
  ~vtkFerroVolumeDepthPeeling();
  vtkFerroVolumeDepthPeeling(const vtkFerroVolumeDepthPeeling&) = delete;
  vtkFerroVolumeDepthPeeling& operator=(const vtkFerroVolumeDepthPeeling&) = delete;

  // The vtkDualDepthPeelingPass drawing `vol` inside its volumetric peels, nullptr when
  // none is.
  static vtkRenderPass* PeelingPass(vtkVolume* vol);

  // Renders the volume for `pass`'s current stage (`renderer` set up for the frame `req`)
  // and writes it into the pass's targets.
  bool Draw(vtkRenderPass* pass, vtkAbstractVolumeMapper* mapper, vtkVolume* vol,
    ferrovol::Renderer& renderer, const vtkFerroVolumeFrameRequest& req,
    vtkFerroVolumeReport& report);

  // Frees the GL resources with `window`'s context current; nullptr forgets them.
  void ReleaseGraphicsResources(vtkWindow* window);

  enum class Stage
  {
    Outside,
    Peel,
    Blend
  };

private:
  bool Prepare(vtkOpenGLRenderWindow* win, vtkFerroVolumeReport& report);
  // Reads `pass`'s texture for `uniform` (as the pass binds it for this stage) into `out`,
  // rows bottom to top; `components` floats per texel (2: a min-max depth, 1: a depth).
  bool ReadPassTexture(vtkOpenGLRenderWindow* win, const char* uniform, int components,
    int width, int height, std::vector<float>& out, vtkFerroVolumeReport& report);
  bool Render(ferrovol::Renderer& renderer, const vtkFerroVolumeFrameRequest& req,
    const std::vector<float>& near, const std::vector<float>& far, vtkTextureObject* texture,
    vtkFerroVolumeReport& report);

  vtkWeakPointer<vtkOpenGLRenderWindow> Window;
  // A program sampling every texture the pass binds: the pass sets its uniforms, which
  // name the texture units to read.
  std::unique_ptr<vtkOpenGLQuadHelper> Probe;
  std::unique_ptr<vtkOpenGLQuadHelper> Quads[3];
  vtkSmartPointer<vtkTextureObject> Front;
  vtkSmartPointer<vtkTextureObject> Back;
  std::vector<float> Outer, Inner, Opaque, NearFront, FarFront, NearBack, FarBack;
};

#endif
