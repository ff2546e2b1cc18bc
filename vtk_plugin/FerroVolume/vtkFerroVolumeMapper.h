/**
 * @class   vtkFerroVolumeMapper
 * @brief   vtkVolumeMapper that ray casts with ferrovol (Rust, wgpu) and composites the
 *          result into VTK's OpenGL framebuffer.
 *
 * A drop-in replacement for vtkGPUVolumeRayCastMapper on vtkImageData inputs, and a
 * subclass of it: code that holds a vtkGPUVolumeRayCastMapper (or checks IsA) takes it, and
 * every public method of vtkGPUVolumeRayCastMapper and vtkOpenGLGPUVolumeRayCastMapper is
 * here, either honoured or answered by a warning (once per mapper and setting) that names
 * what ferrovol does not support (masks, the depth pass, partitions, a shared depth
 * texture, the 2D transfer function's Y axis, time-driven image sample distances). Render
 * is ferrovol's own (the base class's would refuse scalar types ferrovol renders); it fires
 * VolumeMapperRenderStartEvent and VolumeMapperRenderEndEvent as the base class does. No
 * object factory override is registered: vtkGPUVolumeRayCastMapper::New() still makes
 * VTK's mapper. What it draws:
 *
 * - input: point or cell scalars (ScalarMode, SelectScalarArray), every numeric VTK scalar
 *   type, 1 to 4 components, origin, spacing and direction matrix; cell data is rendered as
 *   the grid of cell centres; an axis with a single point (a 2D image, 1xNxM) is rendered as
 *   a slab one spacing thick;
 * - vtkVolumeProperty: colour (RGB or gray), scalar opacity, gradient opacity (in VTK's
 *   units: the x axis is converted to ferrovol's), unit distance, component weights,
 *   IndependentComponents, Shade/Ambient/Diffuse/Specular/SpecularPower, interpolation;
 *   the tables span each component's data range as vtkGPUVolumeRayCastMapper's do;
 * - vtkVolumeMapper: composite, maximum, minimum, average (AverageIPScalarRange),
 *   additive, isosurface and slice blend modes (slice: the property's SliceFunction, a
 *   vtkPlane, drawn as vtkGPUVolumeRayCastMapper draws it: the transfer function where
 *   each ray meets the plane, without step correction; any other function is an error),
 *   cropping with region flags, clipping planes (world coordinates);
 * - isosurfaces (ISOSURFACE_BLEND): the property's iso-values (GetIsoSurfaceValues), each
 *   coloured by the colour function and made translucent by the scalar opacity function at
 *   its value, as vtkGPUVolumeRayCastMapper; each crossing is refined by interval
 *   bisection (vtkGPUVolumeRayCastMapper shades the sample after it), lit by the
 *   renderer's lights when the property's Shade is on (flat colours otherwise), and
 *   optionally by an environment map (diffuse irradiance and a specular lobe), with
 *   ambient occlusion and a shininess that follows the gradient magnitude; see the
 *   Environment*, Specular*, AmbientOcclusion*, Shininess* and Fresnel settings;
 * - vtkGPUVolumeRayCastMapper's settings with the same meaning: AutoAdjustSampleDistances
 *   (the smallest world spacing; not time-driven), SampleDistance,
 *   LockSampleDistanceToInputSpacing, ImageSampleDistance, UseJittering, FinalColorWindow /
 *   FinalColorLevel, the transfer function range types (SCALAR, NATIVE), ReportProgress,
 *   RenderToImage with GetColorImage / GetDepthImage / GetColorTexture / GetDepthTexture,
 *   DepthImageScalarType and ClampDepthToBackface, IsRenderSupported (1 where a ferrovol
 *   device opens), PreLoadData;
 * - device memory: at most MaxMemoryInBytes × MaxMemoryFraction bytes, as
 *   vtkGPUVolumeRayCastMapper's settings, but ferrovol's default MaxMemoryInBytes is 0, the
 *   device's limit (the base class's constructor probes the GPU, 128 MiB when it finds
 *   none); the fraction defaults to 0.75. A larger volume is split into bricks of which only
 *   those a frame needs are on the device; when even those exceed the budget, ray casting
 *   and isosurfaces stream them in several passes of one frame (the same image; each pass
 *   fires the ProgressEvent while ReportProgress is on); path tracing, volumetric shadows
 *   and isosurface ambient occlusion or scattering draw the finest coarser level of the
 *   volume whose needed bricks fit, as an interactive render (DesiredUpdateRate > 1) does
 *   instead of streaming. Takes effect at the next upload;
 * - volumetric shadows (single scattering) with vtkGPUVolumeRayCastMapper's
 *   VolumetricScatteringBlending and GlobalIlluminationReach, in the composite blend mode
 *   with Shade on and at least one light, the anisotropy being the property's
 *   ScatteringAnisotropy; one-component volumes that fit in one 3D texture;
 * - the renderer's lights (headlight, light kit, scene lights; at most 8 switched on);
 * - opaque geometry: rays stop at VTK's depth buffer, and the volume writes its own depth
 *   (first visible sample) so that later passes composite against it.
 *
 * - path tracing (SetRenderModeToPathTrace): the transfer function read as a scattering
 *   medium (opacity per ScalarOpacityUnitDistance as extinction, colour as albedo),
 *   Henyey–Greenstein scattering with the property's ScatteringAnisotropy, lit by the
 *   environment map and the renderer's directional lights, the paths accumulated while
 *   nothing changes (see "Path tracing: progressive or not" below);
 *
 * The volume is uploaded again only when the input scalars change, the tables only when the
 * property changes; camera changes never upload anything (GetVolumeUploadCount,
 * GetTableUploadCount).
 *
 * Frames travel from ferrovol to OpenGL either through memory both APIs share (zero copy:
 * Vulkan external memory imported with GL_EXT_memory_object_fd) or by a CPU readback; see
 * SetOutputPath and GetOutputPathName / GetOutputPathReason.
 *
 * Path tracing: progressive or not. A render is progressive when ProgressiveMode is ON, or
 * AUTOMATIC (the default) and the render window has an interactor that is enabled and runs
 * timers: the platform interactors (X, Win32, Cocoa) and Qt's QVTKInteractor do, as in
 * ParaView's GUI, in pvpython and in any VTK program that starts an interactor; pvbatch's
 * vtkGenericRenderWindowInteractor does not, and batch scripts that render offscreen or
 * capture with vtkWindowToImageFilter usually create no interactor.
 * - Progressive: every render, still or interactive, traces for the time budget
 *   (PathTracingTimeBudget; automatic: 1/DesiredUpdateRate of the window, at most 0.1 s)
 *   less what the rest of the render takes (the most of the last 4 renders, counted apart
 *   with and without the denoiser) but at least half of it, adding as many paths per pixel
 *   as fit (in sixteenths of a path, at least one), up to SamplesPerPixel, and returns.
 *   Where the rest of the render takes longer than half the budget (large windows on a CPU
 *   device such as lavapipe), renders take longer than the budget. While the accumulation is
 *   short of SamplesPerPixel and the window rests (DesiredUpdateRate at most 1), a one-shot
 *   timer of the interactor renders again through interactor->Render() (ParaView turns that
 *   into a still render of the view), so the image refines without the application's help.
 *   Refining stops when SamplesPerPixel is reached, while the user interacts (the end of
 *   the interaction renders and it resumes), when the window or the interactor goes away
 *   (ReleaseGraphicsResources and the destructor remove the timer and the observer), and
 *   after 4 renders of the timer in a row that each started the accumulation over, as when
 *   something the image depends on changes at every render (one warning). A screenshot shows what has
 *   accumulated so far: use SetProgressiveModeToOff for a converged one.
 * - Not progressive: a still render traces SamplesPerPixel paths per pixel before it
 *   returns; an interactive render (DesiredUpdateRate above 1) adds
 *   InteractiveSamplesPerPixel.
 * Either way the accumulation restarts when what it converges to changes (camera, data,
 * property, transfer functions, lights, environment, mapper settings, window size, the
 * depth of opaque geometry) and only then: a render with nothing changed, a Modified() that
 * leaves values equal and renders of other renderers add to it.
 * While it holds fewer than PathTracingDenoiseUntil paths per pixel the image shown is
 * denoised (the accumulation stays unfiltered). GetAccumulatedSamples,
 * GetMeanAccumulatedSamples and GetPathTracingError say how far it is.
 */

