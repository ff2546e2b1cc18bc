/**
 * @class   vtkFerroUnstructuredVolumeRepresentation
 * @brief   ParaView's unstructured-grid volume representation drawn by ferrovol.
 *
 * vtkUnstructuredGridVolumeRepresentation (the "Volume" of unstructured grids) with a
 * vtkFerroUnstructuredVolumeMapper registered as its volume mapper and always the active one.
 * Everything the superclass does stays: the input is a vtkUnstructuredGridBase or a
 * composite dataset of them (its selected blocks merged into one grid, ghost cells removed,
 * cells split into tetrahedra by vtkDataSetTriangleFilter, as for ParaView's own mappers),
 * the array selection on points or cells, the colour and opacity transfer functions,
 * ScalarOpacityUnitDistance, the translucent surface drawn while interacting (LOD), and
 * under MPI the redistribution of the cells over the ranks (vtkPVRenderView's k-d tree,
 * boundary cells assigned to one rank) with IceT compositing the ranks' images in
 * visibility order (NEED_ORDERED_COMPOSITING), as for "Volume".
 *
 * The server-manager XML (FerrovolRepresentation.xml) adds it to
 * UnstructuredGridRepresentation as "Ferrovol Volume", sharing the volume properties with
 * "Volume" there except the mapper selection ("Select Mapper"). Its own settings:
 *
 * - FerrovolBlendMode: composite (VTK's unstructured mappers' only mode), maximum, minimum
 *   or average intensity, additive, or isosurfaces of IsosurfaceValues (vtkVolumeMapper's
 *   numbers 0-5); other values are refused with an error and the mode stays. Under MPI the
 *   ranks' images are composited in visibility order, which is exact for composite and
 *   isosurfaces only; the other modes give a warning there.
 * - Path tracing (FerrovolRenderMode and the settings "Ferrovol Volume" of image data has
 *   for it), forwarded to the mapper.
 *
 * What the mapper refuses (more than one component, a separate opacity array, a 2D
 * transfer function, cells other than linear and quadratic 3D cells) is reported by
 * vtkErrorMacro, naming why, and nothing is drawn.
 */

#ifndef vtkFerroUnstructuredVolumeRepresentation_h
#define vtkFerroUnstructuredVolumeRepresentation_h

#include "vtkFerroVolumeRepresentationModule.h" // For export macro
#include "vtkNew.h"                              // for ivar
#include "vtkUnstructuredGridVolumeRepresentation.h"

class vtkFerroUnstructuredVolumeMapper;

class VTKFERROVOLUMEREPRESENTATION_EXPORT vtkFerroUnstructuredVolumeRepresentation
  : public vtkUnstructuredGridVolumeRepresentation
{
public:
  static vtkFerroUnstructuredVolumeRepresentation* New();
  vtkTypeMacro(vtkFerroUnstructuredVolumeRepresentation, vtkUnstructuredGridVolumeRepresentation);
  void PrintSelf(ostream& os, vtkIndent indent) override;

  /**
   * The name the ferrovol mapper is registered under (AddVolumeMapper).
   */
  static const char* MapperName() { return "Ferrovol"; }

  /**
   * Keeps the ferrovol mapper active: a null or empty name, or MapperName(), is accepted;
   * another of the superclass's mappers ("Projected tetra", "Z sweep", "Bunyk ray cast",
   * "Resample To Image") is refused with an error ("Volume" draws with those).
   */
  void SetActiveVolumeMapper(const char* name) override;

  ///@{
  /**
   * The blend mode: vtkVolumeMapper's COMPOSITE_BLEND (0, the default),
   * MAXIMUM_INTENSITY_BLEND (1), MINIMUM_INTENSITY_BLEND (2), AVERAGE_INTENSITY_BLEND (3),
   * ADDITIVE_BLEND (4) or ISOSURFACE_BLEND (5). Other values are refused with an error.
   */
  void SetFerrovolBlendMode(int mode);
  vtkGetMacro(FerrovolBlendMode, int);
  ///@}

  ///@{
  /**
   * The isosurface blend mode's values, as "Volume" of image data sets them (ParaView's
   * unstructured "Volume" has none): into the volume's vtkVolumeProperty.
   */
  void SetIsosurfaceValue(int i, double value);
  void SetNumberOfIsosurfaces(int number);
  ///@}

  ///@{
  /**
   * Lighting, as "Volume" of image data has it (ParaView's unstructured "Volume" has none):
   * Shade on lights composite with the view's lights; the material's ambient, diffuse,
   * specular and specular power (shared with the Lighting group). They go to the volume's
   * vtkVolumeProperty.
   */
  void SetShade(bool shade);
  void SetAmbient(double value);
  void SetDiffuse(double value);
  void SetSpecular(double value);
  void SetSpecularPower(double value);
  ///@}

  ///@{
  /**
   * Volumetric shadows in shaded composite, as "Volume" of image data has them: the
   * scattering anisotropy (into the vtkVolumeProperty), the reach and the blending (to the
   * mapper).
   */
  void SetVolumeAnisotropy(double anisotropy);
  void SetGlobalIlluminationReach(double reach);
  void SetVolumetricScatteringBlending(double blending);
  ///@}

  ///@{
  /**
   * Path tracing, as "Ferrovol Volume" of image data has it: the mapper's RenderMode,
   * SamplesPerPixel, PathTracingBounces, PathTracingDenoise, PathTracingDenoiseUntil,
   * ProgressiveMode, PathTracingTimeBudget, SecondaryRays, EnvironmentMap and
   * EnvironmentBackground; and the paths per pixel accumulated (-1 before the first frame).
   */
  void SetRenderMode(int mode);
  void SetSamplesPerPixel(int samples);
  void SetPathTracingBounces(int bounces);
  void SetPathTracingDenoise(int on);
  void SetPathTracingDenoiseUntil(int samples);
  void SetProgressiveMode(int mode);
  void SetPathTracingTimeBudget(double seconds);
  void SetSecondaryRays(int rays);
  void SetEnvironmentMap(const char* file);
  void SetEnvironmentBackground(int on);
  int GetFerrovolAccumulatedSamples();
  ///@}

  /**
   * The mapper this representation renders with.
   */
  vtkFerroUnstructuredVolumeMapper* GetFerroUnstructuredVolumeMapper();

  ///@{
  /**
   * What the mapper reports, for information-only properties: whether the last render drew
   * the mesh (0/1), and how many mesh and transfer-table uploads it made.
   */
  int GetFerrovolLastRenderDrew();
  int GetFerrovolVolumeUploadCount();
  int GetFerrovolTableUploadCount();
  ///@}

protected:
  vtkFerroUnstructuredVolumeRepresentation();
  ~vtkFerroUnstructuredVolumeRepresentation() override;

  /**
   * The superclass's work (array and association, independent components, the actor's
   * mapper), then the blend mode. Refuses a separate opacity array with an error (the mapper
   * draws one component). Under MPI warns once about a blend mode other than composite.
   */
  void UpdateMapperParameters() override;

  int FerrovolBlendMode = 0;
  vtkNew<vtkFerroUnstructuredVolumeMapper> FerroMapper;
  // the warning about blend modes under MPI, said once per mode
  int WarnedBlendMode = 0;

private:
  vtkFerroUnstructuredVolumeRepresentation(
    const vtkFerroUnstructuredVolumeRepresentation&) = delete;
  void operator=(const vtkFerroUnstructuredVolumeRepresentation&) = delete;
};

#endif
