#include "vtkFerroVolumeSharedOutput.h"

#include "vtkFerroVolumeContext.h"
#include "vtkFerroVolumeDepthReader.h"
#include "vtkFerroVolumeReport.h"
#include "vtkOpenGLError.h"
#include "vtkOpenGLQuadHelper.h"
#include "vtkOpenGLRenderWindow.h"
#include "vtkOpenGLShaderCache.h"
#include "vtkOpenGLState.h"
#include "vtkShaderProgram.h"
#include "vtkTextureObject.h"

#include <algorithm>
#include <array>

namespace
{
// Depth formats for glTexImage2D.
void DepthTexFormat(GLenum internal, GLenum& format, GLenum& type)
{
  switch (internal)
  {
    case GL_DEPTH24_STENCIL8:
      format = GL_DEPTH_STENCIL;
      type = GL_UNSIGNED_INT_24_8;
      break;
    case GL_DEPTH32F_STENCIL8:
      format = GL_DEPTH_STENCIL;
      type = GL_FLOAT_32_UNSIGNED_INT_24_8_REV;
      break;
    case GL_DEPTH_COMPONENT32F:
      format = GL_DEPTH_COMPONENT;
      type = GL_FLOAT;
      break;
    default:
      format = GL_DEPTH_COMPONENT;
      type = GL_UNSIGNED_INT;
      break;
  }
}

// Samples VTK's depth (a copy of the viewport's depth buffer) into ferrovol's depth input
// image, flipped to rows top to bottom.
const char* DepthInputFragmentShader = R"(//VTK::System::Dec
in vec2 texCoord;
uniform sampler2D vtkDepth;
uniform ivec2 viewportSize;
uniform ivec2 renderSize;
//VTK::Output::Dec
void main()
{
  // rendered pixel (x, row from the top) takes the viewport pixel under its centre, as
  // SourcePixel picks it on the CPU
  ivec2 p = ivec2(gl_FragCoord.xy);
  if (texCoord.x < -1.0)
  {
    discard; // never: keeps texCoord (and the quad's texture coordinates) alive
  }
  ivec2 s = ((2 * p + 1) * viewportSize) / (2 * renderSize);
  gl_FragData[0] = vec4(texelFetch(vtkDepth, ivec2(s.x, viewportSize.y - 1 - s.y), 0).r,
    0.0, 0.0, 1.0);
}
)";

// Whether a depth format has stencil bits (attached as depth-stencil).
bool HasStencil(GLenum format)
{
  return format == GL_DEPTH24_STENCIL8 || format == GL_DEPTH32F_STENCIL8;
}

// What vtkFerroVolumeChooseOutput decides from: ferrovol's device and the current OpenGL
// context.
vtkFerroVolumeOutputFacts Facts(const ferrovol::Context& ctx, bool forced)
{
  vtkFerroVolumeOutputFacts f;
  f.Forced = forced;
  const GLubyte* glRenderer = glGetString(GL_RENDERER);
  f.GLRenderer = glRenderer ? reinterpret_cast<const char*>(glRenderer) : "no GL_RENDERER";
  f.GLHasMemoryObjectFd = vtkFerroVolumeGLHasMemoryObjectFd();
  try
  {
    f.AdapterName = ctx.info().name;
  }
  catch (const ferrovol::Error& e)
  {
    f.AdapterName = "unnamed";
    f.ExportProblem = vtkFerroVolumeFailure("describe its device", e);
    return f;
  }
  if (!ctx.can_share())
  {
    f.ExportProblem = fv_last_error();
    return f;
  }
  try
  {
    const ferrovol::Context::Uuids uuids = ctx.uuids();
    std::copy(uuids.device, uuids.device + 16, f.VulkanDevice.begin());
    std::copy(uuids.driver, uuids.driver + 16, f.VulkanDriver.begin());
  }
  catch (const ferrovol::Error& e)
  {
    f.ExportProblem = vtkFerroVolumeFailure("tell its device UUIDs", e);
    return f;
  }
  if (!f.GLHasMemoryObjectFd)
  {
    return f; // the UUID queries belong to GL_EXT_memory_object
  }
  vtkOpenGLClearErrorMacro();
  glGetUnsignedBytevEXT(GL_DRIVER_UUID_EXT, f.GLDriver.data());
  GLint devices = 0;
  glGetIntegerv(GL_NUM_DEVICE_UUIDS_EXT, &devices);
  f.GLDevices.resize(static_cast<size_t>(std::max(devices, 0)));
  for (GLint i = 0; i < devices; ++i)
  {
    glGetUnsignedBytei_vEXT(GL_DEVICE_UUID_EXT, static_cast<GLuint>(i), f.GLDevices[i].data());
  }
  if (glGetError() != GL_NO_ERROR)
  {
    f.GLDevices.clear(); // read as "none reported"
  }
  return f;
}
} // namespace

