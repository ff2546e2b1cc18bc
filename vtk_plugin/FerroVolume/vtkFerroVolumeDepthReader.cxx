#include "vtkFerroVolumeDepthReader.h"

#include "vtkCollection.h"
#include "vtkFerroVolumeReport.h"
#include "vtkOpenGLError.h"
#include "vtkOpenGLRenderWindow.h"
#include "vtkOpenGLState.h"
#include "vtkProp.h"
#include "vtkPropCollection.h"
#include "vtkRenderer.h"
#include "vtkVolume.h"

#include <algorithm>
#include <sstream>

bool vtkFerroVolumeDepthReader::SceneHasOpaqueGeometry(vtkRenderer* ren, vtkVolume* volume)
{
  vtkPropCollection* props = ren->GetViewProps();
  vtkCollectionSimpleIterator it;
  props->InitTraversal(it);
  while (vtkProp* p = props->GetNextProp(it))
  {
    if (p != volume && p->GetVisibility() && !vtkVolume::SafeDownCast(p) &&
      p->HasOpaqueGeometry())
    {
      return true;
    }
  }
  return false;
}

bool vtkFerroVolumeDepthReader::Read(vtkOpenGLRenderWindow* win, int x, int y, int w, int h,
  std::vector<float>& out, vtkFerroVolumeReport& report)
{
  vtkOpenGLState* ostate = win->GetState();
  out.assign(static_cast<size_t>(w) * h, 1.0f);
  vtkOpenGLClearErrorMacro();

  GLint readFbo = 0, drawFbo = 0, packBuffer = 0;
  glGetIntegerv(GL_READ_FRAMEBUFFER_BINDING, &readFbo);
  glGetIntegerv(GL_DRAW_FRAMEBUFFER_BINDING, &drawFbo);
  glGetIntegerv(GL_PIXEL_PACK_BUFFER_BINDING, &packBuffer);
  if (packBuffer != 0)
  {
    glBindBuffer(GL_PIXEL_PACK_BUFFER, 0);
  }

  // GL_SAMPLES describes the draw framebuffer: look at the read one.
  GLint samples = 0;
  if (drawFbo != readFbo)
  {
    glBindFramebuffer(GL_DRAW_FRAMEBUFFER, readFbo);
  }
  glGetIntegerv(GL_SAMPLES, &samples);
  if (drawFbo != readFbo)
  {
    glBindFramebuffer(GL_DRAW_FRAMEBUFFER, drawFbo);
  }

  bool ok = true;
  if (samples <= 0)
  {
    glReadPixels(x, y, w, h, GL_DEPTH_COMPONENT, GL_FLOAT, out.data());
  }
  else
  {
    GLenum format = DepthFormatOf(readFbo);
    if (format == GL_NONE)
    {
      report.Fail("the framebuffer's depth attachment has an unknown format");
      ok = false;
    }
    else
    {
      this->Prepare(format, w, h);
      vtkOpenGLState::ScopedglEnableDisable scissorSaver(ostate, GL_SCISSOR_TEST);
      ostate->vtkglDisable(GL_SCISSOR_TEST);
      glBindFramebuffer(GL_DRAW_FRAMEBUFFER, this->Fbo);
      glBlitFramebuffer(x, y, x + w, y + h, 0, 0, w, h, GL_DEPTH_BUFFER_BIT, GL_NEAREST);
      glBindFramebuffer(GL_READ_FRAMEBUFFER, this->Fbo);
      glReadPixels(0, 0, w, h, GL_DEPTH_COMPONENT, GL_FLOAT, out.data());
      glBindFramebuffer(GL_READ_FRAMEBUFFER, readFbo);
      glBindFramebuffer(GL_DRAW_FRAMEBUFFER, drawFbo);
    }
  }
  if (packBuffer != 0)
  {
    glBindBuffer(GL_PIXEL_PACK_BUFFER, packBuffer);
  }
  GLenum err = glGetError();
  if (ok && err != GL_NO_ERROR)
  {
    std::ostringstream s;
    s << "reading the depth buffer failed (OpenGL error 0x" << std::hex << err << ")";
    report.Fail(s.str());
    ok = false;
  }
  if (!ok)
  {
    std::fill(out.begin(), out.end(), 1.0f);
  }
  return ok;
}

