#include "vtkFerroVolumeOutputChoice.h"

#include <algorithm>

std::string vtkFerroVolumeUuidText(const vtkFerroVolumeUuid& uuid)
{
  static const char digits[] = "0123456789abcdef";
  std::string text;
  for (size_t i = 0; i < uuid.size(); ++i)
  {
    if (i == 4 || i == 6 || i == 8 || i == 10)
    {
      text += '-';
    }
    text += digits[uuid[i] >> 4];
    text += digits[uuid[i] & 15];
  }
  return text;
}

vtkFerroVolumeOutputChoice vtkFerroVolumeChooseOutput(const vtkFerroVolumeOutputFacts& facts)
{
  vtkFerroVolumeOutputChoice choice;
  choice.Warn = facts.Forced;
  const std::string gl = "OpenGL (" + facts.GLRenderer + ")";
  const std::string device = "ferrovol's device (" + facts.AdapterName + ")";
  if (!facts.GLHasMemoryObjectFd)
  {
    choice.Reason = gl + " has no GL_EXT_memory_object_fd, so it cannot import the memory of " +
      device;
    return choice;
  }
  if (!facts.ExportProblem.empty())
  {
    choice.Reason = device + " cannot export memory: " + facts.ExportProblem;
    return choice;
  }
  if (std::find(facts.GLDevices.begin(), facts.GLDevices.end(), facts.VulkanDevice) ==
    facts.GLDevices.end())
  {
    std::string list;
    for (const vtkFerroVolumeUuid& d : facts.GLDevices)
    {
      list += (list.empty() ? "" : ", ") + vtkFerroVolumeUuidText(d);
    }
    choice.Reason = gl + " runs on another device than " + device + ": the Vulkan device UUID " +
      vtkFerroVolumeUuidText(facts.VulkanDevice) + " is not among OpenGL's device UUIDs (" +
      (list.empty() ? "none reported" : list) + "), and memory is not shared across devices";
    return choice;
  }
  if (facts.GLDriver != facts.VulkanDriver)
  {
    choice.Reason = gl + " runs on another driver than " + device + ": the Vulkan driver UUID " +
      vtkFerroVolumeUuidText(facts.VulkanDriver) + " differs from OpenGL's " +
      vtkFerroVolumeUuidText(facts.GLDriver) + ", and memory is not shared across drivers";
    return choice;
  }
  choice.Shared = true;
  choice.Warn = false;
  choice.Reason = "zero copy: " + facts.AdapterName + " (Vulkan) and " + gl +
    " share the frame on device UUID " + vtkFerroVolumeUuidText(facts.VulkanDevice) +
    ", driver UUID " + vtkFerroVolumeUuidText(facts.VulkanDriver) +
    "; synchronised by CPU waits (ferrovol exports no semaphores)";
  return choice;
}
