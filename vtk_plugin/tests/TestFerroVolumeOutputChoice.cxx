// The output path rule (vtkFerroVolumeChooseOutput) on the devices it meets, described by
// hand (no GL context or ferrovol device is opened):
//   - NVIDIA's Vulkan and NVIDIA's GL on a discrete GPU, UUIDs equal → shared;
//   - Vulkan on the GPU, OpenGL on llvmpipe (another device UUID) → readback, both named;
//   - the same device, another driver UUID → readback, both drivers named;
//   - lavapipe and llvmpipe (a CPU device, UUIDs equal) → shared;
//   - an OpenGL without GL_EXT_memory_object_fd → readback naming the extension;
//   - a device that cannot export memory → readback with its reason;
//   - the Vulkan device second among several GL devices → shared; none reported → readback;
//   - forcing the shared path changes no decision and no reason, only warns.
// Prints each choice; exits non-zero on the first failed check.
#include "vtkFerroVolumeOutputChoice.h"

#include "FerroVolumeTestCheck.h"

#include <cstdio>
#include <string>

namespace
{
// A UUID whose bytes are `first`, first + 1, …
vtkFerroVolumeUuid Uuid(uint8_t first)
{
  vtkFerroVolumeUuid u{};
  for (size_t i = 0; i < u.size(); ++i)
  {
    u[i] = static_cast<uint8_t>(first + i);
  }
  return u;
}

// Vulkan and OpenGL (with GL_EXT_memory_object_fd) on one device and driver: the device
// UUID Uuid(device), the driver UUID Uuid(driver).
vtkFerroVolumeOutputFacts OneDevice(
  const char* adapter, const char* glRenderer, uint8_t device, uint8_t driver)
{
  vtkFerroVolumeOutputFacts f;
  f.AdapterName = adapter;
  f.GLRenderer = glRenderer;
  f.GLHasMemoryObjectFd = true;
  f.VulkanDevice = Uuid(device);
  f.VulkanDriver = Uuid(driver);
  f.GLDevices = { Uuid(device) };
  f.GLDriver = Uuid(driver);
  return f;
}

// Vulkan and OpenGL on one device and driver, as NVIDIA's drivers report them.
vtkFerroVolumeOutputFacts Nvidia()
{
  return OneDevice("NVIDIA H200", "NVIDIA H200/PCIe/SSE2", 0x10, 0x80);
}

bool Contains(const std::string& text, const std::string& part)
{
  return text.find(part) != std::string::npos;
}

vtkFerroVolumeOutputChoice Choose(const char* name, const vtkFerroVolumeOutputFacts& facts)
{
  const vtkFerroVolumeOutputChoice c = vtkFerroVolumeChooseOutput(facts);
  std::printf("%-34s %s%s: %s\n", name, c.Shared ? "shared" : "readback",
    c.Warn ? " (warning)" : "", c.Reason.c_str());
  return c;
}
} // namespace

