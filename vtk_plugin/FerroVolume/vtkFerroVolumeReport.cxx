#include "vtkFerroVolumeReport.h"

#include "vtkObject.h"

bool vtkFerroVolumeReport::Fail(const std::string& message)
{
  this->Error = message;
  return false;
}

void vtkFerroVolumeReport::Warn(const std::string& message) const
{
  if (this->Owner)
  {
    vtkWarningWithObjectMacro(this->Owner, << message);
  }
}

void vtkFerroVolumeReport::WarnOnce(const std::string& key, const std::string& message)
{
  if (this->FirstTime(key))
  {
    this->Warn(message);
  }
}
