// vtkFerroVolumeSettings, the modes beyond ray casting: the isosurfaces (ISOSURFACE_BLEND),
// path tracing (RENDER_MODE_PATH_TRACE) and the environment light both draw with (see
// vtkFerroVolumeSettings.cxx for the rest of a frame's parameters).
#include "vtkFerroVolumeSettings.h"

#include "vtkColorTransferFunction.h"
#include "vtkContourValues.h"
#include "vtkFerroUnstructuredVolumeMapper.h"
#include "vtkFerroVolumeContext.h"
#include "vtkFerroVolumeMapper.h"
#include "vtkFerroVolumeReport.h"
#include "vtkPiecewiseFunction.h"
#include "vtkRenderWindow.h"
#include "vtkRenderer.h"
#include "vtkVolume.h"
#include "vtkVolumeProperty.h"

#include <algorithm>
#include <cfloat>
#include <limits>
#include <sstream>
#include <string>

//------------------------------------------------------------------------------------------
// Gives the renderer the mapper's environment when the map or its placement changed since
// the last frame; false (said once per setting with vtkErrorMacro) when it cannot be used.
template <class Mapper>
bool vtkFerroVolumeSettings::UseEnvironment(Mapper* self, ferrovol::Renderer& renderer)
{
  const char* file = self->GetEnvironmentMap();
  const bool sky = !file || !*file;
  const double* up = self->GetEnvironmentUp();
  std::ostringstream key;
  key << (sky ? "" : file) << '|' << up[0] << ',' << up[1] << ',' << up[2] << '|'
      << self->GetEnvironmentAzimuth() << '|' << self->GetEnvironmentIntensity();
  if (!this->HaveEnvironment ||
    (this->EnvironmentKey != key.str() && this->EnvironmentKey != "failed:" + key.str()))
  {
    this->HaveEnvironment = true;
    this->EnvironmentKey = key.str();
    vtkFerroVolumeReport failure;
    if (!vtkFerroVolumeCall("use the environment map", failure, [&] {
          renderer.set_environment(sky ? nullptr : file,
            static_cast<float>(self->GetEnvironmentIntensity()), up,
            self->GetEnvironmentAzimuth());
        }))
    {
      vtkErrorWithObjectMacro(
        self, << failure.GetError() << " (drawing without environment light)");
      this->EnvironmentKey = "failed:" + key.str();
    }
  }
  return this->EnvironmentKey.rfind("failed:", 0) != 0;
}

template <class Mapper>
uint32_t vtkFerroVolumeSettings::DenoiseUntil(Mapper* self)
{
  return static_cast<uint32_t>(
    std::min(self->GetPathTracingDenoiseUntil(), self->GetSamplesPerPixel()));
}

template <class Mapper>
vtkFerroVolumeRefinement::Settings vtkFerroVolumeSettings::Refining(Mapper* self)
{
  vtkFerroVolumeRefinement::Settings s;
  s.Mode = self->GetProgressiveMode();
  s.Budget = self->GetPathTracingTimeBudget();
  s.Denoise = self->GetPathTracingDenoise() != 0;
  s.DenoiseUntil = DenoiseUntil(self);
  s.Target = static_cast<uint32_t>(self->GetSamplesPerPixel());
  return s;
}

namespace
{
// The surface model of an image volume's path tracing: the hybrid model's threshold or
// stochastic blend, the scattering regions, attenuation and the BSDF.
void SetSurfaceModel(vtkFerroVolumeMapper* self, FvPathTraceParams& pt)
{
  const double psi = self->GetGradientThreshold();
  pt.gradient_threshold = psi >= static_cast<double>(FLT_MAX)
    ? std::numeric_limits<float>::infinity()
    : static_cast<float>(psi);
  pt.stochastic_blend = static_cast<float>(std::min(self->GetStochasticBlend(), 1e30));
  pt.scatter_regions = static_cast<uint32_t>(self->GetScatterRegions());
  pt.attenuation = self->GetAttenuation() != 0;
  pt.roughness = static_cast<float>(self->GetBsdfRoughness());
  pt.fresnel = static_cast<float>(self->GetBsdfFresnel());
  pt.transmission = static_cast<float>(self->GetTransmission());
  pt.cone_angle = static_cast<float>(self->GetTransmissionConeAngle());
}

// Meshes scatter by Henyey-Greenstein everywhere (the defaults).
void SetSurfaceModel(vtkFerroUnstructuredVolumeMapper*, FvPathTraceParams&) {}
}

