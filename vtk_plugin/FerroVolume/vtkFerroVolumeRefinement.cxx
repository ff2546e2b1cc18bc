#include "vtkFerroVolumeRefinement.h"

#include "vtkCallbackCommand.h"
#include "vtkCommand.h"
#include "vtkFerroVolumeContext.h"
#include "vtkFerroVolumeEnums.h"
#include "vtkFerroVolumeReport.h"
#include "vtkRenderWindow.h"
#include "vtkRenderWindowInteractor.h"

#include <algorithm>

namespace
{
// Milliseconds between a refining render and the next: the event loop handles the user's
// input in between.
constexpr unsigned long RefineDelay = 1;

double Seconds(std::chrono::steady_clock::duration d)
{
  return std::chrono::duration<double>(d).count();
}
} // namespace

vtkFerroVolumeRefinement::vtkFerroVolumeRefinement()
{
  this->Callback->SetCallback(&vtkFerroVolumeRefinement::OnTimer);
  this->Callback->SetClientData(this);
}

vtkFerroVolumeRefinement::~vtkFerroVolumeRefinement()
{
  this->Stop();
}

bool vtkFerroVolumeRefinement::CanRefine(vtkRenderWindowInteractor* iren)
{
  if (!iren || !iren->GetEnabled())
  {
    return false;
  }
  if (iren != this->Probed)
  {
    this->Probed = iren;
    const int id = iren->CreateOneShotTimer(60000);
    this->ProbedCanRefine = id != 0;
    if (id != 0)
    {
      iren->DestroyTimer(id);
    }
  }
  return this->ProbedCanRefine;
}

bool vtkFerroVolumeRefinement::IsProgressive(int mode, vtkRenderWindow* win)
{
  switch (mode)
  {
    case vtkFerroVolumeEnums::PROGRESSIVE_ON:
      return true;
    case vtkFerroVolumeEnums::PROGRESSIVE_OFF:
      return false;
    default:
      return win && this->CanRefine(win->GetInteractor());
  }
}

double vtkFerroVolumeRefinement::FrameBudget(double budget, vtkRenderWindow* win)
{
  if (budget > 0.0)
  {
    return budget;
  }
  const double rate = win ? win->GetDesiredUpdateRate() : 0.0;
  return rate > 1.0 / MaxAutomaticBudget ? 1.0 / rate : MaxAutomaticBudget;
}

void vtkFerroVolumeRefinement::Begin()
{
  this->Start = Clock::now();
}

double vtkFerroVolumeRefinement::TraceBudget(double frame, bool denoised)
{
  this->TraceStart = Clock::now();
  const double* after = this->AfterTrace[denoised];
  this->Traced = std::max(MinTraceShare * frame,
    frame - Seconds(this->TraceStart - this->Start) -
      *std::max_element(after, after + AfterTraceRenders));
  return this->Traced;
}

void vtkFerroVolumeRefinement::End(bool limited, bool denoised, int width, int height)
{
  const bool resized = width != this->Size[0] || height != this->Size[1];
  this->Size[0] = width;
  this->Size[1] = height;
  if (limited && !resized)
  {
    int& next = this->AfterTraceNext[denoised];
    this->AfterTrace[denoised][next] =
      std::max(0.0, Seconds(Clock::now() - this->TraceStart) - this->Traced);
    next = (next + 1) % AfterTraceRenders;
  }
}

bool vtkFerroVolumeRefinement::Continue(
  vtkRenderWindow* win, unsigned int samples, unsigned int target, bool restarted)
{
  this->Stalled = this->TimerRender && restarted ? this->Stalled + 1 : 0;
  this->TimerRender = false;
  vtkRenderWindowInteractor* iren = win ? win->GetInteractor() : nullptr;
  if (!iren || iren != this->Interactor || win != this->Window)
  {
    this->Stop();
  }
  const bool restarting = this->Stalled >= StallLimit;
  if (samples >= target || restarting || !iren || win->GetDesiredUpdateRate() > 1.0 ||
    !this->CanRefine(iren))
  {
    if (this->TimerId != 0)
    {
      iren->DestroyTimer(this->TimerId);
      this->TimerId = 0;
    }
    return !restarting;
  }
  if (!this->Interactor)
  {
    this->Interactor = iren;
    this->Window = win;
    this->ObserverTag = iren->AddObserver(vtkCommand::TimerEvent, this->Callback);
  }
  if (this->TimerId == 0)
  {
    this->TimerId = iren->CreateOneShotTimer(RefineDelay);
  }
  return true;
}

