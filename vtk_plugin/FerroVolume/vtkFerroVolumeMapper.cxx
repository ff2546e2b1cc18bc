// vtkFerroVolumeMapper: a vtkGPUVolumeRayCastMapper that ray casts with ferrovol (C ABI,
// ffi/include/ferrovol.h, through the RAII wrapper ferrovol.hpp) and composites the frame into
// VTK's OpenGL framebuffer. The work is split into units, as VTK splits its own GPU mapper:
//   vtkFerroVolumeInputHelper   input → ferrovol volume, only when the scalars (array, MTime,
//                               geometry) changed
//   vtkFerroVolumeLookupTables  property → ferrovol transfer function, only when the property
//                               (or its functions) or the ranges changed
//   vtkFerroVolumeSettings      mapper, property, volume matrix, camera, lights → ferrovol
//                               parameters (every frame, no upload; Apply's parts by
//                               concern, the isosurface and path tracing modes in
//                               vtkFerroVolumeSettingsModes.cxx)
//   vtkFerroVolumeDepthReader   VTK's depth buffer (this viewport) → ferrovol's depth input
//   vtkFerroVolumeOutput        ferrovol renders; the frame reaches GL textures (readback, or
//                               vtkFerroVolumeSharedOutput: zero copy) and one full-screen
//                               quad composites it (premultiplied blending, gl_FragDepth from
//                               ferrovol's depth)
//   vtkFerroVolumeDepthPeeling  inside vtkDualDepthPeelingPass: the volume between its
//                               translucent layers, into the pass's targets
//   vtkFerroVolumeRenderToImage RenderToImage: the frame into the mapper's own colour and
//                               depth textures instead of the window
//   vtkFerroVolumeRefinement    progressive path tracing: whether a render is, its time
//                               budget, the interactor timer that renders again
//   vtkFerroVolumeContext       the process-wide ferrovol device
//   vtkFerroVolumeReport        what goes wrong: the render's error (ends as vtkErrorMacro)
//                               and the warnings said once per mapper; every unit takes it
// The mode constants are in vtkFerroVolumeEnums.h, which units include instead of the
// mapper's header.
#include "vtkFerroVolumeMapper.h"
#include "vtkFerroVolumeMapperInternals.h"

vtkStandardNewMacro(vtkFerroVolumeMapper);

//------------------------------------------------------------------------------------------
vtkFerroVolumeMapper::vtkFerroVolumeMapper()
  : EmptySpaceSkipping(1)
  , ExtremumDepth(0)
  , WholeExtent{ 0, -1, 0, -1, 0, -1 }
  , DistributedSum(0)
  , OutputPath(OUTPUT_PATH_AUTOMATIC)
  , EnvironmentLighting(0.0)
  , EnvironmentMap(nullptr)
  , EnvironmentUp{ 0.0, 1.0, 0.0 }
  , EnvironmentAzimuth(0.0)
  , EnvironmentIntensity(1.0)
  , EnvironmentBackground(0)
  , SpecularSampling(SPECULAR_IMPORTANCE)
  , SpecularSamples(16)
  , AmbientOcclusionSamples(0)
  , AmbientOcclusionSteps(8)
  , AmbientOcclusionRadius(0.0)
  , ShininessFromGradient(0)
  , ShininessRange{ 8.0, 64.0 }
  , ShininessGradientRange{ 0.0, 0.0 }
  , Fresnel(-1.0)
  , IsosurfaceLayers(4)
  , IsosurfaceScattering(ISOSURFACE_SCATTERING_OFF)
  , IsosurfaceScatteringSamples(16)
  , IsosurfaceScatteringAbsorption(1.0)
  , RenderMode(RENDER_MODE_RAY_CAST)
  , SamplesPerPixel(64)
  , InteractiveSamplesPerPixel(1)
  , PathTracingBounces(64)
  , PathTracingDenoise(0)
  , PathTracingDenoiseUntil(16)
  , ProgressiveMode(PROGRESSIVE_AUTOMATIC)
  , PathTracingTimeBudget(0.0)
  , SecondaryRays(1)
  , GradientThreshold(VTK_DOUBLE_MAX)
  , StochasticBlend(0.0)
  , ScatterRegions(SCATTER_EVERYWHERE)
  , Attenuation(1)
  , BsdfRoughness(0.4)
  , BsdfFresnel(0.04)
  , Transmission(0.0)
  , TransmissionConeAngle(30.0)
  , LastRenderDrew(0)
  , LastRenderProgressive(0)
  , LastRenderSize{ 0, 0 }
  , PreIntegration(0)
  , MidpointQuadrature(0)
  , AdaptiveSampling(0)
  , CubicInterpolation(0)
  , Internals(new vtkInternals(this))
{
  // ferrovol's default: the device's limit (vtkGPUVolumeRayCastMapper's constructor probed
  // the GPU's memory, 128 MiB when it found none).
  this->MaxMemoryInBytes = 0;
}

