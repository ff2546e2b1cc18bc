#include "vtkFerroVolumeContext.h"

#include <sstream>

vtkFerroVolumeContext& vtkFerroVolumeContext::Get()
{
  static vtkFerroVolumeContext instance;
  return instance;
}

const ferrovol::Context* vtkFerroVolumeContext::Acquire(vtkFerroVolumeReport& report)
{
  vtkFerroVolumeContext& self = Get();
  std::lock_guard<std::mutex> lock(self.Mutex);
  if (!self.Tried)
  {
    self.Tried = true;
    try
    {
      // Deleted only when lost: see Acquire's comment.
      self.Context = new ferrovol::Context();
      self.Context->limit_device_memory(self.MemoryCap);
    }
    catch (const ferrovol::Error& e)
    {
      self.Error = std::string("no GPU device for ferrovol (") + fv_status_name(e.status()) +
        "): " + e.message() +
        ". Install Mesa's Vulkan drivers (mesa-vulkan-drivers) or check FERROVOL_ADAPTER / "
        "FERROVOL_BACKEND.";
    }
    if (self.Context)
    {
      try
      {
        const FvAdapterInfo info = self.Context->info();
        self.Desc = std::string(info.name) + " (" + info.backend + ", " + info.driver + ")";
      }
      catch (const ferrovol::Error&)
      {
        // no description: the device still renders
      }
    }
  }
  if (!self.Context)
  {
    report.Fail(self.Error);
  }
  return self.Context;
}

unsigned vtkFerroVolumeContext::Generation()
{
  vtkFerroVolumeContext& self = Get();
  std::lock_guard<std::mutex> lock(self.Mutex);
  return self.Losses;
}

void vtkFerroVolumeContext::Lost()
{
  vtkFerroVolumeContext& self = Get();
  std::lock_guard<std::mutex> lock(self.Mutex);
  delete self.Context;
  self.Context = nullptr;
  ++self.Losses;
  self.Tried = false;
  self.Error.clear();
  self.Desc.clear();
}

void vtkFerroVolumeContext::LoseDevice()
{
  vtkFerroVolumeContext& self = Get();
  std::lock_guard<std::mutex> lock(self.Mutex);
  if (self.Context)
  {
    self.Context->lose_device();
  }
}

void vtkFerroVolumeContext::LimitDeviceMemory(vtkTypeUInt64 bytes)
{
  vtkFerroVolumeContext& self = Get();
  std::lock_guard<std::mutex> lock(self.Mutex);
  self.MemoryCap = bytes;
  if (self.Context)
  {
    self.Context->limit_device_memory(bytes);
  }
}

const char* vtkFerroVolumeContext::Description()
{
  vtkFerroVolumeReport report;
  Acquire(report);
  return Get().Desc.c_str();
}

FvDeviceMemory vtkFerroVolumeContext::DeviceMemory()
{
  vtkFerroVolumeContext& self = Get();
  std::lock_guard<std::mutex> lock(self.Mutex);
  FvDeviceMemory m{};
  if (self.Context && fv_context_device_memory(self.Context->get(), &m) != FV_STATUS_OK)
  {
    m = FvDeviceMemory{};
  }
  return m;
}

std::string vtkFerroVolumeFailure(const char* what, const ferrovol::Error& e)
{
  std::ostringstream s;
  s << "ferrovol could not " << what << " (" << fv_status_name(e.status()) << "): " << e.message();
  if (e.status() == FV_STATUS_DEVICE_LOST)
  {
    vtkFerroVolumeContext::Lost();
    s << " (ferrovol opens a new device at the next render)";
  }
  else if (e.status() == FV_STATUS_OUT_OF_MEMORY)
  {
    s << " (make the window or the volume smaller, lower MaxMemoryInBytes or "
         "MaxMemoryFraction, or free GPU memory other programs hold)";
  }
  return s.str();
}

bool vtkFerroVolumeRendererSlot::Make(vtkFerroVolumeReport& report)
{
  this->Renderer.reset();
  const ferrovol::Context* ctx = vtkFerroVolumeContext::Acquire(report);
  this->Generation = vtkFerroVolumeContext::Generation();
  return ctx && vtkFerroVolumeCall("create a renderer", report,
                  [&] { this->Renderer.reset(new ferrovol::Renderer(*ctx)); });
}
