#include "vtkFerroVolumeInputHelper.h"

#include "vtkAlgorithm.h"
#include "vtkCellData.h"
#include "vtkDataArray.h"
#include "vtkFerroVolumeContext.h"
#include "vtkFerroVolumeReport.h"
#include "vtkGPUVolumeRayCastMapper.h"
#include "vtkImageData.h"
#include "vtkMatrix3x3.h"
#include "vtkPointData.h"
#include "vtkRectilinearGrid.h"
#include "vtkUnsignedCharArray.h"
#include "vtkVolumeMapper.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>
#include <memory>
#include <sstream>
#include <vector>

namespace
{

// The scalars of the input as VTK's mappers pick them (ScalarMode, SelectScalarArray), or an
// error saying why there are none.
vtkDataArray* FindScalars(vtkVolumeMapper* self, vtkImageData* image, int& cellFlag,
  vtkFerroVolumeReport& report)
{
  cellFlag = 0;
  vtkDataArray* scalars = vtkAbstractMapper::GetScalars(image, self->GetScalarMode(),
    self->GetArrayAccessMode(), self->GetArrayId(), self->GetArrayName(), cellFlag);
  if (scalars)
  {
    return scalars;
  }
  const int mode = self->GetScalarMode();
  const bool byName = self->GetArrayAccessMode() == VTK_GET_ARRAY_BY_NAME;
  std::string what = byName && self->GetArrayName()
    ? std::string("array '") + self->GetArrayName() + "'"
    : "array " + std::to_string(self->GetArrayId());
  vtkAbstractArray* abstract = nullptr;
  if (mode == VTK_SCALAR_MODE_USE_POINT_FIELD_DATA)
  {
    abstract = byName ? image->GetPointData()->GetAbstractArray(self->GetArrayName())
                      : image->GetPointData()->GetAbstractArray(self->GetArrayId());
  }
  else if (mode == VTK_SCALAR_MODE_USE_CELL_FIELD_DATA)
  {
    abstract = byName ? image->GetCellData()->GetAbstractArray(self->GetArrayName())
                      : image->GetCellData()->GetAbstractArray(self->GetArrayId());
  }
  if (abstract)
  {
    report.Fail("the selected " + what + " (" + abstract->GetClassName() +
      ") is not numeric: volume rendering needs numeric scalars");
  }
  else if (mode == VTK_SCALAR_MODE_USE_POINT_FIELD_DATA ||
    mode == VTK_SCALAR_MODE_USE_CELL_FIELD_DATA)
  {
    report.Fail(std::string("the input has no ") +
      (mode == VTK_SCALAR_MODE_USE_POINT_FIELD_DATA ? "point" : "cell") + " data " + what +
      " (see SelectScalarArray)");
  }
  else
  {
    report.Fail("the input has no scalars to render (set point or cell scalars, or select an "
                "array with SetScalarModeToUsePointFieldData + SelectScalarArray)");
  }
  return nullptr;
}

// The volume to upload: geometry after cell centring and slab thickening, and the bytes.
struct PreparedVolume
{
  FvVolumeDesc Desc;
  const void* Data = nullptr;
  size_t Bytes = 0;
  std::vector<unsigned char> Storage;
  double MeanSpacing = 1.0;
};

bool PrepareVolume(vtkImageData* image, vtkDataArray* scalars, bool cells, PreparedVolume& out,
  vtkFerroVolumeReport& report)
{
  int pointDims[3];
  image->GetDimensions(pointDims);
  double spacing[3], origin[3], dir[9];
  image->GetSpacing(spacing);
  image->GetOrigin(origin);
  vtkMatrix3x3* dm = image->GetDirectionMatrix();
  for (int r = 0; r < 3; ++r)
  {
    for (int c = 0; c < 3; ++c)
    {
      dir[3 * r + c] = dm ? dm->GetElement(r, c) : (r == c ? 1.0 : 0.0);
    }
  }
  // The first point of the extent (which need not start at 0) is the volume's origin.
  int extent[6];
  image->GetExtent(extent);
  for (int r = 0; r < 3; ++r)
  {
    for (int a = 0; a < 3; ++a)
    {
      origin[r] += dir[3 * r + a] * spacing[a] * extent[2 * a];
    }
  }
  for (int a = 0; a < 3; ++a)
  {
    if (pointDims[a] < 1)
    {
      return report.Fail("the input image is empty (dimensions " +
        std::to_string(pointDims[0]) + "x" + std::to_string(pointDims[1]) + "x" +
        std::to_string(pointDims[2]) + ")");
    }
  }

  // Cell data: one value per cell, rendered as the grid of cell centres.
  int dims[3];
  for (int a = 0; a < 3; ++a)
  {
    dims[a] = cells ? std::max(pointDims[a] - 1, 1) : pointDims[a];
    if (cells && pointDims[a] > 1)
    {
      for (int r = 0; r < 3; ++r)
      {
        origin[r] += dir[3 * r + a] * 0.5 * spacing[a];
      }
    }
  }

  const int comps = scalars->GetNumberOfComponents();
  if (comps < 1 || comps > 4)
  {
    return report.Fail("the scalars '" + std::string(scalars->GetName() ? scalars->GetName() : "") +
      "' have " + std::to_string(comps) +
      " components; ferrovol renders 1 to 4 (pick components with "
      "vtkImageExtractComponents)");
  }
  const vtkIdType expected = static_cast<vtkIdType>(dims[0]) * dims[1] * dims[2];
  if (scalars->GetNumberOfTuples() != expected)
  {
    return report.Fail("the scalars have " + std::to_string(scalars->GetNumberOfTuples()) +
      " tuples but " + std::to_string(dims[0]) + "x" + std::to_string(dims[1]) + "x" +
      std::to_string(dims[2]) + (cells ? " cells" : " points") + " need " + std::to_string(expected));
  }
  uint32_t fvType = 0;
  size_t typeSize = 0;
  if (!vtkFerroVolumeInputHelper::ToFvScalarType(scalars->GetDataType(), fvType, typeSize))
  {
    return report.Fail(std::string("scalars of type ") + scalars->GetDataTypeAsString() +
      " cannot be volume rendered (cast them with vtkImageCast)");
  }

  // Spacing: positive along every axis (a negative one flips the direction column); an
  // axis with one point may have any spacing (it is only the slab's thickness).
  double positive[3] = { 0, 0, 0 };
  double minPositive = std::numeric_limits<double>::infinity();
  for (int a = 0; a < 3; ++a)
  {
    if (!std::isfinite(spacing[a]))
    {
      return report.Fail("the input spacing is not finite");
    }
    if (spacing[a] != 0.0)
    {
      minPositive = std::min(minPositive, std::fabs(spacing[a]));
    }
  }
  static const char* axisName[3] = { "x", "y", "z" };
  for (int a = 0; a < 3; ++a)
  {
    if (spacing[a] == 0.0)
    {
      if (dims[a] > 1)
      {
        std::ostringstream s;
        s << "the input spacing (" << spacing[0] << ", " << spacing[1] << ", " << spacing[2]
          << ") is zero along " << axisName[a] << ", which has " << dims[a]
          << " points: every spacing must be non-zero";
        return report.Fail(s.str());
      }
      positive[a] = std::isfinite(minPositive) ? minPositive : 1.0;
    }
    else
    {
      positive[a] = std::fabs(spacing[a]);
      if (spacing[a] < 0.0)
      {
        for (int r = 0; r < 3; ++r)
        {
          dir[3 * r + a] = -dir[3 * r + a];
        }
      }
    }
  }

  // The bytes: the array's own memory where possible.
  const size_t elem = typeSize * comps;
  const size_t count = static_cast<size_t>(expected);
  const unsigned char* src = nullptr;
  std::vector<unsigned char> bits;
  if (scalars->GetDataType() == VTK_BIT)
  {
    bits.resize(count * comps);
    for (size_t i = 0; i < count; ++i)
    {
      for (int c = 0; c < comps; ++c)
      {
        bits[i * comps + c] =
          scalars->GetComponent(static_cast<vtkIdType>(i), c) != 0.0 ? 1 : 0;
      }
    }
    src = bits.data();
  }
  else
  {
    src = static_cast<const unsigned char*>(scalars->GetVoidPointer(0));
  }
  if (!src)
  {
    return report.Fail("the scalars' memory could not be read");
  }

  // An axis with a single point becomes a slab one spacing thick, centred on the plane:
  // the slice is duplicated and the origin moved back half a spacing.
  int nd[3];
  bool flat = false;
  for (int a = 0; a < 3; ++a)
  {
    nd[a] = dims[a] == 1 ? 2 : dims[a];
    if (dims[a] == 1)
    {
      flat = true;
      for (int r = 0; r < 3; ++r)
      {
        origin[r] -= dir[3 * r + a] * 0.5 * positive[a];
      }
    }
  }
  if (flat)
  {
    out.Storage.resize(static_cast<size_t>(nd[0]) * nd[1] * nd[2] * elem);
    for (int k = 0; k < nd[2]; ++k)
    {
      const int sk = std::min(k, dims[2] - 1);
      for (int j = 0; j < nd[1]; ++j)
      {
        const int sj = std::min(j, dims[1] - 1);
        const unsigned char* srow =
          src + (static_cast<size_t>(sk) * dims[1] + sj) * dims[0] * elem;
        unsigned char* drow =
          out.Storage.data() + (static_cast<size_t>(k) * nd[1] + j) * nd[0] * elem;
        if (dims[0] == 1)
        {
          std::memcpy(drow, srow, elem);
          std::memcpy(drow + elem, srow, elem);
        }
        else
        {
          std::memcpy(drow, srow, dims[0] * elem);
        }
      }
    }
    out.Data = out.Storage.data();
    out.Bytes = out.Storage.size();
  }
  else if (!bits.empty())
  {
    out.Storage.swap(bits);
    out.Data = out.Storage.data();
    out.Bytes = out.Storage.size();
  }
  else
  {
    out.Data = src;
    out.Bytes = count * elem;
  }

  FvVolumeDesc& d = out.Desc;
  std::memset(&d, 0, sizeof(d));
  for (int a = 0; a < 3; ++a)
  {
    d.dims[a] = static_cast<uint32_t>(nd[a]);
    d.spacing[a] = positive[a];
    d.origin[a] = origin[a];
  }
  for (int i = 0; i < 9; ++i)
  {
    d.direction[i] = dir[i];
  }
  d.components = static_cast<uint32_t>(comps);
  d.scalar_type = fvType;
  // VTK's gradient magnitude unit (vtkVolumeShaderComposer.h, computeGradient) uses the mean
  // spacing of the input.
  out.MeanSpacing = (positive[0] + positive[1] + positive[2]) / 3.0;
  return true;
}

// A rectilinear grid's coordinates as the prepared volume's points: each axis's
// coordinates, the cells' centres for cell data, and an axis of one point (or cell)
// thickened as PrepareVolume thickens it, to a slab one spacing thick centred on it.
std::array<std::vector<double>, 3> GridCoordinates(
  vtkRectilinearGrid* grid, bool cells, const FvVolumeDesc& desc)
{
  vtkDataArray* arrays[3] = { grid->GetXCoordinates(), grid->GetYCoordinates(),
    grid->GetZCoordinates() };
  std::array<std::vector<double>, 3> out;
  for (int a = 0; a < 3; ++a)
  {
    std::vector<double> c;
    const vtkIdType n = arrays[a] ? arrays[a]->GetNumberOfTuples() : 0;
    for (vtkIdType i = 0; i < n; ++i)
    {
      c.push_back(arrays[a]->GetComponent(i, 0));
    }
    if (cells && c.size() > 1)
    {
      for (size_t i = 0; i + 1 < c.size(); ++i)
      {
        c[i] = 0.5 * (c[i] + c[i + 1]);
      }
      c.pop_back();
    }
    if (c.size() == 1 && desc.dims[a] == 2)
    {
      const double h = 0.5 * desc.spacing[a];
      c = { c[0] - h, c[0] + h };
    }
    out[a] = std::move(c);
  }
  return out;
}
} // namespace

