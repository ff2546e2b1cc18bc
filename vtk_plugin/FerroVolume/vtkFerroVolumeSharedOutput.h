// vtkFerroVolumeSharedOutput: the zero-copy frame path. ferrovol renders into Vulkan memory
// that OpenGL imports (ferrovol's shared images → glImportMemoryFdEXT →
// glTexStorageMem2DEXT). VTK's depth goes into ferrovol's depth input image on the GPU (a
// blit and one full-screen pass). Synchronised by CPU waits, as ferrovol exports no
// semaphores (docs/ARCHITECTURE.md says why): glFinish before ferrovol reads what GL wrote,
// and ferrovol's finish before GL samples what ferrovol wrote. Compiled when ferrovol.h has
// the shared output path (FERROVOL_HAVE_SHARED_OUTPUT). Internal to the FerroVolume module
// (not wrapped).
#ifndef vtkFerroVolumeSharedOutput_h
#define vtkFerroVolumeSharedOutput_h

#include "vtkFerroVolumeOutput.h"
#include "vtkFerroVolumeOutputChoice.h"
#include "vtkSmartPointer.h"
#include "vtkFerroVolumeGL.h"

#include <memory>
#include <string>

class vtkFerroVolumeReport;

class vtkFerroVolumeSharedOutput : public vtkFerroVolumeFramePath
{
public:
  // A shared output for this renderer where vtkFerroVolumeChooseOutput allows one (the
  // window's OpenGL context is current), or nullptr; `choice` says why either way. `forced`:
  // the user asked for the shared path (a refusal is then a warning).
  static std::unique_ptr<vtkFerroVolumeSharedOutput> Create(const ferrovol::Context& ctx,
    ferrovol::Renderer& renderer, bool forced, vtkFerroVolumeOutputChoice& choice);

  ~vtkFerroVolumeSharedOutput() override;

  const char* Name() const override { return "shared"; }
  bool Render(ferrovol::Renderer& renderer, const vtkFerroVolumeFrameRequest& req,
    vtkFerroVolumeReport& report, std::string& warning) override;
  vtkTextureObject* ColorTexture() override;
  vtkTextureObject* DepthTexture() override;
  void ReleaseGraphicsResources(vtkWindow* window) override;

private:
  struct Imported
  {
    GLuint Memory = 0;
    GLuint Texture = 0;
    vtkSmartPointer<vtkTextureObject> Object;
  };

  vtkFerroVolumeSharedOutput() = default;
  bool Import(
    ferrovol::Renderer& renderer, vtkOpenGLRenderWindow* win, vtkFerroVolumeReport& report);
  bool WriteDepthInput(const vtkFerroVolumeFrameRequest& req, vtkFerroVolumeReport& report);
  void ClearDepthInput();
  void DeleteImports();
  void Forget();

  Imported Images[3];
  uint64_t Generation = 0;
  int InputW = 0, InputH = 0;
  GLuint InputFbo = 0;
  GLuint CopyFbo = 0;
  GLuint CopyTex = 0;
  GLenum CopyFormat = GL_NONE;
  int CopyW = 0, CopyH = 0;
  vtkSmartPointer<vtkTextureObject> CopyObject;
  std::unique_ptr<vtkOpenGLQuadHelper> Quad;
};

#endif
