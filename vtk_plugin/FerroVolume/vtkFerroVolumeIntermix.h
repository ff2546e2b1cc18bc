// vtkFerroVolumeIntermix: the inputs of the mapper's ports other than 0, drawn with the
// main volume as vtkGPUVolumeRayCastMapper draws the ports of a vtkMultiVolume — each
// port's vtkImageData (first component of the scalars the mapper's array settings pick),
// its vtkVolume's matrix and property — handed to the renderer as intermixed volumes, the
// data converted only when it changed. Internal to the FerroVolume module (not wrapped).
#ifndef vtkFerroVolumeIntermix_h
#define vtkFerroVolumeIntermix_h

#include "vtkFerroVolumeLookupTables.h"
#include "vtkType.h"

#include "ferrovol.hpp"

#include <array>
#include <memory>
#include <string>
#include <vector>

class vtkDataArray;
class vtkFerroVolumeReport;
class vtkImageData;
class vtkMultiVolume;
class vtkVolumeMapper;
class vtkVolumeProperty;

class vtkFerroVolumeIntermix
{
public:
  // Gives the renderer the volumes of `multi`'s ports other than 0 (none: clears them)
  // when any of them, its matrix or its property changed; false with the reason.
  bool Update(vtkVolumeMapper* self, vtkMultiVolume* multi,
    const vtkFerroVolumeLookupTables::RangeTypes& types, ferrovol::Renderer& renderer,
    vtkFerroVolumeReport& report);

  // Forget what was given (the renderer is gone).
  void Reset()
  {
    this->Ports.clear();
    this->Given = false;
  }

private:
  // One port's volume as converted last, and what it was made from.
  struct Port
  {
    int Index = -1;
    vtkImageData* Image = nullptr;
    vtkMTimeType ImageMTime = 0;
    vtkDataArray* Scalars = nullptr;
    vtkMTimeType ScalarsMTime = 0;
    std::unique_ptr<ferrovol::Volume> Volume;
    std::array<double, 2> Range{ { 0.0, 1.0 } };
    // What the transfer function and placement were given from.
    vtkVolumeProperty* Property = nullptr;
    vtkMTimeType PropertyMTime = 0;
    double Matrix[16] = {};
  };
  // The port's volume converted again when its data changed; false with the reason.
  bool Convert(vtkVolumeMapper* self, int port, Port& p, vtkFerroVolumeReport& report);

  std::vector<Port> Ports;
  // Whether the renderer holds intermixed volumes (then an empty update clears them).
  bool Given = false;
};

#endif
