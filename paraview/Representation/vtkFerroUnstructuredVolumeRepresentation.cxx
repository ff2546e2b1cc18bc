#include "vtkFerroUnstructuredVolumeRepresentation.h"

#include "vtkContourValues.h"
#include "vtkFerroUnstructuredVolumeMapper.h"
#include "vtkMultiProcessController.h"
#include "vtkObjectFactory.h"
#include "vtkVolumeMapper.h"
#include "vtkVolumeProperty.h"

#include <cstring>

vtkStandardNewMacro(vtkFerroUnstructuredVolumeRepresentation);

//------------------------------------------------------------------------------------------
vtkFerroUnstructuredVolumeRepresentation::vtkFerroUnstructuredVolumeRepresentation()
{
  this->AddVolumeMapper(MapperName(), this->FerroMapper);
  this->Superclass::SetActiveVolumeMapper(MapperName());
}

vtkFerroUnstructuredVolumeRepresentation::~vtkFerroUnstructuredVolumeRepresentation() = default;

void vtkFerroUnstructuredVolumeRepresentation::PrintSelf(ostream& os, vtkIndent indent)
{
  this->Superclass::PrintSelf(os, indent);
  os << indent << "FerrovolBlendMode: " << this->FerrovolBlendMode << "\n";
}

vtkFerroUnstructuredVolumeMapper*
vtkFerroUnstructuredVolumeRepresentation::GetFerroUnstructuredVolumeMapper()
{
  return this->FerroMapper;
}

//------------------------------------------------------------------------------------------
void vtkFerroUnstructuredVolumeRepresentation::SetActiveVolumeMapper(const char* name)
{
  if (name && name[0] && std::strcmp(name, MapperName()) != 0)
  {
    vtkErrorMacro(<< "\"Ferrovol Volume\" draws unstructured grids with ferrovol only; the "
                     "mapper \""
                  << name << "\" is one of \"Volume\"'s (its Select Mapper): ignored");
  }
  this->Superclass::SetActiveVolumeMapper(MapperName());
}

void vtkFerroUnstructuredVolumeRepresentation::SetShade(bool shade)
{
  this->Property->SetShade(shade ? 1 : 0);
}

void vtkFerroUnstructuredVolumeRepresentation::SetAmbient(double value)
{
  this->Property->SetAmbient(value);
}

void vtkFerroUnstructuredVolumeRepresentation::SetDiffuse(double value)
{
  this->Property->SetDiffuse(value);
}

void vtkFerroUnstructuredVolumeRepresentation::SetSpecular(double value)
{
  this->Property->SetSpecular(value);
}

void vtkFerroUnstructuredVolumeRepresentation::SetSpecularPower(double value)
{
  this->Property->SetSpecularPower(value);
}

void vtkFerroUnstructuredVolumeRepresentation::SetVolumeAnisotropy(double anisotropy)
{
  this->Property->SetScatteringAnisotropy(anisotropy);
}

void vtkFerroUnstructuredVolumeRepresentation::SetGlobalIlluminationReach(double reach)
{
  this->FerroMapper->SetGlobalIlluminationReach(static_cast<float>(reach));
}

void vtkFerroUnstructuredVolumeRepresentation::SetVolumetricScatteringBlending(double blending)
{
  this->FerroMapper->SetVolumetricScatteringBlending(static_cast<float>(blending));
}

void vtkFerroUnstructuredVolumeRepresentation::SetFerrovolBlendMode(int mode)
{
  if (mode < vtkVolumeMapper::COMPOSITE_BLEND || mode > vtkVolumeMapper::ISOSURFACE_BLEND)
  {
    vtkErrorMacro(<< "blend mode " << mode
                  << " is not drawn on unstructured grids (composite 0, maximum 1, minimum 2, "
                     "average 3, additive 4, isosurface 5 are): the blend mode stays "
                  << this->FerrovolBlendMode);
    return;
  }
  if (this->FerrovolBlendMode != mode)
  {
    this->FerrovolBlendMode = mode;
    this->Modified();
  }
}

