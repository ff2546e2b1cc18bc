#include "vtkFerroVolumeRepresentation.h"

#include "vtkCellData.h"
#include "vtkColorTransferFunction.h"
#include "vtkCommunicator.h"
#include "vtkDataArray.h"
#include "vtkDataSetAttributes.h"
#include "vtkDoubleArray.h"
#include "vtkFerroVolumeMapper.h"
#include "vtkFloatArray.h"
#include "vtkImageData.h"
#include "vtkInformation.h"
#include "vtkInformationVector.h"
#include "vtkMultiProcessController.h"
#include "vtkMultiProcessStream.h"
#include "vtkObjectFactory.h"
#include "vtkPiecewiseFunction.h"
#include "vtkPVLODVolume.h"
#include "vtkPVRenderView.h"
#include "vtkPVView.h"
#include "vtkPointData.h"
#include "vtkRenderWindow.h"
#include "vtkScalarsToColors.h"
#include "vtkTrivialProducer.h"
#include "vtkVolumeMapper.h"
#include "vtkVolumeProperty.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>
#include <vector>

vtkStandardNewMacro(vtkFerroVolumeRepresentation);

namespace
{
// vtkVolumeMapper::BlendModes as ParaView's panel names them; nullptr for other values.
const char* BlendModeName(int mode)
{
  switch (mode)
  {
    case vtkVolumeMapper::COMPOSITE_BLEND:
      return "Composite";
    case vtkVolumeMapper::MAXIMUM_INTENSITY_BLEND:
      return "Maximum Intensity";
    case vtkVolumeMapper::MINIMUM_INTENSITY_BLEND:
      return "Minimum Intensity";
    case vtkVolumeMapper::AVERAGE_INTENSITY_BLEND:
      return "Average Intensity";
    case vtkVolumeMapper::ADDITIVE_BLEND:
      return "Additive";
    case vtkVolumeMapper::ISOSURFACE_BLEND:
      return "Isosurface";
    case vtkVolumeMapper::SLICE_BLEND:
      return "Slice";
    default:
      return nullptr;
  }
}

// A blend mode for a message: its name in quotes, or its number.
std::string QuotedBlendMode(int mode)
{
  const char* name = BlendModeName(mode);
  return name ? "\"" + std::string(name) + "\"" : std::to_string(mode);
}

// "Volume Rendering Mode" (vtkSmartVolumeMapper's requested render modes) as ParaView's
// UniformGridVolumeRepresentation XML names them.
std::string RenderModeName(int mode)
{
  static const char* const names[] = { "Smart", "Ray Cast Only", "GPU Based", "OSPRay Based" };
  return mode >= 0 && mode < 4 ? "\"" + std::string(names[mode]) + "\"" : std::to_string(mode);
}
}

//------------------------------------------------------------------------------------------
vtkFerroVolumeRepresentation::vtkFerroVolumeRepresentation()
{
  // The superclass made a vtkMultiBlockVolumeMapper; nothing has used it yet.
  this->VolumeMapper = vtkSmartPointer<vtkFerroVolumeMapper>::New();
}

//------------------------------------------------------------------------------------------
vtkFerroVolumeRepresentation::~vtkFerroVolumeRepresentation() = default;

//------------------------------------------------------------------------------------------
vtkFerroVolumeMapper* vtkFerroVolumeRepresentation::GetFerroVolumeMapper()
{
  return vtkFerroVolumeMapper::SafeDownCast(this->VolumeMapper);
}

//------------------------------------------------------------------------------------------
void vtkFerroVolumeRepresentation::SetFerrovolBlendMode(int mode)
{
  if (mode != FOLLOW_BLEND_MODE &&
    (mode < vtkVolumeMapper::COMPOSITE_BLEND || mode > vtkVolumeMapper::ISOSURFACE_BLEND))
  {
    vtkErrorMacro(<< "FerrovolBlendMode " << mode
                  << " is not one of follow Blend Mode (-1), composite (0), maximum (1), "
                     "minimum (2), average (3), additive (4) or isosurface (5); keeping "
                  << this->FerrovolBlendMode << ".");
    return;
  }
  this->FerrovolBlendMode = mode;
}

//------------------------------------------------------------------------------------------
void vtkFerroVolumeRepresentation::SetBlendMode(int mode)
{
  this->SharedBlendMode = mode;
}

