// C++ tests of vtkFerroVolumeMapper (the Python suites cover each setting in detail):
//   - a wavelet renders through the C++ API and vtkWindowToImageFilter captures it;
//   - an opaque sphere in front of the volume shows, one behind it is hidden;
//   - camera changes upload nothing, a property change uploads the tables only, a modified
//     input uploads the volume;
//   - bad input raises an ErrorEvent with a message, draws nothing, and does not crash;
//   - code written for vtkGPUVolumeRayCastMapper takes it: set through a base pointer,
//     RenderToImage leaves the window alone and fills GetColorImage / GetDepthImage.
// Prints what it measured; exits non-zero on the first failed check.
#include "vtkFerroVolumeMapper.h"

#include <vtkActor.h>
#include <vtkCamera.h>
#include <vtkColorTransferFunction.h>
#include <vtkCommand.h>
#include <vtkGPUVolumeRayCastMapper.h>
#include <vtkImageData.h>
#include <vtkNew.h>
#include <vtkPiecewiseFunction.h>
#include <vtkPointData.h>
#include <vtkPolyDataMapper.h>
#include <vtkProperty.h>
#include <vtkRTAnalyticSource.h>
#include <vtkRenderWindow.h>
#include <vtkRenderer.h>
#include <vtkSphereSource.h>
#include <vtkUnsignedCharArray.h>
#include <vtkVolume.h>
#include <vtkVolumeProperty.h>
#include <vtkWindowToImageFilter.h>

#include "FerroVolumeTestCheck.h"

#include <cmath>
#include <cstdio>
#include <string>

namespace
{
class ErrorCatcher : public vtkCommand
{
public:
  static ErrorCatcher* New() { return new ErrorCatcher; }
  void Execute(vtkObject*, unsigned long, void* data) override
  {
    ++this->Count;
    this->Last = data ? static_cast<const char*>(data) : "";
  }
  int Count = 0;
  std::string Last;
};

// All windows share one X display connection (Xvfb here resets new connections now and
// then, and VTK aborts when it does): the first window's.
vtkRenderWindow* DisplayOwner()
{
  static vtkNew<vtkRenderWindow> owner;
  static bool ready = false;
  if (!ready)
  {
    owner->SetOffScreenRendering(1);
    owner->SetSize(4, 4);
    owner->Render();
    ready = true;
  }
  return owner;
}

void ShareDisplay(vtkRenderWindow* win)
{
  win->SetDisplayId(DisplayOwner()->GetGenericDisplayId());
}

struct Scene
{
  vtkNew<vtkRTAnalyticSource> Source;
  vtkNew<vtkFerroVolumeMapper> Mapper;
  vtkNew<vtkColorTransferFunction> Color;
  vtkNew<vtkPiecewiseFunction> Opacity;
  vtkNew<vtkVolumeProperty> Property;
  vtkNew<vtkVolume> Volume;
  vtkNew<vtkRenderer> Renderer;
  vtkNew<vtkRenderWindow> Window;
  vtkNew<ErrorCatcher> Errors;

  Scene()
  {
    this->Source->SetWholeExtent(-20, 20, -20, 20, -20, 20);
    this->Mapper->SetInputConnection(this->Source->GetOutputPort());
    this->Mapper->AddObserver(vtkCommand::ErrorEvent, this->Errors);
    this->Color->AddRGBPoint(37.3531, 0.2, 0.29, 1.0);
    this->Color->AddRGBPoint(157.091, 0.87, 0.87, 0.87);
    this->Color->AddRGBPoint(276.829, 0.7, 0.015, 0.15);
    this->Opacity->AddPoint(37.3531, 0.0);
    this->Opacity->AddPoint(276.829, 1.0);
    this->Property->SetColor(this->Color);
    this->Property->SetScalarOpacity(this->Opacity);
    this->Volume->SetMapper(this->Mapper);
    this->Volume->SetProperty(this->Property);
    this->Renderer->AddVolume(this->Volume);
    this->Renderer->SetBackground(0.0, 0.0, 0.0);
    ShareDisplay(this->Window);
    this->Window->SetOffScreenRendering(1);
    this->Window->SetSize(160, 160);
    this->Window->AddRenderer(this->Renderer);
    this->Renderer->ResetCamera();
  }

