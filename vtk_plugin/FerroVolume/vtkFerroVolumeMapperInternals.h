// The state vtkFerroVolumeMapper keeps between renders (its units and the ferrovol renderer),
// shared by the mapper's two sources: vtkFerroVolumeMapper.cxx (settings, queries,
// resources) and vtkFerroVolumeMapperFrame.cxx (a render). Private: neither wrapped nor
// installed.
#ifndef vtkFerroVolumeMapperInternals_h
#define vtkFerroVolumeMapperInternals_h

#include "vtkFerroVolumeMapper.h"

#include "vtkFerroVolumeContext.h"
#include "vtkFerroVolumeDepthPeeling.h"
#include "vtkFerroVolumeDepthReader.h"
#include "vtkFerroVolumeInputHelper.h"
#include "vtkFerroVolumeIntermix.h"
#include "vtkFerroVolumeLookupTables.h"
#include "vtkFerroVolumeOutput.h"
#include "vtkFerroVolumePieceSum.h"
#include "vtkFerroVolumeRefinement.h"
#include "vtkFerroVolumeRenderToImage.h"
#include "vtkFerroVolumeReport.h"
#include "vtkFerroVolumeSettings.h"
#include "vtkBoundingBox.h"
#include "vtkCamera.h"
#include "vtkCommand.h"
#include "vtkDataObject.h"
#include "vtkHardwareSelector.h"
#include "vtkInformation.h"
#include "vtkInformationObjectBaseVectorKey.h"
#include "vtkImageData.h"
#include "vtkMatrix4x4.h"
#include "vtkMultiVolume.h"
#include "vtkNew.h"
#include "vtkObjectFactory.h"
#include "vtkOpenGLRenderWindow.h"
#include "vtkPointData.h"
#include "vtkRenderer.h"
#include "vtkTimerLog.h"
#include "vtkUnsignedCharArray.h"
#include "vtkVolume.h"

#include <algorithm>
#include <cmath>
#include <memory>
#include <optional>
#include <string>

class vtkFerroVolumeMapper::vtkInternals
{
public:
  vtkFerroVolumeRendererSlot Slot;
  vtkFerroVolumeInputHelper Input;
  vtkFerroVolumeLookupTables Tables;
  vtkFerroVolumeIntermix Intermix;
  vtkFerroVolumeSettings Settings;
  vtkFerroVolumeOutput Output;
  vtkFerroVolumeDepthPeeling Peeling;
  vtkFerroVolumeRenderToImage Image;
  vtkFerroVolumeRefinement Refinement;
  vtkFerroVolumePieceSum PieceSum;
  vtkFerroVolumeInputHelper::WholeRanges WholeRanges{};
  // the render's error and the warnings said once per mapper
  vtkFerroVolumeReport Report;
  // the convergence read back for the frame counted `ConvergenceFrame` (stats().frames)
  std::optional<FvConvergence> Convergence;
  uint32_t ConvergenceFrame = 0;

  explicit vtkInternals(vtkFerroVolumeMapper* self)
    : Report(self)
  {
  }
  ~vtkInternals() { this->FreeRenderer(); }

  // Whether the renderer was made on a device since lost.
  bool RendererLost() const { return this->Slot.Lost(); }

  // The renderer, created on first use from the process-wide device; the passes of a
  // streamed frame (a volume over the memory budget) report to `self`'s progress. A
  // renderer made on a device since lost is made again (with its input and tables).
  bool MakeRenderer(vtkFerroVolumeMapper* self, vtkFerroVolumeReport& report)
  {
    if (this->Slot.Renderer && !this->Slot.Lost())
    {
      return true;
    }
    this->FreeRenderer();
    return this->Slot.Make(report) && vtkFerroVolumeCall("create a renderer", report, [&] {
      this->Slot.Renderer->set_progress(&vtkInternals::StreamProgress, self);
    });
  }

  // Each pass of a streamed frame is a ProgressEvent while ReportProgress is on.
  static void StreamProgress(void* mapper, uint32_t done, uint32_t total)
  {
    vtkFerroVolumeMapper* self = static_cast<vtkFerroVolumeMapper*>(mapper);
    if (self->GetReportProgress())
    {
      self->UpdateProgress(static_cast<double>(done) / static_cast<double>(total));
    }
  }

  // The input selected and uploaded (on change) within the mapper's memory budget, the
  // property's tables (on change) and the volumes of `multi`'s other ports (none: cleared);
  // false with the reason.
  bool Prepare(
    vtkFerroVolumeMapper* self, vtkVolume* vol, vtkMultiVolume* multi, vtkFerroVolumeReport& report)
  {
    const vtkIdType bytes = self->GetMaxMemoryInBytes();
    const uint64_t budget = bytes > 0
      ? static_cast<uint64_t>(static_cast<double>(bytes) * self->GetMaxMemoryFraction())
      : 0;
    vtkFerroVolumeLookupTables::RangeTypes types;
    types.Color = self->GetColorRangeType();
    types.ScalarOpacity = self->GetScalarOpacityRangeType();
    types.GradientOpacity = self->GetGradientOpacityRangeType();
    this->Input.SetWholeRanges(this->WholeRanges);
    if (!(this->Input.Select(self, report) && this->MakeRenderer(self, report) &&
          this->Input.Upload(*this->Slot.Renderer, budget, report)))
    {
      return false;
    }
    if (!this->Input.UpdateBlanking(*this->Slot.Renderer, report))
    {
      report.WarnOnce("blanking",
        "the ghost arrays' blanking is not applied (the cells are drawn): " + report.GetError());
      report.ClearError();
    }
    if (!this->Input.UpdateMask(
          self->GetMaskInput(), self->GetMaskType(), *this->Slot.Renderer, report))
    {
      report.PrefixError("MaskInput: ");
      return false;
    }
    return this->Tables.Update(vol, this->Input, types, *this->Slot.Renderer, report) &&
      this->Intermix.Update(self, multi, types, *this->Slot.Renderer, report);
  }

  void FreeRenderer()
  {
    this->Slot.Renderer.reset();
    this->Input.Reset();
    this->Tables.Reset();
    this->Intermix.Reset();
    this->Settings.Reset();
    this->Convergence.reset();
  }

  // The output's images in `window` and RenderToImage's, all made from the renderer's
  // device.
  void ReleaseWindowResources(vtkWindow* window)
  {
    this->Output.ReleaseGraphicsResources(window);
    this->Peeling.ReleaseGraphicsResources(window);
    this->Image.ReleaseGraphicsResources();
  }

  // Those and the renderer.
  void ReleaseDeviceResources(vtkWindow* window)
  {
    this->ReleaseWindowResources(window);
    this->FreeRenderer();
  }

  // The renderer's counters; false before the first frame.
  bool Stats(FvStats& s) const
  {
    if (!this->Slot.Renderer)
    {
      return false;
    }
    try
    {
      s = this->Slot.Renderer->stats();
      return true;
    }
    catch (const ferrovol::Error&)
    {
      return false;
    }
  }

  // The path tracer's convergence, read back once per frame; false before the first frame.
  bool ReadConvergence(FvConvergence& c)
  {
    FvStats s;
    if (!this->Stats(s))
    {
      return false;
    }
    try
    {
      if (!this->Convergence || this->ConvergenceFrame != s.frames)
      {
        this->Convergence = this->Slot.Renderer->convergence();
        this->ConvergenceFrame = s.frames;
      }
      c = *this->Convergence;
      return true;
    }
    catch (const ferrovol::Error&)
    {
      return false;
    }
  }
};

#endif