//------------------------------------------------------------------------------------------
void vtkFerroVolumeRepresentation::SetRequestedRenderMode(int mode)
{
  this->RequestedRenderMode = mode;
}

//------------------------------------------------------------------------------------------
int vtkFerroVolumeRepresentation::DrawnBlendMode() const
{
  return this->FerrovolBlendMode == FOLLOW_BLEND_MODE ? this->SharedBlendMode
                                                      : this->FerrovolBlendMode;
}

//------------------------------------------------------------------------------------------
void vtkFerroVolumeRepresentation::SetAutoAdjustSampleDistances(int value)
{
  this->AutoSampleDistance = value != 0;
  this->UpdateSampleDistanceMode();
}

//------------------------------------------------------------------------------------------
void vtkFerroVolumeRepresentation::UpdateSampleDistanceMode()
{
  // A 2D transfer function's opacities are per sample (as VTK reads them), so its image
  // depends on the sample distance: Auto Sample Distance then takes the distance ParaView's
  // Volume takes (vtkSmartVolumeMapper's default, locked to the input's spacing).
  vtkFerroVolumeMapper* mapper = this->GetFerroVolumeMapper();
  const bool lock = this->UseTransfer2D && this->AutoSampleDistance;
  mapper->SetAutoAdjustSampleDistances(this->AutoSampleDistance && !lock);
  mapper->SetLockSampleDistanceToInputSpacing(lock);
}

//------------------------------------------------------------------------------------------
void vtkFerroVolumeRepresentation::SetSampleDistance(double value)
{
  if (!(value > 0.0))
  {
    vtkErrorMacro(<< "SampleDistance must be positive (got " << value << ").");
    return;
  }
  this->GetFerroVolumeMapper()->SetSampleDistance(static_cast<float>(value));
}

//------------------------------------------------------------------------------------------
void vtkFerroVolumeRepresentation::SetImageSampleDistance(double value)
{
  this->GetFerroVolumeMapper()->SetImageSampleDistance(static_cast<float>(value));
}

//------------------------------------------------------------------------------------------
void vtkFerroVolumeRepresentation::SetUseJittering(int value)
{
  this->GetFerroVolumeMapper()->SetUseJittering(value != 0);
}

//------------------------------------------------------------------------------------------
void vtkFerroVolumeRepresentation::SetEmptySpaceSkipping(int value)
{
  this->GetFerroVolumeMapper()->SetEmptySpaceSkipping(value != 0);
}

//------------------------------------------------------------------------------------------
void vtkFerroVolumeRepresentation::SetPreIntegration(int value)
{
  this->GetFerroVolumeMapper()->SetPreIntegration(value != 0);
}

void vtkFerroVolumeRepresentation::SetMidpointQuadrature(int value)
{
  this->GetFerroVolumeMapper()->SetMidpointQuadrature(value != 0);
}

void vtkFerroVolumeRepresentation::SetAdaptiveSampling(int value)
{
  this->GetFerroVolumeMapper()->SetAdaptiveSampling(value != 0);
}

void vtkFerroVolumeRepresentation::SetCubicInterpolation(int value)
{
  this->GetFerroVolumeMapper()->SetCubicInterpolation(value != 0);
}

//------------------------------------------------------------------------------------------
void vtkFerroVolumeRepresentation::SetMaxMemoryInBytes(vtkIdType value)
{
  this->GetFerroVolumeMapper()->SetMaxMemoryInBytes(value);
}

//------------------------------------------------------------------------------------------
void vtkFerroVolumeRepresentation::SetMaxMemoryFraction(double value)
{
  this->GetFerroVolumeMapper()->SetMaxMemoryFraction(static_cast<float>(value));
}

//------------------------------------------------------------------------------------------
// Isosurface settings: straight to the mapper, which clamps and documents them.
void vtkFerroVolumeRepresentation::SetEnvironmentLighting(double value)
{
  this->GetFerroVolumeMapper()->SetEnvironmentLighting(value);
}

void vtkFerroVolumeRepresentation::SetEnvironmentMap(const char* path)
{
  this->GetFerroVolumeMapper()->SetEnvironmentMap(path);
}

void vtkFerroVolumeRepresentation::SetEnvironmentBackground(int value)
{
  this->GetFerroVolumeMapper()->SetEnvironmentBackground(value != 0);
}

