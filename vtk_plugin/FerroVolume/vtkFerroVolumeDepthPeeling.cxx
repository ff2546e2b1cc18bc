#include "vtkFerroVolumeDepthPeeling.h"

#include "vtkAbstractVolumeMapper.h"
#include "vtkDualDepthPeelingPass.h"
#include "vtkFerroVolumeContext.h"
#include "vtkFerroVolumeDepthReader.h"
#include "vtkFerroVolumeOutput.h"
#include "vtkFerroVolumeReport.h"
#include "vtkInformation.h"
#include "vtkOpenGLError.h"
#include "vtkOpenGLQuadHelper.h"
#include "vtkOpenGLRenderPass.h"
#include "vtkOpenGLRenderWindow.h"
#include "vtkOpenGLShaderCache.h"
#include "vtkOpenGLState.h"
#include "vtkShaderProgram.h"
#include "vtkTextureObject.h"
#include "vtkVolume.h"
#include "vtkFerroVolumeGL.h"

#include <algorithm>

namespace
{
// Samples every texture a volumetric stage of vtkDualDepthPeelingPass binds (so that none is
// optimised away and the pass can set each uniform).
const char* ProbeFragmentShader = R"(//VTK::System::Dec
in vec2 texCoord;
uniform sampler2D outerDepthTex;
uniform sampler2D innerDepthTex;
uniform sampler2D lastFrontColorTex;
uniform sampler2D opaqueDepthTex;
uniform sampler2D depthRangeTex;
//VTK::Output::Dec
void main()
{
  gl_FragData[0] = texture(outerDepthTex, texCoord) + texture(innerDepthTex, texCoord) +
    texture(lastFrontColorTex, texCoord) + texture(opaqueDepthTex, texCoord) +
    texture(depthRangeTex, texCoord);
}
)";

// Writes a stage's targets from ferrovol's front and back ranges (premultiplied, rows top
// to bottom) as vtkOpenGLGPUVolumeRayCastMapper's shader does under dual depth peeling.
const char* QuadFragmentShader = R"(//VTK::System::Dec
in vec2 texCoord;
uniform sampler2D fvFront;
uniform sampler2D fvBack;
uniform float fvColorScale;
uniform float fvColorBias;
#if FV_STAGE == 1
uniform sampler2D outerDepthTex;
uniform sampler2D lastFrontColorTex;
#elif FV_STAGE == 2
uniform sampler2D depthRangeTex;
#endif
//VTK::Output::Dec
vec4 graded(sampler2D t)
{
  // ferrovol's rows run top to bottom, OpenGL's bottom to top; FinalColorWindow / Level
  vec4 c = texture(t, vec2(texCoord.x, 1.0 - texCoord.y));
  return vec4(c.rgb * fvColorScale + fvColorBias * c.a, c.a);
}
void main()
{
  ivec2 px = ivec2(gl_FragCoord.xy);
  vec4 back = graded(fvBack);
#if FV_STAGE == 0
  // outside the layers: straight into the cleared accumulators
  gl_FragData[0] = back;
  gl_FragData[1] = graded(fvFront);
#elif FV_STAGE == 1
  // a peel: pixels already done are left alone; the front range under the front so far
  // (its alpha accumulated), the back range as this peel's back layer
  if (texelFetch(outerDepthTex, px, 0).x == -1.0)
  {
    discard;
  }
  vec4 last = texelFetch(lastFrontColorTex, px, 0);
  vec4 front = graded(fvFront);
  float t = 1.0 - last.a;
  gl_FragData[0] = back;
  gl_FragData[1] = vec4(t * front.rgb + last.rgb, 1.0 - t * (1.0 - front.a));
#else
  // after the last peel: what is left, over the back accumulator
  if (texelFetch(depthRangeTex, px, 0).x == -1.0)
  {
    discard;
  }
  gl_FragData[0] = back;
#endif
}
)";

// The stage of a volumetric peel, from the shader code the pass substitutes for it.
bool DetectStage(vtkRenderPass* pass, vtkAbstractVolumeMapper* mapper, vtkVolume* vol,
  vtkFerroVolumeDepthPeeling::Stage& stage)
{
  std::string vs, gs;
  std::string fs = "//VTK::DepthPeeling::Dec\n//VTK::CallWorker::Impl\n";
  vtkOpenGLRenderPass* glPass = vtkOpenGLRenderPass::SafeDownCast(pass);
  if (!glPass || !glPass->PreReplaceShaderValues(vs, gs, fs, mapper, vol))
  {
    return false;
  }
  if (fs.find("depthRangeTex") != std::string::npos)
  {
    stage = vtkFerroVolumeDepthPeeling::Stage::Blend;
  }
  else if (fs.find("lastFrontColorTex") != std::string::npos)
  {
    stage = vtkFerroVolumeDepthPeeling::Stage::Peel;
  }
  else if (fs.find("innerDepthTex") != std::string::npos)
  {
    stage = vtkFerroVolumeDepthPeeling::Stage::Outside;
  }
  else
  {
    return false;
  }
  return true;
}

