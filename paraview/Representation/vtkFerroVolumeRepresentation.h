/**
 * @class   vtkFerroVolumeRepresentation
 * @brief   ParaView's image volume representation drawn by ferrovol.
 *
 * vtkImageVolumeRepresentation with its vtkMultiBlockVolumeMapper swapped for a
 * vtkFerroVolumeMapper (the pattern of ParaView's NVIDIA IndeX plugin). Everything the
 * superclass does stays: the colour and opacity transfer functions, Shade and the lighting
 * coefficients, ScalarOpacityUnitDistance, InterpolationType, cropping, the array selection,
 * ghost-cell cropping, the outline on ranks without data and, under MPI, ordered compositing
 * of the ranks' translucent images from the bounds of each rank's piece
 * (vtkPVRenderView::USE_BOUNDS_FOR_REDISTRIBUTION; see paraview/README.md). The shared
 * settings ferrovol does not draw (2D transfer functions, Volume Rendering Mode) give a
 * warning; paraview/README.md lists what ferrovol does with every property of
 * "Volume".
 *
 * The server-manager XML (FerrovolRepresentation.xml) adds it to UniformGridRepresentation
 * as "Ferrovol Volume" and shares the standard volume properties with "Volume". ferrovol's
 * own settings come as separate properties ("Ferrovol" group):
 *
 * - FerrovolBlendMode extends ParaView's own "BlendMode" (Composite / Isosurface / Slice,
 *   shared with "Volume", as are the "IsosurfaceValues"): its default, FOLLOW_BLEND_MODE, draws
 *   what BlendMode says; maximum, minimum, average and additive (and, for scripts written
 *   before, composite and isosurface) override it. Slice draws the plane of Slice Type
 *   (SliceFunction, "Volume"'s plane itself) as vtkFerroVolumeMapper's slice blend mode;
 * - the isosurface shading of vtkFerroVolumeMapper: environment lighting and map,
 *   background, specular sampling, ambient occlusion, shininess from the gradient, Fresnel;
 * - the sampling settings of vtkGPUVolumeRayCastMapper with the same meaning:
 *   AutoAdjustSampleDistances, SampleDistance, ImageSampleDistance, UseJittering,
 *   EmptySpaceSkipping, MaxMemoryInBytes and MaxMemoryFraction; and vtkFerroVolumeMapper's
 *   PreIntegration, MidpointQuadrature, AdaptiveSampling and CubicInterpolation.
 *
 * Inputs: vtkImageData only (what vtkFerroVolumeMapper renders). Rectilinear grids and
 * composite datasets of images, which "Volume" accepts, are not drawn; a warning says so.
 * Unstructured grids and composite datasets of them are vtkFerroUnstructuredVolumeRepresentation's.
 *
 * Multi-component arrays with independent components (MapScalars on, MultiComponentsMapping
 * off): the colour map's vector mode decides, as vtkSmartVolumeMapper's VectorMode does for
 * "Volume": the mapper gets one component, or the magnitude, as a single-component array
 * (computed here once per input and mode, not per frame).
 */

#ifndef vtkFerroVolumeRepresentation_h
#define vtkFerroVolumeRepresentation_h

#include "vtkFerroVolumeRepresentationModule.h" // For export macro
#include "vtkImageVolumeRepresentation.h"

#include "vtkSmartPointer.h" // for ivar

#include <array>  // for ivar
#include <map>    // for ivar
#include <string> // for ivar
#include <tuple>  // for ivar
#include <utility> // for ivar
#include <vector> // for ivar

class vtkDataArray;
class vtkFerroVolumeMapper;
class vtkImageData;
class vtkTrivialProducer;