bool vtkFerroVolumeInputHelper::ToFvScalarType(int vtkType, uint32_t& fvType, size_t& size)
{
  struct Entry
  {
    int Vtk;
    FvScalarType Fv;
    size_t Size;
  };
  static const Entry table[] = {
    { VTK_CHAR, std::numeric_limits<char>::is_signed ? FV_SCALAR_TYPE_I8 : FV_SCALAR_TYPE_U8, 1 },
    { VTK_SIGNED_CHAR, FV_SCALAR_TYPE_I8, 1 },
    { VTK_UNSIGNED_CHAR, FV_SCALAR_TYPE_U8, 1 },
    { VTK_BIT, FV_SCALAR_TYPE_U8, 1 }, // converted to one byte per value first
    { VTK_SHORT, FV_SCALAR_TYPE_I16, 2 },
    { VTK_UNSIGNED_SHORT, FV_SCALAR_TYPE_U16, 2 },
    { VTK_INT, FV_SCALAR_TYPE_I32, 4 },
    { VTK_UNSIGNED_INT, FV_SCALAR_TYPE_U32, 4 },
    { VTK_LONG, sizeof(long) == 8 ? FV_SCALAR_TYPE_I64 : FV_SCALAR_TYPE_I32, sizeof(long) },
    { VTK_UNSIGNED_LONG, sizeof(unsigned long) == 8 ? FV_SCALAR_TYPE_U64 : FV_SCALAR_TYPE_U32,
      sizeof(unsigned long) },
    { VTK_LONG_LONG, FV_SCALAR_TYPE_I64, 8 },
    { VTK_UNSIGNED_LONG_LONG, FV_SCALAR_TYPE_U64, 8 },
    { VTK_ID_TYPE, sizeof(vtkIdType) == 8 ? FV_SCALAR_TYPE_I64 : FV_SCALAR_TYPE_I32,
      sizeof(vtkIdType) },
    { VTK_FLOAT, FV_SCALAR_TYPE_F32, 4 },
    { VTK_DOUBLE, FV_SCALAR_TYPE_F64, 8 },
  };
  for (const Entry& e : table)
  {
    if (e.Vtk == vtkType)
    {
      fvType = static_cast<uint32_t>(e.Fv);
      size = e.Size;
      return true;
    }
  }
  return false;
}

