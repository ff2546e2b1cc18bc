// vtkFerroUnstructuredVolumeMapper: a vtkUnstructuredGrid ray cast by ferrovol's unstructured
// pass (fv_unstructured_volume_new, fv_renderer_set_unstructured). It draws through the
// units vtkFerroVolumeMapper draws through (see vtkFerroVolumeMapper.cxx): the process-wide
// device (vtkFerroVolumeContext), the property's tables (vtkFerroVolumeLookupTables), the
// camera, matrix, clipping planes, shading and lights (vtkFerroVolumeSettings), the depth of
// opaque geometry (vtkFerroVolumeDepthReader) and the output into VTK's framebuffer
// (vtkFerroVolumeOutput), with its errors and warnings in a vtkFerroVolumeReport. Its own part is the mesh: VTK's
// arrays handed to the C ABI as they are (vtkCellArray's 64- or 32-bit storage, float or
// double points), only when the input or its scalars changed.
#include "vtkFerroUnstructuredVolumeMapper.h"

#include "vtkFerroVolumeContext.h"
#include "vtkFerroVolumeEnums.h"
#include "vtkFerroVolumeInputHelper.h"
#include "vtkFerroVolumeLookupTables.h"
#include "vtkFerroVolumeOutput.h"
#include "vtkFerroVolumeRefinement.h"
#include "vtkFerroVolumeReport.h"
#include "vtkFerroVolumeSettings.h"
#include "vtkCellArray.h"
#include "vtkDataArray.h"
#include "vtkDoubleArray.h"
#include "vtkIdTypeArray.h"
#include "vtkObjectFactory.h"
#include "vtkOpenGLRenderWindow.h"
#include "vtkPoints.h"
#include "vtkRenderer.h"
#include "vtkUnstructuredGrid.h"
#include "vtkVolume.h"
#include "vtkVolumeProperty.h"
#include "vtkWeakPointer.h"

#include <array>
#include <cmath>
#include <memory>
#include <string>
#include <vector>

vtkStandardNewMacro(vtkFerroUnstructuredVolumeMapper);

namespace
{
// The scalars the mapper's selection picks on `grid`, `cells` saying where they live; false
// with the reason when there are none or they are not one component of a type ferrovol
// takes.
bool SelectScalars(vtkFerroUnstructuredVolumeMapper* self, vtkUnstructuredGrid* grid,
  vtkDataArray*& scalars, bool& cells, vtkFerroVolumeReport& report)
{
  int cellFlag = 0;
  scalars = vtkAbstractMapper::GetScalars(grid, self->GetScalarMode(), self->GetArrayAccessMode(),
    self->GetArrayId(), self->GetArrayName(), cellFlag);
  cells = cellFlag == 1;
  if (!scalars)
  {
    return report.Fail("the input has no scalars to draw (point or cell scalars, or the array "
                       "SelectScalarArray names with a ScalarMode of point or cell field data)");
  }
  if (scalars->GetNumberOfComponents() != 1)
  {
    return report.Fail("the scalars '" + std::string(scalars->GetName() ? scalars->GetName() : "") +
      "' have " + std::to_string(scalars->GetNumberOfComponents()) +
      " components: ferrovol's unstructured pass draws one (select a one-component array)");
  }
  uint32_t type = 0;
  size_t size = 0;
  if (scalars->GetDataType() == VTK_BIT ||
    !vtkFerroVolumeInputHelper::ToFvScalarType(scalars->GetDataType(), type, size))
  {
    return report.Fail(std::string("scalars of type ") + scalars->GetDataTypeAsString() +
      " are not supported by ferrovol's unstructured pass");
  }
  return true;
}
}

class vtkFerroUnstructuredVolumeMapper::vtkInternals
{
public:
  vtkFerroVolumeRendererSlot Slot;
  vtkFerroVolumeOutput Output;
  vtkFerroVolumeReport Report;
  // Path tracing: the environment given to the renderer, and the progressive refinement.
  vtkFerroVolumeSettings Settings;
  vtkFerroVolumeRefinement Refinement;