#ifndef vtkFerroVolumeMapper_h
#define vtkFerroVolumeMapper_h

#include "vtkFerroVolumeEnums.h"  // For the modes
#include "vtkFerroVolumeModule.h" // For export macro
#include "vtkGPUVolumeRayCastMapper.h"

class vtkImageData;
class vtkRenderWindow;
class vtkRenderer;
class vtkTextureObject;
class vtkVolume;
class vtkVolumeProperty;
class vtkWindow;

class VTKFERROVOLUME_EXPORT vtkFerroVolumeMapper : public vtkGPUVolumeRayCastMapper
{
public:
  static vtkFerroVolumeMapper* New();
  vtkTypeMacro(vtkFerroVolumeMapper, vtkGPUVolumeRayCastMapper);
  void PrintSelf(ostream& os, vtkIndent indent) override;

  // The constants of the mode settings (SPECULAR_*, ISOSURFACE_SCATTERING_*, RENDER_MODE_*,
  // PROGRESSIVE_*, SCATTER_*, OUTPUT_PATH_*), declared in vtkFerroVolumeEnums.h.
  vtkFerroVolumeEnumsMacro;

  ///@{
  /**
   * Skip blocks the transfer function makes fully transparent (composite mode, default on;
   * does not change the image).
   */
  vtkSetClampMacro(EmptySpaceSkipping, vtkTypeBool, 0, 1);
  vtkGetMacro(EmptySpaceSkipping, vtkTypeBool);
  vtkBooleanMacro(EmptySpaceSkipping, vtkTypeBool);
  ///@}

  ///@{
  /**
   * MIP and MinIP write the extremum's place in the colour function's range as the frame's
   * depth (0.5 (1 - u) for MIP, 0.5 u for MinIP) instead of the far plane, so that
   * compositing the frames of several pieces of one volume by depth keeps the largest
   * maximum or the smallest minimum over all pieces: what the ParaView representation
   * turns on under MPI, where IceT composites the ranks by depth for these modes. Default
   * off; other blend modes ignore it.
   */
  vtkSetClampMacro(ExtremumDepth, vtkTypeBool, 0, 1);
  vtkGetMacro(ExtremumDepth, vtkTypeBool);
  vtkBooleanMacro(ExtremumDepth, vtkTypeBool);
  ///@}

