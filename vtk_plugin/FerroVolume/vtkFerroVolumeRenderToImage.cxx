#include "vtkFerroVolumeRenderToImage.h"

#include "vtkCamera.h"
#include "vtkDataArray.h"
#include "vtkFerroVolumeOutput.h"
#include "vtkFerroVolumeReport.h"
#include "vtkImageData.h"
#include "vtkMatrix4x4.h"
#include "vtkNew.h"
#include "vtkOpenGLError.h"
#include "vtkOpenGLFramebufferObject.h"
#include "vtkOpenGLQuadHelper.h"
#include "vtkOpenGLRenderWindow.h"
#include "vtkOpenGLShaderCache.h"
#include "vtkOpenGLState.h"
#include "vtkPixelBufferObject.h"
#include "vtkPointData.h"
#include "vtkRenderer.h"
#include "vtkShaderProgram.h"
#include "vtkTextureObject.h"
#include "vtkVolume.h"
#include "vtkFerroVolumeGL.h"

#include <cstring>

namespace
{
// The frame → the two image textures (drawn into one framebuffer, both as colour
// attachments), as vtkOpenGLGPUVolumeRayCastMapper fills its images: where the pixel's ray
// meets the volume's box ([0, 1]³ in fvClipToBox's coordinates; the ray runs from the near
// to the far plane), the frame's premultiplied colour after FinalColorWindow/Level and its
// depth (with fvClamp, where there is no visible sample, the depth where the ray enters the
// box); elsewhere the transparent white and the depth 1 VTK clears its images to.
const char* CaptureFragmentShader = R"(//VTK::System::Dec
in vec2 texCoord;
uniform sampler2D fvColor;
uniform sampler2D fvDepth;
uniform float fvColorScale;
uniform float fvColorBias;
uniform int fvClamp;
uniform mat4 fvBoxToClip;
uniform mat4 fvClipToBox;
//VTK::Output::Dec

// Whether the ray through this pixel meets the box, and the window depth where it enters.
bool entersBox(out float depth)
{
  depth = 1.0;
  vec2 ndc = texCoord * 2.0 - 1.0;
  vec4 n = fvClipToBox * vec4(ndc, -1.0, 1.0);
  vec4 f = fvClipToBox * vec4(ndc, 1.0, 1.0);
  vec3 p0 = n.xyz / n.w;
  vec3 d = f.xyz / f.w - p0;
  float t0 = 0.0;
  float t1 = 1.0;
  for (int a = 0; a < 3; ++a)
  {
    if (abs(d[a]) < 1e-12)
    {
      if (p0[a] < 0.0 || p0[a] > 1.0)
      {
        return false;
      }
    }
    else
    {
      float ta = -p0[a] / d[a];
      float tb = (1.0 - p0[a]) / d[a];
      t0 = max(t0, min(ta, tb));
      t1 = min(t1, max(ta, tb));
    }
  }
  if (t0 > t1)
  {
    return false;
  }
  vec4 c = fvBoxToClip * vec4(p0 + t0 * d, 1.0);
  depth = clamp(0.5 * c.z / c.w + 0.5, 0.0, 1.0);
  return true;
}

void main()
{
  // ferrovol's rows run top to bottom, the image's bottom to top
  vec2 tc = vec2(texCoord.x, 1.0 - texCoord.y);
  float entry;
  if (!entersBox(entry))
  {
    gl_FragData[0] = vec4(1.0, 1.0, 1.0, 0.0);
    gl_FragData[1] = vec4(1.0, 0.0, 0.0, 1.0);
    return;
  }
  vec4 color = texture(fvColor, tc);
  color.rgb = color.rgb * fvColorScale + fvColorBias * color.a;
  gl_FragData[0] = color;
  float depth = texture(fvDepth, tc).r;
  if (fvClamp != 0 && depth >= 1.0)
  {
    depth = entry;
  }
  gl_FragData[1] = vec4(depth, 0.0, 0.0, 1.0);
}
)";

// A vtkMatrix4x4 (VTK's row-major M·p) as a GLSL mat4 (column-major floats).
void ToGLSL(vtkMatrix4x4* m, float out[16])
{
  for (int r = 0; r < 4; ++r)
  {
    for (int c = 0; c < 4; ++c)
    {
      out[4 * c + r] = static_cast<float>(m->GetElement(r, c));
    }
  }
}