std::unique_ptr<vtkFerroVolumeSharedOutput> vtkFerroVolumeSharedOutput::Create(
  const ferrovol::Context& ctx, ferrovol::Renderer& renderer, bool forced,
  vtkFerroVolumeOutputChoice& choice)
{
  choice = vtkFerroVolumeChooseOutput(Facts(ctx, forced));
  if (!choice.Shared)
  {
    return nullptr;
  }
  vtkFerroVolumeReport report;
  if (!vtkFerroVolumeCall("share its output", report,
        [&] { renderer.set_output_path(FV_OUTPUT_PATH_SHARED); }))
  {
    // Everything said it would work: a failure here is worth a warning in any case.
    choice.Shared = false;
    choice.Reason = report.GetError();
    choice.Warn = true;
    return nullptr;
  }
  return std::unique_ptr<vtkFerroVolumeSharedOutput>(new vtkFerroVolumeSharedOutput);
}

vtkFerroVolumeSharedOutput::~vtkFerroVolumeSharedOutput()
{
  this->Forget();
}

bool vtkFerroVolumeSharedOutput::Render(ferrovol::Renderer& renderer,
  const vtkFerroVolumeFrameRequest& req, vtkFerroVolumeReport& report, std::string& warning)
{
  const uint32_t w = static_cast<uint32_t>(req.RenderW), h = static_cast<uint32_t>(req.RenderH);
  // OpenGL must be done with the images of the last frame before ferrovol overwrites them.
  glFinish();
  // A (re)allocation submits a clear of the new images without waiting for it: wait, or it
  // may land after OpenGL wrote the depth input below (zero depth, an empty frame; seen in
  // some first frames under load). Nothing else is in flight here, so the wait is free
  // otherwise.
  if (!vtkFerroVolumeCall("allocate the shared images", report,
        [&] { renderer.prepare_targets(w, h); }) ||
    !vtkFerroVolumeCall(
      "finish allocating the shared images", report, [&] { renderer.finish(); }) ||
    !this->Import(renderer, req.Window, report))
  {
    return false;
  }
  if (req.UseDepth)
  {
    if (!this->WriteDepthInput(req, report))
    {
      warning = "the volume ignores opaque geometry in this frame: " + report.GetError();
      report.ClearError();
      this->ClearDepthInput();
    }
    glFinish(); // ferrovol reads the depth input next
  }
  return vtkFerroVolumeCall("render the frame", report,
           [&] {
             if (req.UseDepth)
             {
               renderer.render_with_shared_depth(w, h);
             }
             else
             {
               renderer.render(w, h);
             }
           }) &&
    vtkFerroVolumeCall("finish the frame", report, [&] { renderer.finish(); });
}

vtkTextureObject* vtkFerroVolumeSharedOutput::ColorTexture()
{
  return this->Images[FV_TARGET_COLOR].Object;
}

vtkTextureObject* vtkFerroVolumeSharedOutput::DepthTexture()
{
  return this->Images[FV_TARGET_DEPTH].Object;
}

