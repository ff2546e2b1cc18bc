// vtkFerroVolumeOutputChoice: the rule that decides whether frames reach OpenGL through
// memory shared with ferrovol's device (zero copy) or through the CPU, and the words that
// say why. A pure function of what the device and the OpenGL context report: it makes no GL
// or ferrovol call (vtkFerroVolumeSharedOutput::Create gathers the facts), so the rule is
// tested on its own (vtk_plugin/tests/TestFerroVolumeOutputChoice.cxx).
// Internal to the FerroVolume module (not wrapped).
#ifndef vtkFerroVolumeOutputChoice_h
#define vtkFerroVolumeOutputChoice_h

#include <array>
#include <cstdint>
#include <string>
#include <vector>

// A device or driver UUID: VkPhysicalDeviceIDProperties' deviceUUID / driverUUID, OpenGL's
// GL_DEVICE_UUID_EXT / GL_DRIVER_UUID_EXT.
using vtkFerroVolumeUuid = std::array<uint8_t, 16>;

// What the choice depends on.
struct vtkFerroVolumeOutputFacts
{
  // ferrovol's device and the window's OpenGL renderer (GL_RENDERER), named in the reason.
  std::string AdapterName;
  std::string GLRenderer;
  // The user asked for the shared path (SetOutputPathToShared): a refusal is a warning.
  bool Forced = false;
  // The OpenGL context has GL_EXT_memory_object_fd (it can import the memory).
  bool GLHasMemoryObjectFd = false;
  // Why ferrovol's device cannot export its output memory or tell its UUIDs; empty when it
  // can.
  std::string ExportProblem;
  // ferrovol's Vulkan device and driver.
  vtkFerroVolumeUuid VulkanDevice{};
  vtkFerroVolumeUuid VulkanDriver{};
  // The OpenGL context's devices (GL_NUM_DEVICE_UUIDS_EXT of them) and its driver.
  std::vector<vtkFerroVolumeUuid> GLDevices;
  vtkFerroVolumeUuid GLDriver{};
};

struct vtkFerroVolumeOutputChoice
{
  bool Shared = false;
  // Why: for the shared path the device and driver both APIs run on; otherwise what is
  // missing or different.
  std::string Reason;
  // The refusal is said as a warning (the user asked for the shared path) rather than noted
  // in the log.
  bool Warn = false;
};

// Shared exactly when OpenGL can import memory (GL_EXT_memory_object_fd), ferrovol's device
// can export it, the Vulkan device UUID is one of the context's device UUIDs and the driver
// UUIDs are equal; whether the device is a GPU or a CPU (lavapipe) does not matter, and
// forcing the shared path cannot share memory across devices or drivers.
vtkFerroVolumeOutputChoice vtkFerroVolumeChooseOutput(const vtkFerroVolumeOutputFacts& facts);

// The UUID as text: 8-4-4-4-12 lowercase hexadecimal digits.
std::string vtkFerroVolumeUuidText(const vtkFerroVolumeUuid& uuid);

#endif