bool vtkFerroVolumeInputHelper::Key::operator==(const Key& o) const
{
  return this->Input == o.Input && this->InputMTime == o.InputMTime &&
    this->Scalars == o.Scalars && this->ScalarsMTime == o.ScalarsMTime &&
    this->CellFlag == o.CellFlag && this->Dims[0] == o.Dims[0] && this->Dims[1] == o.Dims[1] &&
    this->Dims[2] == o.Dims[2] && this->DataType == o.DataType &&
    this->Components == o.Components && this->Budget == o.Budget;
}

int vtkFerroVolumeInputHelper::GetDataType() const
{
  return this->Scalars ? this->Scalars->GetDataType() : VTK_VOID;
}

bool vtkFerroVolumeInputHelper::Select(vtkVolumeMapper* self, vtkFerroVolumeReport& report)
{
  this->Image = nullptr;
  this->Scalars = nullptr;
  vtkAlgorithm* alg = self->GetInputAlgorithm();
  if (!alg || self->GetNumberOfInputConnections(0) < 1)
  {
    return report.Fail("no input: connect a vtkImageData (SetInputData / SetInputConnection)");
  }
  alg->Update();
  vtkDataSet* dataset = self->GetInput();
  vtkImageData* image = vtkImageData::SafeDownCast(dataset);
  this->Grid = vtkRectilinearGrid::SafeDownCast(dataset);
  if (this->Grid)
  {
    image = this->ImageOfGrid(report);
    if (!image)
    {
      return false;
    }
  }
  if (!image)
  {
    return report.Fail(std::string("the input is ") +
      (dataset ? dataset->GetClassName() : "empty") +
      ": vtkFerroVolumeMapper renders vtkImageData and vtkRectilinearGrid");
  }
  vtkDataArray* scalars = FindScalars(self, image, this->CellFlag, report);
  if (!scalars)
  {
    return false;
  }
  if (this->CellFlag == 2)
  {
    return report.Fail("field data scalars cannot be volume rendered: select point or cell data");
  }
  this->Image = image;
  this->Scalars = scalars;
  this->CountGhosts();
  return true;
}

