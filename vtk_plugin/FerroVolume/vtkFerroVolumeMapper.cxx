// vtkFerroVolumeMapper: a vtkVolumeMapper that ray casts with ferrovol (C ABI, ffi/include/
// ferrovol.h) and composites the frame into VTK's OpenGL framebuffer.
//
// One frame (Render):
//   input    → fv volume        only when the scalars (array, MTime, geometry) changed
//   property → fv transfer fn   only when the property (or its functions) or ranges changed
//   mapper, property, volume matrix, camera, lights → fv params/camera/lights (every frame,
//                                 no upload)
//   VTK's depth buffer (this viewport) → fv depth input; fv_renderer_render
//   frame → GL textures (FrameOutput) → one full-screen quad, premultiplied blending,
//            gl_FragDepth from ferrovol's depth
#include "vtkFerroVolumeMapper.h"

#include "vtkBitArray.h"
#include "vtkCamera.h"
#include "vtkCellData.h"
#include "vtkColorTransferFunction.h"
#include "vtkContourValues.h"
#include "vtkDataArray.h"
#include "vtkImageData.h"
#include "vtkLight.h"
#include "vtkLightCollection.h"
#include "vtkMath.h"
#include "vtkMatrix3x3.h"
#include "vtkMatrix4x4.h"
#include "vtkNew.h"
#include "vtkObjectFactory.h"
#include "vtkOpenGLCamera.h"
#include "vtkOpenGLError.h"
#include "vtkOpenGLQuadHelper.h"
#include "vtkOpenGLRenderWindow.h"
#include "vtkOpenGLShaderCache.h"
#include "vtkOpenGLState.h"
#include "vtkPiecewiseFunction.h"
#include "vtkPlane.h"
#include "vtkPlaneCollection.h"
#include "vtkPointData.h"
#include "vtkRenderWindow.h"
#include "vtkRenderer.h"
#include "vtkShaderProgram.h"
#include "vtkSmartPointer.h"
#include "vtkTextureObject.h"
#include "vtkTimerLog.h"
#include "vtkVolume.h"
#include "vtkVolumeProperty.h"
#include "vtkWeakPointer.h"
#include "vtk_glew.h"

#include "ferrovol.h"

#include <algorithm>
#include <array>
#include <cfloat>
#include <cmath>
#include <cstring>
#include <limits>
#include <memory>
#include <mutex>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include <unistd.h> // close

vtkStandardNewMacro(vtkFerroVolumeMapper);

namespace
{
// Entries of ferrovol's lookup tables (core/src/transfer.rs TABLE_SIZE). Colour and opacity
// are sampled with VTK's own GetTable at exactly these positions over the range VTK's GPU
// mapper uses, so ferrovol's tables equal VTK's (midpoints and sharpness included).
constexpr int TableSize = 1024;

//------------------------------------------------------------------------------------------
// The process-wide ferrovol context (a GPU device). Created on first use and kept for the
// life of the process: renderers created from it keep the device alive, and tearing a
// Vulkan device down from static destructors at exit is fragile.
struct SharedContext
{
  std::mutex Mutex;
  FvContext* Context = nullptr;
  bool Tried = false;
  std::string Error;
  std::string Description;

  static SharedContext& Get()
  {
    static SharedContext instance;
    return instance;
  }

  FvContext* Acquire(std::string& error)
  {
    std::lock_guard<std::mutex> lock(this->Mutex);
    if (!this->Tried)
    {
      this->Tried = true;
      FvContext* ctx = nullptr;
      FvStatus st = fv_context_new(&ctx);
      if (st != FV_STATUS_OK)
      {
        this->Error = std::string("no GPU device for ferrovol (") + fv_status_name(st) +
          "): " + fv_last_error() +
          ". Install Mesa's Vulkan drivers (mesa-vulkan-drivers) or check FERROVOL_ADAPTER / "
          "FERROVOL_BACKEND.";
      }
      else
      {
        this->Context = ctx;
        FvAdapterInfo info;
        if (fv_context_info(ctx, &info) == FV_STATUS_OK)
        {
          this->Description =
            std::string(info.name) + " (" + info.backend + ", " + info.driver + ")";
        }
      }
    }
    error = this->Error;
    return this->Context;
  }
};

std::string FvError(const char* what, FvStatus st)
{
  std::ostringstream s;
  s << "ferrovol could not " << what << " (" << fv_status_name(st) << "): " << fv_last_error();
  return s.str();
}

//------------------------------------------------------------------------------------------
// Scalar types

bool ToFvScalarType(int vtkType, uint32_t& fvType, size_t& size)
{
  switch (vtkType)
  {
    case VTK_CHAR:
      fvType = std::numeric_limits<char>::is_signed ? FV_SCALAR_TYPE_I8 : FV_SCALAR_TYPE_U8;
      size = 1;
      return true;
    case VTK_SIGNED_CHAR:
      fvType = FV_SCALAR_TYPE_I8;
      size = 1;
      return true;
    case VTK_UNSIGNED_CHAR:
    case VTK_BIT: // converted to one byte per value first
      fvType = FV_SCALAR_TYPE_U8;
      size = 1;
      return true;
    case VTK_SHORT:
      fvType = FV_SCALAR_TYPE_I16;
      size = 2;
      return true;
    case VTK_UNSIGNED_SHORT:
      fvType = FV_SCALAR_TYPE_U16;
      size = 2;
      return true;
    case VTK_INT:
      fvType = FV_SCALAR_TYPE_I32;
      size = 4;
      return true;
    case VTK_UNSIGNED_INT:
      fvType = FV_SCALAR_TYPE_U32;
      size = 4;
      return true;
    case VTK_LONG:
      fvType = sizeof(long) == 8 ? FV_SCALAR_TYPE_I64 : FV_SCALAR_TYPE_I32;
      size = sizeof(long);
      return true;
    case VTK_UNSIGNED_LONG:
      fvType = sizeof(unsigned long) == 8 ? FV_SCALAR_TYPE_U64 : FV_SCALAR_TYPE_U32;
      size = sizeof(unsigned long);
      return true;
    case VTK_LONG_LONG:
      fvType = FV_SCALAR_TYPE_I64;
      size = 8;
      return true;
    case VTK_UNSIGNED_LONG_LONG:
      fvType = FV_SCALAR_TYPE_U64;
      size = 8;
      return true;
    case VTK_ID_TYPE:
      fvType = sizeof(vtkIdType) == 8 ? FV_SCALAR_TYPE_I64 : FV_SCALAR_TYPE_I32;
      size = sizeof(vtkIdType);
      return true;
    case VTK_FLOAT:
      fvType = FV_SCALAR_TYPE_F32;
      size = 4;
      return true;
    case VTK_DOUBLE:
      fvType = FV_SCALAR_TYPE_F64;
      size = 8;
      return true;
    default:
      return false;
  }
}

// vtkMatrix4x4 (row-major, VTK's M·p) → column-major (OpenGL order), as ferrovol takes them.
void ToColumnMajor(vtkMatrix4x4* m, double out[16])
{
  for (int r = 0; r < 4; ++r)
  {
    for (int c = 0; c < 4; ++c)
    {
      out[4 * c + r] = m->GetElement(r, c);
    }
  }
}

//------------------------------------------------------------------------------------------
// What the uploaded volume was made from: anything here changing means a new upload.
struct VolumeKey
{
  vtkDataObject* Input = nullptr;
  vtkMTimeType InputMTime = 0;
  vtkDataArray* Scalars = nullptr;
  vtkMTimeType ScalarsMTime = 0;
  int CellFlag = -1;
  int Dims[3] = { 0, 0, 0 };
  int DataType = -1;
  int Components = 0;

  bool operator==(const VolumeKey& o) const
  {
    return this->Input == o.Input && this->InputMTime == o.InputMTime &&
      this->Scalars == o.Scalars && this->ScalarsMTime == o.ScalarsMTime &&
      this->CellFlag == o.CellFlag && this->Dims[0] == o.Dims[0] && this->Dims[1] == o.Dims[1] &&
      this->Dims[2] == o.Dims[2] && this->DataType == o.DataType &&
      this->Components == o.Components;
  }
};

// What the uploaded tables were made from.
struct TableKey
{
  vtkVolumeProperty* Property = nullptr;
  vtkMTimeType PropertyMTime = 0;
  int Components = 0;
  std::array<std::array<double, 2>, 4> Ranges{};
  double GradientScale = 0.0;

  bool operator==(const TableKey& o) const
  {
    return this->Property == o.Property && this->PropertyMTime == o.PropertyMTime &&
      this->Components == o.Components && this->Ranges == o.Ranges &&
      this->GradientScale == o.GradientScale;
  }
};

//------------------------------------------------------------------------------------------
// Reads the window depth (0 near … 1 far) of a rectangle of the framebuffer VTK is drawing
// into. A multisampled framebuffer (VTK's default render framebuffer has 8 samples) is first
// resolved into a single-sample depth renderbuffer of the same format.
class DepthReader
{
public:
  ~DepthReader() { this->ReleaseGraphicsResources(); }

  // `out` receives w·h floats, rows bottom to top (OpenGL order).
  bool Read(vtkOpenGLRenderWindow* win, int x, int y, int w, int h, std::vector<float>& out,
    std::string& error)
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
      GLenum format = this->DepthFormat(readFbo);
      if (format == GL_NONE)
      {
        error = "the framebuffer's depth attachment has an unknown format";
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
      error = s.str();
      ok = false;
    }
    if (!ok)
    {
      std::fill(out.begin(), out.end(), 1.0f);
    }
    return ok;
  }

  void ReleaseGraphicsResources()
  {
    // Only called with the window's context current (ReleaseGraphicsResources), or never
    // allocated.
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

  // Forget GL names without deleting them (their context is gone).
  void Forget()
  {
    this->Fbo = this->Rbo = 0;
    this->Width = this->Height = 0;
    this->Format = GL_NONE;
  }

  // The internal format of the depth buffer of framebuffer `fbo` (bound for reading).
  GLenum DepthFormatOf(GLint fbo) { return this->DepthFormat(fbo); }

private:
  GLenum DepthFormat(GLint fbo)
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

  void Prepare(GLenum format, int w, int h)
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

  GLuint Fbo = 0;
  GLuint Rbo = 0;
  GLenum Format = GL_NONE;
  int Width = 0;
  int Height = 0;
};

//------------------------------------------------------------------------------------------
// One frame request: the viewport in the framebuffer and the size ferrovol renders at.
struct FrameRequest
{
  vtkOpenGLRenderWindow* Window;
  int ViewportX, ViewportY, ViewportW, ViewportH;
  int RenderW, RenderH;
  // Whether opaque geometry may be in VTK's depth buffer; without any, the buffer holds only
  // its clear value and the frame is rendered without a depth input (no copy pass).
  bool UseDepth;
};

// How ferrovol's frames reach OpenGL. Each path takes VTK's opaque depth for the viewport,
// renders, and leaves the frame in two textures the compositor samples: premultiplied RGBA
// and window depth, rows top to bottom.
//
// ReadbackOutput copies through the CPU (depth in with glReadPixels, frame out with
// fv_renderer_read_frame + glTexImage2D). SharedOutput (when ferrovol.h has the shared
// output path) imports ferrovol's images with GL_EXT_memory_object_fd: no copy at all.
class FrameOutput
{
public:
  virtual ~FrameOutput() = default;
  virtual const char* Name() const = 0;
  virtual bool Render(FvRenderer* renderer, const FrameRequest& req, std::string& error,
    std::string& warning) = 0;
  virtual vtkTextureObject* ColorTexture() = 0;
  virtual vtkTextureObject* DepthTexture() = 0;
  virtual void ReleaseGraphicsResources(vtkWindow* window) = 0;
};

// The viewport pixel whose depth a rendered pixel takes when ferrovol renders at a reduced
// size (ImageSampleDistance): the one under the rendered pixel's centre, in integers so that
// the CPU (readback) and the GPU (shared path) pick the same one.
inline int SourcePixel(int i, int renderSize, int viewportSize)
{
  return ((2 * i + 1) * viewportSize) / (2 * renderSize);
}

class ReadbackOutput : public FrameOutput
{
public:
  const char* Name() const override { return "readback"; }