void vtkFerroUnstructuredVolumeRepresentation::SetIsosurfaceValue(int i, double value)
{
  this->Property->GetIsoSurfaceValues()->SetValue(i, value);
}

void vtkFerroUnstructuredVolumeRepresentation::SetNumberOfIsosurfaces(int number)
{
  this->Property->GetIsoSurfaceValues()->SetNumberOfContours(number);
}

//------------------------------------------------------------------------------------------
void vtkFerroUnstructuredVolumeRepresentation::UpdateMapperParameters()
{
  this->Superclass::UpdateMapperParameters();
  if (this->UseSeparateOpacityArray)
  {
    vtkErrorMacro(<< "\"Ferrovol Volume\" on unstructured grids draws one component: a "
                     "separate opacity array (Use Separate Opacity Array) is not supported, "
                     "nothing is drawn");
  }
  this->FerroMapper->SetBlendMode(this->FerrovolBlendMode);
  auto* controller = vtkMultiProcessController::GetGlobalController();
  const bool distributed = controller && controller->GetNumberOfProcesses() > 1;
  const bool ordered = this->FerrovolBlendMode == vtkVolumeMapper::COMPOSITE_BLEND ||
    this->FerrovolBlendMode == vtkVolumeMapper::ISOSURFACE_BLEND;
  if (distributed && !ordered && this->WarnedBlendMode != this->FerrovolBlendMode)
  {
    vtkWarningMacro(<< "blend mode " << this->FerrovolBlendMode
                    << " under MPI: each rank draws its piece of the mesh with it and IceT "
                       "composites the pieces' images in visibility order (\"over\"), which "
                       "is exact for composite and isosurfaces only");
  }
  this->WarnedBlendMode = this->FerrovolBlendMode;
}

//------------------------------------------------------------------------------------------
void vtkFerroUnstructuredVolumeRepresentation::SetRenderMode(int mode)
{
  this->FerroMapper->SetRenderMode(mode);
}

void vtkFerroUnstructuredVolumeRepresentation::SetSamplesPerPixel(int samples)
{
  this->FerroMapper->SetSamplesPerPixel(samples);
}

void vtkFerroUnstructuredVolumeRepresentation::SetPathTracingBounces(int bounces)
{
  this->FerroMapper->SetPathTracingBounces(bounces);
}

void vtkFerroUnstructuredVolumeRepresentation::SetPathTracingDenoise(int on)
{
  this->FerroMapper->SetPathTracingDenoise(on);
}

void vtkFerroUnstructuredVolumeRepresentation::SetPathTracingDenoiseUntil(int samples)
{
  this->FerroMapper->SetPathTracingDenoiseUntil(samples);
}

void vtkFerroUnstructuredVolumeRepresentation::SetProgressiveMode(int mode)
{
  this->FerroMapper->SetProgressiveMode(mode);
}

void vtkFerroUnstructuredVolumeRepresentation::SetPathTracingTimeBudget(double seconds)
{
  this->FerroMapper->SetPathTracingTimeBudget(seconds);
}

void vtkFerroUnstructuredVolumeRepresentation::SetSecondaryRays(int rays)
{
  this->FerroMapper->SetSecondaryRays(rays);
}

void vtkFerroUnstructuredVolumeRepresentation::SetEnvironmentMap(const char* file)
{
  this->FerroMapper->SetEnvironmentMap(file);
}

void vtkFerroUnstructuredVolumeRepresentation::SetEnvironmentBackground(int on)
{
  this->FerroMapper->SetEnvironmentBackground(on);
}

int vtkFerroUnstructuredVolumeRepresentation::GetFerrovolAccumulatedSamples()
{
  return this->FerroMapper->GetAccumulatedSamples();
}

int vtkFerroUnstructuredVolumeRepresentation::GetFerrovolLastRenderDrew()
{
  return this->FerroMapper->GetLastRenderDrew();
}

int vtkFerroUnstructuredVolumeRepresentation::GetFerrovolVolumeUploadCount()
{
  return this->FerroMapper->GetMeshUploadCount();
}

int vtkFerroUnstructuredVolumeRepresentation::GetFerrovolTableUploadCount()
{
  return this->FerroMapper->GetTableUploadCount();
}