void vtkFerroVolumeInputHelper::GetCellSpacing(double spacing[3]) const
{
  if (!this->Grid)
  {
    this->Image->GetSpacing(spacing);
    return;
  }
  double bounds[6];
  int dims[3];
  this->Grid->GetBounds(bounds);
  this->Grid->GetDimensions(dims);
  for (int a = 0; a < 3; ++a)
  {
    spacing[a] = (bounds[2 * a + 1] - bounds[2 * a]) / dims[a];
  }
}

vtkImageData* vtkFerroVolumeInputHelper::ImageOfGrid(vtkFerroVolumeReport& report)
{
  vtkRectilinearGrid* grid = this->Grid;
  if (this->GridImage && this->GridImageMTime == grid->GetMTime())
  {
    return this->GridImage;
  }
  vtkDataArray* arrays[3] = { grid->GetXCoordinates(), grid->GetYCoordinates(),
    grid->GetZCoordinates() };
  int dims[3];
  grid->GetDimensions(dims);
  double origin[3], spacing[3];
  static const char* axisName[3] = { "x", "y", "z" };
  for (int a = 0; a < 3; ++a)
  {
    if (!arrays[a] || arrays[a]->GetNumberOfTuples() != dims[a] || dims[a] < 1)
    {
      report.Fail(std::string("the rectilinear grid's ") + axisName[a] + " coordinates number " +
        std::to_string(arrays[a] ? arrays[a]->GetNumberOfTuples() : 0) + " for " +
        std::to_string(dims[a]) + " points along " + axisName[a] + ": give one per point");
      return nullptr;
    }
    const vtkIdType n = dims[a];
    origin[a] = arrays[a]->GetComponent(0, 0);
    spacing[a] = n > 1 ? (arrays[a]->GetComponent(n - 1, 0) - origin[a]) / (n - 1) : 0.0;
  }
  this->GridImage = vtkSmartPointer<vtkImageData>::New();
  this->GridImage->SetExtent(grid->GetExtent());
  this->GridImage->SetSpacing(spacing);
  // (the extent's first point is the origin the grid's coordinates give)
  const int* e = grid->GetExtent();
  this->GridImage->SetOrigin(origin[0] - spacing[0] * e[0], origin[1] - spacing[1] * e[2],
    origin[2] - spacing[2] * e[4]);
  this->GridImage->GetPointData()->ShallowCopy(grid->GetPointData());
  this->GridImage->GetCellData()->ShallowCopy(grid->GetCellData());
  this->GridImageMTime = grid->GetMTime();
  return this->GridImage;
}

