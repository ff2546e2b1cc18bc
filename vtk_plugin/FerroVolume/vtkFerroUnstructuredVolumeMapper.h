/**
 * @class   vtkFerroUnstructuredVolumeMapper
 * @brief   ray casts a vtkUnstructuredGrid on the GPU with ferrovol
 *
 * A vtkUnstructuredGridVolumeMapper: it takes the place of
 * vtkUnstructuredGridVolumeRayCastMapper, vtkUnstructuredGridVolumeZSweepMapper or
 * vtkProjectedTetrahedraMapper wherever they are used. ferrovol splits every linear 3D cell
 * into tetrahedra (hexahedra, voxels, wedges, pyramids and pentagonal and hexagonal prisms
 * by a conforming rule; quadratic cells linearised), walks each pixel's ray from tetrahedron to tetrahedron, entering
 * non-convex meshes again, and integrates each segment exactly as VTK's unstructured
 * integrators model light: the scalar opacity read as attenuation per
 * ScalarOpacityUnitDistance, the colour as emission. The frame is composited into VTK's
 * framebuffer with depth against opaque geometry, as vtkFerroVolumeMapper's is.
 *
 * The scalars are those vtkAbstractVolumeMapper's ScalarMode, ArrayAccessMode, ArrayId and
 * ArrayName select, on points or cells, one component (more are refused). The mesh is
 * uploaded again only when the input or its scalars change; an input that is another
 * vtkUnstructuredGridBase than vtkUnstructuredGrid is copied into one once per change of
 * the input (its MTime), not once per frame. Blend modes: composite (the
 * default, VTK's unstructured ray caster's), maximum and minimum intensity, average and
 * additive, as vtkVolumeMapper numbers them; VTK's own unstructured mappers ignore the
 * blend mode and always composite. The mapper's clipping planes and the vtkVolume's matrix
 * are honoured. With the property's Shade on (which VTK's unstructured mappers ignore),
 * composite is lit by the renderer's lights with the property's ambient, diffuse, specular
 * and specular power, as vtkGPUVolumeRayCastMapper lights image data, each ray segment by
 * the scalar's gradient interpolated from the mesh's points (each point's the mean of its
 * tetrahedra's; from the neighbours across faces for cell scalars), with volumetric shadows
 * as vtkGPUVolumeRayCastMapper's VolumetricScatteringBlending and GlobalIlluminationReach
 * give them (the same settings here; shadow rays walk the mesh). A gradient opacity
 * (which VTK's unstructured mappers ignore too) scales composite's opacity as
 * vtkGPUVolumeRayCastMapper's does, each ray segment by its function of that gradient's
 * magnitude at the segment's middle. A 2D transfer function is refused with an error naming
 * it. Errors from ferrovol reach vtkErrorMacro with its message.
 *
 * Isosurfaces (SetBlendModeToIsoSurface): the property's iso-values (GetIsoSurfaceValues),
 * coloured and made translucent by its colour and scalar opacity functions there, as
 * vtkFerroVolumeMapper draws image data's: each crossing exact (linear in each tetrahedron;
 * with cell scalars, on the faces between cells on either side of a value), its normal the
 * points' gradients interpolated there, shaded with the renderer's lights and the
 * environment, translucent layers composited front to back; ambient occlusion by walks
 * through the mesh. The property's Shade off draws flat colours.
 *
 * Path tracing (SetRenderModeToPathTrace): the mesh as a scattering medium, as
 * vtkFerroVolumeMapper path traces image data, with the same settings and meaning
 * (SamplesPerPixel, InteractiveSamplesPerPixel, PathTracingBounces, SecondaryRays, the
 * progressive refinement and its time budget, the preview denoiser, the environment light
 * and background; the property's ScatteringAnisotropy): extinction the scalar opacity per
 * ScalarOpacityUnitDistance (the ray caster's attenuation), albedo the colour,
 * Henyey-Greenstein scattering. In a window whose interactor runs timers the view refines
 * itself toward SamplesPerPixel while it rests; otherwise a still render traces them all.
 */