void vtkFerroVolumeRepresentation::SetSpecularSampling(int mode)
{
  this->GetFerroVolumeMapper()->SetSpecularSampling(mode);
}

void vtkFerroVolumeRepresentation::SetSpecularSamples(int samples)
{
  this->GetFerroVolumeMapper()->SetSpecularSamples(samples);
}

void vtkFerroVolumeRepresentation::SetAmbientOcclusionSamples(int samples)
{
  this->GetFerroVolumeMapper()->SetAmbientOcclusionSamples(samples);
}

void vtkFerroVolumeRepresentation::SetAmbientOcclusionRadius(double radius)
{
  this->GetFerroVolumeMapper()->SetAmbientOcclusionRadius(radius);
}

void vtkFerroVolumeRepresentation::SetShininessFromGradient(int value)
{
  this->GetFerroVolumeMapper()->SetShininessFromGradient(value != 0);
}

void vtkFerroVolumeRepresentation::SetShininessRange(double weak, double strong)
{
  this->GetFerroVolumeMapper()->SetShininessRange(weak, strong);
}

void vtkFerroVolumeRepresentation::SetFresnel(double reflectance)
{
  this->GetFerroVolumeMapper()->SetFresnel(reflectance);
}

void vtkFerroVolumeRepresentation::SetIsosurfaceScattering(int value)
{
  this->GetFerroVolumeMapper()->SetIsosurfaceScattering(value);
}

void vtkFerroVolumeRepresentation::SetIsosurfaceScatteringSamples(int value)
{
  this->GetFerroVolumeMapper()->SetIsosurfaceScatteringSamples(value);
}

void vtkFerroVolumeRepresentation::SetIsosurfaceScatteringAbsorption(double value)
{
  this->GetFerroVolumeMapper()->SetIsosurfaceScatteringAbsorption(value);
}

void vtkFerroVolumeRepresentation::SetGlobalIlluminationReach(float reach)
{
  this->Superclass::SetGlobalIlluminationReach(reach);
  this->GetFerroVolumeMapper()->SetGlobalIlluminationReach(reach);
}

void vtkFerroVolumeRepresentation::SetVolumetricScatteringBlending(float blending)
{
  this->Superclass::SetVolumetricScatteringBlending(blending);
  this->GetFerroVolumeMapper()->SetVolumetricScatteringBlending(blending);
}

void vtkFerroVolumeRepresentation::SetRenderMode(int mode)
{
  this->GetFerroVolumeMapper()->SetRenderMode(mode);
}

void vtkFerroVolumeRepresentation::SetSamplesPerPixel(int samples)
{
  this->GetFerroVolumeMapper()->SetSamplesPerPixel(samples);
}

void vtkFerroVolumeRepresentation::SetPathTracingBounces(int bounces)
{
  this->GetFerroVolumeMapper()->SetPathTracingBounces(bounces);
}

void vtkFerroVolumeRepresentation::SetPathTracingDenoise(int denoise)
{
  this->GetFerroVolumeMapper()->SetPathTracingDenoise(denoise);
}

void vtkFerroVolumeRepresentation::SetPathTracingDenoiseUntil(int paths)
{
  this->GetFerroVolumeMapper()->SetPathTracingDenoiseUntil(paths);
}

void vtkFerroVolumeRepresentation::SetPathTracingTimeBudget(double seconds)
{
  this->GetFerroVolumeMapper()->SetPathTracingTimeBudget(seconds);
}

void vtkFerroVolumeRepresentation::SetProgressiveMode(int mode)
{
  this->ProgressiveMode = mode;
  this->GetFerroVolumeMapper()->SetProgressiveMode(mode);
}

void vtkFerroVolumeRepresentation::SetSecondaryRays(int value)
{
  this->GetFerroVolumeMapper()->SetSecondaryRays(value);
}

void vtkFerroVolumeRepresentation::SetGradientThreshold(double value)
{
  this->GetFerroVolumeMapper()->SetGradientThreshold(value);
}

void vtkFerroVolumeRepresentation::SetStochasticBlend(double value)
{
  this->GetFerroVolumeMapper()->SetStochasticBlend(value);
}

void vtkFerroVolumeRepresentation::SetScatterRegions(int value)
{
  this->GetFerroVolumeMapper()->SetScatterRegions(value);
}

