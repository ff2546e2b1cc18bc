#include "vtkFerroVolumeSettings.h"

#include "vtkCamera.h"
#include "vtkCommand.h"
#include "vtkFerroVolumeContext.h"
#include "vtkFerroVolumeInputHelper.h"
#include "vtkFerroVolumeMapper.h"
#include "vtkFerroVolumeReport.h"
#include "vtkImageData.h"
#include "vtkImplicitFunction.h"
#include "vtkLight.h"
#include "vtkMath.h"
#include "vtkLightCollection.h"
#include "vtkMatrix3x3.h"
#include "vtkMatrix4x4.h"
#include "vtkOpenGLCamera.h"
#include "vtkPlane.h"
#include "vtkPlaneCollection.h"
#include "vtkRenderWindow.h"
#include "vtkRenderer.h"
#include "vtkShaderProperty.h"
#include "vtkUniforms.h"
#include "vtkVolume.h"
#include "vtkVolumeProperty.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>
#include <iterator>
#include <utility>
#include <vector>

namespace
{
// vtkMatrix4x4 (row-major, VTK's M·p) → column-major (OpenGL order), as ferrovol takes them.
void ToColumnMajor(vtkMatrix4x4* m, double out[16])
{
  for (int r = 0; r < 4; ++r)
  {
    for (int c = 0; c < 4; ++c)
    {
      out[4 * c + r] = m->GetElement(r, c);
    }
  }
}

void ToFloat3(const double in[3], float out[3])
{
  for (int k = 0; k < 3; ++k)
  {
    out[k] = static_cast<float>(in[k]);
  }
}

// A switched-on VTK light as ferrovol's; `defaultLighting`: VTK's default (one headlight of
// intensity 1), whose ambient term is the material's ambient times the sample colour.
FvLight ToFvLight(vtkLight* light, bool defaultLighting)
{
  FvLight l;
  std::memset(&l, 0, sizeof(l));
  if (light->LightTypeIsHeadlight())
  {
    l.space = FV_LIGHT_SPACE_HEADLIGHT;
    light->GetPosition(l.position);
    light->GetFocalPoint(l.focal_point);
  }
  else if (light->LightTypeIsCameraLight())
  {
    l.space = FV_LIGHT_SPACE_CAMERA;
    light->GetPosition(l.position);
    light->GetFocalPoint(l.focal_point);
  }
  else
  {
    l.space = FV_LIGHT_SPACE_WORLD;
    light->GetTransformedPosition(l.position);
    light->GetTransformedFocalPoint(l.focal_point);
  }
  l.positional = light->GetPositional() != 0;
  double c[3];
  light->GetAmbientColor(c);
  ToFloat3(c, l.ambient);
  if (defaultLighting)
  {
    l.ambient[0] = l.ambient[1] = l.ambient[2] = 1.0f;
  }
  light->GetDiffuseColor(c);
  ToFloat3(c, l.diffuse);
  light->GetSpecularColor(c);
  ToFloat3(c, l.specular);
  l.intensity = static_cast<float>(light->GetIntensity());
  light->GetAttenuationValues(c);
  ToFloat3(c, l.attenuation);
  l.cone_angle = static_cast<float>(light->GetConeAngle());
  l.exponent = static_cast<float>(light->GetExponent());
  return l;
}

// The renderer's switched-on lights (at most FV_MAX_LIGHTS, warned once when more).
std::vector<FvLight> SceneLights(vtkObject* self, vtkRenderer* ren,
  vtkFerroVolumeReport& report)
{
  std::vector<FvLight> lights;
  vtkLightCollection* lc = ren->GetLights();
  vtkCollectionSimpleIterator it;
  int on = 0;
  lc->InitTraversal(it);
  while (vtkLight* light = lc->GetNextLight(it))
  {
    if (light->GetSwitch())
    {
      ++on;
    }
  }
  if (on > FV_MAX_LIGHTS && report.FirstTime("lights"))
  {
    vtkWarningWithObjectMacro(
      self, << on << " lights are on: ferrovol uses the first " << FV_MAX_LIGHTS);
  }
  lc->InitTraversal(it);
  while (vtkLight* light = lc->GetNextLight(it))
  {
    if (!light->GetSwitch() || static_cast<int>(lights.size()) >= FV_MAX_LIGHTS)
    {
      continue;
    }
    lights.push_back(ToFvLight(light,
      on == 1 && light->LightTypeIsHeadlight() && light->GetIntensity() == 1.0));
  }
  return lights;
}

// The camera VTK draws the opaque geometry with.
FvCamera ToFvCamera(vtkRenderer* ren, int vw, int vh)
{
  vtkCamera* cam = ren->GetActiveCamera();
  FvCamera fcam;
  std::memset(&fcam, 0, sizeof(fcam));
  cam->GetPosition(fcam.position);
  cam->GetFocalPoint(fcam.focal_point);
  cam->GetViewUp(fcam.view_up);
  fcam.view_angle = cam->GetViewAngle();
  fcam.parallel = cam->GetParallelProjection() != 0;
  fcam.parallel_scale = cam->GetParallelScale();
  cam->GetClippingRange(fcam.clipping_range);
  fcam.use_matrices = true;
  if (vtkOpenGLCamera* glcam = vtkOpenGLCamera::SafeDownCast(cam))
  {
    // GL-ordered (transposed) copies: their storage is column-major already.
    vtkMatrix4x4 *wcvc = nullptr, *vcdc = nullptr, *wcdc = nullptr;
    vtkMatrix3x3* norms = nullptr;
    glcam->GetKeyMatrices(ren, wcvc, norms, vcdc, wcdc);
    std::memcpy(fcam.view_matrix, wcvc->GetData(), sizeof(fcam.view_matrix));
    std::memcpy(fcam.projection_matrix, vcdc->GetData(), sizeof(fcam.projection_matrix));
  }
  else
  {
    ToColumnMajor(cam->GetModelViewTransformMatrix(), fcam.view_matrix);
    ToColumnMajor(cam->GetProjectionTransformMatrix(static_cast<double>(vw) / vh, -1, 1),
      fcam.projection_matrix);
  }
  return fcam;
}

// ClippedVoxelIntensity in the data units of a component with data range `range`.
// vtkGPUVolumeRayCastMapper puts the value in place of a neighbour's texel, before scaling
// texels to the range, so its unit is the texel's: the data's own for float, the
// normalised integer texel for the 8- and 16-bit types (value / 255, / 127, / 32767,
// / 65535), and the range mapped onto [0, 1] for the types it converts on upload (int,
// long, double…).
double ClippedIntensityInDataUnits(int type, double value, const std::array<double, 2>& range)
{
  switch (type)
  {
    case VTK_FLOAT:
      return value;
    case VTK_UNSIGNED_CHAR:
      return value * 255.0;
    case VTK_SIGNED_CHAR:
      return value * 127.0;
    case VTK_SHORT:
      return value * 32767.0;
    case VTK_UNSIGNED_SHORT:
      return value * 65535.0;
    default:
      return range[0] + value * (range[1] - range[0]);
  }
}

} // namespace

