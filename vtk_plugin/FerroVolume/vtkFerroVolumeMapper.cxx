// vtkFerroVolumeMapper: a vtkGPUVolumeRayCastMapper that ray casts with ferrovol (C ABI,
// ffi/include/ferrovol.h, through the RAII wrapper ferrovol.hpp) and composites the frame into
// VTK's OpenGL framebuffer. The work is split into units, as VTK splits its own GPU mapper:
//   vtkFerroVolumeInputHelper   input → ferrovol volume, only when the scalars (array, MTime,
//                               geometry) changed
//   vtkFerroVolumeLookupTables  property → ferrovol transfer function, only when the property
//                               (or its functions) or the ranges changed
//   vtkFerroVolumeSettings      mapper, property, volume matrix, camera, lights → ferrovol
//                               parameters (every frame, no upload)
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
#include "vtkFerroVolumeMapper.h"

#include "vtkFerroVolumeContext.h"
#include "vtkFerroVolumeDepthPeeling.h"
#include "vtkFerroVolumeDepthReader.h"
#include "vtkFerroVolumeInputHelper.h"
#include "vtkFerroVolumeIntermix.h"
#include "vtkFerroVolumeLookupTables.h"
#include "vtkFerroVolumeOutput.h"
#include "vtkFerroVolumePieceSum.h"
#include "vtkFerroVolumeRefinement.h"
#include "vtkFerroVolumeRenderToImage.h"
#include "vtkFerroVolumeSettings.h"
#include "vtkBoundingBox.h"
#include "vtkCamera.h"
#include "vtkCommand.h"
#include "vtkDataObject.h"
#include "vtkHardwareSelector.h"
#include "vtkInformation.h"
#include "vtkInformationObjectBaseVectorKey.h"
#include "vtkImageData.h"
#include "vtkMatrix4x4.h"
#include "vtkMultiVolume.h"
#include "vtkNew.h"
#include "vtkObjectFactory.h"
#include "vtkOpenGLRenderWindow.h"
#include "vtkPointData.h"
#include "vtkRenderer.h"
#include "vtkTimerLog.h"
#include "vtkUnsignedCharArray.h"
#include "vtkVolume.h"

#include <algorithm>
#include <cmath>
#include <memory>
#include <optional>
#include <set>
#include <string>

vtkStandardNewMacro(vtkFerroVolumeMapper);

//------------------------------------------------------------------------------------------
class vtkFerroVolumeMapper::vtkInternals
{
public:
  std::unique_ptr<ferrovol::Renderer> Renderer;
  // vtkFerroVolumeContext::Generation() when the renderer was made
  unsigned RendererGeneration = 0;
  vtkFerroVolumeInputHelper Input;
  vtkFerroVolumeLookupTables Tables;
  vtkFerroVolumeIntermix Intermix;
  vtkFerroVolumeSettings Settings;
  vtkFerroVolumeOutput Output;
  vtkFerroVolumeDepthPeeling Peeling;
  vtkFerroVolumeRenderToImage Image;
  vtkFerroVolumeRefinement Refinement;
  vtkFerroVolumePieceSum PieceSum;
  vtkFerroVolumeInputHelper::WholeRanges WholeRanges{};
  // warnings said once per mapper
  std::set<std::string> Warned;
  // the convergence read back for the frame counted `ConvergenceFrame` (stats().frames)
  std::optional<FvConvergence> Convergence;
  uint32_t ConvergenceFrame = 0;

  ~vtkInternals() { this->FreeRenderer(); }

  // The renderer, created on first use from the process-wide device; the passes of a
  // streamed frame (a volume over the memory budget) report to `self`'s progress.
  // Whether the renderer was made on a device since lost.
  bool RendererLost() const
  {
    return this->Renderer && this->RendererGeneration != vtkFerroVolumeContext::Generation();
  }

  // A renderer made on a device since lost is made again (with its input and tables).
  bool MakeRenderer(vtkFerroVolumeMapper* self, std::string& error)
  {
    if (this->Renderer && !this->RendererLost())
    {
      return true;
    }
    this->FreeRenderer();
    const ferrovol::Context* ctx = vtkFerroVolumeContext::Acquire(error);
    this->RendererGeneration = vtkFerroVolumeContext::Generation();
    return ctx && vtkFerroVolumeCall("create a renderer", error, [&] {
      this->Renderer.reset(new ferrovol::Renderer(*ctx));
      this->Renderer->set_progress(&vtkInternals::StreamProgress, self);
    });
  }