  ///@{
  /**
   * Pre-integrated classification (Engel, Kraus, Ertl 2001): composite ray casting
   * classifies the ray segment between consecutive samples, the scalar taken to run
   * linearly from one to the next, from a table of its integrated colour and opacity
   * (rebuilt when the transfer functions or the sample distance change), instead of each
   * sample alone; shading and gradient opacity are the back sample's. Thin opacity peaks
   * then show without slicing rings at the default sample distance. One component or
   * independent components, without volumetric scattering; other modes ignore it. Default
   * off: vtkGPUVolumeRayCastMapper does not pre-integrate, and off keeps its images
   * (docs/PERFORMANCE.md has the figures).
   */
  vtkSetClampMacro(PreIntegration, vtkTypeBool, 0, 1);
  vtkGetMacro(PreIntegration, vtkTypeBool);
  vtkBooleanMacro(PreIntegration, vtkTypeBool);
  ///@}

  ///@{
  /**
   * The midpoint quadrature: ray casting samples the middle of each step, and the part of a
   * ray past its last whole step (up to where it leaves the volume, opaque geometry or a
   * clipping plane) one more time at its middle, its opacity corrected for its length. The
   * path through the volume is then exact and the rule second order in the step, where
   * vtkGPUVolumeRayCastMapper's lattice (the first sample one step in, each standing for a
   * whole step) is first order and most wrong along silhouettes: on VTK's wavelet benchmark,
   * unshaded, twice the sample distance with midpoints is closer to the converged image than
   * VTK's lattice at its own (docs/PERFORMANCE.md). UseJittering is not applied with it (a
   * warning), nor is it under MPI (pieces of a whole extent) or for a vtkMultiVolume, which
   * keep VTK's lattice. Default off: VTK's images.
   */
  vtkSetClampMacro(MidpointQuadrature, vtkTypeBool, 0, 1);
  vtkGetMacro(MidpointQuadrature, vtkTypeBool);
  vtkBooleanMacro(MidpointQuadrature, vtkTypeBool);
  ///@}

  ///@{
  /**
   * Adaptive sampling: the midpoint quadrature (it implies MidpointQuadrature) with a step per
   * 8-cell block of the volume: unshaded composite rays take 1, 2 or 4 sample distances per
   * step where the transfer function's opacity and colour barely change per step over the
   * block's values (their spread over the block's range times the share of it one voxel
   * crosses, from the data's largest jump between neighbours), a coarse step ending at its
   * block's exit; only where that saves half the samples of the occupied blocks (reading the
   * blocks costs the rest). Shaded rays, other blend modes, gradient opacity, 2D transfer
   * functions, cropping, masks and blanking take every step, as MidpointQuadrature does.
   * Default off: VTK's images (docs/PERFORMANCE.md has what it measures).
   */
  vtkSetClampMacro(AdaptiveSampling, vtkTypeBool, 0, 1);
  vtkGetMacro(AdaptiveSampling, vtkTypeBool);
  vtkBooleanMacro(AdaptiveSampling, vtkTypeBool);
  ///@}

  ///@{
  /**
   * Cubic interpolation: where the property's InterpolationType is linear, ray casting
   * reconstructs the volume with the cubic B-spline of its points (not prefiltered: it
   * smooths at the scale of a voxel and keeps linear fields as they are; Sigg and Hadwiger's
   * eight trilinear fetches per sample) instead of trilinear interpolation. VTK 9.2's
   * vtkVolumeProperty clamps InterpolationType to linear, so this is the mapper's setting.
   * Isosurfaces are those of the B-spline; path tracing keeps trilinear interpolation.
   * Default off.
   */
  vtkSetClampMacro(CubicInterpolation, vtkTypeBool, 0, 1);
  vtkGetMacro(CubicInterpolation, vtkTypeBool);
  vtkBooleanMacro(CubicInterpolation, vtkTypeBool);
  ///@}

  ///@{
  /**
   * The whole extent of the dataset the input is a piece of, when each process of a
   * parallel run draws its own piece and the processes' frames are composited back to front
   * (ParaView sets it under MPI). Rays then sample on the whole volume's lattice and take a
   * sample on a face two pieces share once, and the additive and average blend modes draw
   * nearly transparent sums (alpha 1/255) that the compositing adds up, so the composited
   * image is the whole volume's. Default: an empty extent (the input is whole). With AverageIPScalarRange the
   * average divides by all of the whole ray's samples, in range or not.
   */
  vtkSetVector6Macro(WholeExtent, int);
  vtkGetVector6Macro(WholeExtent, int);
  ///@}

  ///@{
  /**
   * The data range of a component (0-3) over the whole dataset the input is a piece of
   * (ParaView sets them under MPI, with WholeExtent), so that every piece classifies its
   * values as the whole would: the span of the transfer functions' tables, the scalar axis
   * of 2D transfer functions, and the scalars the additive and average blend modes
   * normalise are taken over this range instead of the piece's own (widened to the piece's
   * own where its values go beyond). Default: none (the input's own ranges).
   */
  void SetWholeScalarRange(int component, double low, double high);
  void RemoveAllWholeScalarRanges();
  ///@}