bool vtkFerroVolumeSettings::ToFvBlend(int vtkBlendMode, uint32_t& blend)
{
  static const std::pair<int, FvBlendMode> modes[] = {
    { vtkVolumeMapper::COMPOSITE_BLEND, FV_BLEND_MODE_COMPOSITE },
    { vtkVolumeMapper::MAXIMUM_INTENSITY_BLEND, FV_BLEND_MODE_MAXIMUM },
    { vtkVolumeMapper::MINIMUM_INTENSITY_BLEND, FV_BLEND_MODE_MINIMUM },
    { vtkVolumeMapper::AVERAGE_INTENSITY_BLEND, FV_BLEND_MODE_AVERAGE },
    { vtkVolumeMapper::ADDITIVE_BLEND, FV_BLEND_MODE_ADDITIVE },
    { vtkVolumeMapper::ISOSURFACE_BLEND, FV_BLEND_MODE_ISOSURFACE },
    { vtkVolumeMapper::SLICE_BLEND, FV_BLEND_MODE_SLICE },
  };
  const auto mode = std::find_if(std::begin(modes), std::end(modes),
    [&](const std::pair<int, FvBlendMode>& m) { return m.first == vtkBlendMode; });
  if (mode == std::end(modes))
  {
    return false;
  }
  blend = mode->second;
  return true;
}