void vtkFerroVolumeSharedOutput::ReleaseGraphicsResources(vtkWindow* window)
{
  if (!window)
  {
    this->Forget();
    return;
  }
  // OpenGL may still be reading the imported memory (a frame composited outside the
  // window's own Render, which ends with a finish): let it finish before the renderer, and
  // with it the memory, goes.
  glFinish();
  this->DeleteImports();
  if (this->CopyFbo)
  {
    glDeleteFramebuffers(1, &this->CopyFbo);
  }
  if (this->CopyTex)
  {
    glDeleteTextures(1, &this->CopyTex);
  }
  if (this->Quad)
  {
    this->Quad->ReleaseGraphicsResources(window);
  }
  this->Forget();
}

// Imports the three images again whenever ferrovol reallocated them.
bool vtkFerroVolumeSharedOutput::Import(
  ferrovol::Renderer& renderer, vtkOpenGLRenderWindow* win, vtkFerroVolumeReport& report)
{
  // (descriptors not handed over to OpenGL are closed when `img` goes)
  std::array<ferrovol::SharedImage, 3> img;
  for (uint32_t i = 0; i < 3; ++i)
  {
    if (!vtkFerroVolumeCall(
          "export a shared image", report, [&] { img[i] = renderer.shared_image(i); }))
    {
      return false;
    }
  }
  if (this->Images[0].Texture && img[0].info().generation == this->Generation)
  {
    return true;
  }
  this->DeleteImports();
  vtkOpenGLClearErrorMacro();
  GLint oldTex = 0;
  glGetIntegerv(GL_TEXTURE_BINDING_2D, &oldTex);
  bool ok = true;
  for (int i = 0; i < 3 && ok; ++i)
  {
    Imported& im = this->Images[i];
    const FvSharedImage& info = img[i].info();
    glCreateMemoryObjectsEXT(1, &im.Memory);
    if (info.dedicated)
    {
      GLint yes = GL_TRUE;
      glMemoryObjectParameterivEXT(im.Memory, GL_DEDICATED_MEMORY_OBJECT_EXT, &yes);
    }
    glImportMemoryFdEXT(im.Memory, info.size, GL_HANDLE_TYPE_OPAQUE_FD_EXT, info.fd);
    if (glGetError() != GL_NO_ERROR)
    {
      report.Fail("OpenGL could not import ferrovol's shared memory (glImportMemoryFdEXT)");
      ok = false;
      break;
    }
    img[i].release(); // OpenGL owns the descriptor now
    glGenTextures(1, &im.Texture);
    glBindTexture(GL_TEXTURE_2D, im.Texture);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_TILING_EXT, GL_OPTIMAL_TILING_EXT);
    glTexStorageMem2DEXT(GL_TEXTURE_2D, 1, info.gl_internal_format,
      static_cast<GLsizei>(info.width), static_cast<GLsizei>(info.height), im.Memory, 0);
    if (glGetError() != GL_NO_ERROR)
    {
      report.Fail("OpenGL could not make a texture of ferrovol's shared memory "
                  "(glTexStorageMem2DEXT)");
      ok = false;
      break;
    }
    im.Object = vtkSmartPointer<vtkTextureObject>::New();
    im.Object->SetContext(win);
    im.Object->AssignToExistingTexture(im.Texture, GL_TEXTURE_2D);
    vtkFerroVolumeSetSampling(im.Object, i == FV_TARGET_COLOR);
  }
  glBindTexture(GL_TEXTURE_2D, static_cast<GLuint>(oldTex));
  if (!ok)
  {
    this->DeleteImports();
    return false;
  }
  this->Generation = img[0].info().generation;
  this->InputW = static_cast<int>(img[FV_TARGET_DEPTH_INPUT].info().width);
  this->InputH = static_cast<int>(img[FV_TARGET_DEPTH_INPUT].info().height);
  // the framebuffer that writes the depth input
  GLint oldDraw = 0;
  glGetIntegerv(GL_DRAW_FRAMEBUFFER_BINDING, &oldDraw);
  if (!this->InputFbo)
  {
    glGenFramebuffers(1, &this->InputFbo);
  }
  glBindFramebuffer(GL_DRAW_FRAMEBUFFER, this->InputFbo);
  glFramebufferTexture2D(GL_DRAW_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_TEXTURE_2D,
    this->Images[FV_TARGET_DEPTH_INPUT].Texture, 0);
  const GLenum status = glCheckFramebufferStatus(GL_DRAW_FRAMEBUFFER);
  glBindFramebuffer(GL_DRAW_FRAMEBUFFER, static_cast<GLuint>(oldDraw));
  if (status != GL_FRAMEBUFFER_COMPLETE)
  {
    report.Fail("ferrovol's shared depth input image cannot be drawn into");
    this->DeleteImports();
    return false;
  }
  return true;
}

