/**
 * @class   vtkFerroVolumeMapper
 * @brief   vtkVolumeMapper that ray casts with ferrovol (Rust, wgpu) and composites the
 *          result into VTK's OpenGL framebuffer.
 *
 * A drop-in replacement for vtkGPUVolumeRayCastMapper on vtkImageData inputs:
 *
 * - input: point or cell scalars (ScalarMode, SelectScalarArray), every numeric VTK scalar
 *   type, 1 to 4 components, origin, spacing and direction matrix; cell data is rendered as
 *   the grid of cell centres; an axis with a single point (a 2D image, 1xNxM) is rendered as
 *   a slab one spacing thick;
 * - vtkVolumeProperty: colour (RGB or gray), scalar opacity, gradient opacity (in VTK's
 *   units: the x axis is converted to ferrovol's), unit distance, component weights,
 *   IndependentComponents, Shade/Ambient/Diffuse/Specular/SpecularPower, interpolation;
 *   the tables span each component's data range as vtkGPUVolumeRayCastMapper's do;
 * - vtkVolumeMapper: composite, maximum, minimum, average (AverageIPScalarRange) and
 *   additive blend modes (isosurface and slice are refused with an error), cropping with
 *   region flags, clipping planes (world coordinates);
 * - vtkGPUVolumeRayCastMapper's sampling settings with the same meaning:
 *   AutoAdjustSampleDistances, SampleDistance, ImageSampleDistance, UseJittering;
 * - the renderer's lights (headlight, light kit, scene lights; at most 8 switched on);
 * - opaque geometry: rays stop at VTK's depth buffer, and the volume writes its own depth
 *   (first visible sample) so that later passes composite against it.
 *
 * The volume is uploaded again only when the input scalars change, the tables only when the
 * property changes; camera changes never upload anything (GetVolumeUploadCount,
 * GetTableUploadCount).
 *
 * Frames travel from ferrovol to OpenGL either through memory both APIs share (zero copy:
 * Vulkan external memory imported with GL_EXT_memory_object_fd) or by a CPU readback; see
 * SetOutputPath and GetOutputPathName / GetOutputPathReason.
 */

#ifndef vtkFerroVolumeMapper_h
#define vtkFerroVolumeMapper_h

#include "vtkFerroVolumeModule.h" // For export macro
#include "vtkVolumeMapper.h"

class vtkRenderer;
class vtkVolume;
class vtkWindow;

class VTKFERROVOLUME_EXPORT vtkFerroVolumeMapper : public vtkVolumeMapper
{
public:
  static vtkFerroVolumeMapper* New();
  vtkTypeMacro(vtkFerroVolumeMapper, vtkVolumeMapper);
  void PrintSelf(ostream& os, vtkIndent indent) override;

  ///@{
  /**
   * As vtkGPUVolumeRayCastMapper: when on (the default), the sample distance along rays is
   * the smallest voxel spacing in world coordinates and ImageSampleDistance is ignored; when
   * off, SampleDistance and ImageSampleDistance are used.
   */
  vtkSetClampMacro(AutoAdjustSampleDistances, vtkTypeBool, 0, 1);
  vtkGetMacro(AutoAdjustSampleDistances, vtkTypeBool);
  vtkBooleanMacro(AutoAdjustSampleDistances, vtkTypeBool);
  ///@}

  ///@{
  /**
   * World distance between samples along a ray when AutoAdjustSampleDistances is off
   * (default 1.0, as vtkGPUVolumeRayCastMapper). Must be positive.
   */
  vtkSetMacro(SampleDistance, float);
  vtkGetMacro(SampleDistance, float);
  ///@}

  ///@{
  /**
   * Pixels per ray along each screen axis when AutoAdjustSampleDistances is off: 2 renders
   * a quarter of the rays and scales the image up linearly (default 1).
   */
  vtkSetClampMacro(ImageSampleDistance, float, 0.1f, 100.0f);
  vtkGetMacro(ImageSampleDistance, float);
  ///@}

  ///@{
  /**
   * Offset each ray's first sample by a per-pixel fraction of a step, trading wood-grain
   * artifacts for noise (default off).
   */
  vtkSetClampMacro(UseJittering, vtkTypeBool, 0, 1);
  vtkGetMacro(UseJittering, vtkTypeBool);
  vtkBooleanMacro(UseJittering, vtkTypeBool);
  ///@}