bool vtkFerroVolumeSettings::SelectBlendMode(
  vtkFerroVolumeMapper* self, vtkFerroVolumeReport& report)
{
  uint32_t blend = FV_BLEND_MODE_COMPOSITE;
  if (!ToFvBlend(self->GetBlendMode(), blend))
  {
    return report.Fail("blend mode " + std::to_string(self->GetBlendMode()) +
      " is not supported by vtkFerroVolumeMapper (composite, maximum, minimum, average, "
      "additive, isosurface and slice are): nothing is drawn");
  }
  this->Blend = self->GetRenderMode() == vtkFerroVolumeMapper::RENDER_MODE_PATH_TRACE
    ? static_cast<uint32_t>(FV_BLEND_MODE_PATH_TRACE)
    : blend;
  return true;
}

double vtkFerroVolumeSettings::UpdateReductionFactor(
  vtkFerroVolumeMapper* self, double allocatedTime)
{
  if (self->TimeToDraw > 0.0)
  {
    // The time the last render of this kind (still: allocated time >= 1 s, interactive:
    // less) took, scaled to a full-resolution step; the new factor averages the old one with
    // what would fit the allocated time, and is held to 1, 1/2, 1/5 or 1/10 (steps that do
    // not flicker between frames) within Minimum/MaximumImageSampleDistance.
    double last = allocatedTime < 1.0 ? self->SmallTimeToDraw : self->BigTimeToDraw;
    if (last == 0.0 && allocatedTime < 1.0)
    {
      last = self->BigTimeToDraw / 3.0;
    }
    if (last == 0.0)
    {
      last = 10.0;
    }
    const double fits = allocatedTime / (last / this->ReductionFactor);
    double factor = std::min(1.0, 0.5 * (fits + this->ReductionFactor));
    factor = factor < 0.2 ? 0.1 : factor < 0.5 ? 0.2 : factor < 1.0 ? 0.5 : 1.0;
    const double finest = self->GetMinimumImageSampleDistance();
    const double coarsest = self->GetMaximumImageSampleDistance();
    if (coarsest > 0.0 && 1.0 / factor > coarsest)
    {
      factor = 1.0 / coarsest;
    }
    if (finest > 0.0 && 1.0 / factor < finest)
    {
      factor = 1.0 / finest;
    }
    this->ReductionFactor = factor;
  }
  return this->ReductionFactor;
}

vtkFerroVolumeSettings::Result vtkFerroVolumeSettings::Apply(vtkFerroVolumeMapper* self,
  vtkRenderer* ren, vtkVolume* vol, const vtkFerroVolumeInputHelper& input,
  ferrovol::Renderer& renderer, double traceBudget, vtkFerroVolumeReport& report)
{
  FvRenderParams& params = this->Params;
  if (!vtkFerroVolumeCall("use the mapper's settings", report,
        [&] { params = ferrovol::Renderer::default_params(); }))
  {
    return Result::Failed;
  }
  params.blend_mode = this->Blend;
  params.mask_blend_factor = self->GetMaskBlendFactor();
  if (this->Blend == FV_BLEND_MODE_SLICE && !this->SetUpSlicePlane(vol, report))
  {
    return Result::Failed;
  }
  this->SetUpInterpolation(self, vol->GetProperty(), report);
  if (!this->SetUpSampling(self, vol, input, report))
  {
    return Result::Failed;
  }
  this->SetUpShading(self, ren, vol, input, report);
  this->SetUpCroppingAndClipping(self, vol->GetProperty(), input, report);
  this->SetUpRayOptions(self, ren);
  this->SetUpWholeExtent(self, input);
  this->SetUpQuadrature(self, report);
  SetVolumeMatrix(vol, params);
  this->Background = false;
  if (this->Blend == FV_BLEND_MODE_ISOSURFACE)
  {
    const Result iso = this->SetUpIsosurfaces(
      self, vol, input.GetComponents(), this->Params, renderer, report);
    if (iso != Result::Ready)
    {
      return iso;
    }
  }
  if (this->Blend == FV_BLEND_MODE_PATH_TRACE &&
    !this->SetUpPathTracing(self, ren, vol, renderer, traceBudget, report))
  {
    return Result::Failed;
  }
  if (!vtkFerroVolumeCall(
        "use the mapper's settings", report, [&] { renderer.set_params(params); }))
  {
    return Result::Failed;
  }
  return Result::Ready;
}