void vtkFerroVolumeRefinement::Stop()
{
  if (vtkRenderWindowInteractor* iren = this->Interactor)
  {
    if (this->TimerId != 0)
    {
      iren->DestroyTimer(this->TimerId);
    }
    iren->RemoveObserver(this->ObserverTag);
  }
  this->Interactor = nullptr;
  this->Window = nullptr;
  this->ObserverTag = 0;
  this->TimerId = 0;
  this->FiredId = 0;
  this->Tracing = false;
}

void vtkFerroVolumeRefinement::OnTimer(vtkObject*, unsigned long, void* self, void* timerId)
{
  auto* r = static_cast<vtkFerroVolumeRefinement*>(self);
  if (!timerId || r->TimerId == 0 || *static_cast<int*>(timerId) != r->TimerId)
  {
    return;
  }
  vtkRenderWindowInteractor* iren = r->Interactor;
  if (r->FiredId != 0)
  {
    iren->DestroyTimer(r->FiredId);
  }
  r->FiredId = r->TimerId;
  r->TimerId = 0;
  vtkRenderWindow* win = r->Window;
  if (win && win->GetInteractor() == iren && win->GetDesiredUpdateRate() <= 1.0)
  {
    r->TimerRender = true;
    // (nothing of `r` is used after this: the render may end the mapper)
    iren->Render();
  }
}

bool vtkFerroVolumeRefinement::BeginTracing(const Settings& s, vtkRenderWindow* win,
  ferrovol::Renderer& renderer, vtkFerroVolumeReport& report, double& traceBudget)
{
  traceBudget = 0.0;
  this->Tracing = this->IsProgressive(s.Mode, win);
  if (!this->Tracing)
  {
    this->Stop();
    return true;
  }
  uint32_t before = 0;
  if (!vtkFerroVolumeCall("count the accumulated paths", report, [&] {
        before = renderer.accumulated_samples();
        this->RestartsBefore = renderer.stats().accumulation_restarts;
      }))
  {
    this->Tracing = false;
    return false;
  }
  const bool denoised = s.Denoise ||
    (s.DenoiseUntil > 0 && (before < s.DenoiseUntil || win->GetDesiredUpdateRate() > 1.0));
  traceBudget = this->TraceBudget(FrameBudget(s.Budget, win), denoised);
  return true;
}

bool vtkFerroVolumeRefinement::EndTracing(const Settings& s, vtkObject* self,
  vtkRenderWindow* win, int width, int height, ferrovol::Renderer& renderer,
  vtkFerroVolumeReport& report)
{
  unsigned int samples = 0;
  uint64_t restarts = 0;
  if (!vtkFerroVolumeCall("count the accumulated paths", report, [&] {
        samples = renderer.accumulated_samples();
        restarts = renderer.stats().accumulation_restarts;
      }))
  {
    this->Stop();
    return false;
  }
  this->End(samples < s.Target, s.Denoise || samples < s.DenoiseUntil, width, height);
  if (!this->Continue(win, samples, s.Target, restarts != this->RestartsBefore) &&
    report.FirstTime("restarts"))
  {
    vtkWarningWithObjectMacro(self, << "path tracing starts over at every render (something "
                                       "the image depends on changes each time, such as "
                                       "opaque geometry moved on every render), so the view "
                                       "stops refining itself at "
                                    << samples
                                    << " paths per pixel; render with ProgressiveModeToOff "
                                       "for SamplesPerPixel paths");
  }
  return true;
}