  bool Render(FvRenderer* renderer, const FrameRequest& req, std::string& error,
    std::string& warning) override
  {
    // VTK's depth for the viewport (rows bottom to top), sampled at the centres of the
    // pixels ferrovol renders (rows top to bottom), picking texels as OpenGL's nearest
    // filtering does (the shared path samples the same depth on the GPU).
    std::string depthError;
    const int rw = req.RenderW, rh = req.RenderH, vw = req.ViewportW, vh = req.ViewportH;
    const bool haveDepth = req.UseDepth &&
      this->Depth.Read(req.Window, req.ViewportX, req.ViewportY, req.ViewportW, req.ViewportH,
        this->WindowDepth, depthError);
    if (req.UseDepth && !haveDepth)
    {
      warning = "the volume ignores opaque geometry in this frame: " + depthError;
    }
    this->DepthInput.resize(haveDepth ? static_cast<size_t>(rw) * rh : 0);
    for (int y = 0; haveDepth && y < rh; ++y)
    {
      const float* src =
        this->WindowDepth.data() + static_cast<size_t>(vh - 1 - SourcePixel(y, rh, vh)) * vw;
      float* dst = this->DepthInput.data() + static_cast<size_t>(y) * rw;
      if (rw == vw)
      {
        std::memcpy(dst, src, sizeof(float) * vw);
      }
      else
      {
        for (int x = 0; x < rw; ++x)
        {
          dst[x] = src[SourcePixel(x, rw, vw)];
        }
      }
    }

    FvStatus st = fv_renderer_render(renderer, rw, rh,
      haveDepth ? this->DepthInput.data() : nullptr, this->DepthInput.size());
    if (st != FV_STATUS_OK)
    {
      error = FvError("render the frame", st);
      return false;
    }
    FvFrame* frame = nullptr;
    st = fv_renderer_read_frame(renderer, &frame);
    if (st != FV_STATUS_OK)
    {
      error = FvError("read the frame back", st);
      return false;
    }
    uint32_t fw = 0, fh = 0;
    fv_frame_size(frame, &fw, &fh);
    const uint8_t* rgba = fv_frame_rgba(frame);
    const float* depth = fv_frame_depth(frame);
    bool ok = fw == static_cast<uint32_t>(rw) && fh == static_cast<uint32_t>(rh) && rgba && depth;
    if (!ok)
    {
      error = "ferrovol returned a frame of an unexpected size";
    }
    else
    {
      ok = this->Upload(req.Window, rw, rh, rgba, depth, error);
    }
    fv_frame_free(frame);
    return ok;
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
    std::string& error)
  {
    if (!this->Color)
    {
      this->Color = vtkSmartPointer<vtkTextureObject>::New();
      this->DepthTex = vtkSmartPointer<vtkTextureObject>::New();
    }
    this->Color->SetContext(win);
    this->DepthTex->SetContext(win);
    // The colour is scaled up linearly when ImageSampleDistance > 1; depth is not filtered.
    this->Color->SetMinificationFilter(vtkTextureObject::Linear);
    this->Color->SetMagnificationFilter(vtkTextureObject::Linear);
    this->DepthTex->SetMinificationFilter(vtkTextureObject::Nearest);
    this->DepthTex->SetMagnificationFilter(vtkTextureObject::Nearest);
    for (vtkTextureObject* t : { this->Color.Get(), this->DepthTex.Get() })
    {
      t->SetWrapS(vtkTextureObject::ClampToEdge);
      t->SetWrapT(vtkTextureObject::ClampToEdge);
    }
    if (!this->Color->Create2DFromRaw(w, h, 4, VTK_UNSIGNED_CHAR,
          const_cast<void*>(static_cast<const void*>(rgba))) ||
      !this->DepthTex->Create2DFromRaw(
        w, h, 1, VTK_FLOAT, const_cast<void*>(static_cast<const void*>(depth))))
    {
      error = "could not upload the frame into OpenGL textures";
      return false;
    }
    return true;
  }

  DepthReader Depth;
  std::vector<float> WindowDepth;
  std::vector<float> DepthInput;
  vtkSmartPointer<vtkTextureObject> Color;
  vtkSmartPointer<vtkTextureObject> DepthTex;
};

#if FERROVOL_HAVE_SHARED_OUTPUT
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

// Zero copy: ferrovol renders into Vulkan memory that OpenGL imports
// (fv_renderer_shared_image → glImportMemoryFdEXT → glTexStorageMem2DEXT). VTK's depth goes
// into ferrovol's DEPTH_INPUT image on the GPU (blit + one full-screen pass). No semaphores
// (llvmpipe has no GL_EXT_semaphore_fd): glFinish before ferrovol reads what GL wrote, and
// fv_renderer_finish before GL samples what ferrovol wrote.
class SharedOutput : public FrameOutput
{
public:
  // A shared output for this renderer, or nullptr with the reason (the window's OpenGL
  // context is current).
  static std::unique_ptr<SharedOutput> Create(
    FvContext* ctx, FvRenderer* renderer, bool anyDevice, std::string& reason)
  {
    FvAdapterInfo info;
    if (fv_context_info(ctx, &info) != FV_STATUS_OK)
    {
      reason = std::string("no adapter information: ") + fv_last_error();
      return nullptr;
    }
    if (!anyDevice && !info.is_cpu)
    {
      reason = std::string("memory is shared automatically only with a CPU device (lavapipe); ") +
        info.name + " is not one: SetOutputPathToShared() to share anyway";
      return nullptr;
    }
    if (!GLEW_EXT_memory_object_fd)
    {
      reason = "this OpenGL context has no GL_EXT_memory_object_fd";
      return nullptr;
    }
    if (!fv_context_can_share(ctx))
    {
      reason = std::string("the device cannot export memory: ") + fv_last_error();
      return nullptr;
    }
    uint8_t device[16], driver[16];
    FvStatus st = fv_context_uuids(ctx, &device, &driver);
    if (st != FV_STATUS_OK)
    {
      reason = FvError("tell its device UUIDs", st);
      return nullptr;
    }
    vtkOpenGLClearErrorMacro();
    GLubyte glDriver[16] = { 0 };
    glGetUnsignedBytevEXT(GL_DRIVER_UUID_EXT, glDriver);
    GLint devices = 0;
    glGetIntegerv(GL_NUM_DEVICE_UUIDS_EXT, &devices);
    bool sameDevice = false;
    for (GLint i = 0; i < devices && !sameDevice; ++i)
    {
      GLubyte glDevice[16] = { 0 };
      glGetUnsignedBytei_vEXT(GL_DEVICE_UUID_EXT, i, glDevice);
      sameDevice = std::memcmp(glDevice, device, 16) == 0;
    }
    if (glGetError() != GL_NO_ERROR || !sameDevice || std::memcmp(glDriver, driver, 16) != 0)
    {
      reason = "OpenGL runs on another device or driver than ferrovol (device/driver UUIDs "
               "differ)";
      return nullptr;
    }
    st = fv_renderer_set_output_path(renderer, FV_OUTPUT_PATH_SHARED);
    if (st != FV_STATUS_OK)
    {
      reason = FvError("share its output", st);
      return nullptr;
    }
    std::unique_ptr<SharedOutput> out(new SharedOutput);
    reason = std::string("zero copy: ") + info.name + " (Vulkan) and OpenGL share the frame";
    return out;
  }

  ~SharedOutput() override { this->Forget(); }

  const char* Name() const override { return "shared"; }

  bool Render(FvRenderer* renderer, const FrameRequest& req, std::string& error,
    std::string& warning) override
  {
    vtkOpenGLRenderWindow* win = req.Window;
    // OpenGL must be done with the images of the last frame before ferrovol overwrites them.
    glFinish();
    FvStatus st = fv_renderer_prepare_targets(renderer, req.RenderW, req.RenderH);
    if (st != FV_STATUS_OK)
    {
      error = FvError("allocate the shared images", st);
      return false;
    }
    // A (re)allocation submits a clear of the new images without waiting for it: wait, or
    // it may land after OpenGL wrote the depth input below (zero depth, an empty frame;
    // seen ~5% of first frames under load). Nothing else is in flight here, so this costs
    // nothing otherwise.
    st = fv_renderer_finish(renderer);
    if (st != FV_STATUS_OK)
    {
      error = FvError("finish allocating the shared images", st);
      return false;
    }
    if (!this->Import(renderer, win, error))
    {
      return false;
    }
    if (!req.UseDepth)
    {
      st = fv_renderer_render(renderer, req.RenderW, req.RenderH, nullptr, 0);
    }
    else
    {
      if (!this->WriteDepthInput(req, error))
      {
        warning = "the volume ignores opaque geometry in this frame: " + error;
        error.clear();
        this->ClearDepthInput(req);
      }
      glFinish(); // ferrovol reads the depth input next
      st = fv_renderer_render_with_shared_depth(renderer, req.RenderW, req.RenderH);
    }
    if (st != FV_STATUS_OK)
    {
      error = FvError("render the frame", st);
      return false;
    }
    st = fv_renderer_finish(renderer);
    if (st != FV_STATUS_OK)
    {
      error = FvError("finish the frame", st);
      return false;
    }
    return true;
  }

  vtkTextureObject* ColorTexture() override { return this->Images[FV_TARGET_COLOR].Object; }
  vtkTextureObject* DepthTexture() override { return this->Images[FV_TARGET_DEPTH].Object; }