  // Each pass of a streamed frame is a ProgressEvent while ReportProgress is on.
  static void StreamProgress(void* mapper, uint32_t done, uint32_t total)
  {
    vtkFerroVolumeMapper* self = static_cast<vtkFerroVolumeMapper*>(mapper);
    if (self->GetReportProgress())
    {
      self->UpdateProgress(static_cast<double>(done) / static_cast<double>(total));
    }
  }

  // The input selected and uploaded (on change) within the mapper's memory budget, the
  // property's tables (on change) and the volumes of `multi`'s other ports (none: cleared);
  // false with the reason.
  bool Prepare(
    vtkFerroVolumeMapper* self, vtkVolume* vol, vtkMultiVolume* multi, std::string& error)
  {
    const vtkIdType bytes = self->GetMaxMemoryInBytes();
    const uint64_t budget = bytes > 0
      ? static_cast<uint64_t>(static_cast<double>(bytes) * self->GetMaxMemoryFraction())
      : 0;
    vtkFerroVolumeLookupTables::RangeTypes types;
    types.Color = self->GetColorRangeType();
    types.ScalarOpacity = self->GetScalarOpacityRangeType();
    types.GradientOpacity = self->GetGradientOpacityRangeType();
    this->Input.SetWholeRanges(this->WholeRanges);
    if (!(this->Input.Select(self, error) && this->MakeRenderer(self, error) &&
          this->Input.Upload(*this->Renderer, budget, error)))
    {
      return false;
    }
    std::string blanking;
    if (!this->Input.UpdateBlanking(*this->Renderer, blanking) && this->FirstTime("blanking"))
    {
      vtkWarningWithObjectMacro(
        self, << "the ghost arrays' blanking is not applied (the cells are drawn): " << blanking);
    }
    if (!this->Input.UpdateMask(
          self->GetMaskInput(), self->GetMaskType(), *this->Renderer, error))
    {
      error = "MaskInput: " + error;
      return false;
    }
    return this->Tables.Update(vol, this->Input, types, *this->Renderer, error) &&
      this->Intermix.Update(self, multi, types, *this->Renderer, error);
  }

  // A warning said once per mapper for `key`.
  bool FirstTime(const std::string& key) { return this->Warned.insert(key).second; }

  void FreeRenderer()
  {
    this->Renderer.reset();
    this->Input.Reset();
    this->Tables.Reset();
    this->Intermix.Reset();
    this->Settings.Reset();
    this->Convergence.reset();
  }

  // The output's images in `window` and RenderToImage's, all made from the renderer's
  // device.
  void ReleaseWindowResources(vtkWindow* window)
  {
    this->Output.ReleaseGraphicsResources(window);
    this->Peeling.ReleaseGraphicsResources(window);
    this->Image.ReleaseGraphicsResources();
  }

  // Those and the renderer.
  void ReleaseDeviceResources(vtkWindow* window)
  {
    this->ReleaseWindowResources(window);
    this->FreeRenderer();
  }

  // The renderer's counters; false before the first frame.
  bool Stats(FvStats& s) const
  {
    if (!this->Renderer)
    {
      return false;
    }
    try
    {
      s = this->Renderer->stats();
      return true;
    }
    catch (const ferrovol::Error&)
    {
      return false;
    }
  }

  // The path tracer's convergence, read back once per frame; false before the first frame.
  bool ReadConvergence(FvConvergence& c)
  {
    FvStats s;
    if (!this->Stats(s))
    {
      return false;
    }
    try
    {
      if (!this->Convergence || this->ConvergenceFrame != s.frames)
      {
        this->Convergence = this->Renderer->convergence();
        this->ConvergenceFrame = s.frames;
      }
      c = *this->Convergence;
      return true;
    }
    catch (const ferrovol::Error&)
    {
      return false;
    }
  }
};

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
  , Internals(new vtkInternals)
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
  if (!this->Internals->Renderer)
  {
    return -1;
  }
  try
  {
    return static_cast<int>(this->Internals->Renderer->accumulated_samples());
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
  std::string error;
  return vtkFerroVolumeContext::Acquire(error) ? 1 : 0;
}