void SetRange(std::vector<float>& near, std::vector<float>& far, size_t i, float a, float b)
{
  near[i] = a;
  far[i] = b;
}

bool AnyRange(const std::vector<float>& near, const std::vector<float>& far)
{
  for (size_t i = 0; i < near.size(); ++i)
  {
    if (near[i] < far[i])
    {
      return true;
    }
  }
  return false;
}
}

vtkFerroVolumeDepthPeeling::vtkFerroVolumeDepthPeeling() = default;
vtkFerroVolumeDepthPeeling::~vtkFerroVolumeDepthPeeling() = default;

vtkRenderPass* vtkFerroVolumeDepthPeeling::PeelingPass(vtkVolume* vol)
{
  vtkInformation* keys = vol->GetPropertyKeys();
  if (!keys || !keys->Has(vtkOpenGLRenderPass::RenderPasses()))
  {
    return nullptr;
  }
  const int n = keys->Length(vtkOpenGLRenderPass::RenderPasses());
  for (int i = 0; i < n; ++i)
  {
    if (auto* pass =
          vtkDualDepthPeelingPass::SafeDownCast(keys->Get(vtkOpenGLRenderPass::RenderPasses(), i)))
    {
      return pass;
    }
  }
  return nullptr;
}

bool vtkFerroVolumeDepthPeeling::Prepare(vtkOpenGLRenderWindow* win, vtkFerroVolumeReport& report)
{
  if (this->Window != win)
  {
    this->ReleaseGraphicsResources(nullptr);
    this->Window = win;
  }
  if (!this->Probe)
  {
    this->Probe.reset(new vtkOpenGLQuadHelper(win, nullptr, ProbeFragmentShader, ""));
    for (int s = 0; s < 3; ++s)
    {
      std::string fs = QuadFragmentShader;
      vtkShaderProgram::Substitute(
        fs, "//VTK::System::Dec", "//VTK::System::Dec\n#define FV_STAGE " + std::to_string(s));
      this->Quads[s].reset(new vtkOpenGLQuadHelper(win, nullptr, fs.c_str(), ""));
    }
    this->Front = vtkSmartPointer<vtkTextureObject>::New();
    this->Back = vtkSmartPointer<vtkTextureObject>::New();
  }
  if (!this->Probe->Program || !this->Quads[0]->Program || !this->Quads[1]->Program ||
    !this->Quads[2]->Program)
  {
    report.Fail("could not compile the shaders that draw the volume into depth peeling's layers");
    this->ReleaseGraphicsResources(nullptr);
    return false;
  }
  this->Front->SetContext(win);
  this->Back->SetContext(win);
  return true;
}

bool vtkFerroVolumeDepthPeeling::ReadPassTexture(vtkOpenGLRenderWindow* win,
  const char* uniform, int components, int width, int height, std::vector<float>& out,
  vtkFerroVolumeReport& report)
{
  const GLuint program = static_cast<GLuint>(this->Probe->Program->GetHandle());
  const GLint location = glGetUniformLocation(program, uniform);
  GLint unit = -1;
  if (location >= 0)
  {
    glGetUniformiv(program, location, &unit);
  }
  if (unit < 0)
  {
    return report.Fail(std::string("depth peeling's ") + uniform + " is not bound");
  }
  vtkOpenGLState* ostate = win->GetState();
  vtkOpenGLState::ScopedglActiveTexture unitSaver(ostate);
  ostate->vtkglActiveTexture(GL_TEXTURE0 + unit);
  GLint texture = 0, w = 0, h = 0;
  glGetIntegerv(GL_TEXTURE_BINDING_2D, &texture);
  if (texture != 0)
  {
    glGetTexLevelParameteriv(GL_TEXTURE_2D, 0, GL_TEXTURE_WIDTH, &w);
    glGetTexLevelParameteriv(GL_TEXTURE_2D, 0, GL_TEXTURE_HEIGHT, &h);
  }
  if (texture == 0 || w != width || h != height)
  {
    return report.Fail(std::string("depth peeling's ") + uniform + " is " +
      std::to_string(w) + "x" + std::to_string(h) + ", the viewport " + std::to_string(width) +
      "x" + std::to_string(height));
  }
  out.resize(static_cast<size_t>(width) * height * components);
  // (into client memory: a pixel-pack buffer left bound would take the texels instead)
  GLint pack = 0;
  glGetIntegerv(GL_PIXEL_PACK_BUFFER_BINDING, &pack);
  glBindBuffer(GL_PIXEL_PACK_BUFFER, 0);
  glGetTexImage(GL_TEXTURE_2D, 0, components == 2 ? GL_RG : GL_DEPTH_COMPONENT, GL_FLOAT,
    out.data());
  glBindBuffer(GL_PIXEL_PACK_BUFFER, static_cast<GLuint>(pack));
  vtkOpenGLCheckErrorMacro("after reading a depth peeling texture");
  return true;
}