#ifndef vtkFerroUnstructuredVolumeMapper_h
#define vtkFerroUnstructuredVolumeMapper_h

#include "vtkFerroVolumeEnums.h"  // For the mode constants
#include "vtkFerroVolumeModule.h" // For export macro
#include "vtkUnstructuredGridVolumeMapper.h"
#include "vtkVolumeMapper.h" // For the blend mode numbers

class VTKFERROVOLUME_EXPORT vtkFerroUnstructuredVolumeMapper
  : public vtkUnstructuredGridVolumeMapper
{
public:
  static vtkFerroUnstructuredVolumeMapper* New();
  vtkTypeMacro(vtkFerroUnstructuredVolumeMapper, vtkUnstructuredGridVolumeMapper);
  void PrintSelf(ostream& os, vtkIndent indent) override;

  vtkFerroVolumeEnumsMacro;

  ///@{
  /**
   * The blend modes ferrovol draws meshes with beside the base class's composite and
   * maximum intensity (vtkVolumeMapper's numbers).
   */
  void SetBlendModeToMinimumIntensity()
  {
    this->SetBlendMode(vtkVolumeMapper::MINIMUM_INTENSITY_BLEND);
  }
  void SetBlendModeToAverageIntensity()
  {
    this->SetBlendMode(vtkVolumeMapper::AVERAGE_INTENSITY_BLEND);
  }
  void SetBlendModeToAdditive() { this->SetBlendMode(vtkVolumeMapper::ADDITIVE_BLEND); }
  void SetBlendModeToIsoSurface() { this->SetBlendMode(vtkVolumeMapper::ISOSURFACE_BLEND); }
  ///@}

  ///@{
  /**
   * Volumetric shadows in shaded composite, as vtkGPUVolumeRayCastMapper's settings of the
   * same names give them to image data: VolumetricScatteringBlending (0, the default: none;
   * up to 2, where the volumetric term replaces the gradient lighting) and
   * GlobalIlluminationReach (0, the default: about a cell; 1: across the mesh's box), with
   * the property's ScatteringAnisotropy. Each ray segment is lit as at its middle, its
   * shadow rays walking the mesh toward each light with the attenuation integrated
   * exactly.
   */
  vtkSetClampMacro(VolumetricScatteringBlending, float, 0.0f, 2.0f);
  vtkGetMacro(VolumetricScatteringBlending, float);
  vtkSetClampMacro(GlobalIlluminationReach, float, 0.0f, 1.0f);
  vtkGetMacro(GlobalIlluminationReach, float);
  ///@}

  ///@{
  /**
   * Isosurface blend mode, as vtkFerroVolumeMapper's settings of the same names: the
   * environment's share of the surfaces' light (EnvironmentLighting, default 0), its
   * specular sampling (SpecularSampling, default SPECULAR_IMPORTANCE; SpecularSamples,
   * default 16), ambient occlusion (AmbientOcclusionSamples, default 0: off; its
   * AmbientOcclusionRadius, 0: 8 typical cell sizes, the mesh box's diagonal over the cube
   * root of its tetrahedra; a direction is occluded where its walk through the mesh meets
   * the far side of the iso-value beyond the first of AmbientOcclusionSteps steps), the
   * shininess from the gradient magnitude (ShininessFromGradient, ShininessRange,
   * ShininessGradientRange: by default 0 to a quarter of the data range per typical cell
   * size), Fresnel and the translucent layers kept (IsosurfaceLayers, 1 to 8, default 4).
   */
  vtkSetClampMacro(EnvironmentLighting, double, 0.0, 100.0);
  vtkGetMacro(EnvironmentLighting, double);
  vtkSetClampMacro(SpecularSampling, int, SPECULAR_CONE, SPECULAR_IMPORTANCE);
  vtkGetMacro(SpecularSampling, int);
  vtkSetClampMacro(SpecularSamples, int, 1, 1024);
  vtkGetMacro(SpecularSamples, int);
  vtkSetClampMacro(AmbientOcclusionSamples, int, 0, 1024);
  vtkGetMacro(AmbientOcclusionSamples, int);
  vtkSetClampMacro(AmbientOcclusionSteps, int, 1, 256);
  vtkGetMacro(AmbientOcclusionSteps, int);
  vtkSetClampMacro(AmbientOcclusionRadius, double, 0.0, 1.0e30);
  vtkGetMacro(AmbientOcclusionRadius, double);
  vtkSetClampMacro(ShininessFromGradient, vtkTypeBool, 0, 1);
  vtkGetMacro(ShininessFromGradient, vtkTypeBool);
  vtkBooleanMacro(ShininessFromGradient, vtkTypeBool);
  vtkSetVector2Macro(ShininessRange, double);
  vtkGetVector2Macro(ShininessRange, double);
  vtkSetVector2Macro(ShininessGradientRange, double);
  vtkGetVector2Macro(ShininessGradientRange, double);
  vtkSetClampMacro(Fresnel, double, -1.0, 1.0);
  vtkGetMacro(Fresnel, double);
  vtkSetClampMacro(IsosurfaceLayers, int, 1, 8);
  vtkGetMacro(IsosurfaceLayers, int);
  ///@}

  ///@{
  /**
   * RENDER_MODE_RAY_CAST (the default): ray casting in the blend mode. RENDER_MODE_PATH_TRACE:
   * progressive Monte Carlo path tracing of the mesh (the blend mode is not used).
   */
  vtkSetClampMacro(RenderMode, int, RENDER_MODE_RAY_CAST, RENDER_MODE_PATH_TRACE);
  vtkGetMacro(RenderMode, int);
  void SetRenderModeToRayCast() { this->SetRenderMode(RENDER_MODE_RAY_CAST); }
  void SetRenderModeToPathTrace() { this->SetRenderMode(RENDER_MODE_PATH_TRACE); }
  ///@}

  ///@{
  /**
   * Path tracing, as vtkFerroVolumeMapper's settings of the same names: paths per pixel the
   * accumulation converges to (default 64), paths an interactive render adds when not
   * progressive (default 1), scattering events per path (default 64), paths sharing a
   * camera ray (default 1), the preview denoiser (PathTracingDenoise, default off; until
   * PathTracingDenoiseUntil paths, default 16), ProgressiveMode (default AUTOMATIC) and a
   * progressive render's PathTracingTimeBudget (0: 1/DesiredUpdateRate, at most 0.1 s).
   */
  vtkSetClampMacro(SamplesPerPixel, int, 1, 1000000);
  vtkGetMacro(SamplesPerPixel, int);
  vtkSetClampMacro(InteractiveSamplesPerPixel, int, 1, 4096);
  vtkGetMacro(InteractiveSamplesPerPixel, int);
  vtkSetClampMacro(PathTracingBounces, int, 0, 100000);
  vtkGetMacro(PathTracingBounces, int);
  vtkSetClampMacro(SecondaryRays, int, 1, 4096);
  vtkGetMacro(SecondaryRays, int);
  vtkSetMacro(PathTracingDenoise, vtkTypeBool);
  vtkGetMacro(PathTracingDenoise, vtkTypeBool);
  vtkBooleanMacro(PathTracingDenoise, vtkTypeBool);
  vtkSetClampMacro(PathTracingDenoiseUntil, int, 0, 1000000);
  vtkGetMacro(PathTracingDenoiseUntil, int);
  vtkSetClampMacro(ProgressiveMode, int, PROGRESSIVE_AUTOMATIC, PROGRESSIVE_OFF);
  vtkGetMacro(ProgressiveMode, int);
  void SetProgressiveModeToAutomatic() { this->SetProgressiveMode(PROGRESSIVE_AUTOMATIC); }
  void SetProgressiveModeToOn() { this->SetProgressiveMode(PROGRESSIVE_ON); }
  void SetProgressiveModeToOff() { this->SetProgressiveMode(PROGRESSIVE_OFF); }
  vtkSetClampMacro(PathTracingTimeBudget, double, 0.0, 3600.0);
  vtkGetMacro(PathTracingTimeBudget, double);
  ///@}

  ///@{
  /**
   * The environment that lights path-traced meshes and isosurfaces, as vtkFerroVolumeMapper's:
   * an image file
   * (EnvironmentMap; none: the procedural sky), its up direction, azimuth and intensity, and
   * whether it is the background (EnvironmentBackground, default off).
   */
  vtkSetStringMacro(EnvironmentMap);
  vtkGetStringMacro(EnvironmentMap);
  vtkSetVector3Macro(EnvironmentUp, double);
  vtkGetVector3Macro(EnvironmentUp, double);
  vtkSetMacro(EnvironmentAzimuth, double);
  vtkGetMacro(EnvironmentAzimuth, double);
  vtkSetClampMacro(EnvironmentIntensity, double, 0.0, 1.0e6);
  vtkGetMacro(EnvironmentIntensity, double);
  vtkSetClampMacro(EnvironmentBackground, vtkTypeBool, 0, 1);
  vtkGetMacro(EnvironmentBackground, vtkTypeBool);
  vtkBooleanMacro(EnvironmentBackground, vtkTypeBool);
  ///@}

  /**
   * Path tracing: the paths per pixel every pixel has (0 before the first path-traced
   * render, or -1 without a renderer).
   */
  int GetAccumulatedSamples();

  /**
   * Whether the last Render drew the mesh (0 after an error or before the first render),
   * and whether it path traced within a time budget (progressive).
   */
  vtkGetMacro(LastRenderDrew, int);
  vtkGetMacro(LastRenderProgressive, int);

  ///@{
  /**
   * How many times the mapper handed ferrovol the mesh with its scalars, and the colour and
   * opacity tables (an unchanged input and property upload nothing).
   */
  vtkGetMacro(MeshUploadCount, int);
  vtkGetMacro(TableUploadCount, int);
  ///@}

  /**
   * WARNING: INTERNAL METHOD - NOT INTENDED FOR GENERAL USE
   */
  void Render(vtkRenderer* ren, vtkVolume* vol) override;

  /**
   * WARNING: INTERNAL METHOD - NOT INTENDED FOR GENERAL USE
   */
  void ReleaseGraphicsResources(vtkWindow* window) override;

protected:
  vtkFerroUnstructuredVolumeMapper();
  ~vtkFerroUnstructuredVolumeMapper() override;

  int LastRenderDrew = 0;
  int LastRenderProgressive = 0;
  int MeshUploadCount = 0;
  int RenderMode = RENDER_MODE_RAY_CAST;
  int SamplesPerPixel = 64;
  int InteractiveSamplesPerPixel = 1;
  int PathTracingBounces = 64;
  int SecondaryRays = 1;
  vtkTypeBool PathTracingDenoise = 0;
  int PathTracingDenoiseUntil = 16;
  int ProgressiveMode = PROGRESSIVE_AUTOMATIC;
  double PathTracingTimeBudget = 0.0;
  char* EnvironmentMap = nullptr;
  double EnvironmentUp[3] = { 0.0, 1.0, 0.0 };
  double EnvironmentAzimuth = 0.0;
  double EnvironmentIntensity = 1.0;
  vtkTypeBool EnvironmentBackground = 0;
  float VolumetricScatteringBlending = 0.0f;
  float GlobalIlluminationReach = 0.0f;
  double EnvironmentLighting = 0.0;
  int SpecularSampling = SPECULAR_IMPORTANCE;
  int SpecularSamples = 16;
  int AmbientOcclusionSamples = 0;
  int AmbientOcclusionSteps = 8;
  double AmbientOcclusionRadius = 0.0;
  vtkTypeBool ShininessFromGradient = 0;
  double ShininessRange[2] = { 8.0, 64.0 };
  double ShininessGradientRange[2] = { 0.0, 0.0 };
  double Fresnel = -1.0;
  int IsosurfaceLayers = 4;
  int TableUploadCount = 0;

private:
  vtkFerroUnstructuredVolumeMapper(const vtkFerroUnstructuredVolumeMapper&) = delete;
  void operator=(const vtkFerroUnstructuredVolumeMapper&) = delete;

  class vtkInternals;
  vtkInternals* Internals;
};

#endif
