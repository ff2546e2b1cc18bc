#include "vtkFerroVolumeOutput.h"

#include "vtkCamera.h"
#include "vtkFerroVolumeContext.h"
#include "vtkFerroVolumeDepthReader.h"
#include "vtkFerroVolumeEnums.h"
#include "vtkFerroVolumeReport.h"
#include "vtkLogger.h"
#include "vtkMatrix4x4.h"
#include "vtkOpenGLError.h"
#include "vtkOpenGLQuadHelper.h"
#include "vtkOpenGLRenderWindow.h"
#include "vtkOpenGLShaderCache.h"
#include "vtkOpenGLState.h"
#include "vtkRenderer.h"
#include "vtkShaderProgram.h"
#include "vtkSmartPointer.h"
#include "vtkTextureObject.h"
#include "vtkVolume.h"
#include "vtkFerroVolumeGL.h"

#if FERROVOL_HAVE_SHARED_OUTPUT
#include "vtkFerroVolumeSharedOutput.h"
#endif

#include <algorithm>
#include <cmath>
#include <cstring>
#include <mutex>
#include <vector>

void vtkFerroVolumeSetSampling(vtkTextureObject* texture, bool linear)
{
  const int filter = linear ? vtkTextureObject::Linear : vtkTextureObject::Nearest;
  texture->SetMinificationFilter(filter);
  texture->SetMagnificationFilter(filter);
  texture->SetWrapS(vtkTextureObject::ClampToEdge);
  texture->SetWrapT(vtkTextureObject::ClampToEdge);
}

bool vtkFerroVolumeFrameRequest::ForViewport(
  vtkRenderer* ren, vtkVolume* vol, vtkOpenGLRenderWindow* win)
{
  this->Window = win;
  ren->GetTiledSizeAndOrigin(
    &this->ViewportW, &this->ViewportH, &this->ViewportX, &this->ViewportY);
  this->RenderW = this->ViewportW;
  this->RenderH = this->ViewportH;
  this->UseDepth = vtkFerroVolumeDepthReader::SceneHasOpaqueGeometry(ren, vol);
  return this->ViewportW >= 1 && this->ViewportH >= 1;
}

namespace
{
// Frames through the CPU: VTK's depth with glReadPixels, the frame back with read_frame and
// into two textures with glTexImage2D.
class ReadbackOutput : public vtkFerroVolumeFramePath
{
public:
  const char* Name() const override { return "readback"; }

  bool Render(ferrovol::Renderer& renderer, const vtkFerroVolumeFrameRequest& req,
    vtkFerroVolumeReport& report, std::string& warning) override
  {
    // VTK's depth for the viewport (rows bottom to top), sampled at the centres of the
    // pixels ferrovol renders (rows top to bottom), picking texels as OpenGL's nearest
    // filtering does (the shared path samples the same depth on the GPU).
    vtkFerroVolumeReport depthError;
    const int rw = req.RenderW, rh = req.RenderH, vw = req.ViewportW, vh = req.ViewportH;
    const bool haveDepth = req.UseDepth &&
      this->Depth.Read(req.Window, req.ViewportX, req.ViewportY, req.ViewportW, req.ViewportH,
        this->WindowDepth, depthError);
    if (req.UseDepth && !haveDepth)
    {
      warning = "the volume ignores opaque geometry in this frame: " + depthError.GetError();
    }
    this->DepthInput.resize(haveDepth ? static_cast<size_t>(rw) * rh : 0);
    for (int y = 0; haveDepth && y < rh; ++y)
    {
      const float* src = this->WindowDepth.data() +
        static_cast<size_t>(vh - 1 - vtkFerroVolumeDepthReader::SourcePixel(y, rh, vh)) * vw;
      float* dst = this->DepthInput.data() + static_cast<size_t>(y) * rw;
      if (rw == vw)
      {
        std::memcpy(dst, src, sizeof(float) * vw);
      }
      else
      {
        for (int x = 0; x < rw; ++x)
        {
          dst[x] = src[vtkFerroVolumeDepthReader::SourcePixel(x, rw, vw)];
        }
      }
    }

    if (!vtkFerroVolumeCall("render the frame", report, [&] {
          renderer.render(static_cast<uint32_t>(rw), static_cast<uint32_t>(rh), this->DepthInput);
        }))
    {
      return false;
    }
    std::unique_ptr<ferrovol::Frame> frame;
    if (!vtkFerroVolumeCall("read the frame back", report,
          [&] { frame.reset(new ferrovol::Frame(renderer.read_frame())); }))
    {
      return false;
    }
    const uint8_t* rgba = frame->rgba();
    const float* depth = frame->depth();
    if (frame->width() != static_cast<uint32_t>(rw) ||
      frame->height() != static_cast<uint32_t>(rh) || !rgba || !depth)
    {
      return report.Fail("ferrovol returned a frame of an unexpected size");
    }
    return this->Upload(req.Window, rw, rh, rgba, depth, report);
  }

