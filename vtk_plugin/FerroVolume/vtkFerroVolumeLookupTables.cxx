#include "vtkFerroVolumeLookupTables.h"

#include "vtkColorTransferFunction.h"
#include "vtkFerroVolumeContext.h"
#include "vtkDataArray.h"
#include "vtkFerroVolumeReport.h"
#include "vtkGPUVolumeRayCastMapper.h"
#include "vtkImageData.h"
#include "vtkImageResize.h"
#include "vtkMath.h"
#include "vtkMatrix4x4.h"
#include "vtkNew.h"
#include "vtkPiecewiseFunction.h"
#include "vtkPointData.h"
#include "vtkVolume.h"
#include "vtkVolumeProperty.h"

#include <algorithm>
#include <cmath>
#include <memory>
#include <sstream>
#include <vector>

namespace
{
// Entries of ferrovol's lookup tables (core's transfer table size). Colour and opacity are
// sampled with VTK's own GetTable at exactly these positions over the range VTK's GPU mapper
// uses, so ferrovol's tables equal VTK's (midpoints and sharpness included).
constexpr int TableSize = 1024;

// The x positions of a table over [lo, hi]: TableSize points, as VTK's GetTable places them.
// A single-valued range (constant data) becomes two nodes [lo, lo + 1] holding the value at lo.
void TablePositions(double lo, double hi, std::vector<double>& xs)
{
  if (!(hi > lo))
  {
    xs = { lo, lo + 1.0 };
    return;
  }
  xs.resize(TableSize);
  for (int i = 0; i < TableSize; ++i)
  {
    xs[i] = lo + (hi - lo) * i / (TableSize - 1);
  }
}

void SampleScalar(vtkPiecewiseFunction* f, double lo, double hi, int m, double* out)
{
  if (hi > lo)
  {
    f->GetTable(lo, hi, m, out);
    return;
  }
  std::fill(out, out + m, f->GetValue(lo));
}

void SampleColor(vtkColorTransferFunction* f, double lo, double hi, int m, double* out)
{
  if (hi > lo)
  {
    f->GetTable(lo, hi, m, out);
    return;
  }
  double rgb[3];
  f->GetColor(lo, rgb);
  for (int i = 0; i < m; ++i)
  {
    std::copy(rgb, rgb + 3, out + 3 * i);
  }
}

// A function with no nodes: VTK's GPU mapper puts a ramp over the range in its place, from 0
// to `top` (black to white for colour, (min, 0) to (max, 0.5) for opacity).
void Ramp(const std::vector<double>& xs, double lo, double hi, double top, double* out)
{
  for (size_t i = 0; i < xs.size(); ++i)
  {
    out[i] = (hi > lo) ? top * (xs[i] - lo) / (hi - lo) : 0.0;
  }
}

double Clamp01(double v)
{
  return std::min(1.0, std::max(0.0, v));
}

// Where a function is read for each table position `xs` under vtkGPUVolumeRayCastMapper's
// NATIVE range type: VTK 9.2 builds the table over the function's own range [flo, fhi] but
// looks it up by the sample's position in the data range [dlo, dhi] (clamped to it), so a
// value s reads the function at flo + (s − dlo) / (dhi − dlo) · (fhi − flo).
std::vector<double> NativePositions(
  const std::vector<double>& xs, double dlo, double dhi, const double frange[2])
{
  std::vector<double> out(xs.size());
  for (size_t i = 0; i < xs.size(); ++i)
  {
    const double t = dhi > dlo ? std::min(1.0, std::max(0.0, (xs[i] - dlo) / (dhi - dlo))) : 0.0;
    out[i] = frange[0] + t * (frange[1] - frange[0]);
  }
  return out;
}

// How a table reads its function: SCALAR (the function at the table positions themselves)
// or NATIVE over the data range [DataLo, DataHi] the lookup is normalised by.
struct Lookup
{
  bool Native = false;
  double DataLo = 0.0;
  double DataHi = 0.0;
};

// Colour of component `c` as (x, r, g, b) nodes at `xs` (spanning [lo, hi]).
void ColorNodes(vtkVolumeProperty* prop, int c, double lo, double hi,
  const std::vector<double>& xs, const Lookup& lookup, std::vector<double>& pts)
{
  const int m = static_cast<int>(xs.size());
  std::vector<double> rgb(static_cast<size_t>(3) * m, 0.0);
  if (prop->GetColorChannels(c) == 1)
  {
    std::vector<double> gray(m);
    vtkPiecewiseFunction* g = prop->GetGrayTransferFunction(c);
    if (g->GetSize() < 1)
    {
      Ramp(xs, lo, hi, 1.0, gray.data());
    }
    else if (lookup.Native)
    {
      double frange[2];
      g->GetRange(frange);
      const std::vector<double> at = NativePositions(xs, lookup.DataLo, lookup.DataHi, frange);
      for (int i = 0; i < m; ++i)
      {
        gray[i] = g->GetValue(at[i]);
      }
    }
    else
    {
      SampleScalar(g, lo, hi, m, gray.data());
    }
    for (int i = 0; i < m; ++i)
    {
      rgb[3 * i] = rgb[3 * i + 1] = rgb[3 * i + 2] = gray[i];
    }
  }
  else
  {
    vtkColorTransferFunction* ctf = prop->GetRGBTransferFunction(c);
    if (ctf->GetSize() < 1)
    {
      std::vector<double> ramp(m);
      Ramp(xs, lo, hi, 1.0, ramp.data());
      for (int i = 0; i < m; ++i)
      {
        rgb[3 * i] = rgb[3 * i + 1] = rgb[3 * i + 2] = ramp[i];
      }
    }
    else if (lookup.Native)
    {
      const std::vector<double> at =
        NativePositions(xs, lookup.DataLo, lookup.DataHi, ctf->GetRange());
      for (int i = 0; i < m; ++i)
      {
        ctf->GetColor(at[i], rgb.data() + 3 * i);
      }
    }
    else
    {
      SampleColor(ctf, lo, hi, m, rgb.data());
    }
  }
  pts.resize(static_cast<size_t>(4) * m);
  for (int i = 0; i < m; ++i)
  {
    pts[4 * i] = xs[i];
    for (int k = 0; k < 3; ++k)
    {
      pts[4 * i + 1 + k] = Clamp01(rgb[3 * i + k]);
    }
  }
}

// Scalar opacity of component `c` as (x, opacity) nodes at `xs` (spanning [lo, hi]).
void OpacityNodes(vtkVolumeProperty* prop, int c, double lo, double hi,
  const std::vector<double>& xs, const Lookup& lookup, std::vector<double>& pts)
{
  const int m = static_cast<int>(xs.size());
  std::vector<double> values(m, 0.0);
  vtkPiecewiseFunction* sof = prop->GetScalarOpacity(c);
  if (sof->GetSize() < 1)
  {
    Ramp(xs, lo, hi, 0.5, values.data());
  }
  else if (lookup.Native)
  {
    const std::vector<double> at =
      NativePositions(xs, lookup.DataLo, lookup.DataHi, sof->GetRange());
    for (int i = 0; i < m; ++i)
    {
      values[i] = sof->GetValue(at[i]);
    }
  }
  else
  {
    SampleScalar(sof, lo, hi, m, values.data());
  }
  pts.resize(static_cast<size_t>(2) * m);
  for (int i = 0; i < m; ++i)
  {
    pts[2 * i] = xs[i];
    pts[2 * i + 1] = Clamp01(values[i]);
  }
}

// Gradient opacity. VTK 9.2 (vtkVolumeShaderComposer.h computeGradient and
// vtkOpenGLVolumeGradientOpacityTable) evaluates the function at
//   g_vtk = meanSpacing · |∇s|   (central differences, ∇ in data coordinates)
// clamped to [0, 0.25 · (max − min)] of the component's data range, the table spanning
// exactly that (NATIVE: the table spans [0, 0.25 · the function's own range] and is looked
// up the same way, so the function is read at g_vtk · its range / the data range). ferrovol's
// x axis is |∇s| in scalar units per world unit, so the nodes move to
// x = g_vtk · gradientScale, gradientScale = 1 / (meanSpacing · volume matrix scale);
// ferrovol clamps beyond the last node just as VTK clamps. A constant 1 (VTK's default
// function) changes nothing: `pts` is then empty (gradient opacity off).
void GradientOpacityNodes(vtkPiecewiseFunction* gof, const std::array<double, 2>& dataRange,
  bool native, double gradientScale, std::vector<double>& pts)
{
  const double range = dataRange[1] - dataRange[0];
  const double gmax = 0.25 * (range != 0.0 ? range : 1.0);
  double span = gmax;
  if (native && gof->GetSize() > 0)
  {
    const double* frange = gof->GetRange();
    span = 0.25 * (frange[1] - frange[0]);
  }
  std::vector<double> values(TableSize, 1.0);
  gof->GetTable(0.0, range != 0.0 ? span : 0.0, TableSize, values.data());
  bool allOne = true;
  pts.resize(static_cast<size_t>(2) * TableSize);
  for (int i = 0; i < TableSize; ++i)
  {
    const double v = Clamp01(values[i]);
    allOne = allOne && v == 1.0;
    pts[2 * i] = gmax * i / (TableSize - 1) * gradientScale;
    pts[2 * i + 1] = v;
  }
  if (allOne)
  {
    pts.clear();
  }
}

bool BuildTransferFunction(vtkVolumeProperty* prop, int comps,
  const vtkFerroVolumeInputHelper::Ranges& ranges,
  const vtkFerroVolumeLookupTables::RangeTypes& types, double gradientScale,
  std::unique_ptr<ferrovol::TransferFunction>& tf, vtkFerroVolumeReport& report)
{
  const bool independent = comps == 1 || prop->GetIndependentComponents();
  if (!independent && comps != 2 && comps != 4)
  {
    return report.Fail("IndependentComponents is off with " + std::to_string(comps) +
      " components: dependent components need 2 (colour scalar, opacity scalar) or 4 (RGB + "
      "opacity scalar)");
  }
  const int n = independent ? comps : 1;
  if (!vtkFerroVolumeCall("create a transfer function", report, [&] {
        tf.reset(new ferrovol::TransferFunction(static_cast<uint32_t>(n), independent));
      }))
  {
    return false;
  }
  std::vector<double> xs, pts;
  for (int c = 0; c < n; ++c)
  {
    // Table ranges as vtkGPUVolumeRayCastMapper: each component's data range; dependent
    // components take colour from component 0 and opacity from the last one, and share
    // one table here, spanning both ranges. The NATIVE range types read the functions as
    // VTK does (NativePositions), relative to the range of the component looked up.
    double lo = ranges[c][0], hi = ranges[c][1];
    const int opacityComp = independent ? c : comps - 1;
    if (!independent)
    {
      lo = std::min(ranges[0][0], ranges[comps - 1][0]);
      hi = std::max(ranges[0][1], ranges[comps - 1][1]);
    }
    TablePositions(lo, hi, xs);
    const uint32_t component = static_cast<uint32_t>(c);
    const int colorComp = independent ? c : 0;
    const Lookup colorLookup{ types.Color == vtkGPUVolumeRayCastMapper::NATIVE,
      ranges[colorComp][0], ranges[colorComp][1] };
    const Lookup opacityLookup{ types.ScalarOpacity == vtkGPUVolumeRayCastMapper::NATIVE,
      ranges[opacityComp][0], ranges[opacityComp][1] };
    ColorNodes(prop, c, lo, hi, xs, colorLookup, pts);
    if (!vtkFerroVolumeCall(
          "set the colour transfer function", report, [&] { tf->set_color(component, pts); }))
    {
      return false;
    }
    OpacityNodes(prop, c, lo, hi, xs, opacityLookup, pts);
    if (!vtkFerroVolumeCall(
          "set the scalar opacity function", report, [&] { tf->set_opacity(component, pts); }) ||
      !vtkFerroVolumeCall("set the scalar opacity unit distance", report, [&] {
        tf->set_unit_distance(component, prop->GetScalarOpacityUnitDistance(opacityComp),
          prop->GetComponentWeight(c));
      }))
    {
      return false;
    }
    if (independent && n > 1)
    {
      // vtkGPUVolumeRayCastMapper shades each independent component with its own material.
      const float material[4] = { static_cast<float>(prop->GetAmbient(c)),
        static_cast<float>(prop->GetDiffuse(c)), static_cast<float>(prop->GetSpecular(c)),
        static_cast<float>(prop->GetSpecularPower(c)) };
      if (!vtkFerroVolumeCall("set the component's shading material", report,
            [&] { tf->set_material(component, material); }))
      {
        return false;
      }
    }
    const int goIndex = independent ? c : 0;
    if (prop->HasGradientOpacity(goIndex) && !prop->GetDisableGradientOpacity(goIndex))
    {
      GradientOpacityNodes(prop->GetStoredGradientOpacity(goIndex), ranges[opacityComp],
        types.GradientOpacity == vtkGPUVolumeRayCastMapper::NATIVE, gradientScale, pts);
      if (!vtkFerroVolumeCall("set the gradient opacity function", report,
            [&] { tf->set_gradient_opacity(component, pts); }))
      {
        return false;
      }
    }
  }
  return true;
}

// The labels' own functions (vtkVolumeProperty::SetLabel*) of a one-component volume,
// sampled as VTK 9.2's label-map tables are: colour and scalar opacity with GetTable over
// the component's data range, gradient opacity as the component's. Labels above 255 are left
// out: a label map holds labels 0 to 255.
bool BuildLabels(vtkVolumeProperty* prop, const std::array<double, 2>& range,
  double gradientScale, ferrovol::TransferFunction& tf, vtkFerroVolumeReport& report)
{
  std::vector<double> xs, pts, values;
  TablePositions(range[0], range[1], xs);
  const int m = static_cast<int>(xs.size());
  for (const int label : prop->GetLabelMapLabels())
  {
    if (label < 1 || label > 255)
    {
      continue;
    }
    const uint32_t l = static_cast<uint32_t>(label);
    if (vtkColorTransferFunction* ctf = prop->GetLabelColor(label))
    {
      values.assign(static_cast<size_t>(3) * m, 0.0);
      SampleColor(ctf, range[0], range[1], m, values.data());
      pts.resize(static_cast<size_t>(4) * m);
      for (int i = 0; i < m; ++i)
      {
        pts[4 * i] = xs[i];
        for (int k = 0; k < 3; ++k)
        {
          pts[4 * i + 1 + k] = Clamp01(values[3 * i + k]);
        }
      }
      if (!vtkFerroVolumeCall(
            "set a label's colour function", report, [&] { tf.set_label_color(l, pts); }))
      {
        return false;
      }
    }
    if (vtkPiecewiseFunction* sof = prop->GetLabelScalarOpacity(label))
    {
      values.assign(m, 0.0);
      SampleScalar(sof, range[0], range[1], m, values.data());
      pts.resize(static_cast<size_t>(2) * m);
      for (int i = 0; i < m; ++i)
      {
        pts[2 * i] = xs[i];
        pts[2 * i + 1] = Clamp01(values[i]);
      }
      if (!vtkFerroVolumeCall(
            "set a label's opacity function", report, [&] { tf.set_label_opacity(l, pts); }))
      {
        return false;
      }
    }
    if (vtkPiecewiseFunction* gof = prop->GetLabelGradientOpacity(label))
    {
      GradientOpacityNodes(gof, range, false, gradientScale, pts);
      if (pts.empty())
      {
        // (a constant 1: no attenuation, which the first component's function may have)
        pts = { 0.0, 1.0 };
      }
      if (!vtkFerroVolumeCall("set a label's gradient opacity function", report,
            [&] { tf.set_label_gradient_opacity(l, pts); }))
      {
        return false;
      }
    }
  }
  return true;
}

// Component c's 2D transfer function (vtkVolumeProperty::GetTransferFunction2D, TF_2D mode)
// as VTK 9.2 draws it: the image's RGBA over the component's data range (x) and gradient
// magnitudes up to 0.25 · the data range in VTK's units (y), its opacity per sample. (VTK's
// shader reads the gradient axis only with a gradient opacity function, but its mapper makes
// the property's default one on the first render, so in effect always; the function does not
// multiply.) VTK uploads the image as a texture of at least 1024 texels per side that has
// more than one (a power of two), resampled to it with vtkImageResize's defaults (Lanczos,
// corner points on corner texels): so is the table handed to ferrovol, which then reads it
// as VTK's texture is read.
bool Table2DOf(vtkVolumeProperty* prop, int c, const std::array<double, 2>& range,
  double gradientScale, ferrovol::TransferFunction& tf, vtkFerroVolumeReport& report)
{
  vtkImageData* image = prop->GetTransferFunction2D(c);
  vtkDataArray* scalars = image ? image->GetPointData()->GetScalars() : nullptr;
  int dims[3] = { 0, 0, 0 };
  if (image)
  {
    image->GetDimensions(dims);
  }
  if (!scalars || scalars->GetNumberOfComponents() != 4 || dims[2] != 1 || dims[0] < 1 ||
    dims[1] < 1)
  {
    std::ostringstream os;
    os << "TransferFunctionMode is TF_2D and component " << c << "'s TransferFunction2D is ";
    if (!image)
    {
      os << "not set";
    }
    else
    {
      os << dims[0] << "x" << dims[1] << "x" << dims[2] << " with "
         << (scalars ? scalars->GetNumberOfComponents() : 0)
         << " components per point: it must be a 2D image of RGBA values";
    }
    return report.Fail(os.str());
  }
  const auto texels = [](int n) { return std::max(1024, vtkMath::NearestPowerOfTwo(n)); };
  const int width = texels(dims[0]);
  const int height = dims[1] > 1 ? texels(dims[1]) : 1;
  vtkNew<vtkImageResize> resize;
  if (width != dims[0] || height != dims[1])
  {
    resize->SetInputData(image);
    resize->SetResizeMethodToOutputDimensions();
    resize->SetOutputDimensions(width, height, 1);
    resize->Update();
    scalars = resize->GetOutput()->GetPointData()->GetScalars();
    dims[0] = width;
    dims[1] = height;
  }
  const vtkIdType n = static_cast<vtkIdType>(dims[0]) * dims[1];
  std::vector<float> rgba(static_cast<size_t>(4) * n);
  for (vtkIdType i = 0; i < n; ++i)
  {
    for (int k = 0; k < 4; ++k)
    {
      // (vtkImageResize's windowed sinc rings past [0, 1] at a box's edges: a colour above
      // 1 composites to more colour than opacity, which IceT's 8-bit "over" wraps under MPI)
      const double v = scalars->GetComponent(i, k);
      rgba[4 * i + k] = static_cast<float>(v > 0.0 ? std::min(v, 1.0) : 0.0);
    }
  }
  const double span = range[1] - range[0];
  const double lo = range[0];
  const double hi = span > 0.0 ? range[1] : range[0] + 1.0;
  const double gmax = 0.25 * (span != 0.0 ? span : 1.0) * gradientScale;
  return vtkFerroVolumeCall("set the 2D transfer function", report, [&] {
    tf.set_table_2d(static_cast<uint32_t>(c), static_cast<uint32_t>(dims[0]),
      static_cast<uint32_t>(dims[1]), rgba, lo, hi, gmax);
  });
}

// Every component's 2D table in TF_2D mode (one or independent components; VTK's dependent
// components read one table differently, which ferrovol does not do: an error).
bool Build2D(bool twoD, vtkVolumeProperty* prop, const vtkFerroVolumeLookupTables::Key& key,
  ferrovol::TransferFunction& tf, vtkFerroVolumeReport& report)
{
  if (!twoD)
  {
    return true;
  }
  if (key.Components > 1 && !prop->GetIndependentComponents())
  {
    return report.Fail("2D transfer functions (TF_2D) with dependent components are not "
                       "supported by vtkFerroVolumeMapper: nothing is drawn");
  }
  for (int c = 0; c < key.Components; ++c)
  {
    if (!Table2DOf(prop, c, key.Ranges[c], key.GradientScale, tf, report))
    {
      return false;
    }
  }
  return true;
}

// The latest modification of the property's label functions.
vtkMTimeType LabelsMTime(vtkVolumeProperty* prop)
{
  vtkMTimeType t = 0;
  for (const int label : prop->GetLabelMapLabels())
  {
    vtkObject* functions[3] = { prop->GetLabelColor(label), prop->GetLabelScalarOpacity(label),
      prop->GetLabelGradientOpacity(label) };
    for (vtkObject* f : functions)
    {
      t = f ? std::max(t, f->GetMTime()) : t;
    }
  }
  return t;
}
} // namespace