void vtkFerroVolumeRepresentation::SetAttenuation(int value)
{
  this->GetFerroVolumeMapper()->SetAttenuation(value);
}

void vtkFerroVolumeRepresentation::SetBsdfRoughness(double value)
{
  this->GetFerroVolumeMapper()->SetBsdfRoughness(value);
}

void vtkFerroVolumeRepresentation::SetBsdfFresnel(double value)
{
  this->GetFerroVolumeMapper()->SetBsdfFresnel(value);
}

void vtkFerroVolumeRepresentation::SetTransmission(double value)
{
  this->GetFerroVolumeMapper()->SetTransmission(value);
}

void vtkFerroVolumeRepresentation::SetTransmissionConeAngle(double value)
{
  this->GetFerroVolumeMapper()->SetTransmissionConeAngle(value);
}

//------------------------------------------------------------------------------------------
const char* vtkFerroVolumeRepresentation::GetFerrovolVersion()
{
  return vtkFerroVolumeMapper::GetFerrovolVersion();
}

//------------------------------------------------------------------------------------------
const char* vtkFerroVolumeRepresentation::GetFerrovolAdapter()
{
  const char* adapter = vtkFerroVolumeMapper::GetAdapterDescription();
  this->Adapter = adapter ? adapter : "";
  return this->Adapter.c_str();
}

//------------------------------------------------------------------------------------------
const char* vtkFerroVolumeRepresentation::GetFerrovolOutputPath()
{
  const char* path = this->GetFerroVolumeMapper()->GetOutputPathName();
  this->OutputPath = path ? path : "";
  return this->OutputPath.c_str();
}

//------------------------------------------------------------------------------------------
int vtkFerroVolumeRepresentation::GetFerrovolLastRenderDrew()
{
  return this->GetFerroVolumeMapper()->GetLastRenderDrew() ? 1 : 0;
}

//------------------------------------------------------------------------------------------
int* vtkFerroVolumeRepresentation::GetFerrovolLastRenderSize()
{
  this->GetFerroVolumeMapper()->GetLastRenderSize(this->LastRenderSize);
  return this->LastRenderSize;
}

//------------------------------------------------------------------------------------------
int vtkFerroVolumeRepresentation::GetFerrovolVolumeUploadCount()
{
  return this->GetFerroVolumeMapper()->GetVolumeUploadCount();
}

//------------------------------------------------------------------------------------------
int vtkFerroVolumeRepresentation::GetFerrovolTableUploadCount()
{
  return this->GetFerroVolumeMapper()->GetTableUploadCount();
}

//------------------------------------------------------------------------------------------
int vtkFerroVolumeRepresentation::GetFerrovolAccumulatedSamples()
{
  return this->GetFerroVolumeMapper()->GetAccumulatedSamples();
}

double vtkFerroVolumeRepresentation::GetFerrovolMeanAccumulatedSamples()
{
  return this->GetFerroVolumeMapper()->GetMeanAccumulatedSamples();
}

double vtkFerroVolumeRepresentation::GetFerrovolPathTracingError()
{
  return this->GetFerroVolumeMapper()->GetPathTracingError();
}

//------------------------------------------------------------------------------------------
int vtkFerroVolumeRepresentation::RequestData(
  vtkInformation* request, vtkInformationVector** inputVector, vtkInformationVector* outputVector)
{
  const int result = this->Superclass::RequestData(request, inputVector, outputVector);
  this->GatherWholeRanges();

  // Without input (a client or render server in client/server mode) only the outline shows.
  const bool hasInput = inputVector[0]->GetNumberOfInformationObjects() == 1;
  const bool wasImage = this->InputIsImageData;
  this->InputIsImageData = !hasInput || vtkImageData::SafeDownCast(this->Cache) != nullptr;
  if (!this->InputIsImageData && wasImage)
  {
    vtkWarningMacro(<< "\"Ferrovol Volume\" renders vtkImageData only; this input is "
                    << (this->Cache ? this->Cache->GetClassName() : "empty")
                    << ". Use the \"Volume\" representation, or resample the data to an image "
                       "(Resample To Image) first.");
  }
  return result;
}

