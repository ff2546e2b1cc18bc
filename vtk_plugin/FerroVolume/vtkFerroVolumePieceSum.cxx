#include "vtkFerroVolumePieceSum.h"

#include "vtkCommunicator.h"
#include "vtkFerroVolumeReport.h"
#include "vtkMultiProcessController.h"
#include "vtkTextureObject.h"
#include "vtkType.h"
#include "vtkFerroVolumeGL.h"

#include <algorithm>
#include <climits>

namespace
{
vtkMultiProcessController* Processes()
{
  vtkMultiProcessController* controller = vtkMultiProcessController::GetGlobalController();
  return controller && controller->GetNumberOfProcesses() > 1 ? controller : nullptr;
}

// A pixel's share of the sum: its grey level (the frame's red channel: additive frames are
// grey), and in bits 32 and up whether a ray had samples there (alpha > 0).
constexpr long long CoveredBit = 1LL << 32;
}

void vtkFerroVolumePieceSum::Begin(bool active)
{
  this->Waiting = active && Processes() != nullptr;
}

bool vtkFerroVolumePieceSum::Add(
  vtkTextureObject* color, int w, int h, bool& draw, vtkFerroVolumeReport& report)
{
  draw = true;
  const char* warning = nullptr;
  if (!this->Waiting)
  {
    return true;
  }
  this->Waiting = false;
  bool read = false;
  this->Pixels.assign(static_cast<size_t>(w) * h * 4, 0);
  if (color && color->GetWidth() == static_cast<unsigned>(w) &&
    color->GetHeight() == static_cast<unsigned>(h) && color->GetComponents() == 4)
  {
    for (int i = 0; i < 16 && glGetError() != GL_NO_ERROR; ++i)
    {
      // (errors left by others: not this read's)
    }
    color->Activate();
    // (into client memory: a pixel-pack buffer left bound would take the texels instead)
    GLint pack = 0;
    glGetIntegerv(GL_PIXEL_PACK_BUFFER_BINDING, &pack);
    glBindBuffer(GL_PIXEL_PACK_BUFFER, 0);
    glGetTexImage(GL_TEXTURE_2D, 0, GL_RGBA, GL_UNSIGNED_BYTE, this->Pixels.data());
    glBindBuffer(GL_PIXEL_PACK_BUFFER, static_cast<GLuint>(pack));
    color->Deactivate();
    read = glGetError() == GL_NO_ERROR;
  }
  if (!read)
  {
    this->Pixels.clear();
  }
  switch (this->Reduce(this->Pixels, w, h))
  {
    case Outcome::Skip:
      draw = false;
      break;
    case Outcome::DrawOwn:
      warning = "the additive blend mode's frames differ in size between the processes (an "
                "ImageSampleDistance of their own?): each process's sum is composited with "
                "\"over\", which darkens where two pieces' sums add up past 1";
      break;
    case Outcome::Draw:
      if (!color->Create2DFromRaw(w, h, 4, VTK_UNSIGNED_CHAR, this->Pixels.data()))
      {
        draw = false;
        return report.Fail("could not write the additive sum of the processes' frames into "
                           "the frame's texture");
      }
      break;
  }
  if (!read)
  {
    draw = false;
    return report.Fail("could not read the frame back to add it to the other processes' "
                       "(additive blend mode)");
  }
  if (warning)
  {
    report.WarnOnce(warning);
  }
  return true;
}

void vtkFerroVolumePieceSum::Finish()
{
  if (this->Waiting)
  {
    this->Waiting = false;
    std::vector<unsigned char> none;
    this->Reduce(none, 0, 0);
  }
}

vtkFerroVolumePieceSum::Outcome vtkFerroVolumePieceSum::Reduce(
  std::vector<unsigned char>& rgba, int w, int h)
{
  vtkMultiProcessController* controller = Processes();
  const int rank = controller->GetLocalProcessId();
  const int n = controller->GetNumberOfProcesses();
  const bool frame = !rgba.empty();
  // Over the processes with a frame: the largest and smallest width and height, and the
  // lowest rank (as n − rank, maximised).
  const int mine[5] = { frame ? w : INT_MIN, frame ? h : INT_MIN, frame ? -w : INT_MIN,
    frame ? -h : INT_MIN, frame ? n - rank : 0 };
  int all[5];
  controller->AllReduce(mine, all, 5, vtkCommunicator::MAX_OP);
  if (all[4] == 0)
  {
    return Outcome::Skip; // no process has a frame
  }
  if (all[0] != -all[2] || all[1] != -all[3])
  {
    return Outcome::DrawOwn;
  }
  const int drawer = n - all[4];
  const size_t pixels = static_cast<size_t>(all[0]) * all[1];
  std::vector<long long> shares(pixels, 0);
  if (frame)
  {
    for (size_t i = 0; i < pixels; ++i)
    {
      shares[i] = rgba[4 * i] + (rgba[4 * i + 3] > 0 ? CoveredBit : 0);
    }
  }
  std::vector<long long> sum(rank == drawer ? pixels : 0);
  controller->Reduce(shares.data(), sum.data(), static_cast<vtkIdType>(pixels),
    vtkCommunicator::SUM_OP, drawer);
  if (rank != drawer)
  {
    return Outcome::Skip;
  }
  for (size_t i = 0; i < pixels; ++i)
  {
    const auto grey = static_cast<unsigned char>(std::min<long long>(sum[i] % CoveredBit, 255));
    const unsigned char alpha = sum[i] >= CoveredBit ? 255 : 0;
    rgba[4 * i] = rgba[4 * i + 1] = rgba[4 * i + 2] = grey;
    rgba[4 * i + 3] = alpha;
  }
  return Outcome::Draw;
}
