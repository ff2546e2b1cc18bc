// vtkFerroVolumeRefinement: progressive path tracing. Decides whether a render traces within
// a time budget (the rule is stated in vtkFerroVolumeMapper.h), gives the tracing of each
// progressive render what is left of the budget once the rest of the render is counted, and,
// while the accumulation is short of SamplesPerPixel and the camera rests, asks the window's
// interactor for the next render with a one-shot timer. Internal to the FerroVolume module
// (not wrapped).
#ifndef vtkFerroVolumeRefinement_h
#define vtkFerroVolumeRefinement_h

#include "vtkNew.h"
#include "vtkWeakPointer.h"

#include <chrono>
#include <cstdint>

namespace ferrovol
{
class Renderer;
}
class vtkCallbackCommand;
class vtkFerroVolumeReport;
class vtkObject;
class vtkRenderWindow;
class vtkRenderWindowInteractor;

class vtkFerroVolumeRefinement
{
public:
  vtkFerroVolumeRefinement();
  vtkFerroVolumeRefinement(const vtkFerroVolumeRefinement&) = delete;
  vtkFerroVolumeRefinement& operator=(const vtkFerroVolumeRefinement&) = delete;
  ~vtkFerroVolumeRefinement();

  // Whether renders into `win` trace within a time budget: `mode` (a
  // vtkFerroVolumeEnums::ProgressiveModes value) is ON, or AUTOMATIC and the window has an
  // interactor that can refine it (see CanRefine).
  bool IsProgressive(int mode, vtkRenderWindow* win);

  // A render's whole time budget in seconds: `budget` when positive, otherwise
  // 1/DesiredUpdateRate of `win`, at most MaxAutomaticBudget.
  static double FrameBudget(double budget, vtkRenderWindow* win);
  static constexpr double MaxAutomaticBudget = 0.1;

  // Marks the start of a render.
  void Begin();

  // Seconds the tracing of this render may take: `frame` less the time since Begin and the
  // time a budget-limited render spends after its tracing (the most of the last
  // AfterTraceRenders, counted apart for renders that are `denoised`, as this one is
  // expected to be, and those that are not: the denoiser, the readback and the compositing
  // follow the tracing), and at least MinTraceShare of `frame`: where the rest of the render
  // takes longer (large windows on a CPU device), renders exceed the budget but still trace.
  double TraceBudget(double frame, bool denoised);
  static constexpr double MinTraceShare = 0.5;
  static constexpr int AfterTraceRenders = 4;

  // Marks the end of a progressive render of `width` × `height` pixels, `denoised` or not,
  // whose tracing was given TraceBudget's seconds. What the render spent beyond that is
  // recorded for the next ones when the tracing took its budget (`limited`: the
  // accumulation is short of its target) and the size is the last render's (a new size
  // allocates images and textures).
  void End(bool limited, bool denoised, int width, int height);

  // After a progressive render into `win` that left `samples` complete passes of `target`
  // (`restarted`: the render started the accumulation over): while fewer and the window
  // rests (DesiredUpdateRate at most 1), makes sure a one-shot timer of its interactor will
  // render it again (interactor->Render(), so that applications which route renders
  // through the interactor's RenderEvent, as ParaView does, render the whole view);
  // otherwise cancels the pending timer. Returns false when it stops because the
  // accumulation restarts by itself: StallLimit renders in a row asked for by the timer
  // that each started over.
  bool Continue(vtkRenderWindow* win, unsigned int samples, unsigned int target, bool restarted);
  static constexpr int StallLimit = 4;

  // Cancels the pending timer and stops observing the interactor.
  void Stop();

  // A mapper's path tracing settings as the refinement reads them: ProgressiveMode,
  // PathTracingTimeBudget, PathTracingDenoise, the paths below which the preview is
  // denoised (vtkFerroVolumeSettings::DenoiseUntil) and SamplesPerPixel.
  struct Settings
  {
    int Mode = 0;
    double Budget = 0.0;
    bool Denoise = false;
    uint32_t DenoiseUntil = 0;
    uint32_t Target = 1;
  };

  // A path-traced render into `win`, after Begin: whether it is progressive (IsProgressive;
  // if not, the refinement stops) and then the seconds its tracing may take (TraceBudget;
  // `traceBudget` stays 0 otherwise), the preview taken as denoised while the accumulation
  // is short of DenoiseUntil or the window renders interactively. False when `renderer`
  // cannot count its paths (the reason in `report`).
  bool BeginTracing(const Settings& s, vtkRenderWindow* win, ferrovol::Renderer& renderer,
    vtkFerroVolumeReport& report, double& traceBudget);
  // Whether the render BeginTracing began is progressive (false once stopped).
  bool IsTracing() const { return this->Tracing; }
  // After that progressive render of `width` × `height` pixels was drawn: End, then
  // Continue toward Target with the paths it has; when it stops because every render starts
  // the accumulation over, `self` (the mapper) warns once (`report`). False when `renderer`
  // cannot count the paths (the reason in `report`; the refinement stops).
  bool EndTracing(const Settings& s, vtkObject* self, vtkRenderWindow* win, int width,
    int height, ferrovol::Renderer& renderer, vtkFerroVolumeReport& report);

private:
  using Clock = std::chrono::steady_clock;

  // Whether `iren` is enabled and creates timers (platform interactors do; a
  // vtkGenericRenderWindowInteractor whose application handles no timers, as pvbatch's,
  // does not). Tried once per interactor.
  bool CanRefine(vtkRenderWindowInteractor* iren);
  static void OnTimer(vtkObject* caller, unsigned long event, void* self, void* timerId);

  // The interactor observed (TimerEvent) and the window its timer renders.
  vtkWeakPointer<vtkRenderWindowInteractor> Interactor;
  vtkWeakPointer<vtkRenderWindow> Window;
  vtkNew<vtkCallbackCommand> Callback;
  unsigned long ObserverTag = 0;
  // The pending one-shot timer, and the last one that fired: X's interactor keeps a fired
  // one-shot timer in its map until it is destroyed, which is safe only outside its own
  // TimerEvent (the next one does it).
  int TimerId = 0;
  int FiredId = 0;
  // Whether the render under way was asked for by the timer; how many such renders in a
  // row started the accumulation over.
  bool TimerRender = false;
  int Stalled = 0;
  // Whether the render under way traces progressively, and the accumulation's restarts
  // before it.
  bool Tracing = false;
  uint64_t RestartsBefore = 0;

  vtkWeakPointer<vtkRenderWindowInteractor> Probed;
  bool ProbedCanRefine = false;

  Clock::time_point Start;
  Clock::time_point TraceStart;
  double Traced = 0.0;
  // Seconds after the tracing of the last AfterTraceRenders budget-limited renders, without
  // and with the denoiser, and where the next one goes.
  double AfterTrace[2][AfterTraceRenders] = {};
  int AfterTraceNext[2] = {};
  int Size[2] = { 0, 0 };
};

#endif
