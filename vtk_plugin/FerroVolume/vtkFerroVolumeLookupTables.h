// vtkFerroVolumeLookupTables: vtkVolumeProperty → ferrovol's transfer function (colour,
// scalar opacity, gradient opacity per component), sampled with VTK's own GetTable over the
// ranges vtkGPUVolumeRayCastMapper uses (its transfer function range types included) so
// that ferrovol's tables equal VTK's; uploaded only when the property (or its functions),
// the data ranges, the range types or the gradient scale changed. Internal to the
// FerroVolume module (not wrapped).
#ifndef vtkFerroVolumeLookupTables_h
#define vtkFerroVolumeLookupTables_h

#include "vtkFerroVolumeInputHelper.h"
#include "vtkType.h"

#include "ferrovol.hpp"

#include <array>
#include <memory>
#include <optional>
#include <string>

class vtkFerroVolumeReport;
class vtkVolume;
class vtkVolumeProperty;

class vtkFerroVolumeLookupTables
{
public:
  // The volume's matrix scale (cube root of |det|): world units per data unit.
  static double MatrixScale(vtkVolume* volume);

  // vtkGPUVolumeRayCastMapper's ColorRangeType, ScalarOpacityRangeType and
  // GradientOpacityRangeType (SCALAR or NATIVE).
  struct RangeTypes
  {
    int Color = 0;
    int ScalarOpacity = 0;
    int GradientOpacity = 0;

    bool operator==(const RangeTypes& o) const
    {
      return this->Color == o.Color && this->ScalarOpacity == o.ScalarOpacity &&
        this->GradientOpacity == o.GradientOpacity;
    }
  };

  // Gives the renderer the tables of the volume's property over the input's ranges when
  // anything they are made from changed; false with the reason when the property or the
  // volume's matrix cannot be rendered.
  bool Update(vtkVolume* volume, const vtkFerroVolumeInputHelper& input,
    const RangeTypes& rangeTypes, ferrovol::Renderer& renderer, vtkFerroVolumeReport& report);

  // The transfer function of `prop`'s first component over the data range `range`, for a
  // volume intermixed with the main one or a mesh: colour and scalar opacity, and a
  // gradient opacity read at gradient magnitudes times `gradientScale` (as Update's
  // GradientScale), or refused where that is 0; a 2D function is refused. A refusal says
  // that `what` ("intermixed volumes") are drawn without it; false with the reason.
  static bool BuildFirstComponent(vtkVolumeProperty* prop, const std::array<double, 2>& range,
    const RangeTypes& types, const char* what, double gradientScale,
    std::unique_ptr<ferrovol::TransferFunction>& tf, vtkFerroVolumeReport& report);

  // Forget the upload (the renderer is gone).
  void Reset() { this->Uploaded.reset(); }

  // What the uploaded tables were made from.
  struct Key
  {
    vtkVolumeProperty* Property = nullptr;
    vtkMTimeType PropertyMTime = 0;
    int Components = 0;
    vtkFerroVolumeInputHelper::Ranges Ranges{};
    RangeTypes Types;
    double GradientScale = 0.0;
    vtkMTimeType LabelsMTime = 0;
    vtkMTimeType Tables2DMTime = 0;

    bool operator==(const Key& o) const;
  };

private:
  std::optional<Key> Uploaded;
};

#endif