vtkFerroVolumeMapper::~vtkFerroVolumeMapper()
{
  delete this->Internals;
  this->SetEnvironmentMap(nullptr);
}

//------------------------------------------------------------------------------------------
int vtkFerroVolumeMapper::GetVolumeUploadCount()
{
  FvStats s;
  return this->Internals->Stats(s) ? static_cast<int>(s.volume_uploads) : -1;
}

int vtkFerroVolumeMapper::GetTableUploadCount()
{
  FvStats s;
  return this->Internals->Stats(s) ? static_cast<int>(s.table_uploads) : -1;
}

int vtkFerroVolumeMapper::GetAccumulatedSamples()
{
  if (!this->Internals->Slot.Renderer)
  {
    return -1;
  }
  try
  {
    return static_cast<int>(this->Internals->Slot.Renderer->accumulated_samples());
  }
  catch (const ferrovol::Error&)
  {
    return -1;
  }
}

double vtkFerroVolumeMapper::GetMeanAccumulatedSamples()
{
  FvConvergence c;
  return this->Internals->ReadConvergence(c) ? static_cast<double>(c.mean_paths_per_pixel)
                                             : -1.0;
}

double vtkFerroVolumeMapper::GetPathTracingError()
{
  FvConvergence c;
  return this->Internals->ReadConvergence(c) ? static_cast<double>(c.relative_error) : -1.0;
}

int vtkFerroVolumeMapper::GetFrameCount()
{
  FvStats s;
  return this->Internals->Stats(s) ? static_cast<int>(s.frames) : -1;
}

const char* vtkFerroVolumeMapper::GetOutputPathName()
{
  return this->Internals->Output.Name();
}

const char* vtkFerroVolumeMapper::GetOutputPathReason()
{
  return this->Internals->Output.Reason().c_str();
}

const char* vtkFerroVolumeMapper::GetAdapterDescription()
{
  return vtkFerroVolumeContext::Description();
}

const char* vtkFerroVolumeMapper::GetFerrovolVersion()
{
  return fv_version();
}

void vtkFerroVolumeMapper::LoseDevice()
{
  vtkFerroVolumeContext::LoseDevice();
}

void vtkFerroVolumeMapper::LimitDeviceMemory(vtkTypeUInt64 bytes)
{
  vtkFerroVolumeContext::LimitDeviceMemory(bytes);
}

vtkTypeInt64 vtkFerroVolumeMapper::GetDeviceMemoryInUse()
{
  const FvDeviceMemory m = vtkFerroVolumeContext::DeviceMemory();
  return static_cast<vtkTypeInt64>(m.buffer_bytes + m.texture_bytes);
}

vtkTypeInt64 vtkFerroVolumeMapper::GetDeviceObjectsInUse()
{
  const FvDeviceMemory m = vtkFerroVolumeContext::DeviceMemory();
  return static_cast<vtkTypeInt64>(m.buffers + m.texture_views + m.bind_groups);
}

//------------------------------------------------------------------------------------------
void vtkFerroVolumeMapper::ReleaseGraphicsResources(vtkWindow* window)
{
  this->Internals->Refinement.Stop();
  if (this->RenderMode == RENDER_MODE_PATH_TRACE && !this->Internals->RendererLost())
  {
    this->Internals->ReleaseWindowResources(window);
  }
  else
  {
    this->Internals->ReleaseDeviceResources(window);
  }
  this->Superclass::ReleaseGraphicsResources(window);
}

//------------------------------------------------------------------------------------------
int vtkFerroVolumeMapper::IsRenderSupported(
  vtkRenderWindow* vtkNotUsed(window), vtkVolumeProperty* vtkNotUsed(property))
{
  vtkFerroVolumeReport report;
  return vtkFerroVolumeContext::Acquire(report) ? 1 : 0;
}