  void ReleaseGraphicsResources(vtkWindow* window) override
  {
    if (!window)
    {
      this->Forget();
      return;
    }
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

private:
  struct Imported
  {
    GLuint Memory = 0;
    GLuint Texture = 0;
    vtkSmartPointer<vtkTextureObject> Object;
  };

  SharedOutput() = default;

  // Imports the three images again whenever ferrovol reallocated them.
  bool Import(FvRenderer* renderer, vtkOpenGLRenderWindow* win, std::string& error)
  {
    FvSharedImage img[3];
    int got = 0;
    for (; got < 3; ++got)
    {
      FvStatus st = fv_renderer_shared_image(renderer, static_cast<uint32_t>(got), &img[got]);
      if (st != FV_STATUS_OK)
      {
        error = FvError("export a shared image", st);
        break;
      }
    }
    if (got < 3 || (this->Images[0].Texture && img[0].generation == this->Generation))
    {
      for (int i = 0; i < got; ++i)
      {
        close(img[i].fd);
      }
      return got == 3;
    }
    this->DeleteImports();
    vtkOpenGLClearErrorMacro();
    GLint oldTex = 0;
    glGetIntegerv(GL_TEXTURE_BINDING_2D, &oldTex);
    bool ok = true;
    for (int i = 0; i < 3; ++i)
    {
      Imported& im = this->Images[i];
      if (!ok)
      {
        close(img[i].fd);
        continue;
      }
      glCreateMemoryObjectsEXT(1, &im.Memory);
      if (img[i].dedicated)
      {
        GLint yes = GL_TRUE;
        glMemoryObjectParameterivEXT(im.Memory, GL_DEDICATED_MEMORY_OBJECT_EXT, &yes);
      }
      glImportMemoryFdEXT(im.Memory, img[i].size, GL_HANDLE_TYPE_OPAQUE_FD_EXT, img[i].fd);
      if (glGetError() != GL_NO_ERROR)
      {
        close(img[i].fd); // not taken over
        error = "OpenGL could not import ferrovol's shared memory (glImportMemoryFdEXT)";
        ok = false;
        continue;
      }
      glGenTextures(1, &im.Texture);
      glBindTexture(GL_TEXTURE_2D, im.Texture);
      glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_TILING_EXT, GL_OPTIMAL_TILING_EXT);
      glTexStorageMem2DEXT(GL_TEXTURE_2D, 1, img[i].gl_internal_format,
        static_cast<GLsizei>(img[i].width), static_cast<GLsizei>(img[i].height), im.Memory, 0);
      if (glGetError() != GL_NO_ERROR)
      {
        error = "OpenGL could not make a texture of ferrovol's shared memory "
                "(glTexStorageMem2DEXT)";
        ok = false;
        continue;
      }
      im.Object = vtkSmartPointer<vtkTextureObject>::New();
      im.Object->SetContext(win);
      im.Object->AssignToExistingTexture(im.Texture, GL_TEXTURE_2D);
      const int filter = i == FV_TARGET_COLOR ? vtkTextureObject::Linear : vtkTextureObject::Nearest;
      im.Object->SetMinificationFilter(filter);
      im.Object->SetMagnificationFilter(filter);
      im.Object->SetWrapS(vtkTextureObject::ClampToEdge);
      im.Object->SetWrapT(vtkTextureObject::ClampToEdge);
    }
    glBindTexture(GL_TEXTURE_2D, static_cast<GLuint>(oldTex));
    if (!ok)
    {
      this->DeleteImports();
      return false;
    }
    this->Generation = img[0].generation;
    this->InputW = static_cast<int>(img[FV_TARGET_DEPTH_INPUT].width);
    this->InputH = static_cast<int>(img[FV_TARGET_DEPTH_INPUT].height);
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
      error = "ferrovol's shared depth input image cannot be drawn into";
      this->DeleteImports();
      return false;
    }
    return true;
  }

  // VTK's depth (the viewport of the framebuffer being drawn) → CopyTex (a blit, which also
  // resolves multisampling) → the depth input image (one pass, scaled to the render size).
  bool WriteDepthInput(const FrameRequest& req, std::string& error)
  {
    vtkOpenGLRenderWindow* win = req.Window;
    vtkOpenGLState* ostate = win->GetState();
    vtkOpenGLClearErrorMacro();
    GLint readFbo = 0, drawFbo = 0;
    glGetIntegerv(GL_READ_FRAMEBUFFER_BINDING, &readFbo);
    glGetIntegerv(GL_DRAW_FRAMEBUFFER_BINDING, &drawFbo);
    const GLenum format = this->Depth.DepthFormatOf(readFbo);
    if (format == GL_NONE)
    {
      error = "the framebuffer's depth attachment has an unknown format";
      return false;
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
      const bool stencil = format == GL_DEPTH24_STENCIL8 || format == GL_DEPTH32F_STENCIL8;
      glFramebufferTexture2D(GL_DRAW_FRAMEBUFFER,
        stencil ? GL_DEPTH_STENCIL_ATTACHMENT : GL_DEPTH_ATTACHMENT, GL_TEXTURE_2D,
        this->CopyTex, 0);
      glDrawBuffer(GL_NONE);
      glBindFramebuffer(GL_DRAW_FRAMEBUFFER, static_cast<GLuint>(drawFbo));
      this->CopyFormat = format;
      this->CopyW = vw;
      this->CopyH = vh;
      this->CopyObject = vtkSmartPointer<vtkTextureObject>::New();
      this->CopyObject->SetContext(win);
      this->CopyObject->AssignToExistingTexture(this->CopyTex, GL_TEXTURE_2D);
      this->CopyObject->SetMinificationFilter(vtkTextureObject::Nearest);
      this->CopyObject->SetMagnificationFilter(vtkTextureObject::Nearest);
      this->CopyObject->SetWrapS(vtkTextureObject::ClampToEdge);
      this->CopyObject->SetWrapT(vtkTextureObject::ClampToEdge);
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
      error = "copying the depth buffer failed";
      return false;
    }

    if (!this->Quad)
    {
      this->Quad.reset(new vtkOpenGLQuadHelper(win, nullptr, DepthInputFragmentShader, ""));
    }
    if (!this->Quad->Program)
    {
      error = "could not compile the depth copy shader";
      return false;
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
      error = "writing ferrovol's depth input failed";
      return false;
    }
    return true;
  }

  // No opaque depth: the depth input becomes 1 (far) everywhere.
  void ClearDepthInput(const FrameRequest&)
  {
    GLint drawFbo = 0;
    glGetIntegerv(GL_DRAW_FRAMEBUFFER_BINDING, &drawFbo);
    glBindFramebuffer(GL_DRAW_FRAMEBUFFER, this->InputFbo);
    const GLfloat far[4] = { 1.0f, 1.0f, 1.0f, 1.0f };
    glClearBufferfv(GL_COLOR, 0, far);
    glBindFramebuffer(GL_DRAW_FRAMEBUFFER, static_cast<GLuint>(drawFbo));
  }

  void DeleteImports()
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
  void Forget()
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
    this->Depth.Forget();
  }

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
  DepthReader Depth;
};
#endif

// Draws the frame over the viewport: premultiplied colour, depth from the volume.
const char* CompositeFragmentShader = R"(//VTK::System::Dec
in vec2 texCoord;
uniform sampler2D fvColor;
uniform sampler2D fvDepth;
//VTK::Output::Dec
void main()
{
  // ferrovol's rows run top to bottom, OpenGL's bottom to top
  vec2 tc = vec2(texCoord.x, 1.0 - texCoord.y);
  vec4 color = texture(fvColor, tc);
  if (color.a <= 0.0)
  {
    discard;
  }
  gl_FragData[0] = color;
  gl_FragDepth = texture(fvDepth, tc).r;
}
)";

} // namespace

//------------------------------------------------------------------------------------------
class vtkFerroVolumeMapper::vtkInternals
{
public:
  FvRenderer* Renderer = nullptr;

  bool HaveVolume = false;
  VolumeKey Volume;
  int Components = 0;
  std::array<std::array<double, 2>, 4> Ranges{};
  double MeanSpacing = 1.0;

  bool HaveTables = false;
  TableKey Tables;

  // The environment last given to the renderer (isosurface blend mode).
  bool HaveEnvironment = false;
  std::string EnvironmentKey;

  std::unique_ptr<FrameOutput> Output;
  int OutputPreference = -1;
  // weak: a window destroyed behind our back reads as null, and its GL names are forgotten
  vtkWeakPointer<vtkOpenGLRenderWindow> OutputWindow;
  std::string OutputReason;
  std::unique_ptr<vtkOpenGLQuadHelper> Quad;
  vtkWeakPointer<vtkOpenGLRenderWindow> QuadWindow;

  std::set<std::string> Warned;

  ~vtkInternals() { this->FreeRenderer(); }

  void FreeRenderer()
  {
    fv_renderer_free(this->Renderer);
    this->Renderer = nullptr;
    this->HaveVolume = false;
    this->HaveTables = false;
    this->HaveEnvironment = false;
    this->Volume = VolumeKey();
    this->Tables = TableKey();
  }

  bool Stats(FvStats& s) const
  {
    return this->Renderer && fv_renderer_stats(this->Renderer, &s) == FV_STATUS_OK;
  }
};

//------------------------------------------------------------------------------------------
vtkFerroVolumeMapper::vtkFerroVolumeMapper()
  : AutoAdjustSampleDistances(1)
  , SampleDistance(1.0f)
  , ImageSampleDistance(1.0f)
  , UseJittering(0)
  , EmptySpaceSkipping(1)
  , OutputPath(OUTPUT_PATH_AUTOMATIC)
  , EnvironmentLighting(0.0)
  , EnvironmentMap(nullptr)
  , EnvironmentUp{ 0.0, 1.0, 0.0 }
  , EnvironmentAzimuth(0.0)
  , EnvironmentIntensity(1.0)
  , EnvironmentBackground(0)
  , SpecularSampling(SPECULAR_IMPORTANCE)
  , SpecularSamples(16)
  , AmbientOcclusionSamples(0)
  , AmbientOcclusionSteps(8)
  , AmbientOcclusionRadius(0.0)
  , ShininessFromGradient(0)
  , ShininessRange{ 8.0, 64.0 }
  , ShininessGradientRange{ 0.0, 0.0 }
  , Fresnel(-1.0)
  , IsosurfaceLayers(4)
  , IsosurfaceScattering(ISOSURFACE_SCATTERING_OFF)
  , IsosurfaceScatteringSamples(16)
  , IsosurfaceScatteringAbsorption(1.0)
  , RenderMode(RENDER_MODE_RAY_CAST)
  , SamplesPerPixel(64)
  , InteractiveSamplesPerPixel(1)
  , PathTracingBounces(64)
  , PathTracingDenoise(0)
  , VolumetricScatteringBlending(0.0)
  , GlobalIlluminationReach(0.0)
  , SecondaryRays(1)
  , GradientThreshold(VTK_DOUBLE_MAX)
  , StochasticBlend(0.0)
  , ScatterRegions(SCATTER_EVERYWHERE)
  , Attenuation(1)
  , BsdfRoughness(0.4)
  , BsdfFresnel(0.04)
  , Transmission(0.0)
  , TransmissionConeAngle(30.0)
  , LastRenderDrew(0)
  , LastRenderSize{ 0, 0 }
  , Internals(new vtkInternals)
{
}

vtkFerroVolumeMapper::~vtkFerroVolumeMapper()
{
  if (this->Internals->Output)
  {
    // The GL resources should have been released with their window; if not, their names
    // are forgotten (vtkTextureObject releases what it still owns).
    this->Internals->Output->ReleaseGraphicsResources(nullptr);
  }
  delete this->Internals;
  this->SetEnvironmentMap(nullptr);
}

//------------------------------------------------------------------------------------------
int vtkFerroVolumeMapper::GetVolumeUploadCount()
{
  FvStats s;
  return this->Internals->Stats(s) ? static_cast<int>(s.volume_uploads) : -1;
}

int vtkFerroVolumeMapper::GetTableUploadCount()
{
  FvStats s;
  return this->Internals->Stats(s) ? static_cast<int>(s.table_uploads) : -1;
}

int vtkFerroVolumeMapper::GetAccumulatedSamples()
{
  uint32_t n = 0;
  if (!this->Internals->Renderer ||
    fv_renderer_accumulated_samples(this->Internals->Renderer, &n) != FV_STATUS_OK)
  {
    return -1;
  }
  return static_cast<int>(n);
}

int vtkFerroVolumeMapper::GetFrameCount()
{
  FvStats s;
  return this->Internals->Stats(s) ? static_cast<int>(s.frames) : -1;
}

const char* vtkFerroVolumeMapper::GetOutputPathName()
{
  return this->Internals->Output ? this->Internals->Output->Name() : "none";
}

const char* vtkFerroVolumeMapper::GetOutputPathReason()
{
  return this->Internals->OutputReason.c_str();
}

const char* vtkFerroVolumeMapper::GetAdapterDescription()
{
  std::string error;
  SharedContext& shared = SharedContext::Get();
  shared.Acquire(error);
  return shared.Description.c_str();
}

