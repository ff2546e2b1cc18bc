// vtkFerroVolumeInputHelper: the mapper's input (vtkImageData or vtkRectilinearGrid and the
// scalars VTK's mappers would pick) → a ferrovol volume, uploaded only when the scalars (array, MTime, geometry)
// changed; also each component's data range, which the tables span. Internal to the
// FerroVolume module (not wrapped).
#ifndef vtkFerroVolumeInputHelper_h
#define vtkFerroVolumeInputHelper_h

#include "vtkType.h"

#include "vtkSmartPointer.h"

#include "ferrovol.hpp"

#include <array>
#include <optional>
#include <tuple>
#include <string>
#include <utility>

class vtkDataArray;
class vtkDataObject;
class vtkFerroVolumeReport;
class vtkImageData;
class vtkRectilinearGrid;
class vtkVolumeMapper;

class vtkFerroVolumeInputHelper
{
public:
  // ferrovol's scalar type and the byte size of a VTK scalar type; false when ferrovol has
  // none.
  static bool ToFvScalarType(int vtkType, uint32_t& fvType, size_t& size);

  using Ranges = std::array<std::array<double, 2>, 4>;

  // Updates the mapper's input and finds its image and scalars (ScalarMode,
  // SelectScalarArray); false with the reason when there are none to render.
  bool Select(vtkVolumeMapper* self, vtkFerroVolumeReport& report);

  // Gives the renderer the selected scalars as a volume, within `budget` bytes of device
  // memory (0: the device's limit), when they or the budget changed since the last upload.
  bool Upload(ferrovol::Renderer& renderer, uint64_t budget, vtkFerroVolumeReport& report);

  // Forget the upload (the renderer is gone).
  void Reset() { this->Uploaded.reset(); }

  // The input as an image: the vtkImageData itself, or for a vtkRectilinearGrid an image
  // of the same extent and data on the uniform lattice over its box (whose points the
  // upload then places at the grid's coordinates).
  vtkImageData* GetImage() const { return this->Image; }
  // vtkOpenGLGPUVolumeRayCastMapper's cell spacing, which its sample distance comes from:
  // the image's spacing, or a rectilinear grid's bounds per axis over its number of points.
  void GetCellSpacing(double spacing[3]) const;
  // Whether the input is a vtkRectilinearGrid.
  bool IsRectilinear() const { return this->Grid != nullptr; }
  // Whether the selected scalars are cell data (the volume's points are the cell centres).
  bool UsesCellData() const { return this->CellFlag == 1; }
  int GetComponents() const { return this->Components; }
  // The selected scalars' VTK type (VTK_VOID before Select).
  int GetDataType() const;
  // Each component's finite data range, widened to the whole dataset's (SetWholeRanges).
  const Ranges& GetRanges() const { return this->Effective; }
  // The whole dataset's range of each component the input is a piece of (none: the
  // input's own), which GetRanges() spans besides the input's.
  using WholeRanges = std::array<std::optional<std::array<double, 2>>, 4>;
  void SetWholeRanges(const WholeRanges& whole);
  // The mean voxel spacing, VTK's unit of gradient magnitude.
  double GetMeanSpacing() const { return this->MeanSpacing; }

  // Points and cells the input's ghost arrays mark (any non-zero byte: hidden or duplicate,
  // what vtkGPUVolumeRayCastMapper's blanking leaves out), counted when an array changes.
  struct Ghosts
  {
    vtkIdType Points = 0;
    vtkIdType Cells = 0;
  };

  // Gives the renderer the blanking mask of the ghost arrays (or clears it) when they or the
  // uploaded volume changed; false with the reason when the renderer refuses it.
  bool UpdateBlanking(ferrovol::Renderer& renderer, vtkFerroVolumeReport& report);

  // Gives the renderer `mask` (vtkGPUVolumeRayCastMapper's MaskInput, nullptr for none)
  // with `maskType` (BinaryMaskType or LabelMapMaskType), or clears it, when the mask, its
  // scalars, the type or the uploaded volume changed; false with the reason (the mask is
  // then cleared).
  bool UpdateMask(
    vtkImageData* mask, int maskType, ferrovol::Renderer& renderer, vtkFerroVolumeReport& report);

private:
  // What the uploaded volume was made from: anything here changing means a new upload.
  struct Key
  {
    vtkDataObject* Input = nullptr;
    vtkMTimeType InputMTime = 0;
    vtkDataArray* Scalars = nullptr;
    vtkMTimeType ScalarsMTime = 0;
    int CellFlag = -1;
    int Dims[3] = { 0, 0, 0 };
    int DataType = -1;
    int Components = 0;
    uint64_t Budget = 0;

    bool operator==(const Key& o) const;
  };

  vtkImageData* Image = nullptr;
  vtkDataArray* Scalars = nullptr;
  // A rectilinear input, its image (rebuilt when the grid's MTime changes) and that MTime.
  vtkRectilinearGrid* Grid = nullptr;
  vtkSmartPointer<vtkImageData> GridImage;
  vtkMTimeType GridImageMTime = 0;
  int CellFlag = 0;

  // The image of the rectilinear input (GetImage), made again when the grid changed; null
  // with the reason when its coordinate arrays do not match its dimensions.
  vtkImageData* ImageOfGrid(vtkFerroVolumeReport& report);

  // Counts the marked entries of the image's ghost arrays, when they changed.
  void CountGhosts();

  std::optional<Key> Uploaded;
  // The ghost arrays counted last: (array, MTime) for points and for cells.
  std::array<std::pair<vtkDataArray*, vtkMTimeType>, 2> GhostKey{};
  Ghosts GhostCounts;
  // The mask must be (re)sent: the ghost arrays or the volume changed.
  bool BlankingStale = true;
  // What the mask sent last was made from: (image, its MTime, scalars, their MTime, type);
  // reset by a new volume upload.
  std::optional<std::tuple<vtkImageData*, vtkMTimeType, vtkDataArray*, vtkMTimeType, int>>
    MaskKey;
  uint32_t UploadedDims[3] = { 0, 0, 0 };
  int Components = 0;
  Ranges ComponentRanges{};
  WholeRanges Whole{};
  Ranges Effective{};
  double MeanSpacing = 1.0;
};

#endif