class VTKFERROVOLUMEREPRESENTATION_EXPORT vtkFerroVolumeRepresentation
  : public vtkImageVolumeRepresentation
{
public:
  static vtkFerroVolumeRepresentation* New();
  vtkTypeMacro(vtkFerroVolumeRepresentation, vtkImageVolumeRepresentation);
  void PrintSelf(ostream& os, vtkIndent indent) override;

  /**
   * FerrovolBlendMode's default: draw the shared BlendMode (not one of vtkVolumeMapper's).
   */
  enum
  {
    FOLLOW_BLEND_MODE = -1
  };

  ///@{
  /**
   * ferrovol's blend mode: FOLLOW_BLEND_MODE (the default: the shared BlendMode decides) or a
   * vtkVolumeMapper::BlendModes value that overrides it: COMPOSITE_BLEND (0),
   * MAXIMUM_INTENSITY_BLEND (1), MINIMUM_INTENSITY_BLEND (2), AVERAGE_INTENSITY_BLEND (3),
   * ADDITIVE_BLEND (4) or ISOSURFACE_BLEND (5).
   */
  void SetFerrovolBlendMode(int mode);
  vtkGetMacro(FerrovolBlendMode, int);
  ///@}

  /**
   * Hides vtkImageVolumeRepresentation::SetBlendMode, the target of the "BlendMode" property
   * this representation shares with "Volume" (Composite / Isosurface / Slice; any
   * vtkVolumeMapper::BlendModes value from C++ or SetElement). Kept here and applied in
   * UpdateMapperParameters() unless FerrovolBlendMode overrides it.
   */
  void SetBlendMode(int mode);

  /**
   * Hides vtkImageVolumeRepresentation::SetRequestedRenderMode ("Volume Rendering Mode":
   * which of ParaView's own mappers "Volume" uses). ferrovol always renders this
   * representation; a mode other than Smart (0) gives a warning that says so.
   */
  void SetRequestedRenderMode(int mode);

  ///@{
  /**
   * Forwarded to vtkFerroVolumeMapper (same meaning as vtkGPUVolumeRayCastMapper's).
   */
  void SetAutoAdjustSampleDistances(int value);
  void SetSampleDistance(double value);
  void SetImageSampleDistance(double value);
  void SetUseJittering(int value);
  void SetEmptySpaceSkipping(int value);
  void SetPreIntegration(int value);
  void SetMidpointQuadrature(int value);
  void SetAdaptiveSampling(int value);
  void SetCubicInterpolation(int value);
  void SetMaxMemoryInBytes(vtkIdType value);
  void SetMaxMemoryFraction(double value);
  ///@}

  ///@{
  /**
   * Forwarded to vtkFerroVolumeMapper's isosurface settings (see its documentation);
   * SetShininessRange sets the exponents at weak and strong gradients.
   */
  void SetEnvironmentLighting(double value);
  void SetEnvironmentMap(const char* path);
  void SetEnvironmentBackground(int value);
  void SetSpecularSampling(int mode);
  void SetSpecularSamples(int samples);
  void SetAmbientOcclusionSamples(int samples);
  void SetAmbientOcclusionRadius(double radius);
  void SetShininessFromGradient(int value);
  void SetShininessRange(double weak, double strong);
  void SetFresnel(double reflectance);
  void SetIsosurfaceScattering(int mode);
  void SetIsosurfaceScatteringSamples(int samples);
  void SetIsosurfaceScatteringAbsorption(double scale);
  ///@}

  ///@{
  /**
   * Forwarded to vtkFerroVolumeMapper's path tracing settings: the render mode (ray cast 0,
   * path trace 1), the still render's paths per pixel, the bounces per path, the ray
   * budget's secondary rays, the hybrid model (gradient threshold, stochastic blend,
   * scattering regions, attenuation) and the BSDF (roughness, Fresnel reflectance,
   * transmission and its cone angle). The anisotropy is the shared "VolumeAnisotropy"
   * (vtkVolumeProperty::ScatteringAnisotropy).
   */
  void SetRenderMode(int mode);

  ///@{
  /**
   * ParaView's shared "Global Illumination Reach" and "Volumetric Scattering Blending":
   * forwarded to the base class's mapper and to vtkFerroVolumeMapper (volumetric shadows).
   * (The base class's setters are not virtual: the client-server wrapping of this class
   * calls these.)
   */
  void SetGlobalIlluminationReach(float reach);
  void SetVolumetricScatteringBlending(float blending);
  ///@}

  void SetSamplesPerPixel(int samples);
  void SetPathTracingBounces(int bounces);
  void SetPathTracingDenoise(int denoise);
  void SetPathTracingDenoiseUntil(int paths);
  void SetPathTracingTimeBudget(double seconds);
  void SetSecondaryRays(int value);
  void SetGradientThreshold(double value);
  void SetStochasticBlend(double value);
  void SetScatterRegions(int value);
  void SetAttenuation(int value);
  void SetBsdfRoughness(double value);
  void SetBsdfFresnel(double value);
  void SetTransmission(double value);
  void SetTransmissionConeAngle(double value);
  ///@}

  /**
   * Path tracing: the mapper's progressive mode (automatic 0, on 1, off 2). Renders of a
   * screenshot (SaveScreenshot, CaptureImage: ParaView renders them with the window's buffer
   * swapping off, in the GUI, pvpython and pvbatch) are never progressive: they trace
   * SamplesPerPixel paths per pixel.
   */
  void SetProgressiveMode(int mode);

  ///@{
  /**
   * A mask from an array of the dataset (vtkGPUVolumeRayCastMapper's MaskInput):
   * SetMaskArrayName names a point or cell array of the input ("" or "None": no mask; the
   * mapper reads it as the volume's own association), SetMaskType is the mapper's
   * (BinaryMaskType 0, LabelMapMaskType 1), SetMaskBlendFactor its MaskBlendFactor. Each
   * AddLabelColor(label, r, g, b, opacity) gives label 1-255 a flat colour and scalar opacity
   * of its own (vtkVolumeProperty::SetLabelColor / SetLabelScalarOpacity);
   * RemoveAllLabelColors clears them. Under MPI each rank masks its piece with the array of
   * that piece.
   */
  void SetMaskArrayName(const char* name);
  void SetMaskType(int type);
  void SetMaskBlendFactor(double factor);
  void AddLabelColor(double label, double r, double g, double b, double opacity);
  void RemoveAllLabelColors();
  ///@}

  /**
   * The mapper this representation renders with.
   */
  vtkFerroVolumeMapper* GetFerroVolumeMapper();

  ///@{
  /**
   * What the mapper reports, for information-only properties: the ferrovol library's
   * version, its GPU adapter ("" when none opened), how frames reach OpenGL ("none" before
   * the first frame), whether the last render drew the volume (0/1), the size in pixels of
   * the last frame ferrovol rendered, and how many volume and transfer-table uploads the
   * mapper made (-1 before the first frame).
   */
  const char* GetFerrovolVersion();
  const char* GetFerrovolAdapter();
  const char* GetFerrovolOutputPath();
  int GetFerrovolLastRenderDrew();
  int* GetFerrovolLastRenderSize() VTK_SIZEHINT(2);
  int GetFerrovolVolumeUploadCount();
  int GetFerrovolTableUploadCount();
  ///@}

  ///@{
  /**
   * Path tracing, for information-only properties: paths per pixel every pixel has (-1
   * before the first frame), their mean counting the pass under way, and the estimated
   * relative error of the image shown (-1 below 2 paths per pixel); see
   * vtkFerroVolumeMapper::GetPathTracingError.
   */
  int GetFerrovolAccumulatedSamples();
  double GetFerrovolMeanAccumulatedSamples();
  double GetFerrovolPathTracingError();
  ///@}

protected:
  vtkFerroVolumeRepresentation();
  ~vtkFerroVolumeRepresentation() override;

  int RequestData(vtkInformation* request, vtkInformationVector** inputVector,
    vtkInformationVector* outputVector) override;

  /**
   * The superclass's work; on REQUEST_RENDER, then gives the mapper the single-component
   * image the colour map's vector mode asks for (see ApplyVectorMode()).
   */
  int ProcessViewRequest(vtkInformationRequestKey* request_type, vtkInformation* inInfo,
    vtkInformation* outInfo) override;

  /**
   * For a multi-component array with independent components and a colour map in MAGNITUDE
   * or COMPONENT vector mode: points the mapper at a copy of the image's structure holding
   * only that magnitude or component (cached until the input, array, mode or component
   * changes). Otherwise leaves the mapper on the view's data.
   */
  void ApplyVectorMode();

  /**
   * The superclass's work (array selection, scalar mode, cropping planes, independent
   * components, the transfer-function mode), then the blend mode ferrovol draws (see
   * DrawnBlendMode()). Hides the volume when the input is not image data, when ray casting
   * in a value that is no vtkVolumeMapper mode, or with a 2D transfer function whose second
   * axis is another array than the gradient magnitude; WarnAboutSettings() says so.
   */
  void UpdateMapperParameters() override;

  /**
   * FerrovolBlendMode, or the shared BlendMode when FerrovolBlendMode is FOLLOW_BLEND_MODE.
   */
  int DrawnBlendMode() const;

  /**
   * Warns (vtkWarningMacro) about each shared "Volume" setting this representation does not
   * draw as "Volume" would: when ray casting, the drawn blend mode Slice (and so its Slice
   * Type) or a value that is no vtkVolumeMapper blend mode, and a FerrovolBlendMode that
   * disagrees with a Blend Mode other than Composite; always, a 2D transfer function over
   * another array than the gradient magnitude and a "Volume Rendering Mode" other than
   * Smart. Called while rendering, so only a visible
   * "Ferrovol Volume" speaks; says each warning once while it applies. Returns false when the
   * volume must be hidden.
   */
  bool WarnAboutSettings(int drawn);
  // Auto Sample Distance onto the mapper: AutoAdjustSampleDistances, or with a 2D transfer
  // function LockSampleDistanceToInputSpacing.
  void UpdateSampleDistanceMode();

  int FerrovolBlendMode = FOLLOW_BLEND_MODE;
  int SharedBlendMode = 0;
  int RequestedRenderMode = 0;
  // the warnings that applied at the last render (each said once while it applies)
  std::vector<std::string> SettingsWarnings;
  bool InputIsImageData = true;
  // Auto Sample Distance (UpdateSampleDistanceMode).
  bool AutoSampleDistance = true;
  std::string Adapter;
  std::string OutputPath;
  int LastRenderSize[2] = { 0, 0 };
  // the progressive mode set through the property (screenshots render with it off)
  int ProgressiveMode = 0;

  /**
   * Gives the mapper the mask image of MaskArrayName (rebuilt when the input or the array
   * changed) and the property the labels' colours; warns once when the array is missing.
   */
  void UpdateMask();

  std::string MaskArrayName;
  // the mask image (the input's structure with the array as its scalars) and its source
  vtkSmartPointer<vtkImageData> MaskImage;
  std::string MaskKey;
  // label → (r, g, b, opacity) as the property gives them, and the labels the property holds
  std::vector<std::array<double, 5>> LabelColors;
  std::vector<int> AppliedLabels;

  // ApplyVectorMode()'s single-component image, its producer and what it was made from.
  vtkSmartPointer<vtkImageData> VectorModeImage;
  vtkSmartPointer<vtkTrivialProducer> VectorModeProducer;
  std::string VectorModeKey;
  // What ApplyVectorMode() derived the mapper's array from: (cell data, array name,
  // component, or -1 for the magnitude); empty name: the mapper draws the data's own array.
  std::tuple<bool, std::string, int> VectorModeSource{ false, "", 0 };

  /**
   * Under MPI: every point and cell array's finite range over all ranks, per component
   * and of the magnitude (a collective operation, in RequestData, which every rank runs).
   */
  void GatherWholeRanges();
  /**
   * Gives the mapper the whole dataset's ranges of the array it draws (GatherWholeRanges),
   * so that every rank's piece classifies its values as the whole would.
   */
  void ApplyWholeRanges();
  /**
   * Under MPI, in the additive blend mode: the mapper's DistributedSum, when every rank's
   * mapper has scalars to draw (ParaView's vtkPVLODVolume skips the mapper of a rank
   * without, which the sum, a collective operation in the mapper's render, would wait for).
   * A collective operation itself, at REQUEST_RENDER, which every rank runs.
   */
  void UpdateDistributedSum();
  // The scalars the mapper draws (its input image's, by its scalar mode and array), or
  // nullptr; `cellFlag` 1 for cell data.
  vtkDataArray* MapperScalars(int& cellFlag);
  // (cell data, array name) → each component's range, then the magnitude's
  std::map<std::pair<bool, std::string>, std::vector<std::array<double, 2>>> WholeRanges;

private:
  vtkFerroVolumeRepresentation(const vtkFerroVolumeRepresentation&) = delete;
  void operator=(const vtkFerroVolumeRepresentation&) = delete;
};

#endif
