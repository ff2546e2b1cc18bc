// vtkFerroVolumeSettings: what the mapper, its volume's property and the renderer ask of one
// frame, in ferrovol's terms: blend mode, sampling, shading, cropping and clipping planes,
// the isosurface, path tracing and environment parameters (given to the renderer every frame,
// which uploads nothing), the camera and the lights. Internal to the FerroVolume module (not
// wrapped).
#ifndef vtkFerroVolumeSettings_h
#define vtkFerroVolumeSettings_h

#include "ferrovol.hpp"
#include "vtkFerroVolumeRefinement.h"

#include <string>

class vtkFerroVolumeInputHelper;
class vtkFerroVolumeMapper;
class vtkFerroVolumeReport;
class vtkObject;
class vtkPlaneCollection;
class vtkRenderer;
class vtkVolume;
class vtkVolumeProperty;

class vtkFerroVolumeSettings
{
public:
  // The mapper's blend mode (or path tracing) in ferrovol's terms; false with the reason
  // when ferrovol has no such mode.
  bool SelectBlendMode(vtkFerroVolumeMapper* self, vtkFerroVolumeReport& report);
  // vtkVolumeMapper's blend mode `vtkBlendMode` in ferrovol's terms (an FvBlendMode); false
  // when ferrovol has no such mode.
  static bool ToFvBlend(int vtkBlendMode, uint32_t& blend);
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
  // support (once per mapper, in `report`). `input`: the image and scalars rendered
  // (LockSampleDistanceToInputSpacing reads the spacing and extent; ClippedVoxelIntensity
  // the type and ranges). `traceBudget`: seconds a progressive render's path tracing may
  // take, 0 when the render is not progressive.
  Result Apply(vtkFerroVolumeMapper* self, vtkRenderer* ren, vtkVolume* vol,
    const vtkFerroVolumeInputHelper& input, ferrovol::Renderer& renderer, double traceBudget,
    vtkFerroVolumeReport& report);

  // Gives the renderer the camera VTK draws the opaque geometry with (for a vw × vh
  // viewport) and the renderer's lights.
  bool ApplyView(vtkFerroVolumeMapper* self, vtkRenderer* ren, int vw, int vh,
    ferrovol::Renderer& renderer, vtkFerroVolumeReport& report);

  // What every ferrovol mapper gives the frame alike: the camera VTK draws the opaque
  // geometry with (for a vw × vh viewport), the vtkVolume's matrix, and the first
  // FV_MAX_CLIP_PLANES of `planes` (world coordinates; warned once past them), returning
  // their count.
  static bool ApplyCamera(vtkRenderer* ren, int vw, int vh, ferrovol::Renderer& renderer,
    vtkFerroVolumeReport& report);
  static void SetVolumeMatrix(vtkVolume* vol, FvRenderParams& params);
  // The property's material (ambient, diffuse, specular, specular power) and the renderer's
  // two-sided lighting.
  static void SetMaterial(vtkVolumeProperty* prop, vtkRenderer* ren, FvRenderParams& params);
  // For a mapper without the image mapper's shading settings (params.blend_mode set): Shade
  // from the property (composite and isosurfaces), the material, and FrameLights given to
  // `renderer`. `self` warns, once, past FV_MAX_LIGHTS lights.
  static bool ApplyShading(vtkObject* self, vtkRenderer* ren, vtkVolumeProperty* prop,
    FvRenderParams& params, ferrovol::Renderer& renderer, vtkFerroVolumeReport& report);
  // Volumetric shadows (vtkGPUVolumeRayCastMapper's VolumetricScatteringBlending and
  // GlobalIlluminationReach, the property's ScatteringAnisotropy) into `params`.
  static void SetVolumetric(
    float blending, float reach, vtkVolumeProperty* prop, FvRenderParams& params);
  // The lights of a frame in `blend`: flat isosurfaces (not `shade`) one purely ambient
  // light, as vtkGPUVolumeRayCastMapper draws them; shaded or path-traced frames the
  // renderer's; none otherwise.
  static std::vector<FvLight> FrameLights(
    vtkObject* self, vtkRenderer* ren, uint32_t blend, bool shade, vtkFerroVolumeReport& report);
  // The isosurfaces (ISOSURFACE_BLEND) of either mapper: the property's iso-values and the
  // mapper's isosurface shading given to `renderer`, with `params`' material (set, Shade
  // taken) made flat when Shade is off (vtkFerroVolumeSettingsModes.cxx).
  template <class Mapper>
  Result SetUpIsosurfaces(Mapper* self, vtkVolume* vol, int components, FvRenderParams& params,
    ferrovol::Renderer& renderer, vtkFerroVolumeReport& report);
  static int SetUpClippingPlanes(
    vtkPlaneCollection* planes, FvRenderParams& params, vtkFerroVolumeReport& report);

