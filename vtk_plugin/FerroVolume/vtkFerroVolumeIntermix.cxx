// See vtkFerroVolumeIntermix.h.
#include "vtkFerroVolumeIntermix.h"

#include "vtkAlgorithm.h"
#include "vtkDataArray.h"
#include "vtkFerroVolumeContext.h"
#include "vtkFerroVolumeReport.h"
#include "vtkImageData.h"
#include "vtkMatrix3x3.h"
#include "vtkMatrix4x4.h"
#include "vtkMultiVolume.h"
#include "vtkVolume.h"
#include "vtkVolumeMapper.h"
#include "vtkVolumeProperty.h"

#include <algorithm>
#include <cstring>

bool vtkFerroVolumeIntermix::Convert(
  vtkVolumeMapper* self, int port, Port& p, vtkFerroVolumeReport& report)
{
  const std::string name = "port " + std::to_string(port);
  if (vtkAlgorithm* source = self->GetInputAlgorithm(port, 0))
  {
    source->Update();
  }
  vtkImageData* image = vtkImageData::SafeDownCast(self->GetInputDataObject(port, 0));
  if (!image)
  {
    return report.Fail("the input on " + name +
      " is not a vtkImageData: volumes intermixed with port 0's are images");
  }
  int cellFlag = 0;
  vtkDataArray* scalars = vtkAbstractMapper::GetScalars(image, self->GetScalarMode(),
    self->GetArrayAccessMode(), self->GetArrayId(), self->GetArrayName(), cellFlag);
  if (!scalars)
  {
    return report.Fail("the input on " + name +
      " has no scalars (the mapper's array settings apply to every port)");
  }
  if (cellFlag != 0)
  {
    return report.Fail("the scalars on " + name +
      " are cell data: volumes intermixed with port 0's take point data");
  }
  if (p.Volume && p.Image == image && p.ImageMTime == image->GetMTime() &&
    p.Scalars == scalars && p.ScalarsMTime == scalars->GetMTime())
  {
    return true;
  }
  int dims[3], extent[6];
  image->GetDimensions(dims);
  image->GetExtent(extent);
  double spacing[3], origin[3];
  image->GetSpacing(spacing);
  image->GetOrigin(origin);
  FvVolumeDesc d;
  std::memset(&d, 0, sizeof(d));
  vtkMatrix3x3* dm = image->GetDirectionMatrix();
  for (int r = 0; r < 3; ++r)
  {
    for (int c = 0; c < 3; ++c)
    {
      d.direction[3 * r + c] = dm ? dm->GetElement(r, c) : (r == c ? 1.0 : 0.0);
    }
  }
  for (int a = 0; a < 3; ++a)
  {
    if (!(spacing[a] > 0.0))
    {
      return report.Fail("the spacing on " + name + " is not positive along every axis");
    }
    d.dims[a] = static_cast<uint32_t>(std::max(dims[a], 0));
    d.spacing[a] = spacing[a];
  }
  // The first point of the extent (which need not start at 0) is the volume's origin.
  for (int r = 0; r < 3; ++r)
  {
    d.origin[r] = origin[r];
    for (int a = 0; a < 3; ++a)
    {
      d.origin[r] += d.direction[3 * r + a] * spacing[a] * extent[2 * a];
    }
  }
  d.components = 1;
  d.scalar_type = FV_SCALAR_TYPE_F32;
  // vtkMultiVolume's shader reads each input's first component.
  const vtkIdType n = scalars->GetNumberOfTuples();
  std::vector<float> values(static_cast<size_t>(n));
  for (vtkIdType i = 0; i < n; ++i)
  {
    values[static_cast<size_t>(i)] = static_cast<float>(scalars->GetComponent(i, 0));
  }
  std::unique_ptr<ferrovol::Volume> volume;
  if (!vtkFerroVolumeCall(("copy the volume on " + name).c_str(), report, [&] {
        volume.reset(new ferrovol::Volume(d, values.data(), values.size() * sizeof(float)));
      }))
  {
    return false;
  }
  double range[2];
  scalars->GetRange(range, 0);
  p.Range = { { range[0], range[1] } };
  p.Volume = std::move(volume);
  p.Image = image;
  p.ImageMTime = image->GetMTime();
  p.Scalars = scalars;
  p.ScalarsMTime = scalars->GetMTime();
  p.Property = nullptr; // the tables span the new range
  return true;
}