bool vtkFerroVolumeSettings::SetUpSlicePlane(vtkVolume* vol, vtkFerroVolumeReport& report)
{
  // As vtkOpenGLGPUVolumeRayCastMapper: the plane's origin and normal in world
  // coordinates (the implicit function's own transform is not applied).
  vtkVolumeProperty* prop = vol->GetProperty();
  vtkPlane* plane = vtkPlane::SafeDownCast(prop->GetSliceFunction());
  if (!plane)
  {
    return report.Fail(std::string("SLICE_BLEND needs a vtkPlane as the volume property's "
                       "SliceFunction (it has ") +
      (prop->GetSliceFunction() ? prop->GetSliceFunction()->GetClassName() : "none") +
      "): nothing is drawn");
  }
  // vtkOpenGLGPUVolumeRayCastMapper takes the plane into the volume's data coordinates
  // with the vtkVolume's inverse matrix, its normal as a direction (w = 0) rather than
  // as a normal: with a rotation and a uniform scale that is the same plane, under a
  // non-uniform scale or a shear another one. The world plane it draws has the same
  // origin and the normal (A·Aᵀ)⁻¹·n (A: the matrix's linear part), given here.
  plane->GetOrigin(this->Params.slice_plane.origin);
  double n[3];
  plane->GetNormal(n);
  vtkMatrix4x4* m = vol->GetMatrix();
  double aat[3][3];
  for (int i = 0; i < 3; ++i)
  {
    for (int j = 0; j < 3; ++j)
    {
      aat[i][j] = 0.0;
      for (int k = 0; k < 3; ++k)
      {
        aat[i][j] += m->GetElement(i, k) * m->GetElement(j, k);
      }
    }
  }
  double inv[3][3];
  vtkMath::Invert3x3(aat, inv);
  vtkMath::Multiply3x3(inv, n, this->Params.slice_plane.normal);
  return true;
}

void vtkFerroVolumeSettings::SetUpInterpolation(
  vtkFerroVolumeMapper* self, vtkVolumeProperty* prop, vtkFerroVolumeReport& report)
{
  switch (prop->GetInterpolationType())
  {
    case VTK_NEAREST_INTERPOLATION:
      this->Params.interpolation = FV_INTERPOLATION_NEAREST;
      break;
    case VTK_LINEAR_INTERPOLATION:
      // (path tracing traces the trilinear field)
      this->Params.interpolation =
        self->GetCubicInterpolation() && this->Blend != FV_BLEND_MODE_PATH_TRACE
        ? FV_INTERPOLATION_CUBIC
        : FV_INTERPOLATION_LINEAR;
      break;
    default:
      this->Params.interpolation = FV_INTERPOLATION_LINEAR;
      if (report.FirstTime("interpolation"))
      {
        vtkWarningWithObjectMacro(self, << "interpolation type "
                                        << prop->GetInterpolationTypeAsString()
                                        << " is not supported by ferrovol: using linear "
                                           "interpolation");
      }
      break;
  }
}

