/**
 * @class   vtkFerroUnstructuredVolumeMapper
 * @brief   ray casts a vtkUnstructuredGrid on the GPU with ferrovol
 *
 * A vtkUnstructuredGridVolumeMapper: it takes the place of
 * vtkUnstructuredGridVolumeRayCastMapper, vtkUnstructuredGridVolumeZSweepMapper or
 * vtkProjectedTetrahedraMapper wherever they are used. ferrovol splits every linear 3D cell
 * into tetrahedra (hexahedra, voxels, wedges, pyramids and pentagonal and hexagonal prisms
 * by a conforming rule; quadratic cells linearised), walks each pixel's ray from tetrahedron to tetrahedron, entering
 * non-convex meshes again, and integrates each segment exactly as VTK's unstructured
 * integrators model light: the scalar opacity read as attenuation per
 * ScalarOpacityUnitDistance, the colour as emission. The frame is composited into VTK's
 * framebuffer with depth against opaque geometry, as vtkFerroVolumeMapper's is.
 *
 * The scalars are those vtkAbstractVolumeMapper's ScalarMode, ArrayAccessMode, ArrayId and
 * ArrayName select, on points or cells, one component (more are refused). The mesh is
 * uploaded again only when the input or its scalars change; an input that is another
 * vtkUnstructuredGridBase than vtkUnstructuredGrid is copied into one once per change of
 * the input (its MTime), not once per frame. Blend modes: composite (the
 * default, VTK's unstructured ray caster's), maximum and minimum intensity, average and
 * additive, as vtkVolumeMapper numbers them; VTK's own unstructured mappers ignore the
 * blend mode and always composite. The mapper's clipping planes and the vtkVolume's matrix
 * are honoured. With the property's Shade on (which VTK's unstructured mappers ignore),
 * composite is lit by the renderer's lights with the property's ambient, diffuse, specular
 * and specular power, as vtkGPUVolumeRayCastMapper lights image data, each ray segment by
 * the scalar's gradient interpolated from the mesh's points (each point's the mean of its
 * tetrahedra's; from the neighbours across faces for cell scalars). A gradient opacity
 * (which VTK's unstructured mappers ignore too) scales composite's opacity as
 * vtkGPUVolumeRayCastMapper's does, each ray segment by its function of that gradient's
 * magnitude at the segment's middle. A 2D transfer function is refused with an error naming
 * it. Errors from ferrovol reach vtkErrorMacro with its message.
 */
#ifndef vtkFerroUnstructuredVolumeMapper_h
#define vtkFerroUnstructuredVolumeMapper_h

#include "vtkFerroVolumeModule.h" // For export macro
#include "vtkUnstructuredGridVolumeMapper.h"
#include "vtkVolumeMapper.h" // For the blend mode numbers

class VTKFERROVOLUME_EXPORT vtkFerroUnstructuredVolumeMapper
  : public vtkUnstructuredGridVolumeMapper
{
public:
  static vtkFerroUnstructuredVolumeMapper* New();
  vtkTypeMacro(vtkFerroUnstructuredVolumeMapper, vtkUnstructuredGridVolumeMapper);
  void PrintSelf(ostream& os, vtkIndent indent) override;

  ///@{
  /**
   * The blend modes ferrovol draws meshes with beside the base class's composite and
   * maximum intensity (vtkVolumeMapper's numbers).
   */
  void SetBlendModeToMinimumIntensity()
  {
    this->SetBlendMode(vtkVolumeMapper::MINIMUM_INTENSITY_BLEND);
  }
  void SetBlendModeToAverageIntensity()
  {
    this->SetBlendMode(vtkVolumeMapper::AVERAGE_INTENSITY_BLEND);
  }
  void SetBlendModeToAdditive() { this->SetBlendMode(vtkVolumeMapper::ADDITIVE_BLEND); }
  ///@}

  /**
   * Whether the last Render drew the mesh (0 after an error or before the first render).
   */
  vtkGetMacro(LastRenderDrew, int);

  ///@{
  /**
   * How many times the mapper handed ferrovol the mesh with its scalars, and the colour and
   * opacity tables (an unchanged input and property upload nothing).
   */
  vtkGetMacro(MeshUploadCount, int);
  vtkGetMacro(TableUploadCount, int);
  ///@}

  /**
   * WARNING: INTERNAL METHOD - NOT INTENDED FOR GENERAL USE
   */
  void Render(vtkRenderer* ren, vtkVolume* vol) override;

  /**
   * WARNING: INTERNAL METHOD - NOT INTENDED FOR GENERAL USE
   */
  void ReleaseGraphicsResources(vtkWindow* window) override;

protected:
  vtkFerroUnstructuredVolumeMapper();
  ~vtkFerroUnstructuredVolumeMapper() override;

  int LastRenderDrew = 0;
  int MeshUploadCount = 0;
  int TableUploadCount = 0;

private:
  vtkFerroUnstructuredVolumeMapper(const vtkFerroUnstructuredVolumeMapper&) = delete;
  void operator=(const vtkFerroUnstructuredVolumeMapper&) = delete;

  class vtkInternals;
  vtkInternals* Internals;
};

#endif