  // Renders and returns the RGB pixel at (x, y) (origin bottom left).
  void Pixel(int x, int y, double rgb[3])
  {
    vtkNew<vtkWindowToImageFilter> grab;
    grab->SetInput(this->Window);
    grab->ReadFrontBufferOff();
    grab->Update();
    vtkImageData* img = grab->GetOutput();
    for (int c = 0; c < 3; ++c)
    {
      rgb[c] = img->GetScalarComponentAsDouble(x, y, 0, c) / 255.0;
    }
  }

  double Coverage()
  {
    vtkNew<vtkWindowToImageFilter> grab;
    grab->SetInput(this->Window);
    grab->ReadFrontBufferOff();
    grab->Update();
    vtkImageData* img = grab->GetOutput();
    int dims[3];
    img->GetDimensions(dims);
    int lit = 0;
    for (int y = 0; y < dims[1]; ++y)
    {
      for (int x = 0; x < dims[0]; ++x)
      {
        double s = 0;
        for (int c = 0; c < 3; ++c)
        {
          s += img->GetScalarComponentAsDouble(x, y, 0, c);
        }
        lit += s > 30 ? 1 : 0;
      }
    }
    return static_cast<double>(lit) / (dims[0] * dims[1]);
  }
};

void TestRenderAndCapture()
{
  Scene s;
  s.Window->Render();
  const double cov = s.Coverage();
  std::printf("render: drew=%d, %.1f%% of the window covered, %s path, %d x %d\n",
    static_cast<int>(s.Mapper->GetLastRenderDrew()), 100 * cov, s.Mapper->GetOutputPathName(),
    s.Mapper->GetLastRenderSize()[0], s.Mapper->GetLastRenderSize()[1]);
  CHECK(s.Mapper->GetLastRenderDrew(), "the volume was not drawn: %s", s.Errors->Last.c_str());
  CHECK(s.Errors->Count == 0, "unexpected error: %s", s.Errors->Last.c_str());
  CHECK(cov > 0.2 && cov < 0.9, "coverage %.3f", cov);
  CHECK(s.Mapper->GetLastRenderSize()[0] == 160, "render width %d",
    s.Mapper->GetLastRenderSize()[0]);
}

void TestSphereOcclusion()
{
  for (int front = 1; front >= 0; --front)
  {
    Scene s;
    s.Opacity->RemoveAllPoints();
    s.Opacity->AddPoint(37.3531, 0.0);
    s.Opacity->AddPoint(120.0, 1.0); // nearly opaque volume
    vtkNew<vtkSphereSource> sphere;
    vtkCamera* cam = s.Renderer->GetActiveCamera();
    double dir[3];
    cam->GetDirectionOfProjection(dir);
    // 35 units from the centre toward (front) or away from (back) the camera.
    const double d = front ? -35.0 : 35.0;
    sphere->SetCenter(d * dir[0], d * dir[1], d * dir[2]);
    sphere->SetRadius(6.0);
    sphere->SetThetaResolution(32);
    sphere->SetPhiResolution(32);
    vtkNew<vtkPolyDataMapper> pm;
    pm->SetInputConnection(sphere->GetOutputPort());
    vtkNew<vtkActor> actor;
    actor->SetMapper(pm);
    actor->GetProperty()->SetColor(0.0, 1.0, 0.0);
    actor->GetProperty()->SetAmbient(1.0);
    actor->GetProperty()->SetDiffuse(0.0);
    s.Renderer->AddActor(actor);
    s.Renderer->ResetCameraClippingRange();
    s.Window->Render();
    double rgb[3];
    s.Pixel(80, 80, rgb);
    std::printf("sphere %s the volume: centre pixel (%.2f, %.2f, %.2f)\n",
      front ? "in front of" : "behind", rgb[0], rgb[1], rgb[2]);
    if (front)
    {
      CHECK(rgb[1] > 0.95 && rgb[0] < 0.05 && rgb[2] < 0.05, "sphere not in front");
    }
    else
    {
      CHECK(rgb[1] < 0.9 || rgb[0] > 0.2 || rgb[2] > 0.2, "sphere shows through the volume");
    }
  }
}

void TestUploadCounters()
{
  Scene s;
  s.Window->Render();
  CHECK(s.Mapper->GetVolumeUploadCount() == 1 && s.Mapper->GetTableUploadCount() == 1,
    "first frame: %d volume / %d table uploads", s.Mapper->GetVolumeUploadCount(),
    s.Mapper->GetTableUploadCount());
  for (int i = 0; i < 3; ++i)
  {
    s.Renderer->GetActiveCamera()->Azimuth(20.0);
    s.Window->Render();
  }
  const int v1 = s.Mapper->GetVolumeUploadCount(), t1 = s.Mapper->GetTableUploadCount();
  s.Opacity->AddPoint(200.0, 0.2);
  s.Window->Render();
  const int v2 = s.Mapper->GetVolumeUploadCount(), t2 = s.Mapper->GetTableUploadCount();
  s.Source->SetMaximum(300.0);
  s.Window->Render();
  const int v3 = s.Mapper->GetVolumeUploadCount();
  std::printf("uploads: after camera moves %d/%d, after a property change %d/%d, after an "
              "input change %d volume uploads (%d frames)\n",
    v1, t1, v2, t2, v3, s.Mapper->GetFrameCount());
  CHECK(v1 == 1 && t1 == 1, "camera moves uploaded");
  CHECK(v2 == 1 && t2 == 2, "a property change must upload the tables only");
  CHECK(v3 == 2, "an input change must upload the volume");
}

void TestErrors()
{
  {
    vtkNew<vtkFerroVolumeMapper> mapper;
    vtkNew<ErrorCatcher> errors;
    mapper->AddObserver(vtkCommand::ErrorEvent, errors);
    vtkNew<vtkVolume> volume;
    volume->SetMapper(mapper);
    vtkNew<vtkRenderer> ren;
    ren->AddVolume(volume);
    vtkNew<vtkRenderWindow> win;
    ShareDisplay(win);
    win->SetOffScreenRendering(1);
    win->SetSize(64, 64);
    win->AddRenderer(ren);
    mapper->Render(ren, volume);
    std::printf("no input: %d error(s): %s\n", errors->Count, errors->Last.c_str());
    CHECK(errors->Count >= 1 && errors->Last.find("input") != std::string::npos,
      "no input gave no error");
    CHECK(!mapper->GetLastRenderDrew(), "drew without input");
  }
  {
    Scene s;
    vtkNew<vtkImageData> img;
    img->SetDimensions(8, 8, 8);
    img->SetSpacing(1.0, 0.0, 1.0);
    img->AllocateScalars(VTK_FLOAT, 1);
    s.Mapper->SetInputData(img);
    s.Window->Render();
    std::printf("zero spacing: %s\n", s.Errors->Last.c_str());
    CHECK(s.Errors->Count >= 1 && s.Errors->Last.find("spacing") != std::string::npos,
      "zero spacing gave no error");
    CHECK(!s.Mapper->GetLastRenderDrew(), "drew with zero spacing");
  }
}
void TestAsGPUVolumeRayCastMapper()
{
  Scene s;
  vtkGPUVolumeRayCastMapper* gpu = vtkGPUVolumeRayCastMapper::SafeDownCast(s.Mapper);
  CHECK(gpu != nullptr, "not a vtkGPUVolumeRayCastMapper");
  if (!gpu)
  {
    return;
  }
  CHECK(gpu->IsRenderSupported(s.Window, nullptr) == 1, "render not supported");
  gpu->RenderToImageOn();
  gpu->SetDepthImageScalarTypeToUnsignedShort();
  s.Window->Render();
  const double cov = s.Coverage();
  vtkNew<vtkImageData> color, depth;
  gpu->GetColorImage(color);
  gpu->GetDepthImage(depth);
  int dims[3];
  color->GetDimensions(dims);
  std::printf("as vtkGPUVolumeRayCastMapper*: RenderToImage %d x %d (%s depth), window "
              "covered %.1f%%\n",
    dims[0], dims[1], depth->GetScalarTypeAsString(), 100 * cov);
  CHECK(dims[0] == 160 && dims[1] == 160, "colour image %d x %d", dims[0], dims[1]);
  CHECK(depth->GetScalarType() == VTK_UNSIGNED_SHORT, "depth image of type %s",
    depth->GetScalarTypeAsString());
  CHECK(cov == 0.0, "RenderToImage drew into the window (%.3f)", cov);
}
} // namespace

int main()
{
  std::printf("ferrovol %s on %s\n", vtkFerroVolumeMapper::GetFerrovolVersion(),
    vtkFerroVolumeMapper::GetAdapterDescription());
  TestRenderAndCapture();
  TestSphereOcclusion();
  TestUploadCounters();
  TestErrors();
  TestAsGPUVolumeRayCastMapper();
  std::printf("%s (%d failure(s))\n", failures ? "FAILED" : "passed", failures);
  return failures ? 1 : 0;
}