bool vtkFerroVolumeSettings::SetUpSampling(vtkFerroVolumeMapper* self, vtkVolume* vol,
  const vtkFerroVolumeInputHelper& input, vtkFerroVolumeReport& report)
{
  FvRenderParams& params = this->Params;
  if (!self->GetAutoAdjustSampleDistances())
  {
    if (self->GetLockSampleDistanceToInputSpacing())
    {
      // vtkOpenGLGPUVolumeRayCastMapper: vtkVolumeMapper::SpacingAdjustedSampleDistance of
      // the input's spacing (by magnitude) and extent, whatever SampleDistance says; a piece
      // of a whole (WholeExtent) takes the whole's extent, so every piece samples alike.
      double spacing[3];
      int extent[6];
      input.GetCellSpacing(spacing);
      input.GetImage()->GetExtent(extent);
      const int* whole = self->GetWholeExtent();
      if (whole[0] <= whole[1] && whole[2] <= whole[3] && whole[4] <= whole[5])
      {
        std::copy(whole, whole + 6, extent);
      }
      for (double& s : spacing)
      {
        s = std::fabs(s);
      }
      params.sample_distance =
        static_cast<float>(self->SpacingAdjustedSampleDistance(spacing, extent));
    }
    else
    {
      const float distance = self->GetSampleDistance();
      if (!(distance > 0.0f) || !std::isfinite(distance))
      {
        return report.Fail("SampleDistance " + std::to_string(distance) +
          " must be positive (or turn AutoAdjustSampleDistances on)");
      }
      params.sample_distance = distance;
    }
  }
  else if (this->Blend != FV_BLEND_MODE_PATH_TRACE)
  {
    // vtkOpenGLGPUVolumeRayCastMapper: the smallest world cell spacing of the input,
    // lengthened by the reduction factor the render time asks for. (Path tracing keeps the
    // step: its accumulation would start over at each change, and its renders fill their
    // time budget instead.) The core's default is the same for an image; a rectilinear
    // grid's cell spacing (GetCellSpacing) is its own.
    const double factor = this->UpdateReductionFactor(self, vol->GetAllocatedRenderTime());
    if (factor < 1.0 || input.IsRectilinear())
    {
      double spacing[3];
      input.GetCellSpacing(spacing);
      vtkMatrix4x4* m = vol->GetMatrix();
      double smallest = VTK_DOUBLE_MAX;
      for (int axis = 0; axis < 3; ++axis)
      {
        const double column = std::sqrt(m->GetElement(0, axis) * m->GetElement(0, axis) +
          m->GetElement(1, axis) * m->GetElement(1, axis) +
          m->GetElement(2, axis) * m->GetElement(2, axis));
        smallest = std::min(smallest, std::fabs(spacing[axis]) * column);
      }
      if (smallest > 0.0 && std::isfinite(smallest))
      {
        params.sample_distance = smallest / factor;
      }
    }
  }
  return true;
}

void vtkFerroVolumeSettings::SetUpShading(vtkFerroVolumeMapper* self, vtkRenderer* ren,
  vtkVolume* vol, const vtkFerroVolumeInputHelper& input, vtkFerroVolumeReport& report)
{
  FvRenderParams& params = this->Params;
  vtkVolumeProperty* prop = vol->GetProperty();
  params.jitter = self->GetUseJittering() != 0;
  const bool isosurface = this->Blend == FV_BLEND_MODE_ISOSURFACE;
  params.shade = prop->GetShade(0) != 0 &&
    (this->Blend == FV_BLEND_MODE_COMPOSITE || isosurface || this->Blend == FV_BLEND_MODE_SLICE);
  this->WarnUnsupported(self, vol, report);
  if (self->GetMaskInput() &&
    self->GetMaskType() == vtkGPUVolumeRayCastMapper::LabelMapMaskType &&
    this->Blend == FV_BLEND_MODE_COMPOSITE && input.GetComponents() > 1 &&
    report.FirstTime("label-components"))
  {
    vtkWarningWithObjectMacro(self, << "a label map (MaskType LabelMapMaskType) colours "
                                       "one-component volumes, as vtkGPUVolumeRayCastMapper's: "
                                       "this one has "
                                    << input.GetComponents()
                                    << " components and is drawn without its labels");
  }
  if (self->GetComputeNormalFromOpacity() && params.shade)
  {
    // vtkGPUVolumeRayCastMapper's computeDensityGradient: normals from the opacity's
    // gradient. ferrovol takes them in composite ray casting of one or independent
    // components.
    const bool dependent = input.GetComponents() > 1 && !prop->GetIndependentComponents();
    params.normal_from_opacity = !isosurface && !dependent;
    if (!params.normal_from_opacity && report.FirstTime("normal-from-opacity"))
    {
      vtkWarningWithObjectMacro(self, << "ComputeNormalFromOpacity: ferrovol takes normals "
                                         "from the opacity in the composite blend mode of "
                                         "one or independent components; "
                                      << (isosurface ? "isosurfaces" : "dependent components")
                                      << " are shaded with the scalar gradient");
    }
  }
  SetMaterial(prop, ren, params);
  if (!isosurface)
  {
    SetVolumetric(self->GetVolumetricScatteringBlending(), self->GetGlobalIlluminationReach(),
      prop, params);
  }
}