void vtkFerroVolumeInputHelper::CountGhosts()
{
  vtkDataArray* arrays[2] = { this->Image->GetPointGhostArray(),
    this->Image->GetCellGhostArray() };
  vtkIdType* counts[2] = { &this->GhostCounts.Points, &this->GhostCounts.Cells };
  for (int a = 0; a < 2; ++a)
  {
    const std::pair<vtkDataArray*, vtkMTimeType> key(
      arrays[a], arrays[a] ? arrays[a]->GetMTime() : 0);
    if (key == this->GhostKey[a])
    {
      continue;
    }
    this->GhostKey[a] = key;
    this->BlankingStale = true;
    *counts[a] = 0;
    if (vtkUnsignedCharArray* ghosts = vtkUnsignedCharArray::SafeDownCast(arrays[a]))
    {
      const unsigned char* v = ghosts->GetPointer(0);
      const vtkIdType n = ghosts->GetNumberOfValues();
      *counts[a] = n - std::count(v, v + n, static_cast<unsigned char>(0));
    }
  }
}

bool vtkFerroVolumeInputHelper::Upload(
  ferrovol::Renderer& renderer, uint64_t budget, vtkFerroVolumeReport& report)
{
  Key key;
  key.Budget = budget;
  key.Input = this->Image;
  key.InputMTime = this->Image->GetMTime();
  key.Scalars = this->Scalars;
  key.ScalarsMTime = this->Scalars->GetMTime();
  key.CellFlag = this->CellFlag;
  this->Image->GetDimensions(key.Dims);
  key.DataType = this->Scalars->GetDataType();
  key.Components = this->Scalars->GetNumberOfComponents();
  if (this->Uploaded && *this->Uploaded == key)
  {
    return true;
  }
  this->Uploaded.reset();
  PreparedVolume pv;
  if (!PrepareVolume(this->Image, this->Scalars, this->CellFlag == 1, pv, report))
  {
    return false;
  }
  std::unique_ptr<ferrovol::Volume> volume;
  if (!vtkFerroVolumeCall("take the input volume", report,
        [&] {
          volume.reset(new ferrovol::Volume(pv.Desc, pv.Data, pv.Bytes));
          if (this->Grid)
          {
            const auto c = GridCoordinates(this->Grid, this->CellFlag == 1, pv.Desc);
            volume->set_coordinates(c[0], c[1], c[2]);
          }
        }) ||
    !vtkFerroVolumeCall("upload the volume", report, [&] {
      renderer.set_memory_budget(budget);
      renderer.set_volume(*volume);
    }))
  {
    return false;
  }
  this->Components = key.Components;
  this->ComponentRanges = {};
  for (int c = 0; c < this->Components; ++c)
  {
    double range[2] = { 0.0, 0.0 };
    if (this->Scalars->GetDataType() == VTK_BIT)
    {
      this->Scalars->GetRange(range, c);
    }
    else
    {
      this->Scalars->GetFiniteRange(range, c);
    }
    this->ComponentRanges[c] = { range[0], range[1] };
  }
  this->SetWholeRanges(this->Whole);
  this->MeanSpacing = pv.MeanSpacing;
  std::copy(pv.Desc.dims, pv.Desc.dims + 3, this->UploadedDims);
  this->BlankingStale = true;
  this->MaskKey.reset();
  this->Uploaded = key;
  return true;
}