  // What the uploaded mesh and tables were made from.
  struct MeshKey
  {
    vtkUnstructuredGrid* Grid = nullptr;
    vtkMTimeType GridMTime = 0;
    vtkDataArray* Scalars = nullptr;
    vtkMTimeType ScalarsMTime = 0;
    bool operator==(const MeshKey& o) const
    {
      return this->Grid == o.Grid && this->GridMTime == o.GridMTime &&
        this->Scalars == o.Scalars && this->ScalarsMTime == o.ScalarsMTime;
    }
  };
  bool HaveMesh = false;
  MeshKey Mesh;
  std::array<double, 2> Range{};
  vtkVolumeProperty* Property = nullptr;
  vtkMTimeType PropertyMTime = 0;
  std::array<double, 2> TablesRange{};
  double TablesGradientScale = 0.0;
  int MeshUploads = 0;
  int TableUploads = 0;

  // An input that is not a vtkUnstructuredGrid, copied into one, and the input and its
  // MTime the copy was made from.
  vtkSmartPointer<vtkUnstructuredGrid> Copy;
  vtkWeakPointer<vtkUnstructuredGridBase> CopySource;
  vtkMTimeType CopySourceMTime = 0;

  explicit vtkInternals(vtkObject* self)
    : Report(self)
  {
  }

  void FreeRenderer()
  {
    this->Refinement.Stop();
    this->Slot.Renderer.reset();
    this->HaveMesh = false;
    this->Property = nullptr;
    this->Settings.Reset();
  }

  // `input` as a vtkUnstructuredGrid: itself, or its copy (made again only when the input
  // or its MTime changed, so that an unchanged input keeps the uploaded mesh).
  vtkUnstructuredGrid* AsGrid(vtkUnstructuredGridBase* input)
  {
    if (auto grid = vtkUnstructuredGrid::SafeDownCast(input))
    {
      this->Copy = nullptr;
      this->CopySource = nullptr;
      return grid;
    }
    if (!input)
    {
      return nullptr;
    }
    if (!this->Copy || this->CopySource != input || this->CopySourceMTime != input->GetMTime())
    {
      this->Copy = vtkSmartPointer<vtkUnstructuredGrid>::New();
      this->Copy->DeepCopy(input);
      this->CopySource = input;
      this->CopySourceMTime = input->GetMTime();
    }
    return this->Copy;
  }

  // The renderer, made on first use and again (with the mesh and tables) after a device
  // loss.
  bool MakeRenderer(vtkOpenGLRenderWindow* win)
  {
    if (this->Slot.Renderer && !this->Slot.Lost())
    {
      return true;
    }
    this->Output.ReleaseGraphicsResources(win);
    this->FreeRenderer();
    return this->Slot.Make(this->Report);
  }