void vtkFerroVolumeMapper::GetReductionRatio(double ratio[3])
{
  ratio[0] = ratio[1] = ratio[2] = 1.0;
}

bool vtkFerroVolumeMapper::PreLoadData(vtkRenderer* vtkNotUsed(ren), vtkVolume* vol)
{
  std::string error;
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
  if (!this->Internals->Prepare(this, main, multi, error))
  {
    vtkErrorMacro(<< error);
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
  if (texture && this->Internals->FirstTime("shared-depth-texture"))
  {
    vtkWarningMacro(<< "SetSharedDepthTexture is not supported by ferrovol, which reads VTK's "
                       "depth buffer itself: the texture is not used");
  }
}

void vtkFerroVolumeMapper::SetPartitions(unsigned short x, unsigned short y, unsigned short z)
{
  if ((x != 1 || y != 1 || z != 1) && this->Internals->FirstTime("partitions"))
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
void vtkFerroVolumeMapper::Render(vtkRenderer* ren, vtkVolume* vol)
{
  if (this->GeneratingCanonicalView)
  {
    this->GPURender(ren, vol);
    return;
  }
  this->InvokeEvent(vtkCommand::VolumeMapperRenderStartEvent, nullptr);
  vtkNew<vtkTimerLog> timer;
  timer->StartTimer();
  // (the same on every process of a parallel render: the sum is a collective operation)
  this->Internals->PieceSum.Begin(this->SumsPieces() && ren && vol && !ren->GetSelector() &&
    !this->RenderToImage && !vtkFerroVolumeDepthPeeling::PeelingPass(vol));
  this->GPURender(ren, vol);
  this->Internals->PieceSum.Finish();
  timer->StopTimer();
  this->TimeToDraw = timer->GetElapsedTime();
  (vol->GetAllocatedRenderTime() < 1.0 ? this->SmallTimeToDraw : this->BigTimeToDraw) =
    this->TimeToDraw;
  this->InvokeEvent(vtkCommand::VolumeMapperRenderEndEvent, nullptr);
}

namespace
{
// A hardware-selection pass of `selector` over `image` (placed by `vol`): what
// vtkGPUVolumeRayCastMapper writes, where the frame shows the volume (vtkFerroVolumeSelection).
bool DrawSelection(vtkFerroVolumeOutput& output, vtkRenderer* ren, vtkVolume* vol,
  vtkImageData* image, vtkHardwareSelector* selector, const vtkFerroVolumeFrameRequest& req,
  const int rect[4], std::string& error)
{
  vtkFerroVolumeSelection select;
  switch (selector->GetCurrentPass())
  {
    case vtkHardwareSelector::CELL_ID_LOW24:
      select.What = vtkFerroVolumeSelection::Write::PointLow24;
      break;
    case vtkHardwareSelector::CELL_ID_HIGH24:
      select.What = vtkFerroVolumeSelection::Write::PointHigh24;
      break;
    default:
      select.What = vtkFerroVolumeSelection::Write::Prop;
      break;
  }
  // device coordinates → world → the point index relative to the extent's first point
  vtkNew<vtkMatrix4x4> deviceToWorld;
  deviceToWorld->DeepCopy(ren->GetActiveCamera()->GetCompositeProjectionTransformMatrix(
    static_cast<double>(req.ViewportW) / req.ViewportH, -1, 1));
  deviceToWorld->Invert();
  const int* extent = image->GetExtent();
  vtkNew<vtkMatrix4x4> fromExtent;
  for (int k = 0; k < 3; ++k)
  {
    fromExtent->SetElement(k, 3, extent[2 * k]);
  }
  vtkNew<vtkMatrix4x4> indexToWorld;
  vtkMatrix4x4::Multiply4x4(vol->GetMatrix(), image->GetIndexToPhysicalMatrix(), indexToWorld);
  vtkMatrix4x4::Multiply4x4(indexToWorld, fromExtent, indexToWorld);
  indexToWorld->Invert();
  vtkNew<vtkMatrix4x4> deviceToIndex;
  vtkMatrix4x4::Multiply4x4(indexToWorld, deviceToWorld, deviceToIndex);
  select.DeviceToIndex = deviceToIndex;
  image->GetDimensions(select.Dims);
  selector->BeginRenderProp();
  selector->GetPropColorValue(select.PropColor);
  const bool drawn = output.Select(req, rect, select, error) != vtkFerroVolumeOutput::Composited::Failed;
  const vtkIdType points =
    static_cast<vtkIdType>(select.Dims[0]) * select.Dims[1] * select.Dims[2];
  selector->UpdateMaximumPointId(points);
  selector->UpdateMaximumCellId(points);
  selector->EndRenderProp();
  return drawn;
}
}

//------------------------------------------------------------------------------------------
void vtkFerroVolumeMapper::GPURender(vtkRenderer* ren, vtkVolume* vol)
{
  this->LastRenderDrew = 0;
  this->LastRenderProgressive = 0;
  vtkInternals* in = this->Internals;
  in->Refinement.Begin();
  if (!ren || !vol)
  {
    return;
  }
  // Hardware selection: cell selections, as vtkGPUVolumeRayCastMapper (other associations
  // leave the volume out).
  vtkHardwareSelector* selector = ren->GetSelector();
  if (selector && selector->GetFieldAssociation() != vtkDataObject::FIELD_ASSOCIATION_CELLS)
  {
    return;
  }
  // Inside vtkDualDepthPeelingPass's volumetric peels: the volume between its layers.
  vtkRenderPass* peeling = vtkFerroVolumeDepthPeeling::PeelingPass(vol);
  if (peeling &&
    (this->RenderMode == RENDER_MODE_PATH_TRACE || this->BlendMode == ISOSURFACE_BLEND ||
      this->BlendMode == SLICE_BLEND))
  {
    if (in->FirstTime("depth-peeling"))
    {
      vtkWarningMacro(<< "depth peeling for volumes (vtkRenderer UseDepthPeelingForVolumes "
                         "with translucent geometry) draws ray-cast volumes between the "
                         "translucent layers; path tracing, isosurfaces and slices are not "
                         "drawn there: turn UseDepthPeelingForVolumes off to have this volume "
                         "composited over the translucent geometry (in ParaView: the render "
                         "view's DepthPeelingForVolumes, on by default)");
    }
    return;
  }
  vtkOpenGLRenderWindow* win = vtkOpenGLRenderWindow::SafeDownCast(ren->GetRenderWindow());
  if (!win)
  {
    vtkErrorMacro(<< "vtkFerroVolumeMapper needs an OpenGL render window (vtkOpenGLRenderWindow)");
    return;
  }

  // After a device loss the output's images (imported from the lost device) go with the
  // renderer; both are made again below.
  if (in->RendererLost())
  {
    in->ReleaseDeviceResources(win);
  }

  // A vtkMultiVolume (vtkGPUVolumeRayCastMapper's several inputs): port 0's vtkVolume
  // places and classifies the main volume, the other ports' volumes are intermixed with it;
  // the multi-volume itself gives the box of them all.
  vtkMultiVolume* multi = vtkMultiVolume::SafeDownCast(vol);
  vtkVolume* main = multi ? multi->GetVolume(0) : vol;
  if (!main)
  {
    vtkErrorMacro(<< "the vtkMultiVolume has no vtkVolume on port 0 (SetVolume(volume, 0))");
    return;
  }

  // Blend mode, input, volume (on change), tables (on change), frame parameters.
  std::string error;
  if (!in->Settings.SelectBlendMode(this, error) || !in->Prepare(this, main, multi, error))
  {
    vtkErrorMacro(<< error);
    return;
  }
  vtkImageData* image = in->Input.GetImage();
  // GetTransformedInput and GetBoundsFromPort see the input, as after the base class's
  // validation.
  this->CloneInput(image, 0);
  // Progressive path tracing: what is left of the render's budget for the tracing.
  const bool pathTrace = this->RenderMode == RENDER_MODE_PATH_TRACE;
  const bool progressive = pathTrace && in->Refinement.IsProgressive(this->ProgressiveMode, win);
  if (!progressive)
  {
    in->Refinement.Stop();
  }
  // The preview is denoised while the accumulation is short of PathTracingDenoiseUntil, as
  // it is after a change (which interactive renders usually follow).
  const uint32_t denoiseUntil = vtkFerroVolumeSettings::DenoiseUntil(this);
  double traceBudget = 0.0;
  // (restarts of the accumulation before this render: the refinement stops when the renders
  // it asks for keep starting over)
  FvStats statsBefore{};
  if (progressive && !in->Stats(statsBefore))
  {
    vtkErrorMacro(<< "the renderer's counters are unavailable: " << fv_last_error());
    return;
  }
  if (progressive)
  {
    uint32_t before = 0;
    if (!vtkFerroVolumeCall("count the accumulated paths", error,
          [&] { before = in->Renderer->accumulated_samples(); }))
    {
      vtkErrorMacro(<< error);
      return;
    }
    const bool denoised = this->PathTracingDenoise ||
      (denoiseUntil > 0 && (before < denoiseUntil || win->GetDesiredUpdateRate() > 1.0));
    traceBudget = in->Refinement.TraceBudget(
      vtkFerroVolumeRefinement::FrameBudget(this->PathTracingTimeBudget, win), denoised);
  }
  in->Settings.SetIntermixing(multi != nullptr);
  switch (
    in->Settings.Apply(this, ren, main, in->Input, *in->Renderer, traceBudget, in->Warned, error))
  {
    case vtkFerroVolumeSettings::Result::Failed:
      vtkErrorMacro(<< error);
      return;
    case vtkFerroVolumeSettings::Result::NothingVisible:
      return;
    case vtkFerroVolumeSettings::Result::Ready:
      break;
  }

  // Camera and lights for this viewport.
  vtkFerroVolumeFrameRequest req;
  req.Window = win;
  ren->GetTiledSizeAndOrigin(&req.ViewportW, &req.ViewportH, &req.ViewportX, &req.ViewportY);
  if (req.ViewportW < 1 || req.ViewportH < 1)
  {
    return;
  }
  if (!in->Settings.ApplyView(
        this, ren, req.ViewportW, req.ViewportH, *in->Renderer, in->Warned, error))
  {
    vtkErrorMacro(<< error);
    return;
  }

  // Render at the resolution ImageSampleDistance reduces the viewport to (whether
  // AutoAdjustSampleDistances is on or off, as VTK 9.2), through the output path.
  req.RenderW = std::max(1, static_cast<int>(req.ViewportW / this->ImageSampleDistance));
  req.RenderH = std::max(1, static_cast<int>(req.ViewportH / this->ImageSampleDistance));
  req.UseDepth = vtkFerroVolumeDepthReader::SceneHasOpaqueGeometry(ren, vol);
  req.ColorScale = 1.0f / this->FinalColorWindow;
  req.ColorBias = 0.5f - this->FinalColorLevel / this->FinalColorWindow;
  if (peeling && !selector && !this->RenderToImage)
  {
    if (!in->Peeling.Draw(peeling, this, vol, *in->Renderer, req, error))
    {
      vtkErrorMacro(<< error);
      return;
    }
    this->LastRenderSize[0] = req.RenderW;
    this->LastRenderSize[1] = req.RenderH;
    this->LastRenderDrew = 1;
    return;
  }
  std::string warning;
  // (a frame summed across processes is read back, and the sum written into its texture)
  const int outputPath = in->PieceSum.Pending() ? OUTPUT_PATH_READBACK : this->OutputPath;
  if (!in->Output.Render(this, outputPath, *in->Renderer, req, error, warning))
  {
    vtkErrorMacro(<< error);
    return;
  }
  if (!warning.empty() && in->Warned.insert(warning).second)
  {
    vtkWarningMacro(<< warning);
  }
  bool draw = true;
  std::string sumMessage;
  if (!in->PieceSum.Add(
        in->Output.ColorTexture(), req.RenderW, req.RenderH, draw, sumMessage))
  {
    vtkErrorMacro(<< sumMessage);
    return;
  }
  if (!sumMessage.empty() && in->Warned.insert(sumMessage).second)
  {
    vtkWarningMacro(<< sumMessage);
  }
  this->LastRenderSize[0] = req.RenderW;
  this->LastRenderSize[1] = req.RenderH;
  if (!draw)
  {
    this->LastRenderDrew = 1; // another process draws the sum this frame joined
    return;
  }

  // The part of the viewport the volume can cover (where the frame is composited).
  int rect[4] = { 0, 0, req.ViewportW, req.ViewportH };
  if (!in->Settings.CoversViewport())
  {
    const double* spacing = image->GetSpacing();
    const double pad = vtkFerroVolumeLookupTables::MatrixScale(vol) *
      std::max({ std::fabs(spacing[0]), std::fabs(spacing[1]), std::fabs(spacing[2]) });
    vtkFerroVolumeOutput::ProjectedRect(ren, vol, pad, req.ViewportW, req.ViewportH, rect);
  }
  if (selector)
  {
    if (!DrawSelection(in->Output, ren, main, image, selector, req, rect, error))
    {
      vtkErrorMacro(<< error);
      return;
    }
    this->LastRenderDrew = 1;
    return;
  }
  if (this->RenderToImage)
  {
    // The frame goes into the images, not the window.
    int depthType = this->DepthImageScalarType;
    if (!vtkFerroVolumeRenderToImage::IsDepthType(depthType))
    {
      if (in->FirstTime("depth-image-type"))
      {
        vtkWarningMacro(<< "DepthImageScalarType " << depthType
                        << " is not supported (unsigned char, unsigned short and float are): "
                           "the depth image is float");
      }
      depthType = VTK_FLOAT;
    }
    vtkNew<vtkMatrix4x4> boxToClip;
    vtkFerroVolumeRenderToImage::BoxToClip(ren, main, image, boxToClip);
    if (!in->Image.Capture(req, in->Output.ColorTexture(), in->Output.DepthTexture(), depthType,
          boxToClip, this->ClampDepthToBackface != 0, error))
    {
      vtkErrorMacro(<< error);
      return;
    }
  }
  else
  {
    switch (in->Output.Composite(req, rect, error))
    {
      case vtkFerroVolumeOutput::Composited::Failed:
        vtkErrorMacro(<< error);
        return;
      case vtkFerroVolumeOutput::Composited::OffScreen:
        this->LastRenderDrew = 1; // nothing to composite
        return;
      case vtkFerroVolumeOutput::Composited::Drawn:
        break;
    }
    if (this->GeneratingCanonicalView && this->CanonicalViewImageData)
    {
      // CreateCanonicalView: the window as drawn so far (its other props are hidden).
      int dims[3];
      this->CanonicalViewImageData->GetDimensions(dims);
      vtkUnsignedCharArray* pixels = vtkUnsignedCharArray::SafeDownCast(
        this->CanonicalViewImageData->GetPointData()->GetScalars());
      if (pixels && pixels->GetNumberOfComponents() == 3)
      {
        win->GetPixelData(0, 0, dims[0] - 1, dims[1] - 1, 0, pixels, 0);
      }
    }
  }
  this->LastRenderDrew = 1;
  if (progressive)
  {
    // Refine while the accumulation is short of SamplesPerPixel.
    uint32_t samples = 0;
    if (!vtkFerroVolumeCall("count the accumulated paths", error,
          [&] { samples = in->Renderer->accumulated_samples(); }))
    {
      vtkErrorMacro(<< error);
      in->Refinement.Stop();
      return;
    }
    const uint32_t target = static_cast<uint32_t>(this->SamplesPerPixel);
    in->Refinement.End(samples < target, this->PathTracingDenoise || samples < denoiseUntil,
      req.RenderW, req.RenderH);
    FvStats statsAfter{};
    const bool restarted =
      !in->Stats(statsAfter) || statsAfter.accumulation_restarts != statsBefore.accumulation_restarts;
    if (!in->Refinement.Continue(win, samples, target, restarted) &&
      in->Warned.insert("restarts").second)
    {
      vtkWarningMacro(<< "path tracing starts over at every render (something the image "
                         "depends on changes each time, such as opaque geometry moved on "
                         "every render), so the view stops refining itself at "
                      << samples
                      << " paths per pixel; render with ProgressiveModeToOff for "
                         "SamplesPerPixel paths");
    }
    this->LastRenderProgressive = 1;
  }
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
