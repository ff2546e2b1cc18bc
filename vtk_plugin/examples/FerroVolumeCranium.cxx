// Renders a CT volume with vtkFerroVolumeMapper and a CT bone transfer function, and writes
// a PNG. Uses build/data/cranium.vti (an int16 skull CT made by scripts/fetch-data.sh); when
// it is missing, says so and renders VTK's wavelet instead.
//
//   FerroVolumeCranium [input.vti] [output.png]
//
// An empty or missing input argument means build/data/cranium.vti; the default output is
// cranium-ferrovol.png in the current directory.
#include "vtkFerroVolumeMapper.h"

#include <vtkCamera.h>
#include <vtkColorTransferFunction.h>
#include <vtkImageData.h>
#include <vtkNew.h>
#include <vtkPNGWriter.h>
#include <vtkPiecewiseFunction.h>
#include <vtkRTAnalyticSource.h>
#include <vtkRenderWindow.h>
#include <vtkRenderer.h>
#include <vtkVolume.h>
#include <vtkVolumeProperty.h>
#include <vtkWindowToImageFilter.h>
#include <vtkXMLImageDataReader.h>

#include <chrono>
#include <cstdio>
#include <fstream>
#include <string>

int main(int argc, char* argv[])
{
  std::string input = argc > 1 ? argv[1] : "";
  const std::string output = argc > 2 ? argv[2] : "cranium-ferrovol.png";
  if (input.empty())
  {
    input = std::string(FERROVOL_DATA_DIR) + "/cranium.vti";
  }

  vtkNew<vtkVolumeProperty> property;
  vtkNew<vtkColorTransferFunction> color;
  vtkNew<vtkPiecewiseFunction> opacity;
  vtkNew<vtkFerroVolumeMapper> mapper;
  vtkNew<vtkXMLImageDataReader> reader;
  vtkNew<vtkRTAnalyticSource> wavelet;
  const bool haveCT = std::ifstream(input).good();
  if (haveCT)
  {
    reader->SetFileName(input.c_str());
    reader->Update();
    mapper->SetInputConnection(reader->GetOutputPort());
    // CT bone (Hounsfield units): soft tissue transparent, bone opaque and ivory.
    color->AddRGBPoint(-3024, 0.0, 0.0, 0.0);
    color->AddRGBPoint(-16.4458, 0.729412, 0.254902, 0.301961);
    color->AddRGBPoint(641.385, 0.905882, 0.815686, 0.552941);
    color->AddRGBPoint(3071, 1.0, 1.0, 1.0);
    opacity->AddPoint(-3024, 0.0);
    opacity->AddPoint(-16.4458, 0.0);
    opacity->AddPoint(641.385, 0.715686);
    opacity->AddPoint(3071, 0.705882);
    double* s = reader->GetOutput()->GetSpacing();
    property->SetScalarOpacityUnitDistance((s[0] + s[1] + s[2]) / 3.0);
  }
  else
  {
    std::printf("FerroVolumeCranium: %s not found (run scripts/fetch-data.sh to make it); "
                "rendering VTK's wavelet instead.\n",
      input.c_str());
    wavelet->SetWholeExtent(-63, 64, -63, 64, -63, 64);
    mapper->SetInputConnection(wavelet->GetOutputPort());
    color->AddRGBPoint(37.3531, 0.2, 0.29, 1.0);
    color->AddRGBPoint(157.091, 0.87, 0.87, 0.87);
    color->AddRGBPoint(276.829, 0.7, 0.015, 0.15);
    opacity->AddPoint(37.3531, 0.0);
    opacity->AddPoint(276.829, 1.0);
  }
  property->SetColor(color);
  property->SetScalarOpacity(opacity);
  property->SetInterpolationTypeToLinear();
  property->ShadeOn();
  property->SetAmbient(0.2);
  property->SetDiffuse(0.9);
  property->SetSpecular(0.3);
  property->SetSpecularPower(15.0);

  vtkNew<vtkVolume> volume;
  volume->SetMapper(mapper);
  volume->SetProperty(property);

  vtkNew<vtkRenderer> renderer;
  renderer->AddVolume(volume);
  renderer->SetBackground(0.1, 0.1, 0.12);
  vtkNew<vtkRenderWindow> window;
  window->SetOffScreenRendering(1);
  window->SetSize(512, 512);
  window->AddRenderer(renderer);

  renderer->ResetCamera();
  vtkCamera* camera = renderer->GetActiveCamera();
  if (haveCT)
  {
    // The face looks toward -y in this data set: view it from the front, head up (+z).
    camera->Elevation(-90.0);
    camera->SetViewUp(0.0, 0.0, 1.0);
    camera->OrthogonalizeViewUp();
    renderer->ResetCamera();
    camera->Zoom(1.3);
  }
  else
  {
    camera->Azimuth(30.0);
    camera->Elevation(20.0);
  }

  const auto t0 = std::chrono::steady_clock::now();
  window->Render();
  const double ms =
    std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
  if (!mapper->GetLastRenderDrew())
  {
    std::fprintf(stderr, "FerroVolumeCranium: the volume was not drawn (see the errors above)\n");
    return 1;
  }

  vtkNew<vtkWindowToImageFilter> grab;
  grab->SetInput(window);
  grab->ReadFrontBufferOff();
  grab->Update();
  vtkNew<vtkPNGWriter> writer;
  writer->SetFileName(output.c_str());
  writer->SetInputConnection(grab->GetOutputPort());
  writer->Write();
  std::printf("FerroVolumeCranium: %s on %s, first frame %.0f ms (uploads included), wrote %s\n",
    haveCT ? input.c_str() : "wavelet", vtkFerroVolumeMapper::GetAdapterDescription(), ms,
    output.c_str());
  return 0;
}