void vtkFerroVolumeDepthReader::ReleaseGraphicsResources()
{
  if (this->Fbo)
  {
    glDeleteFramebuffers(1, &this->Fbo);
    this->Fbo = 0;
  }
  if (this->Rbo)
  {
    glDeleteRenderbuffers(1, &this->Rbo);
    this->Rbo = 0;
  }
  this->Width = this->Height = 0;
  this->Format = GL_NONE;
}

void vtkFerroVolumeDepthReader::Forget()
{
  this->Fbo = this->Rbo = 0;
  this->Width = this->Height = 0;
  this->Format = GL_NONE;
}

GLenum vtkFerroVolumeDepthReader::DepthFormatOf(GLint fbo)
{
  GLenum attachment = fbo == 0 ? GL_DEPTH : GL_DEPTH_ATTACHMENT;
  GLint depthBits = 0, stencilBits = 0, type = 0;
  glGetFramebufferAttachmentParameteriv(
    GL_READ_FRAMEBUFFER, attachment, GL_FRAMEBUFFER_ATTACHMENT_DEPTH_SIZE, &depthBits);
  glGetFramebufferAttachmentParameteriv(GL_READ_FRAMEBUFFER, attachment,
    GL_FRAMEBUFFER_ATTACHMENT_COMPONENT_TYPE, &type);
  glGetFramebufferAttachmentParameteriv(GL_READ_FRAMEBUFFER,
    fbo == 0 ? GL_STENCIL : GL_STENCIL_ATTACHMENT, GL_FRAMEBUFFER_ATTACHMENT_STENCIL_SIZE,
    &stencilBits);
  glGetError(); // a missing stencil attachment may raise GL_INVALID_OPERATION
  const bool isFloat = type == GL_FLOAT;
  if (stencilBits > 0)
  {
    return isFloat ? GL_DEPTH32F_STENCIL8 : GL_DEPTH24_STENCIL8;
  }
  switch (depthBits)
  {
    case 16:
      return GL_DEPTH_COMPONENT16;
    case 24:
      return GL_DEPTH_COMPONENT24;
    case 32:
      return isFloat ? GL_DEPTH_COMPONENT32F : GL_DEPTH_COMPONENT32;
    default:
      return GL_NONE;
  }
}

void vtkFerroVolumeDepthReader::Prepare(GLenum format, int w, int h)
{
  if (this->Fbo && this->Format == format && this->Width == w && this->Height == h)
  {
    return;
  }
  if (!this->Rbo)
  {
    glGenRenderbuffers(1, &this->Rbo);
  }
  GLint oldRbo = 0;
  glGetIntegerv(GL_RENDERBUFFER_BINDING, &oldRbo);
  glBindRenderbuffer(GL_RENDERBUFFER, this->Rbo);
  glRenderbufferStorage(GL_RENDERBUFFER, format, w, h);
  glBindRenderbuffer(GL_RENDERBUFFER, oldRbo);
  if (!this->Fbo)
  {
    glGenFramebuffers(1, &this->Fbo);
  }
  // Bound as both draw and read framebuffer while its (per-framebuffer) draw and read
  // buffers are set, so VTK's framebuffer keeps its own.
  GLint oldDraw = 0, oldRead = 0;
  glGetIntegerv(GL_DRAW_FRAMEBUFFER_BINDING, &oldDraw);
  glGetIntegerv(GL_READ_FRAMEBUFFER_BINDING, &oldRead);
  glBindFramebuffer(GL_FRAMEBUFFER, this->Fbo);
  const bool stencil = format == GL_DEPTH24_STENCIL8 || format == GL_DEPTH32F_STENCIL8;
  glFramebufferRenderbuffer(GL_FRAMEBUFFER,
    stencil ? GL_DEPTH_STENCIL_ATTACHMENT : GL_DEPTH_ATTACHMENT, GL_RENDERBUFFER, this->Rbo);
  glDrawBuffer(GL_NONE);
  glReadBuffer(GL_NONE);
  glBindFramebuffer(GL_READ_FRAMEBUFFER, oldRead);
  glBindFramebuffer(GL_DRAW_FRAMEBUFFER, oldDraw);
  this->Format = format;
  this->Width = w;
  this->Height = h;
}