  // The mesh with `scalars` uploaded when the input or its scalars changed.
  bool Upload(vtkUnstructuredGrid* grid, vtkDataArray* scalars, bool cells)
  {
    MeshKey key;
    key.Grid = grid;
    key.GridMTime = grid->GetMTime();
    key.Scalars = scalars;
    key.ScalarsMTime = scalars->GetMTime();
    if (this->HaveMesh && this->Mesh == key)
    {
      return true;
    }
    this->HaveMesh = false;
    vtkCellArray* cellArray = grid->GetCells();
    if (!grid->GetPoints() || grid->GetNumberOfPoints() == 0 || !cellArray ||
      grid->GetNumberOfCells() == 0)
    {
      return this->Report.Fail("the input has no cells: nothing to draw");
    }
    FvUnstructuredVolumeDesc desc;
    if (!vtkFerroVolumeCall("describe the mesh", this->Report,
          [&] { desc = ferrovol::UnstructuredVolume::default_desc(); }))
    {
      return false;
    }
    // Points: float or double as they are, other types converted to double.
    vtkDataArray* points = grid->GetPoints()->GetData();
    vtkNew<vtkDoubleArray> converted;
    if (points->GetDataType() != VTK_FLOAT && points->GetDataType() != VTK_DOUBLE)
    {
      converted->DeepCopy(points);
      points = converted;
    }
    desc.points = points->GetVoidPointer(0);
    desc.point_count = static_cast<size_t>(points->GetNumberOfTuples());
    desc.point_type = points->GetDataType() == VTK_FLOAT ? FV_SCALAR_TYPE_F32 : FV_SCALAR_TYPE_F64;
    // vtkCellArray's connectivity and offsets in their own memory where both are plain
    // arrays of one integer type (VTK 9.2 always); copied as vtkIdType where VTK keeps them
    // otherwise (VTK 9.6's fixed-size and implicit storage).
    vtkDataArray* connectivity = cellArray->GetConnectivityArray();
    vtkDataArray* offsets = cellArray->GetOffsetsArray();
    uint32_t connectivityType = 0, offsetsType = 0;
    size_t indexSize = 0;
    const bool plain = connectivity->HasStandardMemoryLayout() &&
      offsets->HasStandardMemoryLayout() &&
      vtkFerroVolumeInputHelper::ToFvScalarType(
        connectivity->GetDataType(), connectivityType, indexSize) &&
      vtkFerroVolumeInputHelper::ToFvScalarType(offsets->GetDataType(), offsetsType, indexSize) &&
      connectivityType == offsetsType &&
      (connectivityType == FV_SCALAR_TYPE_I32 || connectivityType == FV_SCALAR_TYPE_I64 ||
        connectivityType == FV_SCALAR_TYPE_U32 || connectivityType == FV_SCALAR_TYPE_U64);
    vtkNew<vtkIdTypeArray> connectivityCopy, offsetsCopy;
    if (!plain)
    {
      connectivityCopy->DeepCopy(connectivity);
      offsetsCopy->DeepCopy(offsets);
      connectivity = connectivityCopy;
      offsets = offsetsCopy;
      connectivityType = sizeof(vtkIdType) == 8 ? FV_SCALAR_TYPE_I64 : FV_SCALAR_TYPE_I32;
    }
    desc.index_type = connectivityType;
    desc.connectivity = connectivity->GetVoidPointer(0);
    desc.connectivity_count = static_cast<size_t>(connectivity->GetNumberOfValues());
    desc.offsets = offsets->GetVoidPointer(0);
    // The cell types, one byte each (VTK 9.6 may keep them in an implicit array).
    const vtkIdType cellCount = grid->GetNumberOfCells();
    std::vector<unsigned char> types(static_cast<size_t>(cellCount));
    for (vtkIdType c = 0; c < cellCount; ++c)
    {
      types[static_cast<size_t>(c)] = static_cast<unsigned char>(grid->GetCellType(c));
    }
    desc.cell_types = types.data();
    desc.cell_count = static_cast<size_t>(cellCount);
    size_t size = 0;
    vtkFerroVolumeInputHelper::ToFvScalarType(scalars->GetDataType(), desc.scalar_type, size);
    desc.components = 1;
    desc.location = cells ? FV_SCALAR_LOCATION_CELLS : FV_SCALAR_LOCATION_POINTS;
    desc.scalars = scalars->GetVoidPointer(0);
    if (!vtkFerroVolumeCall("upload the mesh", this->Report, [&] {
          ferrovol::UnstructuredVolume mesh(desc);
          this->Slot.Renderer->set_unstructured(mesh);
        }))
    {
      return false;
    }
    scalars->GetRange(this->Range.data(), 0);
    this->Mesh = key;
    this->HaveMesh = true;
    ++this->MeshUploads;
    return true;
  }

  // The property's colour and scalar opacity over the scalars' range, when either changed.
  bool UpdateTables(vtkVolume* vol)
  {
    vtkVolumeProperty* prop = vol->GetProperty();
    // A gradient opacity reads gradient magnitudes in scalar units per world unit of the
    // mesh's own coordinates (vtkGPUVolumeRayCastMapper's, per voxel, on an image of unit
    // spacing), under the vtkVolume's scale.
    const double matrixScale = vtkFerroVolumeLookupTables::MatrixScale(vol);
    const double gradientScale =
      matrixScale > 0.0 && std::isfinite(matrixScale) ? 1.0 / matrixScale : 1.0;
    if (this->Property == prop && this->PropertyMTime == prop->GetMTime() &&
      this->TablesRange == this->Range && this->TablesGradientScale == gradientScale)
    {
      return true;
    }
    this->Property = nullptr;
    std::unique_ptr<ferrovol::TransferFunction> tf;
    if (!vtkFerroVolumeLookupTables::BuildFirstComponent(prop, this->Range,
          vtkFerroVolumeLookupTables::RangeTypes(), "meshes", gradientScale, tf,
          this->Report) ||
      !vtkFerroVolumeCall("set the transfer function", this->Report,
        [&] { this->Slot.Renderer->set_transfer_function(*tf); }))
    {
      return false;
    }
    this->Property = prop;
    this->PropertyMTime = prop->GetMTime();
    this->TablesRange = this->Range;
    this->TablesGradientScale = gradientScale;
    ++this->TableUploads;
    return true;
  }
};

//------------------------------------------------------------------------------------------
vtkFerroUnstructuredVolumeMapper::vtkFerroUnstructuredVolumeMapper()
  : Internals(new vtkInternals(this))
{
}