  ///@{
  /**
   * The additive blend mode in a parallel run whose processes each draw a piece of one
   * volume (with WholeExtent; ParaView sets it under MPI): the processes' frames are added
   * exactly, across the global controller's processes (vtkMultiProcessController), and the
   * lowest process that drew a frame draws min(1, the sum) while the others draw nothing,
   * so that compositing the processes' frames shows the whole volume's sum (IceT's 8-bit
   * "over" cannot add two sums). Summing is a collective operation: every process must
   * render the mapper in each frame, as ParaView's parallel renders do; the mapper then
   * reports the whole extent's bounds, so that every process culls the volume alike.
   * Frames go through the readback path. Default off; ignored with one process, in other
   * blend modes, in path tracing, RenderToImage, hardware selection and depth peeling.
   */
  vtkSetClampMacro(DistributedSum, vtkTypeBool, 0, 1);
  vtkGetMacro(DistributedSum, vtkTypeBool);
  vtkBooleanMacro(DistributedSum, vtkTypeBool);
  ///@}

  /**
   * The input's bounds; the whole extent's while the additive frames of the pieces are
   * summed across processes (DistributedSum).
   */
  double* GetBounds() VTK_SIZEHINT(6) override;
  using Superclass::GetBounds;

  ///@{
  /**
   * Isosurface blend mode: how much of the environment's light falls on the surfaces,
   * diffuse (irradiance) and specular (the Phong lobe sampled on the environment map),
   * added to the renderer's lights. 0 (the default) lights the surfaces as
   * vtkGPUVolumeRayCastMapper does, with the renderer's lights only.
   */
  vtkSetClampMacro(EnvironmentLighting, double, 0.0, 100.0);
  vtkGetMacro(EnvironmentLighting, double);
  ///@}

  ///@{
  /**
   * The environment map: an equirectangular (latitude-longitude) image twice as wide as
   * high, .hdr, .exr, .png or .jpg; nullptr or "" (the default) for ferrovol's built-in
   * procedural sky. A file that cannot be used is reported with vtkErrorMacro and the
   * surfaces are drawn without environment light.
   */
  vtkSetStringMacro(EnvironmentMap);
  vtkGetStringMacro(EnvironmentMap);
  ///@}

  ///@{
  /**
   * The world direction that is up in the environment map (default 0, 1, 0), its rotation
   * about that axis in degrees (default 0) and a radiance multiplier (default 1).
   */
  vtkSetVector3Macro(EnvironmentUp, double);
  vtkGetVector3Macro(EnvironmentUp, double);
  vtkSetMacro(EnvironmentAzimuth, double);
  vtkGetMacro(EnvironmentAzimuth, double);
  vtkSetClampMacro(EnvironmentIntensity, double, 0.0, 1.0e6);
  vtkGetMacro(EnvironmentIntensity, double);
  ///@}

  ///@{
  /**
   * Isosurface blend mode: show the environment behind the surfaces (default off; the
   * volume's pixels then become opaque).
   */
  vtkSetClampMacro(EnvironmentBackground, vtkTypeBool, 0, 1);
  vtkGetMacro(EnvironmentBackground, vtkTypeBool);
  vtkBooleanMacro(EnvironmentBackground, vtkTypeBool);
  ///@}

  ///@{
  /**
   * How the specular environment light is sampled: SPECULAR_IMPORTANCE (the default)
   * draws directions distributed as the Phong lobe and reads each from the mip level its
   * probability calls for (smooth at few samples); SPECULAR_CONE blends random vectors in
   * a cone with the reflection vector (the simple scheme; noisy). SpecularSamples
   * directions per shaded point (1 to 1024, default 16).
   */
  vtkSetClampMacro(SpecularSampling, int, SPECULAR_CONE, SPECULAR_IMPORTANCE);
  vtkGetMacro(SpecularSampling, int);
  vtkSetClampMacro(SpecularSamples, int, 1, 1024);
  vtkGetMacro(SpecularSamples, int);
  ///@}

  ///@{
  /**
   * Isosurface blend mode: ambient occlusion with this many directions per surface point
   * (0, the default: off; at most 1024), each a short ray of AmbientOcclusionSteps samples
   * (1 to 256, default 8) over AmbientOcclusionRadius world units (0, the default: 8 voxel
   * spacings). The fraction of open directions scales ambient and environment light.
   */
  vtkSetClampMacro(AmbientOcclusionSamples, int, 0, 1024);
  vtkGetMacro(AmbientOcclusionSamples, int);
  vtkSetClampMacro(AmbientOcclusionSteps, int, 1, 256);
  vtkGetMacro(AmbientOcclusionSteps, int);
  vtkSetClampMacro(AmbientOcclusionRadius, double, 0.0, 1.0e30);
  vtkGetMacro(AmbientOcclusionRadius, double);
  ///@}

  ///@{
  /**
   * Isosurface blend mode: when on, the specular exponent follows the gradient magnitude
   * at each surface point, from ShininessRange[0] at ShininessGradientRange[0] to
   * ShininessRange[1] at ShininessGradientRange[1] (gradient magnitude in scalar units per
   * world unit; [0, 0], the default: 0 to a quarter of the data range per voxel), so
   * sharp boundaries look glossier. Off (the default): the property's SpecularPower.
   */
  vtkSetClampMacro(ShininessFromGradient, vtkTypeBool, 0, 1);
  vtkGetMacro(ShininessFromGradient, vtkTypeBool);
  vtkBooleanMacro(ShininessFromGradient, vtkTypeBool);
  vtkSetVector2Macro(ShininessRange, double);
  vtkGetVector2Macro(ShininessRange, double);
  vtkSetVector2Macro(ShininessGradientRange, double);
  vtkGetVector2Macro(ShininessGradientRange, double);
  ///@}

