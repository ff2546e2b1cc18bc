// vtkFerroVolumeSettings: what the mapper, its volume's property and the renderer ask of one
// frame, in ferrovol's terms: blend mode, sampling, shading, cropping and clipping planes,
// the isosurface, path tracing and environment parameters (given to the renderer every frame,
// which uploads nothing), the camera and the lights. Internal to the FerroVolume module (not
// wrapped).
#ifndef vtkFerroVolumeSettings_h
#define vtkFerroVolumeSettings_h

#include "ferrovol.hpp"

#include <set>
#include <string>

class vtkFerroVolumeInputHelper;
class vtkFerroVolumeMapper;
class vtkRenderer;
class vtkVolume;

class vtkFerroVolumeSettings
{
public:
  // The mapper's blend mode (or path tracing) in ferrovol's terms; false with the reason
  // when ferrovol has no such mode.
  bool SelectBlendMode(vtkFerroVolumeMapper* self, std::string& error);
  // The blend mode SelectBlendMode chose (an FvBlendMode).
  uint32_t GetBlend() const { return this->Blend; }

  enum class Result
  {
    Failed,
    NothingVisible, // no iso-value, or every iso-value is transparent (warned once)
    Ready
  };
  // Gives the renderer the frame's parameters (and the isosurfaces, path tracing settings
  // and environment in those modes), and warns about the mapper's settings ferrovol does not
  // support. `input`: the image and scalars rendered (LockSampleDistanceToInputSpacing reads
  // the spacing and extent; ClippedVoxelIntensity the type and ranges). `traceBudget`: seconds a progressive render's path tracing may
  // take, 0 when the render is not progressive. `warned`: the warnings said once per mapper.
  Result Apply(vtkFerroVolumeMapper* self, vtkRenderer* ren, vtkVolume* vol,
    const vtkFerroVolumeInputHelper& input, ferrovol::Renderer& renderer, double traceBudget,
    std::set<std::string>& warned, std::string& error);

  // Gives the renderer the camera VTK draws the opaque geometry with (for a vw × vh
  // viewport) and the renderer's lights.
  bool ApplyView(vtkFerroVolumeMapper* self, vtkRenderer* ren, int vw, int vh,
    ferrovol::Renderer& renderer, std::set<std::string>& warned, std::string& error);

  // Paths per pixel below which the path-traced image shown is denoised as a preview:
  // PathTracingDenoiseUntil, never past SamplesPerPixel (a converged image is unfiltered).
  static uint32_t DenoiseUntil(vtkFerroVolumeMapper* self);

  // Whether the last frame shows the environment behind the volume: it then covers the
  // whole viewport.
  bool CoversViewport() const { return this->Background; }
  // Whether the frame draws the other ports' inputs through a vtkMultiVolume (otherwise
  // an input there is warned about, once).
  void SetIntermixing(bool on) { this->Intermixing = on; }

  // Forget the environment given to the renderer (the renderer is gone).
  void Reset();

private:
  bool Intermixing = false;
  // Warns, once per mapper and setting, about each vtkGPUVolumeRayCastMapper setting in
  // effect that ferrovol does not honour (`vol`: its shader property).
  void WarnUnsupported(
    vtkFerroVolumeMapper* self, vtkVolume* vol, std::set<std::string>& warned) const;
  bool UseEnvironment(vtkFerroVolumeMapper* self, ferrovol::Renderer& renderer);
  // AutoAdjustSampleDistances: the factor (1, 1/2, 1/5 or 1/10) the smallest world spacing
  // is divided by to make the step, from the time the last render took against the time
  // allocated to this one (vtkVolume::GetAllocatedRenderTime, from the window's
  // DesiredUpdateRate), as vtkOpenGLGPUVolumeRayCastMapper::ComputeReductionFactor sets it.
  double UpdateReductionFactor(vtkFerroVolumeMapper* self, double allocatedTime);
  bool SetUpPathTracing(vtkFerroVolumeMapper* self, vtkRenderer* ren, vtkVolume* vol,
    ferrovol::Renderer& renderer, double traceBudget, std::string& error);
  Result SetUpIsosurfaces(vtkFerroVolumeMapper* self, vtkVolume* vol, int components,
    ferrovol::Renderer& renderer, std::set<std::string>& warned, std::string& error);

  uint32_t Blend = FV_BLEND_MODE_COMPOSITE;
  FvRenderParams Params{};
  bool Background = false;
  double ReductionFactor = 1.0;

  // The environment last given to the renderer (isosurfaces, path tracing).
  bool HaveEnvironment = false;
  std::string EnvironmentKey;
};

#endif