const char* vtkFerroVolumeMapper::GetFerrovolVersion()
{
  return fv_version();
}

//------------------------------------------------------------------------------------------
void vtkFerroVolumeMapper::ReleaseGraphicsResources(vtkWindow* window)
{
  vtkInternals* in = this->Internals;
  vtkOpenGLRenderWindow* glwin = vtkOpenGLRenderWindow::SafeDownCast(window);
  if ((in->Output || in->Quad) && glwin && glwin == in->OutputWindow)
  {
    // the GL names below belong to this window's context
    glwin->MakeCurrent();
  }
  else if (in->Output && window)
  {
    // another window (or none we drew into): forget our names rather than delete
    // whatever they mean in the current context
    window = nullptr;
  }
  if (in->Output)
  {
    in->Output->ReleaseGraphicsResources(window);
    in->Output.reset();
  }
  in->OutputWindow = nullptr;
  in->OutputPreference = -1;
  in->OutputReason.clear();
  // The quad helper releases itself through the callback it registered with its window.
  in->Quad.reset();
  in->QuadWindow = nullptr;
  in->FreeRenderer();
  this->Superclass::ReleaseGraphicsResources(window);
}

//------------------------------------------------------------------------------------------
namespace
{

// vtkErrorMacro for the mapper from anywhere in this file (an ErrorEvent on the mapper when
// observed, VTK's output window otherwise).
#define Fail(self, message) vtkErrorWithObjectMacro(self, << (message))

// The scalars of the input as VTK's mappers pick them (ScalarMode, SelectScalarArray), or an
// error saying why there are none.
vtkDataArray* FindScalars(vtkFerroVolumeMapper* self, vtkImageData* image, int& cellFlag,
  std::string& error)
{
  cellFlag = 0;
  vtkDataArray* scalars = vtkAbstractMapper::GetScalars(image, self->GetScalarMode(),
    self->GetArrayAccessMode(), self->GetArrayId(), self->GetArrayName(), cellFlag);
  if (scalars)
  {
    return scalars;
  }
  const int mode = self->GetScalarMode();
  const bool byName = self->GetArrayAccessMode() == VTK_GET_ARRAY_BY_NAME;
  std::string what = byName && self->GetArrayName()
    ? std::string("array '") + self->GetArrayName() + "'"
    : "array " + std::to_string(self->GetArrayId());
  vtkAbstractArray* abstract = nullptr;
  if (mode == VTK_SCALAR_MODE_USE_POINT_FIELD_DATA)
  {
    abstract = byName ? image->GetPointData()->GetAbstractArray(self->GetArrayName())
                      : image->GetPointData()->GetAbstractArray(self->GetArrayId());
  }
  else if (mode == VTK_SCALAR_MODE_USE_CELL_FIELD_DATA)
  {
    abstract = byName ? image->GetCellData()->GetAbstractArray(self->GetArrayName())
                      : image->GetCellData()->GetAbstractArray(self->GetArrayId());
  }
  if (abstract)
  {
    error = "the selected " + what + " (" + abstract->GetClassName() +
      ") is not numeric: volume rendering needs numeric scalars";
  }
  else if (mode == VTK_SCALAR_MODE_USE_POINT_FIELD_DATA ||
    mode == VTK_SCALAR_MODE_USE_CELL_FIELD_DATA)
  {
    error = std::string("the input has no ") +
      (mode == VTK_SCALAR_MODE_USE_POINT_FIELD_DATA ? "point" : "cell") + " data " + what +
      " (see SelectScalarArray)";
  }
  else
  {
    error = "the input has no scalars to render (set point or cell scalars, or select an "
            "array with SetScalarModeToUsePointFieldData + SelectScalarArray)";
  }
  return nullptr;
}

// The volume to upload: geometry after cell centring and slab thickening, and the bytes.
struct PreparedVolume
{
  FvVolumeDesc Desc;
  const void* Data = nullptr;
  size_t Bytes = 0;
  std::vector<unsigned char> Storage;
  double MeanSpacing = 1.0;
};

bool PrepareVolume(
  vtkImageData* image, vtkDataArray* scalars, bool cells, PreparedVolume& out, std::string& error)
{
  int pointDims[3];
  image->GetDimensions(pointDims);
  double spacing[3], origin[3], dir[9];
  image->GetSpacing(spacing);
  image->GetOrigin(origin);
  vtkMatrix3x3* dm = image->GetDirectionMatrix();
  for (int r = 0; r < 3; ++r)
  {
    for (int c = 0; c < 3; ++c)
    {
      dir[3 * r + c] = dm ? dm->GetElement(r, c) : (r == c ? 1.0 : 0.0);
    }
  }
  // The first point of the extent (which need not start at 0) is the volume's origin.
  int extent[6];
  image->GetExtent(extent);
  for (int r = 0; r < 3; ++r)
  {
    for (int a = 0; a < 3; ++a)
    {
      origin[r] += dir[3 * r + a] * spacing[a] * extent[2 * a];
    }
  }
  for (int a = 0; a < 3; ++a)
  {
    if (pointDims[a] < 1)
    {
      error = "the input image is empty (dimensions " + std::to_string(pointDims[0]) + "x" +
        std::to_string(pointDims[1]) + "x" + std::to_string(pointDims[2]) + ")";
      return false;
    }
  }

  // Cell data: one value per cell, rendered as the grid of cell centres.
  int dims[3];
  for (int a = 0; a < 3; ++a)
  {
    dims[a] = cells ? std::max(pointDims[a] - 1, 1) : pointDims[a];
    if (cells && pointDims[a] > 1)
    {
      for (int r = 0; r < 3; ++r)
      {
        origin[r] += dir[3 * r + a] * 0.5 * spacing[a];
      }
    }
  }

  const int comps = scalars->GetNumberOfComponents();
  if (comps < 1 || comps > 4)
  {
    error = "the scalars '" + std::string(scalars->GetName() ? scalars->GetName() : "") +
      "' have " + std::to_string(comps) +
      " components; ferrovol renders 1 to 4 (pick components with "
      "vtkImageExtractComponents)";
    return false;
  }
  const vtkIdType expected = static_cast<vtkIdType>(dims[0]) * dims[1] * dims[2];
  if (scalars->GetNumberOfTuples() != expected)
  {
    error = "the scalars have " + std::to_string(scalars->GetNumberOfTuples()) + " tuples but " +
      std::to_string(dims[0]) + "x" + std::to_string(dims[1]) + "x" + std::to_string(dims[2]) +
      (cells ? " cells" : " points") + " need " + std::to_string(expected);
    return false;
  }
  uint32_t fvType = 0;
  size_t typeSize = 0;
  if (!ToFvScalarType(scalars->GetDataType(), fvType, typeSize))
  {
    error = std::string("scalars of type ") + scalars->GetDataTypeAsString() +
      " cannot be volume rendered (cast them with vtkImageCast)";
    return false;
  }

  // Spacing: positive along every axis (a negative one flips the direction column); an
  // axis with one point may have any spacing (it is only the slab's thickness).
  double positive[3] = { 0, 0, 0 };
  double minPositive = std::numeric_limits<double>::infinity();
  for (int a = 0; a < 3; ++a)
  {
    if (!std::isfinite(spacing[a]))
    {
      error = "the input spacing is not finite";
      return false;
    }
    if (spacing[a] != 0.0)
    {
      minPositive = std::min(minPositive, std::fabs(spacing[a]));
    }
  }
  static const char* axisName[3] = { "x", "y", "z" };
  for (int a = 0; a < 3; ++a)
  {
    if (spacing[a] == 0.0)
    {
      if (dims[a] > 1)
      {
        std::ostringstream s;
        s << "the input spacing (" << spacing[0] << ", " << spacing[1] << ", " << spacing[2]
          << ") is zero along " << axisName[a] << ", which has " << dims[a]
          << " points: every spacing must be non-zero";
        error = s.str();
        return false;
      }
      positive[a] = std::isfinite(minPositive) ? minPositive : 1.0;
    }
    else
    {
      positive[a] = std::fabs(spacing[a]);
      if (spacing[a] < 0.0)
      {
        for (int r = 0; r < 3; ++r)
        {
          dir[3 * r + a] = -dir[3 * r + a];
        }
      }
    }
  }

  // The bytes: the array's own memory where possible.
  const size_t elem = typeSize * comps;
  const size_t count = static_cast<size_t>(expected);
  const unsigned char* src = nullptr;
  std::vector<unsigned char> bits;
  if (scalars->GetDataType() == VTK_BIT)
  {
    bits.resize(count * comps);
    for (size_t i = 0; i < count; ++i)
    {
      for (int c = 0; c < comps; ++c)
      {
        bits[i * comps + c] =
          scalars->GetComponent(static_cast<vtkIdType>(i), c) != 0.0 ? 1 : 0;
      }
    }
    src = bits.data();
  }
  else
  {
    src = static_cast<const unsigned char*>(scalars->GetVoidPointer(0));
  }
  if (!src)
  {
    error = "the scalars' memory could not be read";
    return false;
  }

  // An axis with a single point becomes a slab one spacing thick, centred on the plane:
  // the slice is duplicated and the origin moved back half a spacing.
  int nd[3];
  bool flat = false;
  for (int a = 0; a < 3; ++a)
  {
    nd[a] = dims[a] == 1 ? 2 : dims[a];
    if (dims[a] == 1)
    {
      flat = true;
      for (int r = 0; r < 3; ++r)
      {
        origin[r] -= dir[3 * r + a] * 0.5 * positive[a];
      }
    }
  }
  if (flat)
  {
    out.Storage.resize(static_cast<size_t>(nd[0]) * nd[1] * nd[2] * elem);
    for (int k = 0; k < nd[2]; ++k)
    {
      const int sk = std::min(k, dims[2] - 1);
      for (int j = 0; j < nd[1]; ++j)
      {
        const int sj = std::min(j, dims[1] - 1);
        const unsigned char* srow =
          src + (static_cast<size_t>(sk) * dims[1] + sj) * dims[0] * elem;
        unsigned char* drow =
          out.Storage.data() + (static_cast<size_t>(k) * nd[1] + j) * nd[0] * elem;
        if (dims[0] == 1)
        {
          std::memcpy(drow, srow, elem);
          std::memcpy(drow + elem, srow, elem);
        }
        else
        {
          std::memcpy(drow, srow, dims[0] * elem);
        }
      }
    }
    out.Data = out.Storage.data();
    out.Bytes = out.Storage.size();
  }
  else if (!bits.empty())
  {
    out.Storage.swap(bits);
    out.Data = out.Storage.data();
    out.Bytes = out.Storage.size();
  }
  else
  {
    out.Data = src;
    out.Bytes = count * elem;
  }

  FvVolumeDesc& d = out.Desc;
  std::memset(&d, 0, sizeof(d));
  for (int a = 0; a < 3; ++a)
  {
    d.dims[a] = static_cast<uint32_t>(nd[a]);
    d.spacing[a] = positive[a];
    d.origin[a] = origin[a];
  }
  for (int i = 0; i < 9; ++i)
  {
    d.direction[i] = dir[i];
  }
  d.components = static_cast<uint32_t>(comps);
  d.scalar_type = fvType;
  // VTK's gradient magnitude unit (vtkVolumeShaderComposer.h, computeGradient) uses the mean
  // spacing of the input.
  out.MeanSpacing = (positive[0] + positive[1] + positive[2]) / 3.0;
  return true;
}

// The x positions of a table over [lo, hi]: TableSize points, as VTK's GetTable places them.
// A single-valued range (constant data) becomes two nodes [lo, lo + 1] holding the value at lo.
void TablePositions(double lo, double hi, std::vector<double>& xs)
{
  if (!(hi > lo))
  {
    xs = { lo, lo + 1.0 };
    return;
  }
  xs.resize(TableSize);
  for (int i = 0; i < TableSize; ++i)
  {
    xs[i] = lo + (hi - lo) * i / (TableSize - 1);
  }
}

void SampleScalar(vtkPiecewiseFunction* f, double lo, double hi, int m, double* out)
{
  if (hi > lo)
  {
    f->GetTable(lo, hi, m, out);
    return;
  }
  std::fill(out, out + m, f->GetValue(lo));
}

void SampleColor(vtkColorTransferFunction* f, double lo, double hi, int m, double* out)
{
  if (hi > lo)
  {
    f->GetTable(lo, hi, m, out);
    return;
  }
  double rgb[3];
  f->GetColor(lo, rgb);
  for (int i = 0; i < m; ++i)
  {
    std::copy(rgb, rgb + 3, out + 3 * i);
  }
}

bool BuildTransferFunction(vtkFerroVolumeMapper* self, vtkVolumeProperty* prop, int comps,
  const std::array<std::array<double, 2>, 4>& ranges, double gradientScale,
  FvTransferFunction*& tfOut, std::string& error)
{
  (void)self;
  const bool independent = comps == 1 || prop->GetIndependentComponents();
  if (!independent && comps != 2 && comps != 4)
  {
    error = "IndependentComponents is off with " + std::to_string(comps) +
      " components: dependent components need 2 (colour scalar, opacity scalar) or 4 (RGB + "
      "opacity scalar)";
    return false;
  }
  const int n = independent ? comps : 1;
  FvTransferFunction* tf = nullptr;
  FvStatus st = fv_transfer_function_new(static_cast<uint32_t>(n), independent, &tf);
  if (st != FV_STATUS_OK)
  {
    error = FvError("create a transfer function", st);
    return false;
  }
  std::vector<double> xs, values, pts;
  bool ok = true;
  for (int c = 0; c < n && ok; ++c)
  {
    // Table ranges as vtkGPUVolumeRayCastMapper (SCALAR range type, its default): each
    // component's data range; dependent components take colour from component 0 and
    // opacity from the last one, and share one table here, spanning both ranges.
    double lo = ranges[c][0], hi = ranges[c][1];
    const int opacityComp = independent ? c : comps - 1;
    if (!independent)
    {
      lo = std::min(ranges[0][0], ranges[comps - 1][0]);
      hi = std::max(ranges[0][1], ranges[comps - 1][1]);
    }
    TablePositions(lo, hi, xs);
    const int m = static_cast<int>(xs.size());

    // colour
    values.assign(static_cast<size_t>(3) * m, 0.0);
    if (prop->GetColorChannels(c) == 1)
    {
      std::vector<double> gray(m);
      vtkPiecewiseFunction* g = prop->GetGrayTransferFunction(c);
      if (g->GetSize() < 1)
      {
        for (int i = 0; i < m; ++i)
        {
          gray[i] = (hi > lo) ? (xs[i] - lo) / (hi - lo) : 0.0;
        }
      }
      else
      {
        SampleScalar(g, lo, hi, m, gray.data());
      }
      for (int i = 0; i < m; ++i)
      {
        values[3 * i] = values[3 * i + 1] = values[3 * i + 2] = gray[i];
      }
    }
    else
    {
      vtkColorTransferFunction* ctf = prop->GetRGBTransferFunction(c);
      if (ctf->GetSize() < 1)
      {
        // VTK's GPU mapper adds a black-to-white ramp over the range.
        for (int i = 0; i < m; ++i)
        {
          double v = (hi > lo) ? (xs[i] - lo) / (hi - lo) : 0.0;
          values[3 * i] = values[3 * i + 1] = values[3 * i + 2] = v;
        }
      }
      else
      {
        SampleColor(ctf, lo, hi, m, values.data());
      }
    }
    pts.resize(static_cast<size_t>(4) * m);
    for (int i = 0; i < m; ++i)
    {
      pts[4 * i] = xs[i];
      for (int k = 0; k < 3; ++k)
      {
        pts[4 * i + 1 + k] = std::min(1.0, std::max(0.0, values[3 * i + k]));
      }
    }
    st = fv_transfer_function_set_color(tf, c, pts.data(), m);
    if (st != FV_STATUS_OK)
    {
      error = FvError("set the colour transfer function", st);
      ok = false;
      break;
    }

    // scalar opacity
    values.assign(m, 0.0);
    vtkPiecewiseFunction* sof = prop->GetScalarOpacity(c);
    if (sof->GetSize() < 1)
    {
      // VTK's GPU mapper adds (min, 0) and (max, 0.5).
      for (int i = 0; i < m; ++i)
      {
        values[i] = (hi > lo) ? 0.5 * (xs[i] - lo) / (hi - lo) : 0.0;
      }
    }
    else
    {
      SampleScalar(sof, lo, hi, m, values.data());
    }
    pts.resize(static_cast<size_t>(2) * m);
    for (int i = 0; i < m; ++i)
    {
      pts[2 * i] = xs[i];
      pts[2 * i + 1] = std::min(1.0, std::max(0.0, values[i]));
    }
    st = fv_transfer_function_set_opacity(tf, c, pts.data(), m);
    if (st != FV_STATUS_OK)
    {
      error = FvError("set the scalar opacity function", st);
      ok = false;
      break;
    }

    double unit = prop->GetScalarOpacityUnitDistance(opacityComp);
    double weight = prop->GetComponentWeight(c);
    st = fv_transfer_function_set_unit_distance(tf, c, unit, weight);
    if (st != FV_STATUS_OK)
    {
      error = FvError("set the scalar opacity unit distance", st);
      ok = false;
      break;
    }

    // Gradient opacity. VTK 9.2 (vtkVolumeShaderComposer.h computeGradient and
    // vtkOpenGLVolumeGradientOpacityTable) evaluates the function at
    //   g_vtk = meanSpacing · |∇s|   (central differences, ∇ in data coordinates)
    // clamped to [0, 0.25 · (max − min)] of the component's data range, the table spanning
    // exactly that. ferrovol's x axis is |∇s| in scalar units per world unit, so the nodes
    // move to x = g_vtk · gradientScale, gradientScale = 1 / (meanSpacing · volume matrix
    // scale); ferrovol clamps beyond the last node just as VTK clamps.
    const int goIndex = independent ? c : 0;
    if (prop->HasGradientOpacity(goIndex) && !prop->GetDisableGradientOpacity(goIndex))
    {
      vtkPiecewiseFunction* gof = prop->GetStoredGradientOpacity(goIndex);
      const double range = ranges[opacityComp][1] - ranges[opacityComp][0];
      const double gmax = 0.25 * (range != 0.0 ? range : 1.0);
      values.assign(TableSize, 1.0);
      gof->GetTable(0.0, range != 0.0 ? gmax : 0.0, TableSize, values.data());
      bool allOne = true;
      pts.resize(static_cast<size_t>(2) * TableSize);
      for (int i = 0; i < TableSize; ++i)
      {
        double v = std::min(1.0, std::max(0.0, values[i]));
        allOne = allOne && v == 1.0;
        pts[2 * i] = gmax * i / (TableSize - 1) * gradientScale;
        pts[2 * i + 1] = v;
      }
      // A constant 1 (VTK's default function) changes nothing: leave gradient opacity off.
      st = fv_transfer_function_set_gradient_opacity(
        tf, c, allOne ? nullptr : pts.data(), allOne ? 0 : TableSize);
      if (st != FV_STATUS_OK)
      {
        error = FvError("set the gradient opacity function", st);
        ok = false;
        break;
      }
    }
  }
  if (!ok)
  {
    fv_transfer_function_free(tf);
    return false;
  }
  tfOut = tf;
  return true;
}

} // namespace

