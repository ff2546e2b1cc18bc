// vtkFerroVolumeReport: what goes wrong while vtkFerroVolumeMapper prepares and draws a frame.
// The mapper's units take one by reference: a failing step sets its error (Fail) and returns
// false, and the mapper ends the render with vtkErrorMacro(<< report.GetError()); warnings
// are said on the mapper once per mapper and key (FirstTime, Warn). Each mapper has one
// (vtkFerroVolumeMapperInternals.h); a unit that only wants a failure's reason makes its own,
// without an owner. Internal to the FerroVolume module (not wrapped).
#ifndef vtkFerroVolumeReport_h
#define vtkFerroVolumeReport_h

#include <set>
#include <string>

class vtkObject;

class vtkFerroVolumeReport
{
public:
  // `owner`: the object the warnings are said on (nullptr: none are said).
  explicit vtkFerroVolumeReport(vtkObject* owner = nullptr)
    : Owner(owner)
  {
  }

  // Why the step under way failed ("" while none did).
  const std::string& GetError() const { return this->Error; }
  // Sets the error; false, so that a step can `return report.Fail(...)`.
  bool Fail(const std::string& message);
  // Puts `context` before the error ("MaskInput: ", "port 2: ").
  void PrefixError(const std::string& context) { this->Error.insert(0, context); }
  void ClearError() { this->Error.clear(); }

  // True the first time `key` is asked: the caller then says its warning.
  bool FirstTime(const std::string& key) { return this->Warned.insert(key).second; }
  // A warning on the owner (vtkWarningWithObjectMacro).
  void Warn(const std::string& message) const;
  // A warning on the owner, the first time for `key`.
  void WarnOnce(const std::string& key, const std::string& message);
  // A warning on the owner, the first time it is `message`.
  void WarnOnce(const std::string& message) { this->WarnOnce(message, message); }

private:
  vtkObject* Owner;
  std::string Error;
  // the keys of the warnings said
  std::set<std::string> Warned;
};

#endif