bool vtkFerroVolumeDepthPeeling::Render(ferrovol::Renderer& renderer,
  const vtkFerroVolumeFrameRequest& req, const std::vector<float>& near,
  const std::vector<float>& far, vtkTextureObject* texture, vtkFerroVolumeReport& report)
{
  std::vector<unsigned char> clear;
  const unsigned char* rgba = nullptr;
  std::unique_ptr<ferrovol::Frame> frame;
  if (AnyRange(near, far))
  {
    if (!vtkFerroVolumeCall("render the volume between depth peeling's layers", report, [&] {
          renderer.render_between(static_cast<uint32_t>(req.RenderW),
            static_cast<uint32_t>(req.RenderH), near, far);
          frame.reset(new ferrovol::Frame(renderer.read_frame()));
        }))
    {
      return false;
    }
    rgba = frame->rgba();
    if (frame->width() != static_cast<uint32_t>(req.RenderW) ||
      frame->height() != static_cast<uint32_t>(req.RenderH) || !rgba)
    {
      return report.Fail("ferrovol returned a frame of an unexpected size");
    }
  }
  else
  {
    clear.assign(static_cast<size_t>(req.RenderW) * req.RenderH * 4, 0);
    rgba = clear.data();
  }
  vtkFerroVolumeSetSampling(texture, true);
  if (!texture->Create2DFromRaw(req.RenderW, req.RenderH, 4, VTK_UNSIGNED_CHAR,
        const_cast<void*>(static_cast<const void*>(rgba))))
  {
    return report.Fail("could not upload the volume's layer into an OpenGL texture");
  }
  return true;
}