bool vtkFerroVolumeLookupTables::Key::operator==(const Key& o) const
{
  return this->Property == o.Property && this->PropertyMTime == o.PropertyMTime &&
    this->Components == o.Components && this->Ranges == o.Ranges && this->Types == o.Types &&
    this->GradientScale == o.GradientScale && this->LabelsMTime == o.LabelsMTime &&
    this->Tables2DMTime == o.Tables2DMTime;
}

double vtkFerroVolumeLookupTables::MatrixScale(vtkVolume* volume)
{
  return std::cbrt(std::fabs(volume->GetMatrix()->Determinant()));
}

bool vtkFerroVolumeLookupTables::BuildFirstComponent(vtkVolumeProperty* prop,
  const std::array<double, 2>& range, const RangeTypes& types, const char* what,
  double gradientScale, std::unique_ptr<ferrovol::TransferFunction>& tf,
  vtkFerroVolumeReport& report)
{
  if (prop->GetTransferFunctionMode() == vtkVolumeProperty::TF_2D)
  {
    return report.Fail(std::string("its property has a 2D transfer function: ") + what +
      " are classified by 1D colour and scalar opacity functions");
  }
  if (!(gradientScale > 0.0) && prop->HasGradientOpacity(0) &&
    !prop->GetDisableGradientOpacity(0))
  {
    return report.Fail(std::string("its property has a gradient opacity function: ") + what +
      " are classified by colour and scalar opacity only (DisableGradientOpacityOn)");
  }
  vtkFerroVolumeInputHelper::Ranges ranges{};
  ranges[0] = range;
  return BuildTransferFunction(
    prop, 1, ranges, types, gradientScale > 0.0 ? gradientScale : 1.0, tf, report);
}