// VTK's depth (the viewport of the framebuffer being drawn) → CopyTex (a blit, which also
// resolves multisampling) → the depth input image (one pass, scaled to the render size).
bool vtkFerroVolumeSharedOutput::WriteDepthInput(
  const vtkFerroVolumeFrameRequest& req, vtkFerroVolumeReport& report)
{
  vtkOpenGLRenderWindow* win = req.Window;
  vtkOpenGLState* ostate = win->GetState();
  vtkOpenGLClearErrorMacro();
  GLint readFbo = 0, drawFbo = 0;
  glGetIntegerv(GL_READ_FRAMEBUFFER_BINDING, &readFbo);
  glGetIntegerv(GL_DRAW_FRAMEBUFFER_BINDING, &drawFbo);
  const GLenum format = vtkFerroVolumeDepthReader::DepthFormatOf(readFbo);
  if (format == GL_NONE)
  {
    return report.Fail("the framebuffer's depth attachment has an unknown format");
  }
  const int vw = req.ViewportW, vh = req.ViewportH;
  if (!this->CopyTex || this->CopyFormat != format || this->CopyW != vw || this->CopyH != vh)
  {
    GLint oldTex = 0;
    glGetIntegerv(GL_TEXTURE_BINDING_2D, &oldTex);
    if (!this->CopyTex)
    {
      glGenTextures(1, &this->CopyTex);
    }
    glBindTexture(GL_TEXTURE_2D, this->CopyTex);
    GLenum f, t;
    DepthTexFormat(format, f, t);
    glTexImage2D(GL_TEXTURE_2D, 0, static_cast<GLint>(format), vw, vh, 0, f, t, nullptr);
    glBindTexture(GL_TEXTURE_2D, static_cast<GLuint>(oldTex));
    if (!this->CopyFbo)
    {
      glGenFramebuffers(1, &this->CopyFbo);
    }
    glBindFramebuffer(GL_DRAW_FRAMEBUFFER, this->CopyFbo);
    glFramebufferTexture2D(GL_DRAW_FRAMEBUFFER,
      HasStencil(format) ? GL_DEPTH_STENCIL_ATTACHMENT : GL_DEPTH_ATTACHMENT, GL_TEXTURE_2D,
      this->CopyTex, 0);
    glDrawBuffer(GL_NONE);
    glBindFramebuffer(GL_DRAW_FRAMEBUFFER, static_cast<GLuint>(drawFbo));
    this->CopyFormat = format;
    this->CopyW = vw;
    this->CopyH = vh;
    this->CopyObject = vtkSmartPointer<vtkTextureObject>::New();
    this->CopyObject->SetContext(win);
    this->CopyObject->AssignToExistingTexture(this->CopyTex, GL_TEXTURE_2D);
    vtkFerroVolumeSetSampling(this->CopyObject, false);
  }
  {
    vtkOpenGLState::ScopedglEnableDisable scissorSaver(ostate, GL_SCISSOR_TEST);
    ostate->vtkglDisable(GL_SCISSOR_TEST);
    glBindFramebuffer(GL_DRAW_FRAMEBUFFER, this->CopyFbo);
    glBlitFramebuffer(req.ViewportX, req.ViewportY, req.ViewportX + vw, req.ViewportY + vh, 0,
      0, vw, vh, GL_DEPTH_BUFFER_BIT, GL_NEAREST);
    glBindFramebuffer(GL_DRAW_FRAMEBUFFER, static_cast<GLuint>(drawFbo));
  }
  if (glGetError() != GL_NO_ERROR)
  {
    return report.Fail("copying the depth buffer failed");
  }

  if (!this->Quad)
  {
    this->Quad.reset(new vtkOpenGLQuadHelper(win, nullptr, DepthInputFragmentShader, ""));
  }
  if (!this->Quad->Program)
  {
    return report.Fail("could not compile the depth copy shader");
  }
  win->GetShaderCache()->ReadyShaderProgram(this->Quad->Program);
  {
    vtkOpenGLState::ScopedglViewport viewportSaver(ostate);
    vtkOpenGLState::ScopedglEnableDisable scissorSaver(ostate, GL_SCISSOR_TEST);
    vtkOpenGLState::ScopedglEnableDisable blendSaver(ostate, GL_BLEND);
    vtkOpenGLState::ScopedglEnableDisable depthSaver(ostate, GL_DEPTH_TEST);
    vtkOpenGLState::ScopedglColorMask colorMaskSaver(ostate);
    vtkOpenGLState::ScopedglEnableDisable cullSaver(ostate, GL_CULL_FACE);
    ostate->vtkglDisable(GL_CULL_FACE);
    ostate->vtkglDisable(GL_SCISSOR_TEST);
    ostate->vtkglDisable(GL_BLEND);
    ostate->vtkglDisable(GL_DEPTH_TEST);
    ostate->vtkglColorMask(GL_TRUE, GL_TRUE, GL_TRUE, GL_TRUE);
    ostate->vtkglViewport(0, 0, this->InputW, this->InputH);
    // through VTK's state cache: VTK calls run while this framebuffer is bound
    ostate->PushDrawFramebufferBinding();
    ostate->vtkglBindFramebuffer(GL_DRAW_FRAMEBUFFER, this->InputFbo);
    this->CopyObject->Activate();
    this->Quad->Program->SetUniformi("vtkDepth", this->CopyObject->GetTextureUnit());
    const int viewportSize[2] = { vw, vh };
    const int renderSize[2] = { this->InputW, this->InputH };
    this->Quad->Program->SetUniform2i("viewportSize", viewportSize);
    this->Quad->Program->SetUniform2i("renderSize", renderSize);
    this->Quad->Render();
    this->CopyObject->Deactivate();
    ostate->PopDrawFramebufferBinding();
  }
  if (glGetError() != GL_NO_ERROR)
  {
    return report.Fail("writing ferrovol's depth input failed");
  }
  return true;
}