bool vtkFerroVolumeDepthPeeling::Draw(vtkRenderPass* pass, vtkAbstractVolumeMapper* mapper,
  vtkVolume* vol, ferrovol::Renderer& renderer, const vtkFerroVolumeFrameRequest& req,
  vtkFerroVolumeReport& report)
{
  vtkOpenGLRenderWindow* win = req.Window;
  Stage stage = Stage::Outside;
  if (!DetectStage(pass, mapper, vol, stage))
  {
    return report.Fail("this vtkDualDepthPeelingPass is in a stage ferrovol does not know");
  }
  if (!this->Prepare(win, report))
  {
    return false;
  }
  vtkOpenGLRenderPass* glPass = vtkOpenGLRenderPass::SafeDownCast(pass);
  win->GetShaderCache()->ReadyShaderProgram(this->Probe->Program);
  glPass->SetShaderParameters(this->Probe->Program, mapper, vol, nullptr);

  // The pass's depths (rows bottom to top) at the pixels ferrovol renders (top to bottom).
  const int vw = req.ViewportW, vh = req.ViewportH, rw = req.RenderW, rh = req.RenderH;
  const bool blend = stage == Stage::Blend;
  if (!this->ReadPassTexture(win, blend ? "depthRangeTex" : "outerDepthTex", 2, vw, vh,
        this->Outer, report) ||
    (!blend && !this->ReadPassTexture(win, "innerDepthTex", 2, vw, vh, this->Inner, report)) ||
    (stage == Stage::Peel &&
      !this->ReadPassTexture(win, "opaqueDepthTex", 1, vw, vh, this->Opaque, report)))
  {
    return false;
  }
  const size_t n = static_cast<size_t>(rw) * rh;
  for (auto* v : { &this->NearFront, &this->NearBack })
  {
    v->assign(n, 1.0f);
  }
  for (auto* v : { &this->FarFront, &this->FarBack })
  {
    v->assign(n, 0.0f);
  }
  for (int y = 0; y < rh; ++y)
  {
    const size_t row =
      static_cast<size_t>(vh - 1 - vtkFerroVolumeDepthReader::SourcePixel(y, rh, vh)) * vw;
    for (int x = 0; x < rw; ++x)
    {
      const size_t src = row + vtkFerroVolumeDepthReader::SourcePixel(x, rw, vw);
      const size_t i = static_cast<size_t>(y) * rw + x;
      const float ox = this->Outer[2 * src], oy = this->Outer[2 * src + 1];
      switch (stage)
      {
        case Stage::Outside:
        {
          // outer: (−1, opaque depth), or (−1, −1) without opaque geometry; inner: the
          // translucent layers' (−nearest, farthest), or as outer without any
          const float ix = this->Inner[2 * src], iy = this->Inner[2 * src + 1];
          if (ix == -1.0f)
          {
            SetRange(this->NearBack, this->FarBack, i, 0.0f, oy >= 0.0f ? iy : 1.0f);
          }
          else
          {
            SetRange(this->NearFront, this->FarFront, i, 0.0f, -ix);
            SetRange(this->NearBack, this->FarBack, i, iy, oy >= 0.0f ? oy : 1.0f);
          }
          break;
        }
        case Stage::Peel:
        {
          // outer: the layers peeled last (−near, far), −1 where done; inner: the layers
          // peeled now, −1 where none is left
          if (ox == -1.0f)
          {
            break;
          }
          const float ix = this->Inner[2 * src], iy = this->Inner[2 * src + 1];
          const float frontStart = -ox, backEnd = oy;
          const bool noInner = ix == -1.0f;
          const float frontEnd = noInner ? oy : -ix;
          const bool onlyBack = frontStart == iy && frontEnd == backEnd;
          const float opaque = this->Opaque[src];
          const bool behindOpaque = frontEnd >= opaque;
          if (!onlyBack)
          {
            SetRange(this->NearFront, this->FarFront, i, frontStart,
              behindOpaque ? opaque : frontEnd);
          }
          if (!behindOpaque && !noInner)
          {
            SetRange(this->NearBack, this->FarBack, i, iy, backEnd);
          }
          break;
        }
        case Stage::Blend:
          if (ox != -1.0f)
          {
            SetRange(this->NearBack, this->FarBack, i, -ox, oy);
          }
          break;
      }
    }
  }
  if ((!blend &&
        !this->Render(renderer, req, this->NearFront, this->FarFront, this->Front, report)) ||
    !this->Render(renderer, req, this->NearBack, this->FarBack, this->Back, report))
  {
    return false;
  }

  // Into the pass's targets, with its blending (MAX in the peels, over after them).
  vtkOpenGLQuadHelper* quad = this->Quads[static_cast<int>(stage)].get();
  win->GetShaderCache()->ReadyShaderProgram(quad->Program);
  glPass->SetShaderParameters(quad->Program, mapper, vol, nullptr);
  vtkOpenGLState* ostate = win->GetState();
  vtkOpenGLState::ScopedglEnableDisable cullSaver(ostate, GL_CULL_FACE);
  ostate->vtkglDisable(GL_CULL_FACE);
  this->Front->Activate();
  this->Back->Activate();
  quad->Program->SetUniformi("fvFront", this->Front->GetTextureUnit());
  quad->Program->SetUniformi("fvBack", this->Back->GetTextureUnit());
  quad->Program->SetUniformf("fvColorScale", req.ColorScale);
  quad->Program->SetUniformf("fvColorBias", req.ColorBias);
  quad->Render();
  this->Back->Deactivate();
  this->Front->Deactivate();
  vtkOpenGLCheckErrorMacro("after drawing the volume into depth peeling's layers");
  return true;
}

void vtkFerroVolumeDepthPeeling::ReleaseGraphicsResources(vtkWindow* window)
{
  vtkOpenGLRenderWindow* glwin = vtkOpenGLRenderWindow::SafeDownCast(window);
  if (!glwin || glwin != this->Window)
  {
    // another window (or none we drew into): forget our names
    window = nullptr;
  }
  for (auto* t : { this->Front.Get(), this->Back.Get() })
  {
    if (t)
    {
      t->ReleaseGraphicsResources(window);
    }
  }
  // The quad helpers release themselves through the callback they registered with their
  // window.
  this->Probe.reset();
  for (auto& q : this->Quads)
  {
    q.reset();
  }
  this->Front = nullptr;
  this->Back = nullptr;
  this->Window = nullptr;
}