// A w × h texture of `comps` components of `vtkType` in `win`, allocated when missing or of
// another size or type.
void Allocate(vtkSmartPointer<vtkTextureObject>& tex, vtkOpenGLRenderWindow* win, int w, int h,
  int comps, int vtkType)
{
  if (tex && tex->GetContext() == win && static_cast<int>(tex->GetWidth()) == w &&
    static_cast<int>(tex->GetHeight()) == h && tex->GetVTKDataType() == vtkType)
  {
    return;
  }
  tex = vtkSmartPointer<vtkTextureObject>::New();
  tex->SetContext(win);
  tex->Create2D(static_cast<unsigned int>(w), static_cast<unsigned int>(h), comps, vtkType, false);
  vtkFerroVolumeSetSampling(tex, false);
}
} // namespace

//------------------------------------------------------------------------------------------
vtkFerroVolumeRenderToImage::vtkFerroVolumeRenderToImage() = default;

vtkFerroVolumeRenderToImage::~vtkFerroVolumeRenderToImage() = default;

bool vtkFerroVolumeRenderToImage::IsDepthType(int vtkType)
{
  return vtkType == VTK_UNSIGNED_CHAR || vtkType == VTK_UNSIGNED_SHORT || vtkType == VTK_FLOAT;
}

void vtkFerroVolumeRenderToImage::BoxToClip(
  vtkRenderer* ren, vtkVolume* vol, vtkImageData* input, vtkMatrix4x4* out)
{
  int extent[6];
  input->GetExtent(extent);
  vtkNew<vtkMatrix4x4> box; // [0, 1]³ → index coordinates
  for (int a = 0; a < 3; ++a)
  {
    const double lo = extent[2 * a] - (extent[2 * a] == extent[2 * a + 1] ? 0.5 : 0.0);
    const double hi = extent[2 * a + 1] + (extent[2 * a] == extent[2 * a + 1] ? 0.5 : 0.0);
    box->SetElement(a, a, hi - lo);
    box->SetElement(a, 3, lo);
  }
  vtkMatrix4x4* clip = ren->GetActiveCamera()->GetCompositeProjectionTransformMatrix(
    ren->GetTiledAspectRatio(), -1, 1);
  vtkNew<vtkMatrix4x4> dataToWorld;
  vol->GetModelToWorldMatrix(dataToWorld);
  vtkMatrix4x4::Multiply4x4(input->GetIndexToPhysicalMatrix(), box, out);
  vtkMatrix4x4::Multiply4x4(dataToWorld, out, out);
  vtkMatrix4x4::Multiply4x4(clip, out, out);
}