  vtkTextureObject* ColorTexture() override { return this->Color; }
  vtkTextureObject* DepthTexture() override { return this->DepthTex; }

  void ReleaseGraphicsResources(vtkWindow* window) override
  {
    if (this->Color)
    {
      this->Color->ReleaseGraphicsResources(window);
    }
    if (this->DepthTex)
    {
      this->DepthTex->ReleaseGraphicsResources(window);
    }
    if (window)
    {
      this->Depth.ReleaseGraphicsResources();
    }
    else
    {
      this->Depth.Forget();
    }
  }

private:
  bool Upload(vtkOpenGLRenderWindow* win, int w, int h, const uint8_t* rgba, const float* depth,
    vtkFerroVolumeReport& report)
  {
    if (!this->Color)
    {
      this->Color = vtkSmartPointer<vtkTextureObject>::New();
      this->DepthTex = vtkSmartPointer<vtkTextureObject>::New();
    }
    this->Color->SetContext(win);
    this->DepthTex->SetContext(win);
    // The colour is scaled up linearly when ImageSampleDistance > 1; depth is not filtered.
    vtkFerroVolumeSetSampling(this->Color, true);
    vtkFerroVolumeSetSampling(this->DepthTex, false);
    if (!this->Color->Create2DFromRaw(w, h, 4, VTK_UNSIGNED_CHAR,
          const_cast<void*>(static_cast<const void*>(rgba))) ||
      !this->DepthTex->Create2DFromRaw(
        w, h, 1, VTK_FLOAT, const_cast<void*>(static_cast<const void*>(depth))))
    {
      return report.Fail("could not upload the frame into OpenGL textures");
    }
    return true;
  }

  vtkFerroVolumeDepthReader Depth;
  std::vector<float> WindowDepth;
  std::vector<float> DepthInput;
  vtkSmartPointer<vtkTextureObject> Color;
  vtkSmartPointer<vtkTextureObject> DepthTex;
};

// Draws the frame over the viewport: premultiplied colour, depth from the volume.
const char* CompositeFragmentShader = R"(//VTK::System::Dec
in vec2 texCoord;
uniform sampler2D fvColor;
uniform sampler2D fvDepth;
uniform float fvColorScale;
uniform float fvColorBias;
//VTK::Output::Dec
void main()
{
  // ferrovol's rows run top to bottom, OpenGL's bottom to top
  vec2 tc = vec2(texCoord.x, 1.0 - texCoord.y);
  vec4 color = texture(fvColor, tc);
  float depth = texture(fvDepth, tc).r;
  // (kept: a transparent pixel with a depth, an extremum that must still win the depth test
  // (ExtremumDepth), and a transparent colour, a piece's sum that compositing adds up
  // (WholeExtent))
  if (color == vec4(0.0) && depth >= 1.0)
  {
    discard;
  }
  // FinalColorWindow / FinalColorLevel, as vtkGPUVolumeRayCastMapper's finalizeRayCast
  color.rgb = color.rgb * fvColorScale + fvColorBias * color.a;
  gl_FragData[0] = color;
  gl_FragDepth = depth;
}
)";