//------------------------------------------------------------------------------------------
namespace
{
// What the mapper remembers about the environment between frames.
struct EnvironmentState
{
  bool& Have;
  std::string& Key;
  std::set<std::string>& Warned;
  // Out: the frame shows the environment behind the surfaces (it covers the viewport).
  bool& Background;
};

// Gives the renderer the mapper's environment when the map or its placement changed since
// the last frame; false (said once per setting with vtkErrorMacro) when it cannot be used.
bool UseEnvironment(vtkFerroVolumeMapper* self, FvRenderer* r, EnvironmentState& env)
{
  const char* file = self->GetEnvironmentMap();
  const bool sky = !file || !*file;
  const double* up = self->GetEnvironmentUp();
  std::ostringstream key;
  key << (sky ? "" : file) << '|' << up[0] << ',' << up[1] << ',' << up[2] << '|'
      << self->GetEnvironmentAzimuth() << '|' << self->GetEnvironmentIntensity();
  if (!env.Have || (env.Key != key.str() && env.Key != "failed:" + key.str()))
  {
    env.Have = true;
    env.Key = key.str();
    const FvStatus st = fv_renderer_set_environment(r, sky ? nullptr : file,
      static_cast<float>(self->GetEnvironmentIntensity()), up, self->GetEnvironmentAzimuth());
    if (st != FV_STATUS_OK)
    {
      vtkErrorWithObjectMacro(self, << FvError("use the environment map", st)
                                    << " (drawing without environment light)");
      env.Key = "failed:" + key.str();
    }
  }
  return env.Key.rfind("failed:", 0) != 0;
}

// Gives the renderer the path tracing settings: the property's ScatteringAnisotropy, the
// mapper's budget (the still budget, or InteractiveSamplesPerPixel per frame while the
// window renders interactively), bounces and environment (weight 1; background when
// EnvironmentBackground is on).
bool SetUpPathTracing(vtkFerroVolumeMapper* self, FvRenderer* r, vtkRenderer* ren,
  vtkVolumeProperty* prop, EnvironmentState env, std::string& error)
{
  FvPathTraceParams pt;
  fv_path_trace_params_default(&pt);
  vtkRenderWindow* win = ren->GetRenderWindow();
  const bool interactive = win && win->GetDesiredUpdateRate() > 1.0;
  if (interactive)
  {
    pt.samples_per_frame = static_cast<uint32_t>(self->GetInteractiveSamplesPerPixel());
    pt.max_samples = 0;
  }
  else
  {
    pt.samples_per_frame = static_cast<uint32_t>(std::min(self->GetSamplesPerPixel(), 4096));
    pt.max_samples = static_cast<uint32_t>(self->GetSamplesPerPixel());
    pt.secondary_rays = static_cast<uint32_t>(self->GetSecondaryRays());
  }
  pt.max_bounces = static_cast<uint32_t>(self->GetPathTracingBounces());
  const double psi = self->GetGradientThreshold();
  pt.gradient_threshold = psi >= static_cast<double>(FLT_MAX)
    ? std::numeric_limits<float>::infinity()
    : static_cast<float>(psi);
  pt.stochastic_blend = static_cast<float>(std::min(self->GetStochasticBlend(), 1e30));
  pt.scatter_regions = static_cast<uint32_t>(self->GetScatterRegions());
  pt.attenuation = self->GetAttenuation() != 0;
  pt.denoise = self->GetPathTracingDenoise() != 0;
  pt.roughness = static_cast<float>(self->GetBsdfRoughness());
  pt.fresnel = static_cast<float>(self->GetBsdfFresnel());
  pt.transmission = static_cast<float>(self->GetTransmission());
  pt.cone_angle = static_cast<float>(self->GetTransmissionConeAngle());
  // (|g| = 1 is a delta, which a Monte Carlo estimate cannot sample: clamp inside)
  pt.anisotropy = std::max(-0.99f, std::min(0.99f, prop->GetScatteringAnisotropy()));
  pt.background = self->GetEnvironmentBackground() != 0;
  if (!UseEnvironment(self, r, env))
  {
    pt.environment_light = 0.0f;
    pt.background = false;
  }
  env.Background = pt.background;
  const FvStatus st = fv_renderer_set_path_tracing(r, &pt);
  if (st != FV_STATUS_OK)
  {
    error = FvError("use the path tracing settings", st);
    return false;
  }
  return true;
}

enum class IsoSetup
{
  Failed,
  NothingVisible,
  Ready
};


// Gives the renderer the property's iso-values and the mapper's isosurface shading, and the
// environment when it changed. The surfaces' colours and opacities are the property's
// colour and scalar opacity functions at the iso-values (first component), as
// vtkGPUVolumeRayCastMapper's; Shade off draws flat colours (ambient 1, no diffuse or
// specular light, no environment light).
IsoSetup SetUpIsosurfaces(vtkFerroVolumeMapper* self, FvRenderer* r, vtkVolumeProperty* prop,
  EnvironmentState env, FvRenderParams& params, std::string& error)
{
  vtkContourValues* contours = prop->GetIsoSurfaceValues();
  const int n = contours ? contours->GetNumberOfContours() : 0;
  if (n < 1)
  {
    error = "the isosurface blend mode needs iso-values: set them with "
            "volumeProperty->GetIsoSurfaceValues()->SetValue(0, value)";
    return IsoSetup::Failed;
  }
  if (n > FV_MAX_ISO_VALUES && env.Warned.insert("iso-count").second)
  {
    vtkWarningWithObjectMacro(self, << n << " iso-values: ferrovol draws the first "
                                    << FV_MAX_ISO_VALUES);
  }
  FvIsoParams iso;
  fv_iso_params_default(&iso);
  // (Get{Gray,RGB}TransferFunction create a default function, and switch the property to
  // it, when it has none: ask for the one the property uses.)
  const bool grayColor = prop->GetColorChannels(0) == 1;
  vtkColorTransferFunction* rgb = grayColor ? nullptr : prop->GetRGBTransferFunction(0);
  vtkPiecewiseFunction* gray = grayColor ? prop->GetGrayTransferFunction(0) : nullptr;
  vtkPiecewiseFunction* opacity = prop->GetScalarOpacity(0);
  uint32_t count = 0;
  for (int i = 0; i < std::min(n, static_cast<int>(FV_MAX_ISO_VALUES)); ++i)
  {
    const double v = contours->GetValue(i);
    const double a = std::min(1.0, opacity->GetValue(v));
    if (!(a > 0.0))
    {
      if (env.Warned.insert("iso-transparent-" + std::to_string(v)).second)
      {
        vtkWarningWithObjectMacro(self, << "iso-value " << v
                                        << " has opacity 0 in the scalar opacity function: "
                                           "it is not drawn");
      }
      continue;
    }
    FvIsoValue& iv = iso.values[count++];
    iv.value = v;
    double c[3];
    if (grayColor)
    {
      c[0] = c[1] = c[2] = gray->GetValue(v);
    }
    else
    {
      rgb->GetColor(v, c);
    }
    for (int k = 0; k < 3; ++k)
    {
      iv.color[k] = static_cast<float>(std::min(1.0, std::max(0.0, c[k])));
    }
    iv.opacity = static_cast<float>(a);
  }
  if (count == 0)
  {
    return IsoSetup::NothingVisible;
  }
  iso.value_count = count;
  iso.max_layers = static_cast<uint32_t>(self->GetIsosurfaceLayers());
  iso.specular_mode = self->GetSpecularSampling() == vtkFerroVolumeMapper::SPECULAR_CONE
    ? FV_SPECULAR_MODE_CONE
    : FV_SPECULAR_MODE_IMPORTANCE;
  iso.specular_samples = static_cast<uint32_t>(self->GetSpecularSamples());
  if (self->GetShininessFromGradient())
  {
    const double* e = self->GetShininessRange();
    const double* g = self->GetShininessGradientRange();
    iso.shininess[0] = static_cast<float>(e[0]);
    iso.shininess[1] = static_cast<float>(e[1]);
    iso.shininess_range[0] = g[0];
    iso.shininess_range[1] = g[1];
  }
  else
  {
    iso.shininess[0] = iso.shininess[1] = params.specular_power;
  }
  iso.fresnel = static_cast<float>(self->GetFresnel());
  iso.scatter_mode = static_cast<uint32_t>(self->GetIsosurfaceScattering());
  iso.scatter_samples = static_cast<uint32_t>(self->GetIsosurfaceScatteringSamples());
  iso.scatter_absorption =
    static_cast<float>(std::min(self->GetIsosurfaceScatteringAbsorption(), 1e30));
  if (self->GetFresnel() >= 0.0)
  {
    iso.scatter_fresnel = static_cast<float>(self->GetFresnel());
  }
  iso.ao_samples = static_cast<uint32_t>(self->GetAmbientOcclusionSamples());
  iso.ao_steps = static_cast<uint32_t>(self->GetAmbientOcclusionSteps());
  iso.ao_radius = self->GetAmbientOcclusionRadius();
  iso.background = self->GetEnvironmentBackground() != 0;
  iso.environment_light = params.shade ? static_cast<float>(self->GetEnvironmentLighting()) : 0.0f;
  if (!params.shade)
  {
    params.ambient = 1.0f;
    params.diffuse = 0.0f;
    params.specular = 0.0f;
  }

  if ((iso.environment_light > 0.0f || iso.background) && !UseEnvironment(self, r, env))
  {
    iso.environment_light = 0.0f;
    iso.background = false;
  }
  env.Background = iso.background;
  const FvStatus st = fv_renderer_set_isosurface(r, &iso);
  if (st != FV_STATUS_OK)
  {
    error = FvError("use the isosurface settings", st);
    return IsoSetup::Failed;
  }
  return IsoSetup::Ready;
}
}