bool vtkFerroVolumeLookupTables::Update(vtkVolume* volume,
  const vtkFerroVolumeInputHelper& input, const RangeTypes& rangeTypes,
  ferrovol::Renderer& renderer, vtkFerroVolumeReport& report)
{
  vtkVolumeProperty* prop = volume->GetProperty();
  const bool twoD = prop->GetTransferFunctionMode() == vtkVolumeProperty::TF_2D;
  const double matrixScale = MatrixScale(volume);
  if (!(matrixScale > 0.0) || !std::isfinite(matrixScale))
  {
    return report.Fail("the vtkVolume's matrix is singular (zero scale?): nothing is drawn");
  }
  Key key;
  key.Property = prop;
  key.PropertyMTime = prop->GetMTime();
  key.Components = input.GetComponents();
  key.Ranges = input.GetRanges();
  key.Types = rangeTypes;
  key.GradientScale = 1.0 / (input.GetMeanSpacing() * matrixScale);
  key.LabelsMTime = LabelsMTime(prop);
  if (twoD)
  {
    for (int c = 0; c < key.Components; ++c)
    {
      if (vtkImageData* image = prop->GetTransferFunction2D(c))
      {
        key.Tables2DMTime = std::max(key.Tables2DMTime, image->GetMTime());
      }
    }
  }
  if (this->Uploaded && *this->Uploaded == key)
  {
    return true;
  }
  this->Uploaded.reset();
  std::unique_ptr<ferrovol::TransferFunction> tf;
  if (!BuildTransferFunction(
        prop, key.Components, key.Ranges, key.Types, key.GradientScale, tf, report) ||
    (key.Components == 1 &&
      !BuildLabels(prop, key.Ranges[0], key.GradientScale, *tf, report)) ||
    !Build2D(twoD, prop, key, *tf, report) ||
    !vtkFerroVolumeCall(
      "set the transfer function", report, [&] { renderer.set_transfer_function(*tf); }))
  {
    return false;
  }
  this->Uploaded = key;
  return true;
}