  ///@{
  /**
   * Isosurface blend mode: Schlick's Fresnel weighting of specular light with this
   * reflectance at normal incidence, in [0, 1] (e.g. 0.04); negative (the default): none.
   */
  vtkSetClampMacro(Fresnel, double, -1.0, 1.0);
  vtkGetMacro(Fresnel, double);
  ///@}

  ///@{
  /**
   * Isosurface blend mode: surfaces kept per pixel when they are translucent (1 to 8,
   * default 4); marching also ends where the accumulated opacity is nearly 1.
   */
  vtkSetClampMacro(IsosurfaceLayers, int, 1, 8);
  vtkGetMacro(IsosurfaceLayers, int);
  ///@}

  ///@{
  /**
   * Isosurface blend mode: light scattered between the isosurfaces (the fast path of
   * multiple scattering), lit by the environment (EnvironmentLighting > 0): it enters at the
   * first surface, is absorbed on its way to the next (the scalar opacity function read as
   * extinction per ScalarOpacityUnitDistance, times IsosurfaceScatteringAbsorption), scatters
   * there and leaves toward the environment. PREVIEW squares the inward transmittance and
   * reads the irradiance map; TRACED follows IsosurfaceScatteringSamples directions out of
   * the volume. The first surface becomes opaque, blended with the scattered light by
   * Schlick's term (Fresnel, 0.04 when negative). Needs a volume in one 3D texture.
   */
  vtkSetClampMacro(IsosurfaceScattering, int, ISOSURFACE_SCATTERING_OFF,
    ISOSURFACE_SCATTERING_TRACED);
  vtkGetMacro(IsosurfaceScattering, int);
  vtkSetClampMacro(IsosurfaceScatteringSamples, int, 1, 256);
  vtkGetMacro(IsosurfaceScatteringSamples, int);
  vtkSetClampMacro(IsosurfaceScatteringAbsorption, double, 0.0, VTK_DOUBLE_MAX);
  vtkGetMacro(IsosurfaceScatteringAbsorption, double);
  ///@}

  ///@{
  /**
   * RENDER_MODE_RAY_CAST (the default): ray casting in the blend mode. RENDER_MODE_PATH_TRACE:
   * progressive Monte Carlo path tracing of the volume as a scattering medium (the blend
   * mode is not used; see the class documentation).
   */
  vtkSetClampMacro(RenderMode, int, RENDER_MODE_RAY_CAST, RENDER_MODE_PATH_TRACE);
  vtkGetMacro(RenderMode, int);
  void SetRenderModeToRayCast() { this->SetRenderMode(RENDER_MODE_RAY_CAST); }
  void SetRenderModeToPathTrace() { this->SetRenderMode(RENDER_MODE_PATH_TRACE); }
  ///@}

  ///@{
  /**
   * Path tracing: paths per pixel the accumulation converges to (default 64; a render that
   * is not progressive traces what is missing, at most 4096 at once, and renders after that
   * show the converged image), paths an interactive render adds when not progressive
   * (default 1); PathTracingBounces scattering events at most per path (default 64).
   */
  vtkSetClampMacro(SamplesPerPixel, int, 1, 1000000);
  vtkGetMacro(SamplesPerPixel, int);
  vtkSetClampMacro(InteractiveSamplesPerPixel, int, 1, 4096);
  vtkGetMacro(InteractiveSamplesPerPixel, int);
  vtkSetClampMacro(PathTracingBounces, int, 0, 100000);
  vtkGetMacro(PathTracingBounces, int);
  ///@}

  ///@{
  /**
   * Path tracing: show the image through the edge-aware a-trous denoiser (guided by the
   * normal and depth where the paths first meet the medium): always with PathTracingDenoise
   * on (default off), otherwise while the accumulation holds fewer than
   * PathTracingDenoiseUntil paths per pixel (default 16; 0: never), and never once it holds
   * SamplesPerPixel. The accumulation itself stays unfiltered.
   */
  vtkSetMacro(PathTracingDenoise, vtkTypeBool);
  vtkGetMacro(PathTracingDenoise, vtkTypeBool);
  vtkBooleanMacro(PathTracingDenoise, vtkTypeBool);
  vtkSetClampMacro(PathTracingDenoiseUntil, int, 0, 1000000);
  vtkGetMacro(PathTracingDenoiseUntil, int);
  ///@}

  ///@{
  /**
   * Path tracing: whether renders trace within a time budget and the view refines itself
   * (see "Path tracing: progressive or not" in the class documentation). AUTOMATIC (the
   * default): where the window has an interactor that runs timers; ON: always (without such
   * an interactor the application renders again to refine); OFF: never (a still render
   * traces SamplesPerPixel paths before it returns).
   */
  vtkSetClampMacro(ProgressiveMode, int, PROGRESSIVE_AUTOMATIC, PROGRESSIVE_OFF);
  vtkGetMacro(ProgressiveMode, int);
  void SetProgressiveModeToAutomatic() { this->SetProgressiveMode(PROGRESSIVE_AUTOMATIC); }
  void SetProgressiveModeToOn() { this->SetProgressiveMode(PROGRESSIVE_ON); }
  void SetProgressiveModeToOff() { this->SetProgressiveMode(PROGRESSIVE_OFF); }
  ///@}