  // Paths per pixel below which the path-traced image shown is denoised as a preview:
  // PathTracingDenoiseUntil, never past SamplesPerPixel (a converged image is unfiltered).
  // (Mapper: vtkFerroVolumeMapper or vtkFerroUnstructuredVolumeMapper, which path trace
  // with the same settings.)
  template <class Mapper>
  static uint32_t DenoiseUntil(Mapper* self);
  // The mapper's path tracing settings as its refinement reads them.
  template <class Mapper>
  static vtkFerroVolumeRefinement::Settings Refining(Mapper* self);
  // Gives the renderer the mapper's path tracing settings and environment (the surface
  // model for an image volume; meshes scatter by Henyey-Greenstein alone).
  template <class Mapper>
  bool SetUpPathTracing(Mapper* self, vtkRenderer* ren, vtkVolume* vol,
    ferrovol::Renderer& renderer, double traceBudget, vtkFerroVolumeReport& report);

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
    vtkFerroVolumeMapper* self, vtkVolume* vol, vtkFerroVolumeReport& report) const;
  // Apply's parts, by concern, each filling its fields of Params.
  // SLICE_BLEND: the property's SliceFunction, a vtkPlane (an error otherwise).
  bool SetUpSlicePlane(vtkVolume* vol, vtkFerroVolumeReport& report);
  // The property's InterpolationType (cubic: the mapper's CubicInterpolation).
  void SetUpInterpolation(
    vtkFerroVolumeMapper* self, vtkVolumeProperty* prop, vtkFerroVolumeReport& report);
  // The step along the rays: SampleDistance, LockSampleDistanceToInputSpacing or
  // AutoAdjustSampleDistances (an error for a SampleDistance that is not positive).
  bool SetUpSampling(vtkFerroVolumeMapper* self, vtkVolume* vol,
    const vtkFerroVolumeInputHelper& input, vtkFerroVolumeReport& report);
  // Jittering, shading (Shade, the material, normals from the opacity), volumetric
  // scattering, and the warnings about what ferrovol does not honour.
  void SetUpShading(vtkFerroVolumeMapper* self, vtkRenderer* ren, vtkVolume* vol,
    const vtkFerroVolumeInputHelper& input, vtkFerroVolumeReport& report);
  // Cropping regions, clipping planes and ClippedVoxelIntensity.
  void SetUpCroppingAndClipping(vtkFerroVolumeMapper* self, vtkVolumeProperty* prop,
    const vtkFerroVolumeInputHelper& input, vtkFerroVolumeReport& report);
  // The blend modes' options: the average's range, empty space skipping, the extremum's
  // depth, pre-integration, and the coarser preview of interactive renders.
  void SetUpRayOptions(vtkFerroVolumeMapper* self, vtkRenderer* ren);
  // WholeExtent: the whole dataset's box in the piece's index space.
  void SetUpWholeExtent(vtkFerroVolumeMapper* self, const vtkFerroVolumeInputHelper& input);
  // MidpointQuadrature and AdaptiveSampling (after SetUpWholeExtent: not for pieces).
  void SetUpQuadrature(vtkFerroVolumeMapper* self, vtkFerroVolumeReport& report);
  // The modes (vtkFerroVolumeSettingsModes.cxx): the environment light, path tracing and
  // the isosurfaces.
  template <class Mapper>
  bool UseEnvironment(Mapper* self, ferrovol::Renderer& renderer);
  // AutoAdjustSampleDistances: the factor (1, 1/2, 1/5 or 1/10) the smallest world spacing
  // is divided by to make the step, from the time the last render took against the time
  // allocated to this one (vtkVolume::GetAllocatedRenderTime, from the window's
  // DesiredUpdateRate), as vtkOpenGLGPUVolumeRayCastMapper::ComputeReductionFactor sets it.
  double UpdateReductionFactor(vtkFerroVolumeMapper* self, double allocatedTime);

  uint32_t Blend = FV_BLEND_MODE_COMPOSITE;
  FvRenderParams Params{};
  bool Background = false;
  double ReductionFactor = 1.0;

  // The environment last given to the renderer (isosurfaces, path tracing).
  bool HaveEnvironment = false;
  std::string EnvironmentKey;
};

#endif