void vtkFerroVolumeSettings::SetVolumetric(
  float blending, float reach, vtkVolumeProperty* prop, FvRenderParams& params)
{
  params.volumetric_scattering_blending = blending;
  params.global_illumination_reach = reach;
  params.scattering_anisotropy = std::max(-1.0f, std::min(1.0f, prop->GetScatteringAnisotropy()));
}

void vtkFerroVolumeSettings::SetUpCroppingAndClipping(vtkFerroVolumeMapper* self,
  vtkVolumeProperty* prop, const vtkFerroVolumeInputHelper& input, vtkFerroVolumeReport& report)
{
  FvRenderParams& params = this->Params;
  params.cropping = self->GetCropping() != 0;
  const double* crop = self->GetCroppingRegionPlanes();
  std::copy(crop, crop + 6, params.cropping_planes);
  params.cropping_regions = static_cast<uint32_t>(self->GetCroppingRegionFlags());
  const int count = SetUpClippingPlanes(self->GetClippingPlanes(), params, report);
  if (!prop->GetUseClippedVoxelIntensity() || count == 0)
  {
    return;
  }
  params.clipped_voxel_enabled = true;
  for (int c = 0; c < 4; ++c)
  {
    params.clipped_voxel_value[c] = ClippedIntensityInDataUnits(
      input.GetDataType(), prop->GetClippedVoxelIntensity(), input.GetRanges()[c]);
  }
  const bool isosurface = this->Blend == FV_BLEND_MODE_ISOSURFACE;
  if ((isosurface || params.normal_from_opacity) && report.FirstTime("clipped-voxel-intensity"))
  {
    vtkWarningWithObjectMacro(self, << "UseClippedVoxelIntensity: ferrovol uses "
                                       "ClippedVoxelIntensity in the scalar gradient of "
                                       "composite ray casting; "
                                    << (isosurface ? "isosurface normals"
                                                   : "normals from the opacity")
                                    << " read the data beyond the clipping planes");
  }
}

int vtkFerroVolumeSettings::SetUpClippingPlanes(
  vtkPlaneCollection* planes, FvRenderParams& params, vtkFerroVolumeReport& report)
{
  int count = planes ? planes->GetNumberOfItems() : 0;
  if (count > FV_MAX_CLIP_PLANES)
  {
    report.WarnOnce("planes",
      std::to_string(count) + " clipping planes: ferrovol, as vtkGPUVolumeRayCastMapper, " +
        "takes at most " + std::to_string(FV_MAX_CLIP_PLANES) + " and uses the first " +
        std::to_string(FV_MAX_CLIP_PLANES));
    count = FV_MAX_CLIP_PLANES;
  }
  for (int i = 0; i < count; ++i)
  {
    vtkPlane* plane = planes->GetItem(i);
    plane->GetOrigin(params.clip_planes[i].origin);
    plane->GetNormal(params.clip_planes[i].normal);
  }
  params.clip_plane_count = static_cast<uint32_t>(count);
  return count;
}

void vtkFerroVolumeSettings::SetUpRayOptions(vtkFerroVolumeMapper* self, vtkRenderer* ren)
{
  FvRenderParams& params = this->Params;
  params.average_range_enabled = this->Blend == FV_BLEND_MODE_AVERAGE;
  const double* average = self->GetAverageIPScalarRange();
  params.average_range[0] = average[0];
  params.average_range[1] = average[1];
  params.empty_space_skipping = self->GetEmptySpaceSkipping() != 0;
  params.extremum_depth = self->GetExtremumDepth() != 0;
  params.preintegration = self->GetPreIntegration() != 0;
  // An interactive render of a volume whose bricks exceed MaxMemoryInBytes draws in one
  // pass, a coarser level's bricks where fine ones are missing (those its rays read come in
  // the next interactive renders); a still render streams the volume itself. (Path
  // tracing's accumulation must not restart between the two.)
  vtkRenderWindow* window = ren->GetRenderWindow();
  params.preview_level = this->Blend != FV_BLEND_MODE_PATH_TRACE && window &&
    window->GetDesiredUpdateRate() > 1.0;
}