void vtkFerroVolumeInputHelper::SetWholeRanges(const WholeRanges& whole)
{
  this->Whole = whole;
  this->Effective = this->ComponentRanges;
  for (int c = 0; c < this->Components && c < 4; ++c)
  {
    if (whole[c])
    {
      this->Effective[c] = { std::min(this->Effective[c][0], (*whole[c])[0]),
        std::max(this->Effective[c][1], (*whole[c])[1]) };
    }
  }
}

// vtkGPUVolumeRayCastMapper's blanking texture, on ferrovol's grid: a point is hidden where
// its point ghost byte, or the byte of the cell it starts (the last cell for an axis's last
// point), is non-zero. Cell data (a grid of cell centres): the cell's own byte, or its first
// corner's point byte. An axis of one point, uploaded as two, repeats it.
bool vtkFerroVolumeInputHelper::UpdateBlanking(
  ferrovol::Renderer& renderer, vtkFerroVolumeReport& report)
{
  if (!this->BlankingStale)
  {
    return true;
  }
  this->BlankingStale = false;
  if (this->GhostCounts.Points == 0 && this->GhostCounts.Cells == 0)
  {
    return vtkFerroVolumeCall(
      "clear the blanking", report, [&] { renderer.set_blanking(nullptr, 0); });
  }
  vtkUnsignedCharArray* pg = vtkUnsignedCharArray::SafeDownCast(this->Image->GetPointGhostArray());
  vtkUnsignedCharArray* cg = vtkUnsignedCharArray::SafeDownCast(this->Image->GetCellGhostArray());
  int pd[3];
  this->Image->GetDimensions(pd);
  int cd[3];
  for (int a = 0; a < 3; ++a)
  {
    cd[a] = std::max(pd[a] - 1, 1);
  }
  const uint32_t* vd = this->UploadedDims;
  std::vector<uint8_t> mask(static_cast<size_t>(vd[0]) * vd[1] * vd[2], 0);
  size_t at = 0;
  for (uint32_t k = 0; k < vd[2]; ++k)
  {
    for (uint32_t j = 0; j < vd[1]; ++j)
    {
      for (uint32_t i = 0; i < vd[0]; ++i, ++at)
      {
        const int q[3] = { static_cast<int>(i), static_cast<int>(j), static_cast<int>(k) };
        int p[3], c[3];
        for (int a = 0; a < 3; ++a)
        {
          p[a] = std::min(q[a], pd[a] - 1);
          c[a] = std::min(q[a], cd[a] - 1);
        }
        const vtkIdType point = (static_cast<vtkIdType>(p[2]) * pd[1] + p[1]) * pd[0] + p[0];
        const vtkIdType cell = (static_cast<vtkIdType>(c[2]) * cd[1] + c[1]) * cd[0] + c[0];
        const bool hidden =
          (pg && pg->GetValue(point) != 0) || (cg && cg->GetValue(cell) != 0);
        mask[at] = hidden ? 1 : 0;
      }
    }
  }
  return vtkFerroVolumeCall(
    "blank the volume", report, [&] { renderer.set_blanking(mask.data(), mask.size()); });
}