//------------------------------------------------------------------------------------------
int vtkFerroVolumeRepresentation::ProcessViewRequest(
  vtkInformationRequestKey* request_type, vtkInformation* inInfo, vtkInformation* outInfo)
{
  if (!this->Superclass::ProcessViewRequest(request_type, inInfo, outInfo))
  {
    return 0;
  }
  if (request_type == vtkPVRenderView::REQUEST_UPDATE())
  {
    // Under MPI each rank draws its own piece, on the whole volume's sample lattice (the
    // mapper's WholeExtent). vtkImageVolumeRepresentation asks for ordered compositing (IceT
    // blends the ranks' frames back to front with "over"), which is right for composite
    // rays and for the nearly transparent shares of the average, but not for the extremum
    // of MIP and MinIP: for those the ranks' frames are composited by depth instead, and
    // each rank writes its extremum's place in the colour range as the depth, so the
    // largest maximum (smallest minimum) wins. Nor for additive sums, which "over" cannot
    // add in 8 bits: the mapper sums the ranks' frames itself, and one rank draws the sum.
    vtkMultiProcessController* controller = vtkMultiProcessController::GetGlobalController();
    const bool parallel = controller && controller->GetNumberOfProcesses() > 1;
    vtkFerroVolumeMapper* mapper = this->GetFerroVolumeMapper();
    if (parallel)
    {
      mapper->SetWholeExtent(this->WholeExtent);
    }
    const int drawn = this->DrawnBlendMode();
    const bool extremum = parallel &&
      mapper->GetRenderMode() != vtkFerroVolumeMapper::RENDER_MODE_PATH_TRACE &&
      (drawn == vtkVolumeMapper::MAXIMUM_INTENSITY_BLEND ||
        drawn == vtkVolumeMapper::MINIMUM_INTENSITY_BLEND);
    mapper->SetExtremumDepth(extremum);
    if (extremum)
    {
      outInfo->Set(vtkPVRenderView::NEED_ORDERED_COMPOSITING(), 0);
    }
  }
  if (request_type == vtkPVView::REQUEST_RENDER())
  {
    this->ApplyVectorMode();
    this->ApplyWholeRanges();
    this->UpdateDistributedSum();
    // A screenshot is a converged image: its render traces the whole budget. ParaView
    // renders a capture with the window's buffer swapping off (vtkSMViewProxy::
    // CaptureWindowInternal), in the GUI, pvpython and pvbatch alike.
    vtkPVView* view = vtkPVView::SafeDownCast(inInfo->Get(vtkPVView::VIEW()));
    vtkRenderWindow* window = view ? view->GetRenderWindow() : nullptr;
    const bool capture = window && !window->GetSwapBuffers();
    this->GetFerroVolumeMapper()->SetProgressiveMode(
      capture ? vtkFerroVolumeMapper::PROGRESSIVE_OFF : this->ProgressiveMode);
  }
  return 1;
}

namespace
{
using RangeMap = std::map<std::pair<bool, std::string>, std::vector<std::array<double, 2>>>;

// A map of ranges as a stream: the count, then each (cell data, name, count of ranges,
// the ranges).
void WriteRanges(const RangeMap& ranges, vtkMultiProcessStream& stream)
{
  stream << static_cast<int>(ranges.size());
  for (const auto& entry : ranges)
  {
    stream << static_cast<int>(entry.first.first) << entry.first.second
           << static_cast<int>(entry.second.size());
    for (const auto& range : entry.second)
    {
      stream << range[0] << range[1];
    }
  }
}

// Widens `ranges` by the ranges WriteRanges put in `stream` (an array whose number of
// ranges differs starts again from the stream's).
void MergeRanges(vtkMultiProcessStream& stream, RangeMap& ranges)
{
  int count = 0;
  stream >> count;
  for (int i = 0; i < count; ++i)
  {
    int cell = 0, size = 0;
    std::string name;
    stream >> cell >> name >> size;
    auto& merged = ranges[{ cell != 0, name }];
    if (merged.size() != static_cast<size_t>(size))
    {
      merged.assign(static_cast<size_t>(size),
        { std::numeric_limits<double>::infinity(), -std::numeric_limits<double>::infinity() });
    }
    for (auto& range : merged)
    {
      double lo = 0.0, hi = 0.0;
      stream >> lo >> hi;
      if (lo <= hi)
      {
        range = { std::min(range[0], lo), std::max(range[1], hi) };
      }
    }
  }
}
}