// A hardware-selection pass: the prop's id colour, or the index + 1 of the point at the
// frame's depth (low or high 24 bits), where the accumulated opacity exceeds 3/255.
const char* SelectFragmentShader = R"(//VTK::System::Dec
in vec2 texCoord;
uniform sampler2D fvColor;
uniform sampler2D fvDepth;
uniform int fvWrite;
uniform vec3 fvPropColor;
uniform vec4 fvToIndex[4];
uniform vec3 fvDims;
//VTK::Output::Dec
void main()
{
  vec2 tc = vec2(texCoord.x, 1.0 - texCoord.y);
  float alpha = texture(fvColor, tc).a;
  float depth = texture(fvDepth, tc).r;
  if (alpha <= 3.0 / 255.0)
  {
    discard;
  }
  gl_FragDepth = depth;
  if (fvWrite == 0)
  {
    gl_FragData[0] = vec4(fvPropColor, 1.0);
    return;
  }
  vec4 d = vec4(2.0 * texCoord - 1.0, 2.0 * depth - 1.0, 1.0);
  vec4 p = vec4(dot(fvToIndex[0], d), dot(fvToIndex[1], d), dot(fvToIndex[2], d),
    dot(fvToIndex[3], d));
  ivec3 n = ivec3(fvDims);
  ivec3 v = clamp(ivec3(floor(p.xyz / p.w + 0.5)), ivec3(0), n - 1);
  uint id = uint(v.x) + uint(n.x) * (uint(v.y) + uint(n.y) * uint(v.z)) + 1u;
  if (fvWrite == 2)
  {
    id = id >> 24;
  }
  gl_FragData[0] =
    vec4(float(id & 255u), float((id >> 8) & 255u), float((id >> 16) & 255u), 255.0) / 255.0;
}
)";
} // namespace

//------------------------------------------------------------------------------------------
vtkFerroVolumeOutput::vtkFerroVolumeOutput() = default;

vtkFerroVolumeOutput::~vtkFerroVolumeOutput()
{
  if (this->Path)
  {
    // The GL resources should have been released with their window; if not, their names
    // are forgotten (vtkTextureObject releases what it still owns).
    this->Path->ReleaseGraphicsResources(nullptr);
  }
}

const char* vtkFerroVolumeOutput::Name() const
{
  return this->Path ? this->Path->Name() : "none";
}

vtkTextureObject* vtkFerroVolumeOutput::ColorTexture() const
{
  return this->Path ? this->Path->ColorTexture() : nullptr;
}

vtkTextureObject* vtkFerroVolumeOutput::DepthTexture() const
{
  return this->Path ? this->Path->DepthTexture() : nullptr;
}

void vtkFerroVolumeOutput::UseReadback(ferrovol::Renderer& renderer)
{
  // The readback path needs nothing of the device: a refusal here changes nothing.
  (void)fv_renderer_set_output_path(renderer.get(), FV_OUTPUT_PATH_READBACK);
  this->Path.reset(new ReadbackOutput);
}

void vtkFerroVolumeOutput::Choose(int preference, ferrovol::Renderer& renderer,
  vtkOpenGLRenderWindow* win, vtkFerroVolumeReport& report)
{
  if (this->Path && this->Preference == preference && this->PathWindow == win)
  {
    return;
  }
  if (this->Path)
  {
    this->Path->ReleaseGraphicsResources(this->PathWindow == win ? win : nullptr);
    this->Path.reset();
  }
  this->Preference = preference;
  this->PathWindow = win;
#if FERROVOL_HAVE_SHARED_OUTPUT
  if (preference != vtkFerroVolumeEnums::OUTPUT_PATH_READBACK)
  {
    vtkFerroVolumeReport ignored;
    vtkFerroVolumeOutputChoice choice;
    this->Path = vtkFerroVolumeSharedOutput::Create(*vtkFerroVolumeContext::Acquire(ignored),
      renderer, preference == vtkFerroVolumeEnums::OUTPUT_PATH_SHARED, choice);
    this->PathReason = choice.Reason;
    if (!this->Path)
    {
      this->AnnounceReadback(choice.Reason, choice.Warn, report);
    }
  }
  else
  {
    this->PathReason = "OutputPath is readback";
  }
  if (!this->Path)
  {
    this->UseReadback(renderer);
  }
#else
  (void)report;
  (void)renderer;
  this->PathReason = "this build's ferrovol.h has no shared output path (readback only)";
  this->Path.reset(new ReadbackOutput);
#endif
}

#if FERROVOL_HAVE_SHARED_OUTPUT
void vtkFerroVolumeOutput::AnnounceReadback(
  const std::string& reason, bool warn, vtkFerroVolumeReport& report)
{
  if (warn)
  {
    report.WarnOnce(
      "readback: " + reason, "shared output unavailable, frames go through the CPU: " + reason);
    return;
  }
  static std::mutex mutex;
  static std::set<std::string> noted;
  const std::lock_guard<std::mutex> lock(mutex);
  if (noted.insert(reason).second)
  {
    vtkLog(INFO, "vtkFerroVolumeMapper: frames go through the CPU (readback): " << reason);
  }
}
#endif