  ///@{
  /**
   * Path tracing, progressive renders: seconds one Render() may take, tracing included
   * (0, the default: 1/DesiredUpdateRate of the render window, at most 0.1 s, so a resting
   * window answers the user within a tenth of a second). A render traces at least a
   * sixteenth of a path per pixel, which may take longer on a slow device.
   */
  vtkSetClampMacro(PathTracingTimeBudget, double, 0.0, 3600.0);
  vtkGetMacro(PathTracingTimeBudget, double);
  ///@}

  ///@{
  /**
   * Path tracing, the ray budget: each SecondaryRays consecutive paths of a pixel share
   * their camera ray and first collision (SamplesPerPixel = primary x secondary rays;
   * default 1, independent paths). Interactive frames use independent paths.
   */
  vtkSetClampMacro(SecondaryRays, int, 1, 4096);
  vtkGetMacro(SecondaryRays, int);
  ///@}

  ///@{
  /**
   * Path tracing, the hybrid scattering model: collisions where the gradient magnitude
   * (scalar units per world unit) exceeds GradientThreshold scatter by the surface-like
   * BSDF oriented by the gradient, the others by Henyey-Greenstein with the property's
   * ScatteringAnisotropy (default VTK_DOUBLE_MAX: Henyey-Greenstein everywhere). A
   * StochasticBlend k > 0 replaces the threshold: the BSDF with probability
   * 1 - exp(-k |grad s|) (default 0).
   */
  vtkSetClampMacro(GradientThreshold, double, 0.0, VTK_DOUBLE_MAX);
  vtkGetMacro(GradientThreshold, double);
  vtkSetClampMacro(StochasticBlend, double, 0.0, VTK_DOUBLE_MAX);
  vtkGetMacro(StochasticBlend, double);
  ///@}

  ///@{
  /**
   * Path tracing: where collisions scatter (SCATTER_EVERYWHERE by default; SURFACES: only
   * where the BSDF applies, BETWEEN: only where Henyey-Greenstein does, NOWHERE: none).
   * With Attenuation on (the default) the other collisions absorb; off, they are left out
   * (the medium is transparent there).
   */
  vtkSetClampMacro(ScatterRegions, int, SCATTER_NOWHERE, SCATTER_EVERYWHERE);
  vtkGetMacro(ScatterRegions, int);
  void SetScatterRegionsToNowhere() { this->SetScatterRegions(SCATTER_NOWHERE); }
  void SetScatterRegionsToSurfaces() { this->SetScatterRegions(SCATTER_SURFACES); }
  void SetScatterRegionsToBetween() { this->SetScatterRegions(SCATTER_BETWEEN); }
  void SetScatterRegionsToEverywhere() { this->SetScatterRegions(SCATTER_EVERYWHERE); }
  vtkSetMacro(Attenuation, vtkTypeBool);
  vtkGetMacro(Attenuation, vtkTypeBool);
  vtkBooleanMacro(Attenuation, vtkTypeBool);
  ///@}

  ///@{
  /**
   * Path tracing, the BSDF: GGX roughness (0.01 to 1, default 0.4), Fresnel reflectance at
   * normal incidence (0 to 1, default 0.04), the share of the rest transmitted through the
   * surface (0 to 1, default 0) and the transmitted lobe's cone angle (half of it within
   * this many degrees, 0.5 to 60, default 30).
   */
  vtkSetClampMacro(BsdfRoughness, double, 0.01, 1.0);
  vtkGetMacro(BsdfRoughness, double);
  vtkSetClampMacro(BsdfFresnel, double, 0.0, 1.0);
  vtkGetMacro(BsdfFresnel, double);
  vtkSetClampMacro(Transmission, double, 0.0, 1.0);
  vtkGetMacro(Transmission, double);
  vtkSetClampMacro(TransmissionConeAngle, double, 0.5, 60.0);
  vtkGetMacro(TransmissionConeAngle, double);
  ///@}

  ///@{
  /**
   * Path tracing, how far the accumulation is: GetAccumulatedSamples, the paths per pixel
   * every pixel has (complete passes; -1 before the first frame, cheap);
   * GetMeanAccumulatedSamples, the mean over the pixels, counting the pass under way;
   * GetPathTracingError, the estimated relative RMS error of the image shown (the standard
   * error of each pixel's mean luminance, RMS over the pixels the volume covers, over their
   * mean luminance; -1 below 2 paths per pixel). The last two wait for the device and read
   * the accumulation back (once per frame, however often they are asked; -1 before the
   * first frame).
   */
  int GetAccumulatedSamples();
  double GetMeanAccumulatedSamples();
  double GetPathTracingError();
  ///@}