// vtkGPUVolumeRayCastMapper's mask texture, on ferrovol's grid: the mask image must have the
// input's extent; its point scalars mask point data, its cell scalars cell data (first
// component). Binary: a point is kept where its value is above 0 (VTK tests the texture
// value > 0). Label map: the value is the point's label, an integer 0 to 255.
bool vtkFerroVolumeInputHelper::UpdateMask(
  vtkImageData* mask, int maskType, ferrovol::Renderer& renderer, vtkFerroVolumeReport& report)
{
  vtkDataArray* scalars = nullptr;
  if (mask)
  {
    scalars = this->CellFlag == 1 ? mask->GetCellData()->GetScalars()
                                  : mask->GetPointData()->GetScalars();
  }
  const auto key = std::make_tuple(mask, mask ? mask->GetMTime() : 0, scalars,
    scalars ? scalars->GetMTime() : 0, maskType);
  if (this->MaskKey && *this->MaskKey == key)
  {
    return true;
  }
  this->MaskKey = key;
  auto clear = [&] { renderer.set_mask(nullptr, 0, FV_MASK_TYPE_BINARY); };
  if (!mask)
  {
    return vtkFerroVolumeCall("clear the mask", report, clear);
  }
  std::string problem;
  int md[3], pd[3];
  mask->GetDimensions(md);
  this->Image->GetDimensions(pd);
  const char* where = this->CellFlag == 1 ? "cell" : "point";
  if (!std::equal(md, md + 3, pd))
  {
    std::ostringstream os;
    os << "the mask input is " << md[0] << "x" << md[1] << "x" << md[2]
       << " points and the volume " << pd[0] << "x" << pd[1] << "x" << pd[2]
       << ": a mask needs the volume's extent";
    problem = os.str();
  }
  else if (!scalars)
  {
    problem = std::string("the mask input has no ") + where + " scalars (the volume's are " +
      where + " data)";
  }
  const bool labels = maskType == vtkGPUVolumeRayCastMapper::LabelMapMaskType;
  std::vector<uint8_t> values;
  if (problem.empty())
  {
    int sd[3];
    for (int a = 0; a < 3; ++a)
    {
      sd[a] = this->CellFlag == 1 ? std::max(pd[a] - 1, 1) : pd[a];
    }
    const uint32_t* vd = this->UploadedDims;
    values.resize(static_cast<size_t>(vd[0]) * vd[1] * vd[2]);
    size_t at = 0;
    for (uint32_t k = 0; k < vd[2] && problem.empty(); ++k)
    {
      for (uint32_t j = 0; j < vd[1] && problem.empty(); ++j)
      {
        for (uint32_t i = 0; i < vd[0]; ++i, ++at)
        {
          const int q[3] = { static_cast<int>(i), static_cast<int>(j), static_cast<int>(k) };
          vtkIdType id = 0;
          for (int a = 2; a >= 0; --a)
          {
            id = id * sd[a] + std::min(q[a], sd[a] - 1);
          }
          const double v = scalars->GetComponent(id, 0);
          if (!labels)
          {
            values[at] = v > 0.0 ? 1 : 0;
          }
          else if (v >= 0.0 && v <= 255.0 && v == std::floor(v))
          {
            values[at] = static_cast<uint8_t>(v);
          }
          else
          {
            std::ostringstream os;
            os << "the label map holds " << v << " at " << where << " " << id
               << ": labels are integers from 0 to 255";
            problem = os.str();
            break;
          }
        }
      }
    }
  }
  if (!problem.empty())
  {
    vtkFerroVolumeCall("clear the mask", report, clear);
    return report.Fail(problem);
  }
  return vtkFerroVolumeCall("set the mask", report, [&] {
    renderer.set_mask(
      values.data(), values.size(), labels ? FV_MASK_TYPE_LABEL_MAP : FV_MASK_TYPE_BINARY);
  });
}