bool vtkFerroVolumeOutput::Render(int preference, ferrovol::Renderer& renderer,
  const vtkFerroVolumeFrameRequest& req, vtkFerroVolumeReport& report, std::string& warning)
{
  this->Choose(preference, renderer, req.Window, report);
  if (this->Path->Render(renderer, req, report, warning))
  {
    return true;
  }
#if FERROVOL_HAVE_SHARED_OUTPUT
  if (std::strcmp(this->Path->Name(), "shared") == 0)
  {
    // Fall back to the readback path for good and try this frame again.
    report.Warn("shared output failed, frames go through the CPU from now on: " +
      report.GetError());
    this->Path->ReleaseGraphicsResources(req.Window);
    this->UseReadback(renderer);
    this->PathReason = "the shared output failed: " + report.GetError();
    report.ClearError();
    warning.clear();
    return this->Path->Render(renderer, req, report, warning);
  }
#endif
  return false;
}

vtkFerroVolumeOutput::Composited vtkFerroVolumeOutput::Composite(
  const vtkFerroVolumeFrameRequest& req, const int rect[4], vtkFerroVolumeReport& report)
{
  return this->DrawQuad(this->Quad, CompositeFragmentShader, req, rect, true, report,
    [&](vtkShaderProgram* program)
    {
      program->SetUniformf("fvColorScale", req.ColorScale);
      program->SetUniformf("fvColorBias", req.ColorBias);
    });
}

vtkFerroVolumeOutput::Composited vtkFerroVolumeOutput::Select(
  const vtkFerroVolumeFrameRequest& req, const int rect[4], const vtkFerroVolumeSelection& select,
  vtkFerroVolumeReport& report)
{
  return this->DrawQuad(this->SelectQuad, SelectFragmentShader, req, rect, false, report,
    [&](vtkShaderProgram* program)
    {
      program->SetUniformi("fvWrite", static_cast<int>(select.What));
      program->SetUniform3f("fvPropColor", select.PropColor);
      float rows[4][4];
      for (int i = 0; i < 4; ++i)
      {
        for (int j = 0; j < 4; ++j)
        {
          rows[i][j] = static_cast<float>(select.DeviceToIndex->GetElement(i, j));
        }
      }
      program->SetUniform4fv("fvToIndex", 4, rows);
      const float dims[3] = { static_cast<float>(select.Dims[0]),
        static_cast<float>(select.Dims[1]), static_cast<float>(select.Dims[2]) };
      program->SetUniform3f("fvDims", dims);
    });
}

template <typename Uniforms>
vtkFerroVolumeOutput::Composited vtkFerroVolumeOutput::DrawQuad(
  std::unique_ptr<vtkOpenGLQuadHelper>& quad, const char* shader,
  const vtkFerroVolumeFrameRequest& req, const int rect[4], bool blend,
  vtkFerroVolumeReport& report, Uniforms uniforms)
{
  vtkOpenGLRenderWindow* win = req.Window;
  if (this->QuadWindow != win)
  {
    this->Quad.reset();
    this->SelectQuad.reset();
    this->QuadWindow = win;
  }
  if (!quad)
  {
    quad.reset(new vtkOpenGLQuadHelper(win, nullptr, shader, ""));
  }
  if (!quad->Program)
  {
    report.Fail("could not compile the shader that composites the volume into OpenGL");
    quad.reset();
    return Composited::Failed;
  }
  win->GetShaderCache()->ReadyShaderProgram(quad->Program);
  if (rect[2] < 1 || rect[3] < 1)
  {
    return Composited::OffScreen;
  }
  vtkOpenGLState* ostate = win->GetState();
  vtkOpenGLState::ScopedglEnableDisable blendSaver(ostate, GL_BLEND);
  vtkOpenGLState::ScopedglEnableDisable depthTestSaver(ostate, GL_DEPTH_TEST);
  vtkOpenGLState::ScopedglBlendFuncSeparate blendFuncSaver(ostate);
  vtkOpenGLState::ScopedglDepthMask depthMaskSaver(ostate);
  vtkOpenGLState::ScopedglDepthFunc depthFuncSaver(ostate);
  vtkOpenGLState::ScopedglViewport viewportSaver(ostate);
  vtkOpenGLState::ScopedglEnableDisable cullSaver(ostate, GL_CULL_FACE);
  vtkOpenGLState::ScopedglEnableDisable scissorSaver(ostate, GL_SCISSOR_TEST);
  vtkOpenGLState::ScopedglScissor scissorBoxSaver(ostate);
  ostate->vtkglDisable(GL_CULL_FACE);
  ostate->vtkglViewport(req.ViewportX, req.ViewportY, req.ViewportW, req.ViewportH);
  ostate->vtkglEnable(GL_SCISSOR_TEST);
  ostate->vtkglScissor(req.ViewportX + rect[0], req.ViewportY + rect[1], rect[2], rect[3]);
  if (blend)
  {
    ostate->vtkglEnable(GL_BLEND);
    ostate->vtkglBlendFuncSeparate(GL_ONE, GL_ONE_MINUS_SRC_ALPHA, GL_ONE, GL_ONE_MINUS_SRC_ALPHA);
  }
  else
  {
    ostate->vtkglDisable(GL_BLEND);
  }
  // Rays already stopped at the opaque geometry: the volume's depth is written as is.
  ostate->vtkglEnable(GL_DEPTH_TEST);
  ostate->vtkglDepthFunc(GL_ALWAYS);
  ostate->vtkglDepthMask(GL_TRUE);
  vtkTextureObject* color = this->Path->ColorTexture();
  vtkTextureObject* depth = this->Path->DepthTexture();
  color->Activate();
  depth->Activate();
  quad->Program->SetUniformi("fvColor", color->GetTextureUnit());
  quad->Program->SetUniformi("fvDepth", depth->GetTextureUnit());
  uniforms(quad->Program);
  quad->Render();
  depth->Deactivate();
  color->Deactivate();
  vtkOpenGLCheckErrorMacro("after compositing the ferrovol frame");
  return Composited::Drawn;
}

