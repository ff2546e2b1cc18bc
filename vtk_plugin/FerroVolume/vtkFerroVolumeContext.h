// vtkFerroVolumeContext: ferrovol's process-wide GPU device for every vtkFerroVolumeMapper,
// and the wording of a failed ferrovol call. Internal to the FerroVolume module (not wrapped).
#ifndef vtkFerroVolumeContext_h
#define vtkFerroVolumeContext_h

#include "ferrovol.hpp"
#include "vtkFerroVolumeReport.h"
#include "vtkType.h"

#include <memory>
#include <mutex>
#include <string>

class vtkFerroVolumeContext
{
public:
  // Opens the device on first use and keeps it for the life of the process (or until it is
  // lost): renderers created from it keep the device alive, and tearing a Vulkan device down
  // from static destructors at exit is fragile. nullptr, with the reason in `error`, when
  // there is none.
  static const ferrovol::Context* Acquire(vtkFerroVolumeReport& report);

  // Counts the devices lost: a renderer made under an older generation was made on a device
  // since lost, and is made again.
  static unsigned Generation();

  // Forgets a lost device (a call failed with FV_STATUS_DEVICE_LOST): the next Acquire opens
  // a new one. Renderers keep the old device alive until they are freed.
  static void Lost();

  // Loses the device on purpose, to test recovery (fv_context_lose_device).
  static void LoseDevice();

  // Caps the device memory ferrovol may hold, as a smaller device would (0: no cap), to test
  // out-of-memory handling (fv_context_limit_device_memory); kept for devices opened later.
  static void LimitDeviceMemory(vtkTypeUInt64 bytes);

  // "name (backend, driver)" of the device, "" when none could be opened.
  static const char* Description();

  // What the device holds now; all zero when no mapper has opened it (it is not opened for
  // this).
  static FvDeviceMemory DeviceMemory();

private:
  static vtkFerroVolumeContext& Get();

  std::mutex Mutex;
  const ferrovol::Context* Context = nullptr;
  unsigned Losses = 0;
  vtkTypeUInt64 MemoryCap = 0;
  bool Tried = false;
  std::string Error;
  std::string Desc;
};

// A mapper's ferrovol renderer and the device generation it was made under.
struct vtkFerroVolumeRendererSlot
{
  std::unique_ptr<ferrovol::Renderer> Renderer;
  // vtkFerroVolumeContext::Generation() when the renderer was made
  unsigned Generation = 0;

  // Whether the renderer was made on a device since lost.
  bool Lost() const
  {
    return this->Renderer && this->Generation != vtkFerroVolumeContext::Generation();
  }
  // A new renderer from the process-wide device (the old one released first); false with
  // the reason.
  bool Make(vtkFerroVolumeReport& report);
};

// "ferrovol could not <what> (FV_STATUS_…): <the library's message>"; a lost device is
// forgotten (vtkFerroVolumeContext::Lost) and the message says a new one is opened.
std::string vtkFerroVolumeFailure(const char* what, const ferrovol::Error& e);

// Runs `call` (ferrovol.hpp calls); when one fails, says so in `error` (see
// vtkFerroVolumeFailure) and returns false.
template <typename Call>
bool vtkFerroVolumeCall(const char* what, vtkFerroVolumeReport& report, Call&& call)
{
  try
  {
    call();
    return true;
  }
  catch (const ferrovol::Error& e)
  {
    report.Fail(vtkFerroVolumeFailure(what, e));
    return false;
  }
}

#endif