//------------------------------------------------------------------------------------------
void vtkFerroVolumeRepresentation::GatherWholeRanges()
{
  this->WholeRanges.clear();
  vtkMultiProcessController* controller = vtkMultiProcessController::GetGlobalController();
  if (!controller || controller->GetNumberOfProcesses() < 2)
  {
    return;
  }
  // this rank's point and cell arrays: each component's range, then the magnitude's
  RangeMap local;
  auto* image = vtkImageData::SafeDownCast(this->Cache);
  vtkDataSetAttributes* attributes[2] = { image ? image->GetPointData() : nullptr,
    image ? image->GetCellData() : nullptr };
  for (int a = 0; a < 2; ++a)
  {
    for (int i = 0; attributes[a] && i < attributes[a]->GetNumberOfArrays(); ++i)
    {
      vtkDataArray* array = attributes[a]->GetArray(i);
      if (!array || !array->GetName() || array->GetNumberOfTuples() == 0)
      {
        continue;
      }
      const int comps = array->GetNumberOfComponents();
      auto& ranges = local[{ a == 1, array->GetName() }];
      ranges.resize(static_cast<size_t>(comps) + 1);
      for (int c = 0; c <= comps; ++c)
      {
        array->GetFiniteRange(ranges[c].data(), c < comps ? c : -1); // (-1: the magnitude)
      }
    }
  }
  vtkMultiProcessStream mine;
  WriteRanges(local, mine);
  std::vector<vtkMultiProcessStream> all;
  controller->Gather(mine, all, 0);
  vtkMultiProcessStream merged;
  if (controller->GetLocalProcessId() == 0)
  {
    RangeMap whole;
    for (auto& stream : all)
    {
      MergeRanges(stream, whole);
    }
    WriteRanges(whole, merged);
  }
  controller->Broadcast(merged, 0);
  MergeRanges(merged, this->WholeRanges);
}

//------------------------------------------------------------------------------------------
vtkDataArray* vtkFerroVolumeRepresentation::MapperScalars(int& cellFlag)
{
  auto* image = vtkImageData::SafeDownCast(this->VolumeMapper->GetInputDataObject(0, 0));
  cellFlag = 0;
  return image ? vtkAbstractMapper::GetScalars(image, this->VolumeMapper->GetScalarMode(),
                   this->VolumeMapper->GetArrayAccessMode(), this->VolumeMapper->GetArrayId(),
                   this->VolumeMapper->GetArrayName(), cellFlag)
               : nullptr;
}

//------------------------------------------------------------------------------------------
void vtkFerroVolumeRepresentation::UpdateDistributedSum()
{
  vtkFerroVolumeMapper* mapper = this->GetFerroVolumeMapper();
  vtkMultiProcessController* controller = vtkMultiProcessController::GetGlobalController();
  bool sum = controller && controller->GetNumberOfProcesses() > 1 &&
    this->DrawnBlendMode() == vtkVolumeMapper::ADDITIVE_BLEND;
  if (sum)
  {
    // (the same on every rank, and so is this collective operation)
    int cellFlag = 0;
    vtkDataArray* scalars = this->MapperScalars(cellFlag);
    const int mine = scalars && scalars->GetNumberOfTuples() > 0 ? 1 : 0;
    int all = 0;
    controller->AllReduce(&mine, &all, 1, vtkCommunicator::MIN_OP);
    sum = all == 1;
  }
  mapper->SetDistributedSum(sum);
}

//------------------------------------------------------------------------------------------
void vtkFerroVolumeRepresentation::ApplyWholeRanges()
{
  vtkFerroVolumeMapper* mapper = this->GetFerroVolumeMapper();
  mapper->RemoveAllWholeScalarRanges();
  if (this->WholeRanges.empty())
  {
    return;
  }
  // the array the mapper draws, or the one ApplyVectorMode() derived it from
  bool cell = std::get<0>(this->VectorModeSource);
  std::string name = std::get<1>(this->VectorModeSource);
  if (name.empty())
  {
    int cellFlag = 0;
    vtkDataArray* array = this->MapperScalars(cellFlag);
    if (!array || !array->GetName())
    {
      return;
    }
    cell = cellFlag == 1;
    name = array->GetName();
  }
  const auto found = this->WholeRanges.find({ cell, name });
  if (found == this->WholeRanges.end() || found->second.size() < 2)
  {
    return;
  }
  const auto& ranges = found->second;
  const int comps = static_cast<int>(ranges.size()) - 1;
  if (!std::get<1>(this->VectorModeSource).empty())
  {
    // one derived component: the magnitude (-1, the last range) or a component's
    const int c = std::get<2>(this->VectorModeSource);
    const auto& range = ranges[c < 0 || c >= comps ? comps : c];
    if (range[0] <= range[1])
    {
      mapper->SetWholeScalarRange(0, range[0], range[1]);
    }
    return;
  }
  for (int c = 0; c < std::min(comps, 4); ++c)
  {
    if (ranges[c][0] <= ranges[c][1])
    {
      mapper->SetWholeScalarRange(c, ranges[c][0], ranges[c][1]);
    }
  }
}