// Gives the renderer the path tracing settings: the property's ScatteringAnisotropy, the
// mapper's budget (progressive: `traceBudget` seconds of paths toward SamplesPerPixel;
// otherwise the still budget, or InteractiveSamplesPerPixel per frame while the window
// renders interactively), the preview denoising (until PathTracingDenoiseUntil paths, never
// past SamplesPerPixel), bounces, the surface model and environment (weight 1; background
// when EnvironmentBackground is on).
template <class Mapper>
bool vtkFerroVolumeSettings::SetUpPathTracing(Mapper* self, vtkRenderer* ren, vtkVolume* vol,
  ferrovol::Renderer& renderer, double traceBudget, vtkFerroVolumeReport& report)
{
  FvPathTraceParams pt;
  if (!vtkFerroVolumeCall("use the path tracing settings", report,
        [&] { pt = ferrovol::Renderer::default_path_trace_params(); }))
  {
    return false;
  }
  vtkRenderWindow* win = ren->GetRenderWindow();
  const bool interactive = win && win->GetDesiredUpdateRate() > 1.0;
  const uint32_t spp = static_cast<uint32_t>(self->GetSamplesPerPixel());
  if (interactive && !(traceBudget > 0.0))
  {
    pt.samples_per_frame = static_cast<uint32_t>(self->GetInteractiveSamplesPerPixel());
    pt.max_samples = 0;
  }
  else
  {
    pt.samples_per_frame = std::min(spp, 4096u);
    pt.max_samples = spp;
    pt.time_budget = static_cast<float>(traceBudget);
  }
  if (!interactive)
  {
    pt.secondary_rays = static_cast<uint32_t>(self->GetSecondaryRays());
  }
  pt.denoise_until = DenoiseUntil(self);
  pt.max_bounces = static_cast<uint32_t>(self->GetPathTracingBounces());
  SetSurfaceModel(self, pt);
  pt.denoise = self->GetPathTracingDenoise() != 0;
  // (|g| = 1 is a delta, which a Monte Carlo estimate cannot sample: clamp inside)
  pt.anisotropy =
    std::max(-0.99f, std::min(0.99f, vol->GetProperty()->GetScatteringAnisotropy()));
  pt.background = self->GetEnvironmentBackground() != 0;
  if (!this->UseEnvironment(self, renderer))
  {
    pt.environment_light = 0.0f;
    pt.background = false;
  }
  this->Background = pt.background;
  return vtkFerroVolumeCall(
    "use the path tracing settings", report, [&] { renderer.set_path_tracing(pt); });
}

namespace
{
// The scattering between the isosurfaces (the image mapper's IsosurfaceScattering*).
void SetScattering(vtkFerroVolumeMapper* self, FvIsoParams& iso)
{
  iso.scatter_mode = static_cast<uint32_t>(self->GetIsosurfaceScattering());
  iso.scatter_samples = static_cast<uint32_t>(self->GetIsosurfaceScatteringSamples());
  iso.scatter_absorption =
    static_cast<float>(std::min(self->GetIsosurfaceScatteringAbsorption(), 1e30));
  if (self->GetFresnel() >= 0.0)
  {
    iso.scatter_fresnel = static_cast<float>(self->GetFresnel());
  }
}

// A mesh's surfaces are shaded as layers, without scattering between them.
void SetScattering(vtkFerroUnstructuredVolumeMapper*, FvIsoParams&) {}
}