vtkFerroUnstructuredVolumeMapper::~vtkFerroUnstructuredVolumeMapper()
{
  delete this->Internals;
  this->SetEnvironmentMap(nullptr);
}

int vtkFerroUnstructuredVolumeMapper::GetAccumulatedSamples()
{
  if (!this->Internals->Slot.Renderer)
  {
    return -1;
  }
  int samples = -1;
  vtkFerroVolumeReport quiet;
  vtkFerroVolumeCall("count the accumulated paths", quiet, [&] {
    samples = static_cast<int>(this->Internals->Slot.Renderer->accumulated_samples());
  });
  return samples;
}

void vtkFerroUnstructuredVolumeMapper::PrintSelf(ostream& os, vtkIndent indent)
{
  this->Superclass::PrintSelf(os, indent);
  os << indent << "LastRenderDrew: " << this->LastRenderDrew << "\n";
  os << indent << "LastRenderProgressive: " << this->LastRenderProgressive << "\n";
  os << indent << "RenderMode: "
     << (this->RenderMode == RENDER_MODE_PATH_TRACE ? "path trace" : "ray cast") << "\n";
  os << indent << "SamplesPerPixel: " << this->SamplesPerPixel << "\n";
  os << indent << "InteractiveSamplesPerPixel: " << this->InteractiveSamplesPerPixel << "\n";
  os << indent << "PathTracingBounces: " << this->PathTracingBounces << "\n";
  os << indent << "SecondaryRays: " << this->SecondaryRays << "\n";
  os << indent << "PathTracingDenoise: " << this->PathTracingDenoise << "\n";
  os << indent << "PathTracingDenoiseUntil: " << this->PathTracingDenoiseUntil << "\n";
  os << indent << "ProgressiveMode: " << this->ProgressiveMode << "\n";
  os << indent << "PathTracingTimeBudget: " << this->PathTracingTimeBudget << "\n";
  os << indent << "EnvironmentMap: " << (this->EnvironmentMap ? this->EnvironmentMap : "(sky)")
     << "\n";
  os << indent << "EnvironmentUp: " << this->EnvironmentUp[0] << " " << this->EnvironmentUp[1]
     << " " << this->EnvironmentUp[2] << "\n";
  os << indent << "EnvironmentAzimuth: " << this->EnvironmentAzimuth << "\n";
  os << indent << "EnvironmentIntensity: " << this->EnvironmentIntensity << "\n";
  os << indent << "EnvironmentBackground: " << this->EnvironmentBackground << "\n";
  os << indent << "VolumetricScatteringBlending: " << this->VolumetricScatteringBlending
     << "\n";
  os << indent << "GlobalIlluminationReach: " << this->GlobalIlluminationReach << "\n";
  os << indent << "EnvironmentLighting: " << this->EnvironmentLighting << "\n";
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
}

void vtkFerroUnstructuredVolumeMapper::ReleaseGraphicsResources(vtkWindow* window)
{
  this->Internals->Output.ReleaseGraphicsResources(window);
  this->Internals->FreeRenderer();
}

