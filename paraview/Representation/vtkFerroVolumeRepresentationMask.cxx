// vtkFerroVolumeRepresentation's masks: the mask array of the representation's own input
// (ParaView's "Mask Array"), its type and blend factor, the label colours, and the mask
// image handed to the mapper.
#include "vtkFerroVolumeRepresentation.h"

#include "vtkCellData.h"
#include "vtkColorTransferFunction.h"
#include "vtkDataArray.h"
#include "vtkFerroVolumeMapper.h"
#include "vtkImageData.h"
#include "vtkPiecewiseFunction.h"
#include "vtkPointData.h"
#include "vtkVolumeProperty.h"

#include <algorithm>
#include <cmath>
#include <sstream>
#include <string>
#include <vector>

//------------------------------------------------------------------------------------------
void vtkFerroVolumeRepresentation::SetMaskArrayName(const char* name)
{
  const std::string n = name ? name : "";
  if (n != this->MaskArrayName)
  {
    this->MaskArrayName = n;
    this->MaskKey.clear();
  }
}

void vtkFerroVolumeRepresentation::SetMaskType(int type)
{
  this->GetFerroVolumeMapper()->SetMaskType(type);
}

void vtkFerroVolumeRepresentation::SetMaskBlendFactor(double factor)
{
  this->GetFerroVolumeMapper()->SetMaskBlendFactor(static_cast<float>(factor));
}

void vtkFerroVolumeRepresentation::AddLabelColor(
  double label, double r, double g, double b, double opacity)
{
  this->LabelColors.push_back({ label, r, g, b, opacity });
}

void vtkFerroVolumeRepresentation::RemoveAllLabelColors()
{
  this->LabelColors.clear();
}

//------------------------------------------------------------------------------------------
void vtkFerroVolumeRepresentation::UpdateMask()
{
  vtkVolumeProperty* prop = this->Property;
  // The labels' colours: each listed label a flat colour and opacity; labels no longer
  // listed lose theirs.
  std::vector<int> labels;
  for (const auto& c : this->LabelColors)
  {
    const int label = static_cast<int>(std::lround(c[0]));
    if (label < 1 || label > 255 || label != c[0])
    {
      vtkWarningMacro(<< "\"Ferrovol Volume\": Label Colors names label " << c[0]
                      << "; labels are integers from 1 to 255 (0 is the unlabelled "
                         "background): it is left out.");
      continue;
    }
    auto color = vtkSmartPointer<vtkColorTransferFunction>::New();
    color->AddRGBPoint(0.0, c[1], c[2], c[3]);
    auto opacity = vtkSmartPointer<vtkPiecewiseFunction>::New();
    opacity->AddPoint(0.0, c[4]);
    if (prop)
    {
      const bool same = prop->GetLabelColor(label) && prop->GetLabelScalarOpacity(label) &&
        prop->GetLabelColor(label)->GetSize() == 1 &&
        prop->GetLabelScalarOpacity(label)->GetSize() == 1 &&
        [&] {
          double node[6], point[4];
          prop->GetLabelColor(label)->GetNodeValue(0, node);
          prop->GetLabelScalarOpacity(label)->GetNodeValue(0, point);
          return node[1] == c[1] && node[2] == c[2] && node[3] == c[3] && point[1] == c[4];
        }();
      if (!same)
      {
        prop->SetLabelColor(label, color);
        prop->SetLabelScalarOpacity(label, opacity);
      }
    }
    labels.push_back(label);
  }
  for (const int old : this->AppliedLabels)
  {
    if (prop && std::find(labels.begin(), labels.end(), old) == labels.end())
    {
      prop->SetLabelColor(old, nullptr);
      prop->SetLabelScalarOpacity(old, nullptr);
    }
  }
  this->AppliedLabels = labels;

  // The mask image: the input's structure with the named array as its scalars.
  vtkFerroVolumeMapper* mapper = this->GetFerroVolumeMapper();
  auto* image = vtkImageData::SafeDownCast(this->Cache);
  const std::string& name = this->MaskArrayName;
  if (!image || name.empty() || name == "None")
  {
    mapper->SetMaskInput(nullptr);
    this->MaskImage = nullptr;
    this->MaskKey.clear();
    return;
  }
  vtkDataArray* array = image->GetPointData()->GetArray(name.c_str());
  const bool cells = array == nullptr;
  if (cells)
  {
    array = image->GetCellData()->GetArray(name.c_str());
  }
  if (!array)
  {
    if (this->MaskKey != "missing:" + name)
    {
      vtkWarningMacro(<< "\"Ferrovol Volume\": Mask Array \"" << name
                      << "\" is not a point or cell array of this dataset: drawn unmasked.");
    }
    this->MaskKey = "missing:" + name;
    mapper->SetMaskInput(nullptr);
    this->MaskImage = nullptr;
    return;
  }
  std::ostringstream key;
  key << image << ':' << image->GetMTime() << ':' << array << ':' << array->GetMTime();
  if (key.str() != this->MaskKey || !this->MaskImage)
  {
    auto mask = vtkSmartPointer<vtkImageData>::New();
    mask->CopyStructure(image);
    if (cells)
    {
      mask->GetCellData()->SetScalars(array);
    }
    else
    {
      mask->GetPointData()->SetScalars(array);
    }
    this->MaskImage = mask;
    this->MaskKey = key.str();
  }
  mapper->SetMaskInput(this->MaskImage);
}