void vtkFerroVolumeSettings::SetUpWholeExtent(
  vtkFerroVolumeMapper* self, const vtkFerroVolumeInputHelper& input)
{
  // A piece of a whole extent: the whole's box in the piece's index space (points, or the
  // cell centres with cell data).
  FvRenderParams& params = this->Params;
  const int* whole = self->GetWholeExtent();
  const int* extent = input.GetImage()->GetExtent();
  params.whole_box_enabled = whole[0] <= whole[1] && whole[2] <= whole[3] && whole[4] <= whole[5];
  if (params.whole_box_enabled)
  {
    const int cells = input.UsesCellData() ? 1 : 0;
    for (int a = 0; a < 3; ++a)
    {
      params.whole_box[a] = whole[2 * a] - extent[2 * a];
      params.whole_box[3 + a] = std::max(whole[2 * a], whole[2 * a + 1] - cells) - extent[2 * a];
    }
  }
}

void vtkFerroVolumeSettings::SetUpQuadrature(
  vtkFerroVolumeMapper* self, vtkFerroVolumeReport& report)
{
  // MidpointQuadrature and AdaptiveSampling: samples placed mid-step (not jittered), on one
  // whole volume.
  FvRenderParams& params = this->Params;
  const bool midpoints = self->GetMidpointQuadrature() || self->GetAdaptiveSampling();
  const char* quadrature = self->GetAdaptiveSampling() ? "AdaptiveSampling" : "MidpointQuadrature";
  if (midpoints && (params.whole_box_enabled || this->Intermixing) &&
    report.FirstTime("midpoint-pieces"))
  {
    vtkWarningWithObjectMacro(self, << quadrature << " is not applied to "
                                    << (this->Intermixing ? "a vtkMultiVolume"
                                                          : "a piece of a whole extent (MPI)")
                                    << ": its rays sample on VTK's lattice");
  }
  if (midpoints && !params.whole_box_enabled && !this->Intermixing)
  {
    params.quadrature =
      self->GetAdaptiveSampling() ? FV_QUADRATURE_ADAPTIVE : FV_QUADRATURE_MIDPOINT;
    if (params.jitter && report.FirstTime("midpoint-jitter"))
    {
      vtkWarningWithObjectMacro(self, << "UseJittering is not applied with " << quadrature
                                      << ": its samples sit in the middle of their steps");
    }
    params.jitter = false;
  }
}

void vtkFerroVolumeSettings::SetVolumeMatrix(vtkVolume* vol, FvRenderParams& params)
{
  ToColumnMajor(vol->GetMatrix(), params.volume_matrix);
}

bool vtkFerroVolumeSettings::ApplyCamera(
  vtkRenderer* ren, int vw, int vh, ferrovol::Renderer& renderer, vtkFerroVolumeReport& report)
{
  return vtkFerroVolumeCall(
    "use the camera", report, [&] { renderer.set_camera(ToFvCamera(ren, vw, vh)); });
}

bool vtkFerroVolumeSettings::ApplyView(vtkFerroVolumeMapper* self, vtkRenderer* ren, int vw,
  int vh, ferrovol::Renderer& renderer, vtkFerroVolumeReport& report)
{
  if (!ApplyCamera(ren, vw, vh, renderer, report))
  {
    return false;
  }
  const std::vector<FvLight> lights =
    FrameLights(self, ren, this->Blend, this->Params.shade, report);
  return vtkFerroVolumeCall(
    "use the renderer's lights", report, [&] { renderer.set_lights(lights); });
}

std::vector<FvLight> vtkFerroVolumeSettings::FrameLights(
  vtkObject* self, vtkRenderer* ren, uint32_t blend, bool shade, vtkFerroVolumeReport& report)
{
  std::vector<FvLight> lights;
  if (blend == FV_BLEND_MODE_ISOSURFACE && !shade)
  {
    // (SetUpIsosurfaces made the material flat: the surface colour alone)
    FvLight l;
    std::memset(&l, 0, sizeof(l));
    l.space = FV_LIGHT_SPACE_HEADLIGHT;
    l.ambient[0] = l.ambient[1] = l.ambient[2] = 1.0f;
    l.intensity = 1.0f;
    l.attenuation[0] = 1.0f;
    lights.push_back(l);
  }
  else if (shade || blend == FV_BLEND_MODE_PATH_TRACE)
  {
    lights = SceneLights(self, ren, report);
  }
  return lights;
}