int main()
{
  CHECK(vtkFerroVolumeUuidText(Uuid(0x10)) == "10111213-1415-1617-1819-1a1b1c1d1e1f", "%s",
    vtkFerroVolumeUuidText(Uuid(0x10)).c_str());

  const vtkFerroVolumeOutputChoice gpu = Choose("NVIDIA Vulkan + NVIDIA GL", Nvidia());
  CHECK(gpu.Shared && !gpu.Warn, "a GPU whose UUIDs match shares");
  CHECK(Contains(gpu.Reason, "zero copy") && Contains(gpu.Reason, "NVIDIA H200") &&
      Contains(gpu.Reason, "10111213-1415-1617-1819-1a1b1c1d1e1f"),
    "the reason names the device and its UUID: %s", gpu.Reason.c_str());

  vtkFerroVolumeOutputFacts llvmpipeGL = Nvidia();
  llvmpipeGL.GLRenderer = "llvmpipe (LLVM 15.0.6, 256 bits)";
  llvmpipeGL.GLDevices = { Uuid(0x40) };
  llvmpipeGL.GLDriver = Uuid(0xa0);
  const vtkFerroVolumeOutputChoice otherDevice = Choose("NVIDIA Vulkan + llvmpipe GL", llvmpipeGL);
  CHECK(!otherDevice.Shared && !otherDevice.Warn, "another device reads back, noted");
  CHECK(Contains(otherDevice.Reason, "another device") &&
      Contains(otherDevice.Reason, "10111213-1415-1617-1819-1a1b1c1d1e1f") &&
      Contains(otherDevice.Reason, "40414243-4445-4647-4849-4a4b4c4d4e4f") &&
      Contains(otherDevice.Reason, "llvmpipe"),
    "the reason names both device UUIDs and the GL renderer: %s", otherDevice.Reason.c_str());

  vtkFerroVolumeOutputFacts otherDriverFacts = Nvidia();
  otherDriverFacts.GLDriver = Uuid(0x90);
  const vtkFerroVolumeOutputChoice otherDriver =
    Choose("same device, another driver", otherDriverFacts);
  CHECK(!otherDriver.Shared, "another driver reads back");
  CHECK(Contains(otherDriver.Reason, "another driver") &&
      Contains(otherDriver.Reason, "80818283-8485-8687-8889-8a8b8c8d8e8f") &&
      Contains(otherDriver.Reason, "90919293-9495-9697-9899-9a9b9c9d9e9f"),
    "the reason names both driver UUIDs: %s", otherDriver.Reason.c_str());

  const vtkFerroVolumeOutputFacts cpuFacts = OneDevice(
    "llvmpipe (LLVM 15.0.6, 256 bits)", "llvmpipe (LLVM 15.0.6, 256 bits)", 0x6c, 0x4d);
  const vtkFerroVolumeOutputChoice cpu = Choose("lavapipe + llvmpipe", cpuFacts);
  CHECK(cpu.Shared && !cpu.Warn, "a CPU device whose UUIDs match shares");

  vtkFerroVolumeOutputFacts noExtension = Nvidia();
  noExtension.GLHasMemoryObjectFd = false;
  noExtension.GLDevices.clear();
  const vtkFerroVolumeOutputChoice noImport =
    Choose("GL without GL_EXT_memory_object_fd", noExtension);
  CHECK(!noImport.Shared && Contains(noImport.Reason, "GL_EXT_memory_object_fd"),
    "the reason names the missing extension: %s", noImport.Reason.c_str());

  vtkFerroVolumeOutputFacts noExport = Nvidia();
  noExport.ExportProblem = "the Vulkan driver lacks VK_KHR_external_memory_fd";
  const vtkFerroVolumeOutputChoice cannotExport = Choose("device cannot export", noExport);
  CHECK(!cannotExport.Shared && Contains(cannotExport.Reason, "VK_KHR_external_memory_fd"),
    "the reason carries the device's: %s", cannotExport.Reason.c_str());

  vtkFerroVolumeOutputFacts twoDevices = Nvidia();
  twoDevices.GLDevices = { Uuid(0x30), Uuid(0x10) };
  CHECK(Choose("second of two GL devices", twoDevices).Shared,
    "any of the context's devices may be the Vulkan device");

  vtkFerroVolumeOutputFacts noDevices = Nvidia();
  noDevices.GLDevices.clear();
  const vtkFerroVolumeOutputChoice none = Choose("GL reports no device UUID", noDevices);
  CHECK(!none.Shared && Contains(none.Reason, "none reported"), "%s", none.Reason.c_str());

  vtkFerroVolumeOutputFacts forcedFacts = llvmpipeGL;
  forcedFacts.Forced = true;
  const vtkFerroVolumeOutputChoice forced = Choose("forced, another device", forcedFacts);
  CHECK(!forced.Shared && forced.Warn, "forcing cannot share memory across devices");
  CHECK(forced.Reason == otherDevice.Reason, "forcing changes the reason: %s",
    forced.Reason.c_str());
  vtkFerroVolumeOutputFacts forcedMatch = Nvidia();
  forcedMatch.Forced = true;
  const vtkFerroVolumeOutputChoice forcedShared = Choose("forced, UUIDs equal", forcedMatch);
  CHECK(forcedShared.Shared && !forcedShared.Warn && forcedShared.Reason == gpu.Reason,
    "forcing where the rule shares anyway changes nothing");

  std::printf("%s (%d failed checks)\n", failures ? "FAILED" : "passed", failures);
  return failures ? 1 : 0;
}