//------------------------------------------------------------------------------------------
void vtkFerroUnstructuredVolumeMapper::Render(vtkRenderer* ren, vtkVolume* vol)
{
  this->LastRenderDrew = 0;
  this->LastRenderProgressive = 0;
  vtkInternals* in = this->Internals;
  in->Refinement.Begin();
  vtkFerroVolumeReport& report = in->Report;
  report.ClearError();
  if (!ren || !vol || !vol->GetProperty())
  {
    return;
  }
  vtkOpenGLRenderWindow* win = vtkOpenGLRenderWindow::SafeDownCast(ren->GetRenderWindow());
  if (!win)
  {
    vtkErrorMacro(<< "vtkFerroUnstructuredVolumeMapper needs an OpenGL render window "
                     "(vtkOpenGLRenderWindow)");
    return;
  }
  const bool pathTrace = this->RenderMode == RENDER_MODE_PATH_TRACE;
  uint32_t blend = FV_BLEND_MODE_PATH_TRACE;
  if (!pathTrace &&
    (!vtkFerroVolumeSettings::ToFvBlend(this->BlendMode, blend) || blend == FV_BLEND_MODE_SLICE))
  {
    vtkErrorMacro(<< "blend mode " << this->BlendMode
                  << " is not supported by vtkFerroUnstructuredVolumeMapper (composite, "
                     "maximum, minimum, average, additive and isosurface are): nothing is "
                     "drawn");
    return;
  }
  // The input: a vtkUnstructuredGrid, or another vtkUnstructuredGridBase copied into one.
  vtkUnstructuredGrid* grid = in->AsGrid(this->GetInput());
  if (!grid)
  {
    vtkErrorMacro(<< "no input: SetInputData or SetInputConnection with a vtkUnstructuredGrid");
    return;
  }
  vtkDataArray* scalars = nullptr;
  bool cells = false;
  const bool ready = SelectScalars(this, grid, scalars, cells, report) &&
    in->MakeRenderer(win) && in->Upload(grid, scalars, cells) &&
    in->UpdateTables(vol);
  this->MeshUploadCount = in->MeshUploads;
  this->TableUploadCount = in->TableUploads;
  if (!ready)
  {
    vtkErrorMacro(<< report.GetError());
    return;
  }

  // The frame's parameters, camera and output.
  vtkFerroVolumeFrameRequest req;
  if (!req.ForViewport(ren, vol, win))
  {
    return;
  }
  // Path tracing: its settings, and for a progressive render what is left of its budget.
  const vtkFerroVolumeRefinement::Settings refining = vtkFerroVolumeSettings::Refining(this);
  double traceBudget = 0.0;
  if (pathTrace)
  {
    if (!in->Refinement.BeginTracing(refining, win, *in->Slot.Renderer, report, traceBudget) ||
      !in->Settings.SetUpPathTracing(this, ren, vol, *in->Slot.Renderer, traceBudget, report))
    {
      vtkErrorMacro(<< report.GetError());
      return;
    }
  }
  else
  {
    in->Refinement.Stop();
  }
  FvRenderParams params;
  if (!vtkFerroVolumeCall(
        "use the mapper's settings", report, [&] { params = ferrovol::Renderer::default_params(); }))
  {
    vtkErrorMacro(<< report.GetError());
    return;
  }
  params.blend_mode = blend;
  vtkFerroVolumeSettings::SetVolumeMatrix(vol, params);
  vtkFerroVolumeSettings::SetUpClippingPlanes(this->ClippingPlanes, params, report);
  if (!vtkFerroVolumeSettings::ApplyShading(
        this, ren, vol->GetProperty(), params, *in->Slot.Renderer, report))
  {
    vtkErrorMacro(<< report.GetError());
    return;
  }
  if (params.shade && blend == FV_BLEND_MODE_COMPOSITE)
  {
    vtkFerroVolumeSettings::SetVolumetric(this->VolumetricScatteringBlending,
      this->GlobalIlluminationReach, vol->GetProperty(), params);
  }
  if (blend == FV_BLEND_MODE_ISOSURFACE)
  {
    using Result = vtkFerroVolumeSettings::Result;
    const Result iso =
      in->Settings.SetUpIsosurfaces(this, vol, 1, params, *in->Slot.Renderer, report);
    if (iso == Result::Failed)
    {
      vtkErrorMacro(<< report.GetError());
    }
    if (iso != Result::Ready)
    {
      return;
    }
  }
  std::string warning;
  if (!vtkFerroVolumeCall(
      "use the mapper's settings", report, [&] { in->Slot.Renderer->set_params(params); }) ||
    !vtkFerroVolumeSettings::ApplyCamera(
      ren, req.ViewportW, req.ViewportH, *in->Slot.Renderer, report) ||
    !in->Output.Render(vtkFerroVolumeEnums::OUTPUT_PATH_AUTOMATIC, *in->Slot.Renderer, req, report,
      warning))
  {
    vtkErrorMacro(<< report.GetError());
    return;
  }
  if (!warning.empty())
  {
    report.WarnOnce(warning);
  }
  const int rect[4] = { 0, 0, req.ViewportW, req.ViewportH };
  if (in->Output.Composite(req, rect, report) == vtkFerroVolumeOutput::Composited::Failed)
  {
    vtkErrorMacro(<< report.GetError());
    return;
  }
  this->LastRenderDrew = 1;
  if (in->Refinement.IsTracing())
  {
    // Refine while the accumulation is short of SamplesPerPixel.
    if (!in->Refinement.EndTracing(
          refining, this, win, req.RenderW, req.RenderH, *in->Slot.Renderer, report))
    {
      vtkErrorMacro(<< report.GetError());
      return;
    }
    this->LastRenderProgressive = 1;
  }
}