void vtkFerroVolumeSettings::SetMaterial(
  vtkVolumeProperty* prop, vtkRenderer* ren, FvRenderParams& params)
{
  params.ambient = static_cast<float>(prop->GetAmbient(0));
  params.diffuse = static_cast<float>(prop->GetDiffuse(0));
  params.specular = static_cast<float>(prop->GetSpecular(0));
  params.specular_power = static_cast<float>(prop->GetSpecularPower(0));
  params.two_sided_lighting = ren->GetTwoSidedLighting() != 0;
}

bool vtkFerroVolumeSettings::ApplyShading(vtkObject* self, vtkRenderer* ren,
  vtkVolumeProperty* prop, FvRenderParams& params, ferrovol::Renderer& renderer,
  vtkFerroVolumeReport& report)
{
  params.shade = prop->GetShade(0) != 0 &&
    (params.blend_mode == FV_BLEND_MODE_COMPOSITE || params.blend_mode == FV_BLEND_MODE_ISOSURFACE);
  SetMaterial(prop, ren, params);
  const std::vector<FvLight> lights =
    FrameLights(self, ren, params.blend_mode, params.shade, report);
  return vtkFerroVolumeCall(
    "use the renderer's lights", report, [&] { renderer.set_lights(lights); });
}

void vtkFerroVolumeSettings::WarnUnsupported(
  vtkFerroVolumeMapper* self, vtkVolume* vol, vtkFerroVolumeReport& report) const
{
  // vtkOpenGLGPUVolumeRayCastMapper applies the volume's shader property to its GLSL ray
  // caster and fires UpdateShaderEvent with the program; ferrovol runs no GLSL ray caster.
  vtkShaderProperty* shader = vol->GetShaderProperty();
  const auto customUniforms = [](vtkUniforms* u) { return u && u->GetNumberOfUniforms() > 0; };
  if (shader &&
    (shader->HasVertexShaderCode() || shader->HasFragmentShaderCode() ||
      shader->HasGeometryShaderCode() || shader->GetNumberOfShaderReplacements() > 0 ||
      customUniforms(shader->GetVertexCustomUniforms()) ||
      customUniforms(shader->GetFragmentCustomUniforms()) ||
      customUniforms(shader->GetGeometryCustomUniforms())) &&
    report.FirstTime("shader-property"))
  {
    vtkWarningWithObjectMacro(self, << "the volume's ShaderProperty (custom shader code, "
                                       "replacements or uniforms) is not applied: ferrovol "
                                       "ray casts in its own shaders, not VTK's GLSL");
  }
  if (self->HasObserver(vtkCommand::UpdateShaderEvent) &&
    report.FirstTime("update-shader-event"))
  {
    vtkWarningWithObjectMacro(self, << "UpdateShaderEvent is never fired: ferrovol ray casts "
                                       "in its own shaders, there is no GLSL program to update");
  }
  if (self->GetUseDepthPass() && this->Blend == FV_BLEND_MODE_COMPOSITE &&
    report.FirstTime("depth-pass"))
  {
    vtkWarningWithObjectMacro(self, << "UseDepthPass (rays starting at the surface of "
                                       "DepthPassContourValues) is not supported by ferrovol: "
                                       "rays start where they enter the volume");
  }
  if (self->GetTransfer2DYAxisArray() && report.FirstTime("transfer-2d-y"))
  {
    vtkWarningWithObjectMacro(self, << "Transfer2DYAxisArray '" << self->GetTransfer2DYAxisArray()
                                    << "' is not used: ferrovol's 2D transfer functions read "
                                       "the gradient magnitude on their second axis");
  }
  for (int port = 1; port < self->GetNumberOfInputPorts(); ++port)
  {
    if (!this->Intermixing && self->GetNumberOfInputConnections(port) > 0 &&
      report.FirstTime("port-" + std::to_string(port)))
    {
      vtkWarningWithObjectMacro(self, << "the input on port " << port
                                      << " is not drawn: the inputs of ports other than 0 are "
                                         "drawn through a vtkMultiVolume (SetVolume(volume, "
                                      << port << ") and the vtkMultiVolume in the renderer)");
    }
  }
}


void vtkFerroVolumeSettings::Reset()
{
  this->HaveEnvironment = false;
  this->EnvironmentKey.clear();
}