void vtkFerroVolumeMapper::GetReductionRatio(double ratio[3])
{
  ratio[0] = ratio[1] = ratio[2] = 1.0;
}

bool vtkFerroVolumeMapper::PreLoadData(vtkRenderer* vtkNotUsed(ren), vtkVolume* vol)
{
  vtkFerroVolumeReport& report = this->Internals->Report;
  report.ClearError();
  if (!vol)
  {
    vtkErrorMacro(<< "PreLoadData needs the vtkVolume whose property gives the tables");
    return false;
  }
  vtkMultiVolume* multi = vtkMultiVolume::SafeDownCast(vol);
  vtkVolume* main = multi ? multi->GetVolume(0) : vol;
  if (!main)
  {
    vtkErrorMacro(<< "the vtkMultiVolume has no vtkVolume on port 0 (SetVolume(volume, 0))");
    return false;
  }
  if (!this->Internals->Prepare(this, main, multi, report))
  {
    vtkErrorMacro(<< report.GetError());
    return false;
  }
  return true;
}

void vtkFerroVolumeMapper::GetColorImage(vtkImageData* image)
{
  vtkFerroVolumeRenderToImage::ToImage(this->Internals->Image.ColorTexture(), image);
}

void vtkFerroVolumeMapper::GetDepthImage(vtkImageData* image)
{
  vtkFerroVolumeRenderToImage::ToImage(this->Internals->Image.DepthTexture(), image);
}

vtkTextureObject* vtkFerroVolumeMapper::GetColorTexture()
{
  return this->Internals->Image.ColorTexture();
}

vtkTextureObject* vtkFerroVolumeMapper::GetDepthTexture()
{
  return this->Internals->Image.DepthTexture();
}

void vtkFerroVolumeMapper::SetSharedDepthTexture(vtkTextureObject* texture)
{
  if (texture && this->Internals->Report.FirstTime("shared-depth-texture"))
  {
    vtkWarningMacro(<< "SetSharedDepthTexture is not supported by ferrovol, which reads VTK's "
                       "depth buffer itself: the texture is not used");
  }
}

void vtkFerroVolumeMapper::SetPartitions(unsigned short x, unsigned short y, unsigned short z)
{
  if ((x != 1 || y != 1 || z != 1) && this->Internals->Report.FirstTime("partitions"))
  {
    vtkWarningMacro(<< "SetPartitions(" << x << ", " << y << ", " << z
                    << ") is not used: ferrovol splits a volume over the memory budget "
                       "(MaxMemoryInBytes × MaxMemoryFraction) into bricks itself");
  }
}

void vtkFerroVolumeMapper::PreRender(vtkRenderer* vtkNotUsed(ren), vtkVolume* vtkNotUsed(vol),
  double vtkNotUsed(datasetBounds)[6], double vtkNotUsed(scalarRange)[2],
  int vtkNotUsed(numberOfScalarComponents), unsigned int vtkNotUsed(numberOfLevels))
{
}

void vtkFerroVolumeMapper::RenderBlock(
  vtkRenderer* vtkNotUsed(ren), vtkVolume* vtkNotUsed(vol), unsigned int vtkNotUsed(level))
{
}

void vtkFerroVolumeMapper::PostRender(
  vtkRenderer* vtkNotUsed(ren), int vtkNotUsed(numberOfScalarComponents))
{
}

//------------------------------------------------------------------------------------------
void vtkFerroVolumeMapper::SetWholeScalarRange(int component, double low, double high)
{
  if (component < 0 || component > 3 || !(low <= high) || !std::isfinite(low) ||
    !std::isfinite(high))
  {
    vtkErrorMacro(<< "SetWholeScalarRange(" << component << ", " << low << ", " << high
                  << "): wants a component from 0 to 3 and a finite range, low <= high");
    return;
  }
  auto& range = this->Internals->WholeRanges[component];
  if (!range || (*range)[0] != low || (*range)[1] != high)
  {
    range = std::array<double, 2>{ low, high };
    this->Modified();
  }
}

void vtkFerroVolumeMapper::RemoveAllWholeScalarRanges()
{
  auto& ranges = this->Internals->WholeRanges;
  if (std::any_of(ranges.begin(), ranges.end(), [](const auto& r) { return r.has_value(); }))
  {
    ranges = {};
    this->Modified();
  }
}