//------------------------------------------------------------------------------------------
void vtkFerroVolumeRepresentation::ApplyVectorMode()
{
  this->VectorModeSource = { false, "", 0 };
  auto* image = vtkImageData::SafeDownCast(this->VolumeMapper->GetInputDataObject(0, 0));
  vtkVolumeProperty* prop = this->Property;
  vtkColorTransferFunction* ctf = prop ? prop->GetRGBTransferFunction(0) : nullptr;
  if (!image || !ctf || !prop->GetIndependentComponents())
  {
    return;
  }
  const int mode = ctf->GetVectorMode();
  if (mode != vtkScalarsToColors::MAGNITUDE && mode != vtkScalarsToColors::COMPONENT)
  {
    return;
  }
  int cellFlag = 0;
  vtkDataArray* array = this->MapperScalars(cellFlag);
  const int comps = array ? array->GetNumberOfComponents() : 0;
  if (comps < 2)
  {
    return;
  }
  const int component = std::max(0, std::min(ctf->GetVectorComponent(), comps - 1));

  std::ostringstream key;
  key << image << ':' << image->GetMTime() << ':' << array << ':' << array->GetMTime() << ':'
      << mode << ':' << component << ':' << cellFlag;
  const std::string name = std::string(array->GetName() ? array->GetName() : "scalars") +
    (mode == vtkScalarsToColors::MAGNITUDE ? "_ferrovol_magnitude"
                                           : "_ferrovol_" + std::to_string(component));
  if (key.str() != this->VectorModeKey || !this->VectorModeImage)
  {
    // The same grid with one array: the chosen component (its own type), or the magnitude
    // (double for double input, float otherwise), as vtkSmartVolumeMapper makes them.
    vtkSmartPointer<vtkDataArray> out;
    const vtkIdType n = array->GetNumberOfTuples();
    if (mode == vtkScalarsToColors::COMPONENT)
    {
      out.TakeReference(array->NewInstance());
      out->SetNumberOfComponents(1);
      out->SetNumberOfTuples(n);
      out->CopyComponent(0, array, component);
    }
    else
    {
      if (array->GetDataType() == VTK_DOUBLE)
      {
        out = vtkSmartPointer<vtkDoubleArray>::New();
      }
      else
      {
        out = vtkSmartPointer<vtkFloatArray>::New();
      }
      out->SetNumberOfComponents(1);
      out->SetNumberOfTuples(n);
      for (vtkIdType i = 0; i < n; ++i)
      {
        double sum = 0.0;
        for (int c = 0; c < comps; ++c)
        {
          const double v = array->GetComponent(i, c);
          sum += v * v;
        }
        out->SetComponent(i, 0, std::sqrt(sum));
      }
    }
    out->SetName(name.c_str());
    auto derived = vtkSmartPointer<vtkImageData>::New();
    derived->CopyStructure(image);
    if (cellFlag)
    {
      derived->GetCellData()->SetScalars(out);
    }
    else
    {
      derived->GetPointData()->SetScalars(out);
    }
    this->VectorModeImage = derived;
    if (!this->VectorModeProducer)
    {
      this->VectorModeProducer = vtkSmartPointer<vtkTrivialProducer>::New();
    }
    this->VectorModeProducer->SetOutput(derived);
    this->VectorModeKey = key.str();
  }
  this->VolumeMapper->SetInputConnection(this->VectorModeProducer->GetOutputPort());
  this->VolumeMapper->SelectScalarArray(name.c_str());
  this->VectorModeSource = { cellFlag == 1, array->GetName() ? array->GetName() : "",
    mode == vtkScalarsToColors::MAGNITUDE ? -1 : component };
}