bool vtkFerroVolumeRenderToImage::Capture(const vtkFerroVolumeFrameRequest& req,
  vtkTextureObject* color, vtkTextureObject* depth, int depthType, vtkMatrix4x4* boxToClip,
  bool clampDepth, vtkFerroVolumeReport& report)
{
  vtkOpenGLRenderWindow* win = req.Window;
  if (this->Window != win)
  {
    this->ReleaseGraphicsResources();
    this->Window = win;
  }
  Allocate(this->Color, win, req.RenderW, req.RenderH, 4, VTK_UNSIGNED_CHAR);
  Allocate(this->Depth, win, req.RenderW, req.RenderH, 1, depthType);
  if (!this->Fbo)
  {
    this->Fbo = vtkSmartPointer<vtkOpenGLFramebufferObject>::New();
    this->Fbo->SetContext(win);
  }
  if (!this->Quad)
  {
    this->Quad.reset(new vtkOpenGLQuadHelper(win, nullptr, CaptureFragmentShader, ""));
  }
  if (!this->Quad->Program)
  {
    report.Fail("could not compile the shader that writes the RenderToImage images");
    this->Quad.reset();
    return false;
  }
  win->GetShaderCache()->ReadyShaderProgram(this->Quad->Program);
  vtkShaderProgram* program = this->Quad->Program;
  float boxMatrix[16];
  float clipMatrix[16];
  vtkNew<vtkMatrix4x4> inverse;
  vtkMatrix4x4::Invert(boxToClip, inverse);
  ToGLSL(boxToClip, boxMatrix);
  ToGLSL(inverse, clipMatrix);

  vtkOpenGLState* ostate = win->GetState();
  vtkOpenGLState::ScopedglViewport viewportSaver(ostate);
  vtkOpenGLState::ScopedglEnableDisable blendSaver(ostate, GL_BLEND);
  vtkOpenGLState::ScopedglEnableDisable depthSaver(ostate, GL_DEPTH_TEST);
  vtkOpenGLState::ScopedglEnableDisable scissorSaver(ostate, GL_SCISSOR_TEST);
  vtkOpenGLState::ScopedglEnableDisable cullSaver(ostate, GL_CULL_FACE);
  vtkOpenGLState::ScopedglColorMask colorMaskSaver(ostate);
  ostate->vtkglDisable(GL_BLEND);
  ostate->vtkglDisable(GL_DEPTH_TEST);
  ostate->vtkglDisable(GL_SCISSOR_TEST);
  ostate->vtkglDisable(GL_CULL_FACE);
  ostate->vtkglColorMask(GL_TRUE, GL_TRUE, GL_TRUE, GL_TRUE);
  ostate->PushFramebufferBindings();
  this->Fbo->Bind(GL_FRAMEBUFFER);
  this->Fbo->AddColorAttachment(0U, this->Color);
  this->Fbo->AddColorAttachment(1U, this->Depth);
  this->Fbo->ActivateDrawBuffers(2);
  const bool complete = this->Fbo->CheckFrameBufferStatus(GL_FRAMEBUFFER) != 0;
  if (complete)
  {
    ostate->vtkglViewport(0, 0, req.RenderW, req.RenderH);
    color->Activate();
    depth->Activate();
    program->SetUniformi("fvColor", color->GetTextureUnit());
    program->SetUniformi("fvDepth", depth->GetTextureUnit());
    program->SetUniformf("fvColorScale", req.ColorScale);
    program->SetUniformf("fvColorBias", req.ColorBias);
    program->SetUniformi("fvClamp", clampDepth ? 1 : 0);
    program->SetUniformMatrix4x4("fvBoxToClip", boxMatrix);
    program->SetUniformMatrix4x4("fvClipToBox", clipMatrix);
    this->Quad->Render();
    depth->Deactivate();
    color->Deactivate();
  }
  this->Fbo->RemoveColorAttachment(0U);
  this->Fbo->RemoveColorAttachment(1U);
  this->Fbo->DeactivateDrawBuffers();
  ostate->PopFramebufferBindings();
  vtkOpenGLCheckErrorMacro("after writing the RenderToImage images");
  if (!complete)
  {
    return report.Fail("the RenderToImage images cannot be drawn into (incomplete framebuffer)");
  }
  return true;
}

vtkTextureObject* vtkFerroVolumeRenderToImage::ColorTexture() const
{
  return this->Color;
}

vtkTextureObject* vtkFerroVolumeRenderToImage::DepthTexture() const
{
  return this->Depth;
}

void vtkFerroVolumeRenderToImage::ToImage(vtkTextureObject* texture, vtkImageData* image)
{
  if (!texture || !image)
  {
    return;
  }
  texture->GetContext()->MakeCurrent();
  const int w = static_cast<int>(texture->GetWidth());
  const int h = static_cast<int>(texture->GetHeight());
  const int comps = texture->GetComponents();
  const int type = texture->GetVTKDataType();
  image->Initialize();
  image->SetOrigin(0.0, 0.0, 0.0);
  image->SetSpacing(1.0, 1.0, 1.0);
  image->SetExtent(0, w - 1, 0, h - 1, 0, 0);
  image->AllocateScalars(type, comps);
  vtkPixelBufferObject* pbo = texture->Download();
  if (!pbo)
  {
    return;
  }
  // the download is packed: rows of w · comps values, bottom to top, as the image's
  const size_t bytes = static_cast<size_t>(w) * h * comps *
    static_cast<size_t>(image->GetPointData()->GetScalars()->GetDataTypeSize());
  if (const void* data = pbo->MapPackedBuffer())
  {
    std::memcpy(image->GetScalarPointer(), data, bytes);
    pbo->UnmapPackedBuffer();
  }
  pbo->Delete();
}

void vtkFerroVolumeRenderToImage::ReleaseGraphicsResources()
{
  // Each GL object frees its names in its own window's context through the callback it
  // registered with the window (or did when the window went away).
  this->Color = nullptr;
  this->Depth = nullptr;
  this->Fbo = nullptr;
  this->Quad.reset();
  this->Window = nullptr;
}