  ///@{
  /**
   * How frames travel from ferrovol to OpenGL.
   * AUTOMATIC (default): shared memory (zero copy) wherever OpenGL has
   * GL_EXT_memory_object_fd, ferrovol's device can export memory and the Vulkan device and
   * driver UUIDs are OpenGL's, on a GPU or a CPU device alike (NVIDIA's Vulkan with NVIDIA's
   * GL, lavapipe with llvmpipe); CPU readback otherwise, the reason going to VTK's log once.
   * READBACK: always through the CPU. SHARED: the same rule, and a refusal (memory is not
   * shared across devices or drivers) is a warning, once per mapper for each reason.
   * Takes effect at the next frame; GetOutputPathName says which path is active.
   */
  vtkSetClampMacro(OutputPath, int, OUTPUT_PATH_AUTOMATIC, OUTPUT_PATH_SHARED);
  vtkGetMacro(OutputPath, int);
  void SetOutputPathToAutomatic() { this->SetOutputPath(OUTPUT_PATH_AUTOMATIC); }
  void SetOutputPathToReadback() { this->SetOutputPath(OUTPUT_PATH_READBACK); }
  void SetOutputPathToShared() { this->SetOutputPath(OUTPUT_PATH_SHARED); }
  ///@}

  ///@{
  /**
   * What ferrovol has done for this mapper since its renderer was created (or since
   * ReleaseGraphicsResources): volume uploads, transfer table uploads, frames rendered.
   * -1 before the first frame.
   */
  int GetVolumeUploadCount();
  int GetTableUploadCount();
  int GetFrameCount();
  ///@}

  /**
   * Whether the last Render() drew the volume (false after an error, with no input, or when
   * the volume was outside the view).
   */
  vtkGetMacro(LastRenderDrew, vtkTypeBool);

  /**
   * Whether the last Render() was progressive (path tracing within a time budget).
   */
  vtkGetMacro(LastRenderProgressive, vtkTypeBool);

  /**
   * Size in pixels of the last frame ferrovol rendered (the viewport divided by the image
   * sample distance).
   */
  vtkGetVector2Macro(LastRenderSize, int);

  /**
   * How frames reach OpenGL now: "shared" (zero copy), "readback" (CPU copy), or "none"
   * before the first frame.
   */
  const char* GetOutputPathName();

  /**
   * Why the active output path was chosen (for readback: why memory is not shared).
   */
  const char* GetOutputPathReason();

  /**
   * The GPU ferrovol runs on (name, backend, driver), "" when no device could be opened.
   */
  static const char* GetAdapterDescription();

  /**
   * The ferrovol library's version ("MAJOR.MINOR.PATCH").
   */
  static const char* GetFerrovolVersion();

  /**
   * Loses ferrovol's GPU device on purpose, as a driver reset or a removed GPU would, to test
   * a host's recovery (the role of WebGL's WEBGL_lose_context). The next render of every
   * mapper fails with a vtkErrorMacro saying the device was lost; the render after it opens
   * a new device, uploads the input again and draws.
   */
  static void LoseDevice();

  /**
   * Caps the GPU memory ferrovol may hold (every mapper of the process together), as a
   * device with that much memory would, to test a host's handling of out-of-memory: a render
   * that needs more fails with a vtkErrorMacro saying what to do and draws nothing; the
   * renders after the cap is lifted (0) draw again.
   */
  static void LimitDeviceMemory(vtkTypeUInt64 bytes);

  ///@{
  /**
   * What ferrovol holds on its GPU device now, every mapper of the process together (wgpu's
   * own counters): the bytes of device memory bound to its buffers and textures, and its
   * live GPU objects (buffers, texture views, bind groups). Both stay flat over a long
   * session; 0 before any mapper has opened the device. Images shared with OpenGL are not
   * counted (OpenGL owns them).
   */
  static vtkTypeInt64 GetDeviceMemoryInUse();
  static vtkTypeInt64 GetDeviceObjectsInUse();
  ///@}

  /**
   * Renders the volume into the renderer's viewport (called by vtkVolume): fires
   * VolumeMapperRenderStartEvent, renders (GPURender), records TimeToDraw and fires
   * VolumeMapperRenderEndEvent, as vtkGPUVolumeRayCastMapper::Render does, without its input
   * validation (ferrovol renders every numeric scalar type, VTK_CHAR, VTK_BIT and
   * VTK_ID_TYPE included). While CreateCanonicalView renders, no events are fired and the
   * rendered pixels become the canonical view.
   */
  void Render(vtkRenderer* ren, vtkVolume* vol) override;

  /**
   * The render itself: uploads what changed, renders with ferrovol and composites the frame
   * into the viewport (or, with RenderToImage on, into the images GetColorImage and
   * GetDepthImage return). Errors are reported with vtkErrorMacro and nothing is drawn.
   */
  void GPURender(vtkRenderer* ren, vtkVolume* vol) override;

  /**
   * 1 when ferrovol's device opens (GetAdapterDescription names it), 0 otherwise; neither
   * the window nor the property changes that.
   */
  int IsRenderSupported(vtkRenderWindow* window, vtkVolumeProperty* property) override;

  /**
   * 1, 1, 1: ferrovol never resamples the input; a volume over the memory budget is bricked
   * and streamed instead.
   */
  void GetReductionRatio(double ratio[3]) override;

  /**
   * Uploads the input and the property's transfer functions now, so that the first render
   * does not; true on success (false with an error as a render would report it).
   */
  bool PreLoadData(vtkRenderer* ren, vtkVolume* vol);