  ///@{
  /**
   * Skip blocks the transfer function makes fully transparent (composite mode, default on;
   * does not change the image).
   */
  vtkSetClampMacro(EmptySpaceSkipping, vtkTypeBool, 0, 1);
  vtkGetMacro(EmptySpaceSkipping, vtkTypeBool);
  vtkBooleanMacro(EmptySpaceSkipping, vtkTypeBool);
  ///@}

  enum OutputPaths
  {
    OUTPUT_PATH_AUTOMATIC = 0,
    OUTPUT_PATH_READBACK = 1,
    OUTPUT_PATH_SHARED = 2
  };

  ///@{
  /**
   * How frames travel from ferrovol to OpenGL.
   * AUTOMATIC (default): shared memory (zero copy) where this build, the device and the
   * OpenGL context allow it (GL_EXT_memory_object_fd, same device and driver UUIDs) and the
   * device is a CPU device (Mesa's lavapipe with llvmpipe: ferrovol shares images without
   * semaphores or layout transitions, which is sound there); CPU readback otherwise.
   * READBACK: always through the CPU. SHARED: shared memory wherever it is supported.
   * Takes effect at the next frame; GetOutputPathName says which path is active.
   */
  vtkSetClampMacro(OutputPath, int, OUTPUT_PATH_AUTOMATIC, OUTPUT_PATH_SHARED);
  vtkGetMacro(OutputPath, int);
  void SetOutputPathToAutomatic() { this->SetOutputPath(OUTPUT_PATH_AUTOMATIC); }
  void SetOutputPathToReadback() { this->SetOutputPath(OUTPUT_PATH_READBACK); }
  void SetOutputPathToShared() { this->SetOutputPath(OUTPUT_PATH_SHARED); }
  ///@}

  ///@{
  /**
   * What ferrovol has done for this mapper since its renderer was created (or since
   * ReleaseGraphicsResources): volume uploads, transfer table uploads, frames rendered.
   * -1 before the first frame.
   */
  int GetVolumeUploadCount();
  int GetTableUploadCount();
  int GetFrameCount();
  ///@}

  /**
   * Whether the last Render() drew the volume (false after an error, with no input, or when
   * the volume was outside the view).
   */
  vtkGetMacro(LastRenderDrew, vtkTypeBool);

  /**
   * Size in pixels of the last frame ferrovol rendered (the viewport divided by the image
   * sample distance).
   */
  vtkGetVector2Macro(LastRenderSize, int);

  /**
   * How frames reach OpenGL now: "shared" (zero copy), "readback" (CPU copy), or "none"
   * before the first frame.
   */
  const char* GetOutputPathName();

  /**
   * Why the active output path was chosen (for readback: why memory is not shared).
   */
  const char* GetOutputPathReason();

  /**
   * The GPU ferrovol runs on (name, backend, driver), "" when no device could be opened.
   */
  static const char* GetAdapterDescription();

  /**
   * The ferrovol library's version ("MAJOR.MINOR.PATCH").
   */
  static const char* GetFerrovolVersion();

  /**
   * Renders the volume into the renderer's viewport (called by vtkVolume).
   */
  void Render(vtkRenderer* ren, vtkVolume* vol) override;

  /**
   * Frees the OpenGL resources and the ferrovol renderer; the next Render() uploads again.
   */
  void ReleaseGraphicsResources(vtkWindow* window) override;

protected:
  vtkFerroVolumeMapper();
  ~vtkFerroVolumeMapper() override;

  vtkTypeBool AutoAdjustSampleDistances;
  float SampleDistance;
  float ImageSampleDistance;
  vtkTypeBool UseJittering;
  vtkTypeBool EmptySpaceSkipping;
  int OutputPath;
  vtkTypeBool LastRenderDrew;
  int LastRenderSize[2];

private:
  vtkFerroVolumeMapper(const vtkFerroVolumeMapper&) = delete;
  void operator=(const vtkFerroVolumeMapper&) = delete;

  class vtkInternals;
  vtkInternals* Internals;
};

#endif