//------------------------------------------------------------------------------------------
namespace
{
// Whether the renderer has visible props other than volumes that draw opaque geometry
// before the volume pass. Without any, VTK's depth buffer holds only its clear value: the
// frame then needs no depth input, which saves a full-viewport copy (about 6 ms of a 900x900
// frame on llvmpipe, measured).
bool HasOpaqueGeometry(vtkRenderer* ren, vtkVolume* self)
{
  vtkPropCollection* props = ren->GetViewProps();
  vtkCollectionSimpleIterator it;
  props->InitTraversal(it);
  while (vtkProp* p = props->GetNextProp(it))
  {
    if (p != self && p->GetVisibility() && !vtkVolume::SafeDownCast(p) && p->HasOpaqueGeometry())
    {
      return true;
    }
  }
  return false;
}

// The viewport pixels (x, y, w, h relative to the viewport) the volume's world bounding box,
// grown by `pad` world units on every side, can cover (a volume one point thick renders as a
// slab one spacing thick, beyond VTK's flat bounds); the whole viewport when a corner is
// behind the camera. Outside them ferrovol's
// frame is empty, so the compositing pass is scissored to them (it is a full-viewport
// fragment pass otherwise: ~8 ms of a 900x900 frame on llvmpipe, measured).
void ProjectedRect(vtkRenderer* ren, vtkVolume* vol, double pad, int vw, int vh, int rect[4])
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
}