// No opaque depth: the depth input becomes 1 (far) everywhere.
void vtkFerroVolumeSharedOutput::ClearDepthInput()
{
  GLint drawFbo = 0;
  glGetIntegerv(GL_DRAW_FRAMEBUFFER_BINDING, &drawFbo);
  glBindFramebuffer(GL_DRAW_FRAMEBUFFER, this->InputFbo);
  const GLfloat far[4] = { 1.0f, 1.0f, 1.0f, 1.0f };
  glClearBufferfv(GL_COLOR, 0, far);
  glBindFramebuffer(GL_DRAW_FRAMEBUFFER, static_cast<GLuint>(drawFbo));
}

void vtkFerroVolumeSharedOutput::DeleteImports()
{
  for (Imported& im : this->Images)
  {
    if (im.Texture)
    {
      glDeleteTextures(1, &im.Texture);
    }
    if (im.Memory)
    {
      glDeleteMemoryObjectsEXT(1, &im.Memory);
    }
    im = Imported();
  }
  if (this->InputFbo)
  {
    glDeleteFramebuffers(1, &this->InputFbo);
    this->InputFbo = 0;
  }
}

// Drops GL names without deleting them (their context is gone or being torn down).
void vtkFerroVolumeSharedOutput::Forget()
{
  for (Imported& im : this->Images)
  {
    im = Imported();
  }
  this->InputFbo = this->CopyFbo = this->CopyTex = 0;
  this->CopyObject = nullptr;
  this->CopyFormat = GL_NONE;
  this->CopyW = this->CopyH = 0;
  this->Quad.reset();
}