bool vtkFerroVolumeIntermix::Update(vtkVolumeMapper* self, vtkMultiVolume* multi,
  const vtkFerroVolumeLookupTables::RangeTypes& types, ferrovol::Renderer& renderer,
  vtkFerroVolumeReport& report)
{
  std::vector<int> ports;
  if (multi)
  {
    for (int port = 1; port < self->GetNumberOfInputPorts(); ++port)
    {
      if (self->GetNumberOfInputConnections(port) > 0)
      {
        if (!multi->GetVolume(port))
        {
          return report.Fail("the mapper has an input on port " + std::to_string(port) +
            " but the vtkMultiVolume no vtkVolume there (SetVolume(volume, " +
            std::to_string(port) + "))");
        }
        ports.push_back(port);
      }
    }
  }
  if (ports.size() > FV_MAX_INTERMIXED_VOLUMES)
  {
    return report.Fail(std::to_string(ports.size() + 1) + " inputs: ferrovol intermixes at most " +
      std::to_string(FV_MAX_INTERMIXED_VOLUMES + 1) + " volumes (ports 0 to " +
      std::to_string(FV_MAX_INTERMIXED_VOLUMES) + ")");
  }
  bool changed = ports.size() != this->Ports.size();
  this->Ports.resize(ports.size());
  for (size_t i = 0; i < ports.size(); ++i)
  {
    Port& p = this->Ports[i];
    if (p.Index != ports[i])
    {
      p = Port();
      p.Index = ports[i];
    }
    const FvVolume* old = p.Volume ? p.Volume->get() : nullptr;
    if (!this->Convert(self, ports[i], p, report))
    {
      return false;
    }
    vtkVolume* vol = multi->GetVolume(ports[i]);
    vol->ComputeMatrix();
    double matrix[16];
    vtkMatrix4x4* m = vol->GetMatrix();
    for (int r = 0; r < 4; ++r)
    {
      for (int c = 0; c < 4; ++c)
      {
        matrix[4 * c + r] = m->GetElement(r, c);
      }
    }
    vtkVolumeProperty* prop = vol->GetProperty();
    changed = changed || old != p.Volume->get() || p.Property != prop ||
      p.PropertyMTime != prop->GetMTime() || !std::equal(matrix, matrix + 16, p.Matrix);
    std::copy(matrix, matrix + 16, p.Matrix);
    p.Property = prop;
    p.PropertyMTime = prop->GetMTime();
  }
  if (!changed && (this->Given || ports.empty()))
  {
    return true;
  }
  std::vector<std::unique_ptr<ferrovol::TransferFunction>> tfs(this->Ports.size());
  std::vector<FvIntermixedVolume> given(this->Ports.size());
  for (size_t i = 0; i < this->Ports.size(); ++i)
  {
    Port& p = this->Ports[i];
    if (!vtkFerroVolumeLookupTables::BuildFirstComponent(
          p.Property, p.Range, types, "intermixed volumes", 0.0, tfs[i], report))
    {
      report.PrefixError("port " + std::to_string(p.Index) + ": ");
      p.Property = nullptr;
      return false;
    }
    given[i].interpolation = p.Property->GetInterpolationType() == VTK_NEAREST_INTERPOLATION
      ? FV_INTERPOLATION_NEAREST
      : FV_INTERPOLATION_LINEAR;
    given[i].volume = p.Volume->get();
    given[i].transfer_function = tfs[i]->get();
    std::copy(p.Matrix, p.Matrix + 16, given[i].matrix);
  }
  if (!vtkFerroVolumeCall("intermix the volumes of the mapper's ports", report,
        [&] { renderer.set_intermixed_volumes(given); }))
  {
    this->Ports.clear();
    return false;
  }
  this->Given = !given.empty();
  return true;
}