void vtkFerroVolumeOutput::ProjectedRect(
  vtkRenderer* ren, vtkVolume* vol, double pad, int vw, int vh, int rect[4])
{
  rect[0] = 0;
  rect[1] = 0;
  rect[2] = vw;
  rect[3] = vh;
  double b[6];
  vol->GetBounds(b);
  for (int k = 0; k < 3; ++k)
  {
    b[2 * k] -= pad;
    b[2 * k + 1] += pad;
  }
  vtkMatrix4x4* m = ren->GetActiveCamera()->GetCompositeProjectionTransformMatrix(
    static_cast<double>(vw) / vh, -1, 1);
  double lo[2] = { 1e300, 1e300 }, hi[2] = { -1e300, -1e300 };
  for (int i = 0; i < 8; ++i)
  {
    const double p[4] = { b[i & 1], b[2 + ((i >> 1) & 1)], b[4 + ((i >> 2) & 1)], 1.0 };
    double c[4];
    m->MultiplyPoint(p, c);
    if (!(c[3] > 1e-12))
    {
      return;
    }
    for (int k = 0; k < 2; ++k)
    {
      lo[k] = std::min(lo[k], c[k] / c[3]);
      hi[k] = std::max(hi[k], c[k] / c[3]);
    }
  }
  const int size[2] = { vw, vh };
  int r[4];
  for (int k = 0; k < 2; ++k)
  {
    // NDC to pixels, one pixel of margin for rounding.
    const double a = std::floor((lo[k] + 1.0) * 0.5 * size[k]) - 1.0;
    const double z = std::ceil((hi[k] + 1.0) * 0.5 * size[k]) + 1.0;
    r[k] = static_cast<int>(std::max(0.0, std::min(a, static_cast<double>(size[k]))));
    r[k + 2] = static_cast<int>(std::max(0.0, std::min(z, static_cast<double>(size[k])))) - r[k];
  }
  std::copy(r, r + 4, rect);
}

void vtkFerroVolumeOutput::ReleaseGraphicsResources(vtkWindow* window)
{
  vtkOpenGLRenderWindow* glwin = vtkOpenGLRenderWindow::SafeDownCast(window);
  if ((this->Path || this->Quad || this->SelectQuad) && glwin && glwin == this->PathWindow)
  {
    // the GL names below belong to this window's context
    glwin->MakeCurrent();
  }
  else if (this->Path && window)
  {
    // another window (or none we drew into): forget our names rather than delete
    // whatever they mean in the current context
    window = nullptr;
  }
  if (this->Path)
  {
    this->Path->ReleaseGraphicsResources(window);
    this->Path.reset();
  }
  this->PathWindow = nullptr;
  this->Preference = -1;
  this->PathReason.clear();
  // The quad helper releases itself through the callback it registered with its window.
  this->Quad.reset();
  this->SelectQuad.reset();
  this->QuadWindow = nullptr;
}