// Gives the renderer the property's iso-values and the mapper's isosurface shading, and the
// environment when it changed. The surfaces' colours and opacities are the property's
// colour and scalar opacity functions at the iso-values, as vtkGPUVolumeRayCastMapper's:
// those of the component the surfaces are of (independent components: the one of the
// largest weight, the first of equal ones, as ferrovol's core picks it; else the first);
// Shade off draws flat colours (ambient 1, no diffuse or specular light, no environment
// light). Without iso-values nothing is drawn, silently, as vtkGPUVolumeRayCastMapper does.
template <class Mapper>
vtkFerroVolumeSettings::Result vtkFerroVolumeSettings::SetUpIsosurfaces(Mapper* self,
  vtkVolume* vol, int components, FvRenderParams& params, ferrovol::Renderer& renderer,
  vtkFerroVolumeReport& report)
{
  vtkVolumeProperty* prop = vol->GetProperty();
  int comp = 0;
  if (prop->GetIndependentComponents())
  {
    for (int c = 1; c < components; ++c)
    {
      if (prop->GetComponentWeight(c) > prop->GetComponentWeight(comp))
      {
        comp = c;
      }
    }
  }
  vtkContourValues* contours = prop->GetIsoSurfaceValues();
  const int n = contours ? contours->GetNumberOfContours() : 0;
  if (n < 1)
  {
    return Result::NothingVisible;
  }
  if (n > FV_MAX_ISO_VALUES && report.FirstTime("iso-count"))
  {
    vtkWarningWithObjectMacro(self, << n << " iso-values: ferrovol draws the first "
                                    << FV_MAX_ISO_VALUES);
  }
  FvIsoParams iso;
  if (!vtkFerroVolumeCall("use the isosurface settings", report,
        [&] { iso = ferrovol::Renderer::default_iso_params(); }))
  {
    return Result::Failed;
  }
  // (Get{Gray,RGB}TransferFunction create a default function, and switch the property to
  // it, when it has none: ask for the one the property uses.)
  const bool grayColor = prop->GetColorChannels(comp) == 1;
  vtkColorTransferFunction* rgb = grayColor ? nullptr : prop->GetRGBTransferFunction(comp);
  vtkPiecewiseFunction* gray = grayColor ? prop->GetGrayTransferFunction(comp) : nullptr;
  vtkPiecewiseFunction* opacity = prop->GetScalarOpacity(comp);
  uint32_t count = 0;
  for (int i = 0; i < std::min(n, static_cast<int>(FV_MAX_ISO_VALUES)); ++i)
  {
    const double v = contours->GetValue(i);
    const double a = std::min(1.0, opacity->GetValue(v));
    if (!(a > 0.0))
    {
      if (report.FirstTime("iso-transparent-" + std::to_string(v)))
      {
        vtkWarningWithObjectMacro(self, << "iso-value " << v
                                        << " has opacity 0 in the scalar opacity function: "
                                           "it is not drawn");
      }
      continue;
    }
    FvIsoValue& iv = iso.values[count++];
    iv.value = v;
    double c[3];
    if (grayColor)
    {
      c[0] = c[1] = c[2] = gray->GetValue(v);
    }
    else
    {
      rgb->GetColor(v, c);
    }
    for (int k = 0; k < 3; ++k)
    {
      iv.color[k] = static_cast<float>(std::min(1.0, std::max(0.0, c[k])));
    }
    iv.opacity = static_cast<float>(a);
  }
  if (count == 0)
  {
    return Result::NothingVisible;
  }
  iso.value_count = count;
  iso.max_layers = static_cast<uint32_t>(self->GetIsosurfaceLayers());
  iso.specular_mode = self->GetSpecularSampling() == vtkFerroVolumeMapper::SPECULAR_CONE
    ? FV_SPECULAR_MODE_CONE
    : FV_SPECULAR_MODE_IMPORTANCE;
  iso.specular_samples = static_cast<uint32_t>(self->GetSpecularSamples());
  if (self->GetShininessFromGradient())
  {
    const double* e = self->GetShininessRange();
    const double* g = self->GetShininessGradientRange();
    iso.shininess[0] = static_cast<float>(e[0]);
    iso.shininess[1] = static_cast<float>(e[1]);
    iso.shininess_range[0] = g[0];
    iso.shininess_range[1] = g[1];
  }
  else
  {
    iso.shininess[0] = iso.shininess[1] = params.specular_power;
  }
  iso.fresnel = static_cast<float>(self->GetFresnel());
  SetScattering(self, iso);
  iso.ao_samples = static_cast<uint32_t>(self->GetAmbientOcclusionSamples());
  iso.ao_steps = static_cast<uint32_t>(self->GetAmbientOcclusionSteps());
  iso.ao_radius = self->GetAmbientOcclusionRadius();
  iso.background = self->GetEnvironmentBackground() != 0;
  iso.environment_light = params.shade ? static_cast<float>(self->GetEnvironmentLighting()) : 0.0f;
  if (!params.shade)
  {
    params.ambient = 1.0f;
    params.diffuse = 0.0f;
    params.specular = 0.0f;
  }

  if ((iso.environment_light > 0.0f || iso.background) && !this->UseEnvironment(self, renderer))
  {
    iso.environment_light = 0.0f;
    iso.background = false;
  }
  this->Background = iso.background;
  if (!vtkFerroVolumeCall(
        "use the isosurface settings", report, [&] { renderer.set_isosurface(iso); }))
  {
    return Result::Failed;
  }
  return Result::Ready;
}

// The two mappers that path trace and draw isosurfaces.
template vtkFerroVolumeRefinement::Settings vtkFerroVolumeSettings::Refining(
  vtkFerroVolumeMapper*);
template vtkFerroVolumeRefinement::Settings vtkFerroVolumeSettings::Refining(
  vtkFerroUnstructuredVolumeMapper*);
template bool vtkFerroVolumeSettings::SetUpPathTracing(vtkFerroVolumeMapper*, vtkRenderer*,
  vtkVolume*, ferrovol::Renderer&, double, vtkFerroVolumeReport&);
template bool vtkFerroVolumeSettings::SetUpPathTracing(vtkFerroUnstructuredVolumeMapper*,
  vtkRenderer*, vtkVolume*, ferrovol::Renderer&, double, vtkFerroVolumeReport&);
template vtkFerroVolumeSettings::Result vtkFerroVolumeSettings::SetUpIsosurfaces(
  vtkFerroVolumeMapper*, vtkVolume*, int, FvRenderParams&, ferrovol::Renderer&,
  vtkFerroVolumeReport&);
template vtkFerroVolumeSettings::Result vtkFerroVolumeSettings::SetUpIsosurfaces(
  vtkFerroUnstructuredVolumeMapper*, vtkVolume*, int, FvRenderParams&, ferrovol::Renderer&,
  vtkFerroVolumeReport&);