void vtkFerroVolumeMapper::Render(vtkRenderer* ren, vtkVolume* vol)
{
  this->LastRenderDrew = 0;
  vtkInternals* in = this->Internals;
  if (!ren || !vol)
  {
    return;
  }
  if (ren->GetSelector())
  {
    // Hardware selection passes are not supported: draw nothing into them.
    return;
  }
  vtkOpenGLRenderWindow* win = vtkOpenGLRenderWindow::SafeDownCast(ren->GetRenderWindow());
  if (!win)
  {
    Fail(this, "vtkFerroVolumeMapper needs an OpenGL render window (vtkOpenGLRenderWindow)");
    return;
  }
  vtkNew<vtkTimerLog> timer;
  timer->StartTimer();

  // ---- blend mode
  uint32_t blend = FV_BLEND_MODE_COMPOSITE;
  switch (this->BlendMode)
  {
    case vtkVolumeMapper::COMPOSITE_BLEND:
      blend = FV_BLEND_MODE_COMPOSITE;
      break;
    case vtkVolumeMapper::MAXIMUM_INTENSITY_BLEND:
      blend = FV_BLEND_MODE_MAXIMUM;
      break;
    case vtkVolumeMapper::MINIMUM_INTENSITY_BLEND:
      blend = FV_BLEND_MODE_MINIMUM;
      break;
    case vtkVolumeMapper::AVERAGE_INTENSITY_BLEND:
      blend = FV_BLEND_MODE_AVERAGE;
      break;
    case vtkVolumeMapper::ADDITIVE_BLEND:
      blend = FV_BLEND_MODE_ADDITIVE;
      break;
    case vtkVolumeMapper::ISOSURFACE_BLEND:
      blend = FV_BLEND_MODE_ISOSURFACE;
      break;
    default:
      Fail(this,
        "blend mode " + std::to_string(this->BlendMode) +
          " is not supported by vtkFerroVolumeMapper (composite, maximum, minimum, average, "
          "additive and isosurface are): nothing is drawn");
      return;
  }

  const bool pathTrace = this->RenderMode == RENDER_MODE_PATH_TRACE;
  if (pathTrace)
  {
    blend = FV_BLEND_MODE_PATH_TRACE;
  }

  // ---- input
  vtkAlgorithm* alg = this->GetInputAlgorithm();
  if (!alg || this->GetNumberOfInputConnections(0) < 1)
  {
    Fail(this, "no input: connect a vtkImageData (SetInputData / SetInputConnection)");
    return;
  }
  alg->Update();
  vtkDataSet* dataset = this->GetInput();
  vtkImageData* image = vtkImageData::SafeDownCast(dataset);
  if (!image)
  {
    Fail(this,
      std::string("the input is ") + (dataset ? dataset->GetClassName() : "empty") +
        ": vtkFerroVolumeMapper renders vtkImageData");
    return;
  }
  int cellFlag = 0;
  std::string error;
  vtkDataArray* scalars = FindScalars(this, image, cellFlag, error);
  if (!scalars)
  {
    Fail(this, error);
    return;
  }
  if (cellFlag == 2)
  {
    Fail(this, "field data scalars cannot be volume rendered: select point or cell data");
    return;
  }

  // ---- renderer
  if (!in->Renderer)
  {
    FvContext* ctx = SharedContext::Get().Acquire(error);
    if (!ctx)
    {
      Fail(this, error);
      return;
    }
    FvStatus st = fv_renderer_new(ctx, &in->Renderer);
    if (st != FV_STATUS_OK)
    {
      in->Renderer = nullptr;
      Fail(this, FvError("create a renderer", st));
      return;
    }
  }
  FvRenderer* r = in->Renderer;

  // ---- volume (only when the scalars changed)
  VolumeKey vkey;
  vkey.Input = image;
  vkey.InputMTime = image->GetMTime();
  vkey.Scalars = scalars;
  vkey.ScalarsMTime = scalars->GetMTime();
  vkey.CellFlag = cellFlag;
  image->GetDimensions(vkey.Dims);
  vkey.DataType = scalars->GetDataType();
  vkey.Components = scalars->GetNumberOfComponents();
  if (!in->HaveVolume || !(in->Volume == vkey))
  {
    in->HaveVolume = false;
    PreparedVolume pv;
    if (!PrepareVolume(image, scalars, cellFlag == 1, pv, error))
    {
      Fail(this, error);
      return;
    }
    FvVolume* fvol = nullptr;
    FvStatus st = fv_volume_new(&pv.Desc, pv.Data, pv.Bytes, &fvol);
    if (st != FV_STATUS_OK)
    {
      Fail(this, FvError("take the input volume", st));
      return;
    }
    st = fv_renderer_set_volume(r, fvol);
    fv_volume_free(fvol);
    if (st != FV_STATUS_OK)
    {
      Fail(this, FvError("upload the volume", st));
      return;
    }
    in->Components = vkey.Components;
    in->Ranges = {};
    for (int c = 0; c < in->Components; ++c)
    {
      double range[2] = { 0.0, 0.0 };
      if (scalars->GetDataType() == VTK_BIT)
      {
        scalars->GetRange(range, c);
      }
      else
      {
        scalars->GetFiniteRange(range, c);
      }
      in->Ranges[c] = { range[0], range[1] };
    }
    in->MeanSpacing = pv.MeanSpacing;
    in->Volume = vkey;
    in->HaveVolume = true;
  }

  // ---- transfer function (only when the property changed)
  vtkVolumeProperty* prop = vol->GetProperty();
  if (prop->GetTransferFunctionMode() != vtkVolumeProperty::TF_1D)
  {
    Fail(this,
      "2D transfer functions (vtkVolumeProperty::TransferFunctionMode TF_2D) are not supported "
      "by vtkFerroVolumeMapper: nothing is drawn");
    return;
  }
  vtkMatrix4x4* volumeMatrix = vol->GetMatrix();
  double matrixScale = std::cbrt(std::fabs(volumeMatrix->Determinant()));
  if (!(matrixScale > 0.0) || !std::isfinite(matrixScale))
  {
    Fail(this, "the vtkVolume's matrix is singular (zero scale?): nothing is drawn");
    return;
  }
  TableKey tkey;
  tkey.Property = prop;
  tkey.PropertyMTime = prop->GetMTime();
  tkey.Components = in->Components;
  tkey.Ranges = in->Ranges;
  tkey.GradientScale = 1.0 / (in->MeanSpacing * matrixScale);
  if (!in->HaveTables || !(in->Tables == tkey))
  {
    in->HaveTables = false;
    FvTransferFunction* tf = nullptr;
    if (!BuildTransferFunction(
          this, prop, in->Components, in->Ranges, tkey.GradientScale, tf, error))
    {
      Fail(this, error);
      return;
    }
    FvStatus st = fv_renderer_set_transfer_function(r, tf);
    fv_transfer_function_free(tf);
    if (st != FV_STATUS_OK)
    {
      Fail(this, FvError("set the transfer function", st));
      return;
    }
    in->Tables = tkey;
    in->HaveTables = true;
  }

  // ---- parameters (every frame; never uploads)
  FvRenderParams params;
  fv_render_params_default(&params);
  params.blend_mode = blend;
  switch (prop->GetInterpolationType())
  {
    case VTK_NEAREST_INTERPOLATION:
      params.interpolation = FV_INTERPOLATION_NEAREST;
      break;
    case VTK_LINEAR_INTERPOLATION:
      params.interpolation = FV_INTERPOLATION_LINEAR;
      break;
    default:
      params.interpolation = FV_INTERPOLATION_LINEAR;
      if (in->Warned.insert("interpolation").second)
      {
        vtkWarningMacro(<< "interpolation type " << prop->GetInterpolationTypeAsString()
                        << " is not supported by ferrovol: using linear interpolation");
      }
      break;
  }
  if (!this->AutoAdjustSampleDistances)
  {
    if (!(this->SampleDistance > 0.0f) || !std::isfinite(this->SampleDistance))
    {
      Fail(this,
        "SampleDistance " + std::to_string(this->SampleDistance) +
          " must be positive (or turn AutoAdjustSampleDistances on)");
      return;
    }
    params.sample_distance = this->SampleDistance;
  }
  params.jitter = this->UseJittering != 0;
  const bool isosurface = blend == FV_BLEND_MODE_ISOSURFACE;
  params.shade = prop->GetShade(0) != 0 && (blend == FV_BLEND_MODE_COMPOSITE || isosurface);
  params.ambient = static_cast<float>(prop->GetAmbient(0));
  params.diffuse = static_cast<float>(prop->GetDiffuse(0));
  params.specular = static_cast<float>(prop->GetSpecular(0));
  params.specular_power = static_cast<float>(prop->GetSpecularPower(0));
  params.two_sided_lighting = ren->GetTwoSidedLighting() != 0;
  if (!isosurface)
  {
    params.volumetric_scattering_blending =
      static_cast<float>(this->VolumetricScatteringBlending);
    params.global_illumination_reach = static_cast<float>(this->GlobalIlluminationReach);
    params.scattering_anisotropy = std::max(-1.0f, std::min(1.0f, prop->GetScatteringAnisotropy()));
  }
  params.cropping = this->Cropping != 0;
  for (int i = 0; i < 6; ++i)
  {
    params.cropping_planes[i] = this->CroppingRegionPlanes[i];
  }
  params.cropping_regions = static_cast<uint32_t>(this->CroppingRegionFlags);
  if (vtkPlaneCollection* planes = this->GetClippingPlanes())
  {
    int count = planes->GetNumberOfItems();
    if (count > FV_MAX_CLIP_PLANES)
    {
      if (in->Warned.insert("planes").second)
      {
        vtkWarningMacro(<< count << " clipping planes: ferrovol uses the first "
                        << FV_MAX_CLIP_PLANES);
      }
      count = FV_MAX_CLIP_PLANES;
    }
    for (int i = 0; i < count; ++i)
    {
      vtkPlane* plane = planes->GetItem(i);
      plane->GetOrigin(params.clip_planes[i].origin);
      plane->GetNormal(params.clip_planes[i].normal);
    }
    params.clip_plane_count = static_cast<uint32_t>(count);
  }
  params.average_range_enabled = blend == FV_BLEND_MODE_AVERAGE;
  params.average_range[0] = this->AverageIPScalarRange[0];
  params.average_range[1] = this->AverageIPScalarRange[1];
  params.empty_space_skipping = this->EmptySpaceSkipping != 0;
  ToColumnMajor(volumeMatrix, params.volume_matrix);
  bool fullViewport = false;
  if (isosurface)
  {
    EnvironmentState env{ in->HaveEnvironment, in->EnvironmentKey, in->Warned, fullViewport };
    switch (SetUpIsosurfaces(this, r, prop, env, params, error))
    {
      case IsoSetup::Failed:
        Fail(this, error);
        return;
      case IsoSetup::NothingVisible:
        return; // every iso-value is transparent (SetUpIsosurfaces warned once)
      case IsoSetup::Ready:
        break;
    }
  }
  if (pathTrace)
  {
    EnvironmentState env{ in->HaveEnvironment, in->EnvironmentKey, in->Warned, fullViewport };
    if (!SetUpPathTracing(this, r, ren, prop, env, error))
    {
      Fail(this, error);
      return;
    }
  }
  FvStatus st = fv_renderer_set_params(r, &params);
  if (st != FV_STATUS_OK)
  {
    Fail(this, FvError("use the mapper's settings", st));
    return;
  }

  // ---- camera: the matrices VTK draws the opaque geometry with
  int vw = 0, vh = 0, vx = 0, vy = 0;
  ren->GetTiledSizeAndOrigin(&vw, &vh, &vx, &vy);
  if (vw < 1 || vh < 1)
  {
    return;
  }
  vtkCamera* cam = ren->GetActiveCamera();
  FvCamera fcam;
  std::memset(&fcam, 0, sizeof(fcam));
  cam->GetPosition(fcam.position);
  cam->GetFocalPoint(fcam.focal_point);
  cam->GetViewUp(fcam.view_up);
  fcam.view_angle = cam->GetViewAngle();
  fcam.parallel = cam->GetParallelProjection() != 0;
  fcam.parallel_scale = cam->GetParallelScale();
  cam->GetClippingRange(fcam.clipping_range);
  fcam.use_matrices = true;
  if (vtkOpenGLCamera* glcam = vtkOpenGLCamera::SafeDownCast(cam))
  {
    // GL-ordered (transposed) copies: their storage is column-major already.
    vtkMatrix4x4 *wcvc = nullptr, *vcdc = nullptr, *wcdc = nullptr;
    vtkMatrix3x3* norms = nullptr;
    glcam->GetKeyMatrices(ren, wcvc, norms, vcdc, wcdc);
    std::memcpy(fcam.view_matrix, wcvc->GetData(), sizeof(fcam.view_matrix));
    std::memcpy(fcam.projection_matrix, vcdc->GetData(), sizeof(fcam.projection_matrix));
  }
  else
  {
    ToColumnMajor(cam->GetModelViewTransformMatrix(), fcam.view_matrix);
    ToColumnMajor(cam->GetProjectionTransformMatrix(static_cast<double>(vw) / vh, -1, 1),
      fcam.projection_matrix);
  }
  st = fv_renderer_set_camera(r, &fcam);
  if (st != FV_STATUS_OK)
  {
    Fail(this, FvError("use the camera", st));
    return;
  }

  // ---- lights (VTK's default lighting: one headlight of intensity 1, whose ambient term is
  // the material's ambient times the sample colour)
  std::vector<FvLight> lights;
  if (isosurface && !params.shade)
  {
    // Flat isosurfaces (Shade off), as vtkGPUVolumeRayCastMapper draws them: the surface
    // colour alone, through one purely ambient light (SetUpIsosurfaces set the material).
    FvLight l;
    std::memset(&l, 0, sizeof(l));
    l.space = FV_LIGHT_SPACE_HEADLIGHT;
    l.ambient[0] = l.ambient[1] = l.ambient[2] = 1.0f;
    l.intensity = 1.0f;
    l.attenuation[0] = 1.0f;
    lights.push_back(l);
  }
  else if (params.shade || pathTrace)
  {
    vtkLightCollection* lc = ren->GetLights();
    vtkCollectionSimpleIterator it;
    int on = 0;
    lc->InitTraversal(it);
    while (vtkLight* light = lc->GetNextLight(it))
    {
      if (light->GetSwitch())
      {
        ++on;
      }
    }
    if (on > FV_MAX_LIGHTS && in->Warned.insert("lights").second)
    {
      vtkWarningMacro(<< on << " lights are on: ferrovol uses the first " << FV_MAX_LIGHTS);
    }
    lc->InitTraversal(it);
    while (vtkLight* light = lc->GetNextLight(it))
    {
      if (!light->GetSwitch() || static_cast<int>(lights.size()) >= FV_MAX_LIGHTS)
      {
        continue;
      }
      FvLight l;
      std::memset(&l, 0, sizeof(l));
      const bool defaultLighting =
        on == 1 && light->LightTypeIsHeadlight() && light->GetIntensity() == 1.0;
      if (light->LightTypeIsHeadlight())
      {
        l.space = FV_LIGHT_SPACE_HEADLIGHT;
        light->GetPosition(l.position);
        light->GetFocalPoint(l.focal_point);
      }
      else if (light->LightTypeIsCameraLight())
      {
        l.space = FV_LIGHT_SPACE_CAMERA;
        light->GetPosition(l.position);
        light->GetFocalPoint(l.focal_point);
      }
      else
      {
        l.space = FV_LIGHT_SPACE_WORLD;
        light->GetTransformedPosition(l.position);
        light->GetTransformedFocalPoint(l.focal_point);
      }
      l.positional = light->GetPositional() != 0;
      double c[3];
      light->GetAmbientColor(c);
      for (int k = 0; k < 3; ++k)
      {
        l.ambient[k] = defaultLighting ? 1.0f : static_cast<float>(c[k]);
      }
      light->GetDiffuseColor(c);
      for (int k = 0; k < 3; ++k)
      {
        l.diffuse[k] = static_cast<float>(c[k]);
      }
      light->GetSpecularColor(c);
      for (int k = 0; k < 3; ++k)
      {
        l.specular[k] = static_cast<float>(c[k]);
      }
      l.intensity = static_cast<float>(light->GetIntensity());
      double att[3];
      light->GetAttenuationValues(att);
      for (int k = 0; k < 3; ++k)
      {
        l.attenuation[k] = static_cast<float>(att[k]);
      }
      l.cone_angle = static_cast<float>(light->GetConeAngle());
      l.exponent = static_cast<float>(light->GetExponent());
      lights.push_back(l);
    }
  }
  st = fv_renderer_set_lights(r, lights.empty() ? nullptr : lights.data(), lights.size());
  if (st != FV_STATUS_OK)
  {
    Fail(this, FvError("use the renderer's lights", st));
    return;
  }

  // ---- render at the (possibly reduced) resolution, through the output path
  const float isd = this->AutoAdjustSampleDistances ? 1.0f : this->ImageSampleDistance;
  FrameRequest req;
  req.Window = win;
  req.ViewportX = vx;
  req.ViewportY = vy;
  req.ViewportW = vw;
  req.ViewportH = vh;
  req.RenderW = std::max(1, static_cast<int>(vw / isd));
  req.RenderH = std::max(1, static_cast<int>(vh / isd));
  req.UseDepth = HasOpaqueGeometry(ren, vol);
  if (!in->Output || in->OutputPreference != this->OutputPath || in->OutputWindow != win)
  {
    if (in->Output)
    {
      in->Output->ReleaseGraphicsResources(in->OutputWindow == win ? win : nullptr);
      in->Output.reset();
    }
    in->OutputPreference = this->OutputPath;
    in->OutputWindow = win;
#if FERROVOL_HAVE_SHARED_OUTPUT
    if (this->OutputPath != OUTPUT_PATH_READBACK)
    {
      std::string ignored;
      in->Output = SharedOutput::Create(SharedContext::Get().Acquire(ignored), r,
        this->OutputPath == OUTPUT_PATH_SHARED, in->OutputReason);
      if (!in->Output && this->OutputPath == OUTPUT_PATH_SHARED)
      {
        vtkWarningMacro(<< "shared output unavailable, frames go through the CPU: "
                        << in->OutputReason);
      }
    }
    else
    {
      in->OutputReason = "OutputPath is readback";
    }
    if (!in->Output)
    {
      fv_renderer_set_output_path(r, FV_OUTPUT_PATH_READBACK);
      in->Output.reset(new ReadbackOutput);
    }
#else
    in->OutputReason = "this build's ferrovol.h has no shared output path (readback only)";
    in->Output.reset(new ReadbackOutput);
#endif
  }
  std::string warning;
  if (!in->Output->Render(r, req, error, warning))
  {
#if FERROVOL_HAVE_SHARED_OUTPUT
    if (std::strcmp(in->Output->Name(), "shared") == 0)
    {
      // Fall back to the readback path for good and try this frame again.
      vtkWarningMacro(<< "shared output failed, frames go through the CPU from now on: "
                      << error);
      in->Output->ReleaseGraphicsResources(win);
      fv_renderer_set_output_path(r, FV_OUTPUT_PATH_READBACK);
      in->Output.reset(new ReadbackOutput);
      in->OutputReason = "the shared output failed: " + error;
      error.clear();
      warning.clear();
    }
    if (!error.empty() || !in->Output->Render(r, req, error, warning))
#endif
    {
      Fail(this, error);
      return;
    }
  }
  if (!warning.empty() && in->Warned.insert(warning).second)
  {
    vtkWarningMacro(<< warning);
  }
  this->LastRenderSize[0] = req.RenderW;
  this->LastRenderSize[1] = req.RenderH;

  // ---- composite over the viewport
  if (!in->Quad || in->QuadWindow != win)
  {
    in->Quad.reset(new vtkOpenGLQuadHelper(win, nullptr, CompositeFragmentShader, ""));
    in->QuadWindow = win;
  }
  if (!in->Quad->Program)
  {
    Fail(this, "could not compile the shader that composites the volume into OpenGL");
    in->Quad.reset();
    return;
  }
  win->GetShaderCache()->ReadyShaderProgram(in->Quad->Program);
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
  ostate->vtkglViewport(vx, vy, vw, vh);
  int rect[4];
  const double* spacing = image->GetSpacing();
  const double pad = matrixScale *
    std::max({ std::fabs(spacing[0]), std::fabs(spacing[1]), std::fabs(spacing[2]) });
  ProjectedRect(ren, vol, pad, vw, vh, rect);
  if (fullViewport)
  {
    rect[0] = rect[1] = 0;
    rect[2] = vw;
    rect[3] = vh;
  }
  if (rect[2] < 1 || rect[3] < 1)
  {
    this->LastRenderDrew = 1; // the volume is entirely off screen: nothing to composite
    return;
  }
  ostate->vtkglEnable(GL_SCISSOR_TEST);
  ostate->vtkglScissor(vx + rect[0], vy + rect[1], rect[2], rect[3]);
  ostate->vtkglEnable(GL_BLEND);
  ostate->vtkglBlendFuncSeparate(GL_ONE, GL_ONE_MINUS_SRC_ALPHA, GL_ONE, GL_ONE_MINUS_SRC_ALPHA);
  // Rays already stopped at the opaque geometry: the volume's depth is written as is.
  ostate->vtkglEnable(GL_DEPTH_TEST);
  ostate->vtkglDepthFunc(GL_ALWAYS);
  ostate->vtkglDepthMask(GL_TRUE);
  vtkTextureObject* color = in->Output->ColorTexture();
  vtkTextureObject* depth = in->Output->DepthTexture();
  color->Activate();
  depth->Activate();
  in->Quad->Program->SetUniformi("fvColor", color->GetTextureUnit());
  in->Quad->Program->SetUniformi("fvDepth", depth->GetTextureUnit());
  in->Quad->Render();
  depth->Deactivate();
  color->Deactivate();
  vtkOpenGLCheckErrorMacro("after compositing the ferrovol frame");

  timer->StopTimer();
  this->TimeToDraw = timer->GetElapsedTime();
  this->LastRenderDrew = 1;
}