//------------------------------------------------------------------------------------------
bool vtkFerroVolumeMapper::SumsPieces() const
{
  const int* whole = this->WholeExtent;
  return this->DistributedSum && this->BlendMode == ADDITIVE_BLEND &&
    this->RenderMode != RENDER_MODE_PATH_TRACE && whole[0] <= whole[1] &&
    whole[2] <= whole[3] && whole[4] <= whole[5];
}

//------------------------------------------------------------------------------------------
double* vtkFerroVolumeMapper::GetBounds()
{
  double* bounds = this->Superclass::GetBounds();
  vtkImageData* image = vtkImageData::SafeDownCast(this->GetDataSetInput());
  if (!this->SumsPieces() || !image)
  {
    return bounds;
  }
  // the whole extent's corners, placed as the piece's points are
  vtkBoundingBox box;
  const int* whole = this->WholeExtent;
  for (int corner = 0; corner < 8; ++corner)
  {
    double point[3];
    image->TransformIndexToPhysicalPoint(whole[corner & 1 ? 1 : 0],
      whole[corner & 2 ? 3 : 2], whole[corner & 4 ? 5 : 4], point);
    box.AddPoint(point);
  }
  box.GetBounds(this->Bounds);
  return this->Bounds;
}

//------------------------------------------------------------------------------------------
void vtkFerroVolumeMapper::PrintSelf(ostream& os, vtkIndent indent)
{
  // (vtkGPUVolumeRayCastMapper prints the sample distances, the final colour, the mask,
  // the memory budget and ReportProgress)
  this->Superclass::PrintSelf(os, indent);
  os << indent << "LockSampleDistanceToInputSpacing: " << this->LockSampleDistanceToInputSpacing
     << "\n";
  os << indent << "UseJittering: " << this->UseJittering << "\n";
  os << indent << "UseDepthPass: " << this->UseDepthPass << " (not supported)\n";
  os << indent << "RenderToImage: " << this->RenderToImage << "\n";
  os << indent << "DepthImageScalarType: " << this->DepthImageScalarType << "\n";
  os << indent << "ClampDepthToBackface: " << this->ClampDepthToBackface << "\n";
  os << indent << "ColorRangeType: " << this->ColorRangeType << "\n";
  os << indent << "ScalarOpacityRangeType: " << this->ScalarOpacityRangeType << "\n";
  os << indent << "GradientOpacityRangeType: " << this->GradientOpacityRangeType << "\n";
  os << indent << "Transfer2DYAxisArray: "
     << (this->Transfer2DYAxisArray ? this->Transfer2DYAxisArray : "(none)") << "\n";
  os << indent << "EmptySpaceSkipping: " << this->EmptySpaceSkipping << "\n";
  os << indent << "ExtremumDepth: " << this->ExtremumDepth << "\n";
  os << indent << "DistributedSum: " << this->DistributedSum << "\n";
  for (int c = 0; c < 4; ++c)
  {
    if (const auto& range = this->Internals->WholeRanges[c])
    {
      os << indent << "WholeScalarRange " << c << ": " << (*range)[0] << " " << (*range)[1]
         << "\n";
    }
  }
  os << indent << "PreIntegration: " << this->PreIntegration << "\n";
  os << indent << "MidpointQuadrature: " << this->MidpointQuadrature << "\n";
  os << indent << "AdaptiveSampling: " << this->AdaptiveSampling << "\n";
  os << indent << "CubicInterpolation: " << this->CubicInterpolation << "\n";
  os << indent << "WholeExtent: " << this->WholeExtent[0] << " " << this->WholeExtent[1] << " "
     << this->WholeExtent[2] << " " << this->WholeExtent[3] << " " << this->WholeExtent[4] << " "
     << this->WholeExtent[5] << "\n";
  os << indent << "EnvironmentLighting: " << this->EnvironmentLighting << "\n";
  os << indent << "EnvironmentMap: "
     << (this->EnvironmentMap && *this->EnvironmentMap ? this->EnvironmentMap : "(sky)") << "\n";
  os << indent << "EnvironmentUp: " << this->EnvironmentUp[0] << " " << this->EnvironmentUp[1]
     << " " << this->EnvironmentUp[2] << "\n";
  os << indent << "EnvironmentAzimuth: " << this->EnvironmentAzimuth << "\n";
  os << indent << "EnvironmentIntensity: " << this->EnvironmentIntensity << "\n";
  os << indent << "EnvironmentBackground: " << this->EnvironmentBackground << "\n";
  os << indent << "SpecularSampling: "
     << (this->SpecularSampling == SPECULAR_CONE ? "cone" : "importance") << "\n";
  os << indent << "SpecularSamples: " << this->SpecularSamples << "\n";
  os << indent << "AmbientOcclusionSamples: " << this->AmbientOcclusionSamples << "\n";
  os << indent << "AmbientOcclusionSteps: " << this->AmbientOcclusionSteps << "\n";
  os << indent << "AmbientOcclusionRadius: " << this->AmbientOcclusionRadius << "\n";
  os << indent << "ShininessFromGradient: " << this->ShininessFromGradient << "\n";
  os << indent << "ShininessRange: " << this->ShininessRange[0] << " "
     << this->ShininessRange[1] << "\n";
  os << indent << "ShininessGradientRange: " << this->ShininessGradientRange[0] << " "
     << this->ShininessGradientRange[1] << "\n";
  os << indent << "Fresnel: " << this->Fresnel << "\n";
  os << indent << "IsosurfaceLayers: " << this->IsosurfaceLayers << "\n";
  os << indent << "IsosurfaceScattering: " << this->IsosurfaceScattering << "\n";
  os << indent << "IsosurfaceScatteringSamples: " << this->IsosurfaceScatteringSamples << "\n";
  os << indent << "IsosurfaceScatteringAbsorption: " << this->IsosurfaceScatteringAbsorption
     << "\n";
  os << indent << "RenderMode: "
     << (this->RenderMode == RENDER_MODE_PATH_TRACE ? "path trace" : "ray cast") << "\n";
  os << indent << "SamplesPerPixel: " << this->SamplesPerPixel << "\n";
  os << indent << "InteractiveSamplesPerPixel: " << this->InteractiveSamplesPerPixel << "\n";
  os << indent << "PathTracingBounces: " << this->PathTracingBounces << "\n";
  os << indent << "PathTracingDenoise: " << this->PathTracingDenoise << "\n";
  os << indent << "PathTracingDenoiseUntil: " << this->PathTracingDenoiseUntil << "\n";
  os << indent << "ProgressiveMode: "
     << (this->ProgressiveMode == PROGRESSIVE_ON
            ? "on"
            : this->ProgressiveMode == PROGRESSIVE_OFF ? "off" : "automatic")
     << "\n";
  os << indent << "PathTracingTimeBudget: " << this->PathTracingTimeBudget << "\n";
  os << indent << "VolumetricScatteringBlending: " << this->VolumetricScatteringBlending << "\n";
  os << indent << "GlobalIlluminationReach: " << this->GlobalIlluminationReach << "\n";
  os << indent << "SecondaryRays: " << this->SecondaryRays << "\n";
  os << indent << "GradientThreshold: " << this->GradientThreshold << "\n";
  os << indent << "StochasticBlend: " << this->StochasticBlend << "\n";
  os << indent << "ScatterRegions: " << this->ScatterRegions << "\n";
  os << indent << "Attenuation: " << this->Attenuation << "\n";
  os << indent << "BsdfRoughness: " << this->BsdfRoughness << "\n";
  os << indent << "BsdfFresnel: " << this->BsdfFresnel << "\n";
  os << indent << "Transmission: " << this->Transmission << "\n";
  os << indent << "TransmissionConeAngle: " << this->TransmissionConeAngle << "\n";
  os << indent << "LastRenderDrew: " << this->LastRenderDrew << "\n";
  os << indent << "LastRenderProgressive: " << this->LastRenderProgressive << "\n";
  os << indent << "LastRenderSize: " << this->LastRenderSize[0] << " x "
     << this->LastRenderSize[1] << "\n";
  os << indent << "OutputPath: " << this->OutputPath << " (active: " << this->GetOutputPathName()
     << "; " << this->GetOutputPathReason() << ")\n";
  os << indent << "VolumeUploads: " << this->GetVolumeUploadCount() << "\n";
  os << indent << "TableUploads: " << this->GetTableUploadCount() << "\n";
  os << indent << "Frames: " << this->GetFrameCount() << "\n";
  os << indent << "ferrovol: " << GetFerrovolVersion() << "\n";
}