//------------------------------------------------------------------------------------------
bool vtkFerroVolumeRepresentation::WarnAboutSettings(int drawn)
{
  std::vector<std::string> warnings;
  bool draw = true;
  // Path tracing does not read the blend mode: none of the blend-mode warnings apply.
  const int renderMode = this->GetFerroVolumeMapper()->GetRenderMode();
  if (renderMode != vtkFerroVolumeMapper::RENDER_MODE_PATH_TRACE)
  {
    if (!BlendModeName(drawn))
    {
      warnings.emplace_back("Blend Mode " + std::to_string(drawn) +
        " is not one of vtkVolumeMapper's blend modes (0-6): the volume is hidden.");
      draw = false;
    }
    if (this->FerrovolBlendMode != FOLLOW_BLEND_MODE &&
      this->SharedBlendMode != vtkVolumeMapper::COMPOSITE_BLEND &&
      this->SharedBlendMode != this->FerrovolBlendMode)
    {
      warnings.emplace_back("Ferrovol Blend Mode " + QuotedBlendMode(this->FerrovolBlendMode) +
        " overrides Blend Mode " + QuotedBlendMode(this->SharedBlendMode) +
        ". Set Ferrovol Blend Mode to \"Follow Blend Mode\" to draw what Blend Mode says.");
    }
  }
  // A 2D transfer function (the superclass puts it on the property in TF_2D mode) over the
  // scalar and its gradient magnitude, as vtkGPUVolumeRayCastMapper reads it; another array
  // on the second axis (vtkMultiBlockVolumeMapper's Transfer2DYAxisArray) is not read.
  if (this->UseTransfer2D && !this->UseGradientForTransfer2D && !this->ColorArray2Name.empty())
  {
    warnings.emplace_back("the 2D transfer function's second axis is array \"" +
      this->ColorArray2Name +
      "\": ferrovol reads the gradient magnitude there (choose \"Gradient Magnitude\"), so the "
      "volume is hidden while another array is chosen.");
    draw = false;
  }
  if (this->RequestedRenderMode != 0)
  {
    warnings.emplace_back("Volume Rendering Mode " + RenderModeName(this->RequestedRenderMode) +
      " chooses among ParaView's own volume mappers; \"Ferrovol Volume\" always renders "
      "with ferrovol (Ferrovol Render Mode chooses ray casting or path tracing).");
  }
  for (const std::string& warning : warnings)
  {
    if (std::find(this->SettingsWarnings.begin(), this->SettingsWarnings.end(), warning) ==
      this->SettingsWarnings.end())
    {
      vtkWarningMacro(<< "\"Ferrovol Volume\": " << warning);
    }
  }
  this->SettingsWarnings = warnings;
  return draw;
}

//------------------------------------------------------------------------------------------
void vtkFerroVolumeRepresentation::UpdateMapperParameters()
{
  this->Superclass::UpdateMapperParameters();

  const int drawn = this->DrawnBlendMode();
  const bool drawable =
    drawn >= vtkVolumeMapper::COMPOSITE_BLEND && drawn <= vtkVolumeMapper::SLICE_BLEND;
  // A value that is no blend mode: the mapper gets composite, which path tracing ignores;
  // ray casting hides the volume (WarnAboutSettings). Slice draws the property's
  // SliceFunction (Slice Type), which the superclass sets.
  this->VolumeMapper->SetBlendMode(drawable ? drawn : vtkVolumeMapper::COMPOSITE_BLEND);
  this->UpdateMask();
  this->UpdateSampleDistanceMode();

  if (!this->WarnAboutSettings(drawn) || !this->InputIsImageData)
  {
    this->Actor->SetVisibility(false);
  }
}

//------------------------------------------------------------------------------------------
void vtkFerroVolumeRepresentation::PrintSelf(ostream& os, vtkIndent indent)
{
  this->Superclass::PrintSelf(os, indent);
  os << indent << "FerrovolBlendMode: " << this->FerrovolBlendMode << "\n";
  os << indent << "BlendMode (shared): " << this->SharedBlendMode << "\n";
  os << indent << "RequestedRenderMode (shared, not used): " << this->RequestedRenderMode
     << "\n";
  os << indent << "InputIsImageData: " << this->InputIsImageData << "\n";
  os << indent << "FerroVolumeMapper:\n";
  this->VolumeMapper->PrintSelf(os, indent.GetNextIndent());
}