//------------------------------------------------------------------------------------------
void vtkFerroVolumeMapper::PrintSelf(ostream& os, vtkIndent indent)
{
  this->Superclass::PrintSelf(os, indent);
  os << indent << "AutoAdjustSampleDistances: " << this->AutoAdjustSampleDistances << "\n";
  os << indent << "SampleDistance: " << this->SampleDistance << "\n";
  os << indent << "ImageSampleDistance: " << this->ImageSampleDistance << "\n";
  os << indent << "UseJittering: " << this->UseJittering << "\n";
  os << indent << "EmptySpaceSkipping: " << this->EmptySpaceSkipping << "\n";
  os << indent << "EnvironmentLighting: " << this->EnvironmentLighting << "\n";
  os << indent << "EnvironmentMap: "
     << (this->EnvironmentMap && *this->EnvironmentMap ? this->EnvironmentMap : "(sky)") << "\n";
  os << indent << "EnvironmentUp: " << this->EnvironmentUp[0] << " " << this->EnvironmentUp[1]
     << " " << this->EnvironmentUp[2] << "\n";
  os << indent << "EnvironmentAzimuth: " << this->EnvironmentAzimuth << "\n";
  os << indent << "EnvironmentIntensity: " << this->EnvironmentIntensity << "\n";
  os << indent << "EnvironmentBackground: " << this->EnvironmentBackground << "\n";
  os << indent << "SpecularSampling: "
     << (this->SpecularSampling == SPECULAR_CONE ? "cone" : "importance") << "\n";
  os << indent << "SpecularSamples: " << this->SpecularSamples << "\n";
  os << indent << "AmbientOcclusionSamples: " << this->AmbientOcclusionSamples << "\n";
  os << indent << "AmbientOcclusionSteps: " << this->AmbientOcclusionSteps << "\n";
  os << indent << "AmbientOcclusionRadius: " << this->AmbientOcclusionRadius << "\n";
  os << indent << "ShininessFromGradient: " << this->ShininessFromGradient << "\n";
  os << indent << "ShininessRange: " << this->ShininessRange[0] << " "
     << this->ShininessRange[1] << "\n";
  os << indent << "ShininessGradientRange: " << this->ShininessGradientRange[0] << " "
     << this->ShininessGradientRange[1] << "\n";
  os << indent << "Fresnel: " << this->Fresnel << "\n";
  os << indent << "IsosurfaceLayers: " << this->IsosurfaceLayers << "\n";
  os << indent << "IsosurfaceScattering: " << this->IsosurfaceScattering << "\n";
  os << indent << "IsosurfaceScatteringSamples: " << this->IsosurfaceScatteringSamples << "\n";
  os << indent << "IsosurfaceScatteringAbsorption: " << this->IsosurfaceScatteringAbsorption
     << "\n";
  os << indent << "RenderMode: "
     << (this->RenderMode == RENDER_MODE_PATH_TRACE ? "path trace" : "ray cast") << "\n";
  os << indent << "SamplesPerPixel: " << this->SamplesPerPixel << "\n";
  os << indent << "InteractiveSamplesPerPixel: " << this->InteractiveSamplesPerPixel << "\n";
  os << indent << "PathTracingBounces: " << this->PathTracingBounces << "\n";
  os << indent << "PathTracingDenoise: " << this->PathTracingDenoise << "\n";
  os << indent << "VolumetricScatteringBlending: " << this->VolumetricScatteringBlending << "\n";
  os << indent << "GlobalIlluminationReach: " << this->GlobalIlluminationReach << "\n";
  os << indent << "SecondaryRays: " << this->SecondaryRays << "\n";
  os << indent << "GradientThreshold: " << this->GradientThreshold << "\n";
  os << indent << "StochasticBlend: " << this->StochasticBlend << "\n";
  os << indent << "ScatterRegions: " << this->ScatterRegions << "\n";
  os << indent << "Attenuation: " << this->Attenuation << "\n";
  os << indent << "BsdfRoughness: " << this->BsdfRoughness << "\n";
  os << indent << "BsdfFresnel: " << this->BsdfFresnel << "\n";
  os << indent << "Transmission: " << this->Transmission << "\n";
  os << indent << "TransmissionConeAngle: " << this->TransmissionConeAngle << "\n";
  os << indent << "LastRenderDrew: " << this->LastRenderDrew << "\n";
  os << indent << "LastRenderSize: " << this->LastRenderSize[0] << " x "
     << this->LastRenderSize[1] << "\n";
  os << indent << "OutputPath: " << this->OutputPath << " (active: " << this->GetOutputPathName()
     << "; " << this->GetOutputPathReason() << ")\n";
  os << indent << "VolumeUploads: " << this->GetVolumeUploadCount() << "\n";
  os << indent << "TableUploads: " << this->GetTableUploadCount() << "\n";
  os << indent << "Frames: " << this->GetFrameCount() << "\n";
  os << indent << "ferrovol: " << fv_version() << "\n";
}