  ///@{
  /**
   * RenderToImage: the last frame rendered with RenderToImage on, as
   * vtkOpenGLGPUVolumeRayCastMapper gives it. The colour image is RGBA unsigned char: the
   * premultiplied colour after FinalColorWindow/Level where rays meet the volume's box,
   * (255, 255, 255, 0) elsewhere. The depth image has one component of DepthImageScalarType:
   * the window depth of the first visible sample, 1 where there is none (with
   * ClampDepthToBackface, the depth where the ray enters the volume's box, which is what
   * VTK 9.2 draws under that name). Both are
   * the size ferrovol rendered (the viewport divided by the image sample distance), rows
   * bottom to top. Before such a frame the images are left as they are and the textures
   * are null; the textures belong to the window rendered into.
   */
  void GetColorImage(vtkImageData* image) override;
  void GetDepthImage(vtkImageData* image) override;
  vtkTextureObject* GetColorTexture();
  vtkTextureObject* GetDepthTexture();
  ///@}

  /**
   * vtkOpenGLGPUVolumeRayCastMapper's passes. ferrovol renders in one pass (no depth pass),
   * so GetCurrentPass is always RenderPass.
   */
  enum Passes
  {
    RenderPass,
    DepthPass = 1
  };
  int GetCurrentPass() { return RenderPass; }

  /**
   * vtkOpenGLGPUVolumeRayCastMapper's shared depth texture: not supported (ferrovol reads
   * VTK's depth buffer itself). A texture given here is not used, with a warning.
   */
  void SetSharedDepthTexture(vtkTextureObject* texture);

  /**
   * vtkOpenGLGPUVolumeRayCastMapper's partitions of a large volume: not needed (ferrovol
   * bricks and streams a volume over the memory budget). Anything but 1, 1, 1 is not used,
   * with a warning.
   */
  void SetPartitions(unsigned short x, unsigned short y, unsigned short z);

  /**
   * Frees the OpenGL resources in `window` and, but for path tracing, the ferrovol renderer
   * (its device memory); the next Render() uploads again. A path-traced volume keeps its
   * renderer, and with it the accumulation, until the mapper is destroyed or released
   * while ray casting: a window that goes away and renders again (VTK 9.2's interactor
   * finalizes its window when its event loop ends, and a screenshot after Start() or
   * PyVista's show() renders it again) goes on from the paths already traced.
   */
  void ReleaseGraphicsResources(vtkWindow* window) override;

protected:
  vtkFerroVolumeMapper();
  ~vtkFerroVolumeMapper() override;

  // Whether additive frames are summed across processes (DistributedSum and its conditions
  // that are the same on every process and in every render).
  bool SumsPieces() const;

  ///@{
  /**
   * vtkGPUVolumeRayCastMapper's pure virtual hooks for AMR rendering, which nothing in
   * VTK 9.2 calls: empty, as vtkOpenGLGPUVolumeRayCastMapper's are.
   */
  void PreRender(vtkRenderer* ren, vtkVolume* vol, double datasetBounds[6],
    double scalarRange[2], int numberOfScalarComponents, unsigned int numberOfLevels) override;
  void RenderBlock(vtkRenderer* ren, vtkVolume* vol, unsigned int level) override;
  void PostRender(vtkRenderer* ren, int numberOfScalarComponents) override;
  ///@}

  vtkTypeBool EmptySpaceSkipping;
  vtkTypeBool ExtremumDepth;
  int WholeExtent[6];
  vtkTypeBool DistributedSum;
  int OutputPath;
  double EnvironmentLighting;
  char* EnvironmentMap;
  double EnvironmentUp[3];
  double EnvironmentAzimuth;
  double EnvironmentIntensity;
  vtkTypeBool EnvironmentBackground;
  int SpecularSampling;
  int SpecularSamples;
  int AmbientOcclusionSamples;
  int AmbientOcclusionSteps;
  double AmbientOcclusionRadius;
  vtkTypeBool ShininessFromGradient;
  double ShininessRange[2];
  double ShininessGradientRange[2];
  double Fresnel;
  int IsosurfaceLayers;
  int IsosurfaceScattering;
  int IsosurfaceScatteringSamples;
  double IsosurfaceScatteringAbsorption;
  int RenderMode;
  int SamplesPerPixel;
  int InteractiveSamplesPerPixel;
  int PathTracingBounces;
  vtkTypeBool PathTracingDenoise;
  int PathTracingDenoiseUntil;
  int ProgressiveMode;
  double PathTracingTimeBudget;
  int SecondaryRays;
  double GradientThreshold;
  double StochasticBlend;
  int ScatterRegions;
  vtkTypeBool Attenuation;
  double BsdfRoughness;
  double BsdfFresnel;
  double Transmission;
  double TransmissionConeAngle;
  vtkTypeBool LastRenderDrew;
  vtkTypeBool LastRenderProgressive;
  int LastRenderSize[2];
  vtkTypeBool PreIntegration;
  vtkTypeBool MidpointQuadrature;
  vtkTypeBool AdaptiveSampling;
  vtkTypeBool CubicInterpolation;

private:
  vtkFerroVolumeMapper(const vtkFerroVolumeMapper&) = delete;
  void operator=(const vtkFerroVolumeMapper&) = delete;

  class vtkInternals;
  vtkInternals* Internals;
  // (reads vtkVolumeMapper::SpacingAdjustedSampleDistance for
  // LockSampleDistanceToInputSpacing)
  friend class vtkFerroVolumeSettings;
};

#endif
