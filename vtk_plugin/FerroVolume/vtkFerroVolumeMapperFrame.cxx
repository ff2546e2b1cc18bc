// vtkFerroVolumeMapper's render: Render (progressive path tracing's timer and budget around
// it) and GPURender, which brings the units up to date and draws the frame (see
// vtkFerroVolumeMapper.cxx for the units).
#include "vtkFerroVolumeMapperInternals.h"

//------------------------------------------------------------------------------------------
void vtkFerroVolumeMapper::Render(vtkRenderer* ren, vtkVolume* vol)
{
  if (this->GeneratingCanonicalView)
  {
    this->GPURender(ren, vol);
    return;
  }
  this->InvokeEvent(vtkCommand::VolumeMapperRenderStartEvent, nullptr);
  vtkNew<vtkTimerLog> timer;
  timer->StartTimer();
  // (the same on every process of a parallel render: the sum is a collective operation)
  this->Internals->PieceSum.Begin(this->SumsPieces() && ren && vol && !ren->GetSelector() &&
    !this->RenderToImage && !vtkFerroVolumeDepthPeeling::PeelingPass(vol));
  this->GPURender(ren, vol);
  this->Internals->PieceSum.Finish();
  timer->StopTimer();
  this->TimeToDraw = timer->GetElapsedTime();
  (vol->GetAllocatedRenderTime() < 1.0 ? this->SmallTimeToDraw : this->BigTimeToDraw) =
    this->TimeToDraw;
  this->InvokeEvent(vtkCommand::VolumeMapperRenderEndEvent, nullptr);
}

namespace
{
// A hardware-selection pass of `selector` over `image` (placed by `vol`): what
// vtkGPUVolumeRayCastMapper writes, where the frame shows the volume (vtkFerroVolumeSelection).
bool DrawSelection(vtkFerroVolumeOutput& output, vtkRenderer* ren, vtkVolume* vol,
  vtkImageData* image, vtkHardwareSelector* selector, const vtkFerroVolumeFrameRequest& req,
  const int rect[4], vtkFerroVolumeReport& report)
{
  vtkFerroVolumeSelection select;
  switch (selector->GetCurrentPass())
  {
    case vtkHardwareSelector::CELL_ID_LOW24:
      select.What = vtkFerroVolumeSelection::Write::PointLow24;
      break;
    case vtkHardwareSelector::CELL_ID_HIGH24:
      select.What = vtkFerroVolumeSelection::Write::PointHigh24;
      break;
    default:
      select.What = vtkFerroVolumeSelection::Write::Prop;
      break;
  }
  // device coordinates → world → the point index relative to the extent's first point
  vtkNew<vtkMatrix4x4> deviceToWorld;
  deviceToWorld->DeepCopy(ren->GetActiveCamera()->GetCompositeProjectionTransformMatrix(
    static_cast<double>(req.ViewportW) / req.ViewportH, -1, 1));
  deviceToWorld->Invert();
  const int* extent = image->GetExtent();
  vtkNew<vtkMatrix4x4> fromExtent;
  for (int k = 0; k < 3; ++k)
  {
    fromExtent->SetElement(k, 3, extent[2 * k]);
  }
  vtkNew<vtkMatrix4x4> indexToWorld;
  vtkMatrix4x4::Multiply4x4(vol->GetMatrix(), image->GetIndexToPhysicalMatrix(), indexToWorld);
  vtkMatrix4x4::Multiply4x4(indexToWorld, fromExtent, indexToWorld);
  indexToWorld->Invert();
  vtkNew<vtkMatrix4x4> deviceToIndex;
  vtkMatrix4x4::Multiply4x4(indexToWorld, deviceToWorld, deviceToIndex);
  select.DeviceToIndex = deviceToIndex;
  image->GetDimensions(select.Dims);
  selector->BeginRenderProp();
  selector->GetPropColorValue(select.PropColor);
  const bool drawn =
    output.Select(req, rect, select, report) != vtkFerroVolumeOutput::Composited::Failed;
  const vtkIdType points =
    static_cast<vtkIdType>(select.Dims[0]) * select.Dims[1] * select.Dims[2];
  selector->UpdateMaximumPointId(points);
  selector->UpdateMaximumCellId(points);
  selector->EndRenderProp();
  return drawn;
}
}

//------------------------------------------------------------------------------------------
void vtkFerroVolumeMapper::GPURender(vtkRenderer* ren, vtkVolume* vol)
{
  this->LastRenderDrew = 0;
  this->LastRenderProgressive = 0;
  vtkInternals* in = this->Internals;
  in->Refinement.Begin();
  if (!ren || !vol)
  {
    return;
  }
  // Hardware selection: cell selections, as vtkGPUVolumeRayCastMapper (other associations
  // leave the volume out).
  vtkHardwareSelector* selector = ren->GetSelector();
  if (selector && selector->GetFieldAssociation() != vtkDataObject::FIELD_ASSOCIATION_CELLS)
  {
    return;
  }
  // Inside vtkDualDepthPeelingPass's volumetric peels: the volume between its layers.
  vtkRenderPass* peeling = vtkFerroVolumeDepthPeeling::PeelingPass(vol);
  if (peeling &&
    (this->RenderMode == RENDER_MODE_PATH_TRACE || this->BlendMode == ISOSURFACE_BLEND ||
      this->BlendMode == SLICE_BLEND))
  {
    if (in->Report.FirstTime("depth-peeling"))
    {
      vtkWarningMacro(<< "depth peeling for volumes (vtkRenderer UseDepthPeelingForVolumes "
                         "with translucent geometry) draws ray-cast volumes between the "
                         "translucent layers; path tracing, isosurfaces and slices are not "
                         "drawn there: turn UseDepthPeelingForVolumes off to have this volume "
                         "composited over the translucent geometry (in ParaView: the render "
                         "view's DepthPeelingForVolumes, on by default)");
    }
    return;
  }
  vtkOpenGLRenderWindow* win = vtkOpenGLRenderWindow::SafeDownCast(ren->GetRenderWindow());
  if (!win)
  {
    vtkErrorMacro(<< "vtkFerroVolumeMapper needs an OpenGL render window (vtkOpenGLRenderWindow)");
    return;
  }

  // After a device loss the output's images (imported from the lost device) go with the
  // renderer; both are made again below.
  if (in->RendererLost())
  {
    in->ReleaseDeviceResources(win);
  }

  // A vtkMultiVolume (vtkGPUVolumeRayCastMapper's several inputs): port 0's vtkVolume
  // places and classifies the main volume, the other ports' volumes are intermixed with it;
  // the multi-volume itself gives the box of them all.
  vtkMultiVolume* multi = vtkMultiVolume::SafeDownCast(vol);
  vtkVolume* main = multi ? multi->GetVolume(0) : vol;
  if (!main)
  {
    vtkErrorMacro(<< "the vtkMultiVolume has no vtkVolume on port 0 (SetVolume(volume, 0))");
    return;
  }

  // Blend mode, input, volume (on change), tables (on change), frame parameters.
  vtkFerroVolumeReport& report = in->Report;
  report.ClearError();
  if (!in->Settings.SelectBlendMode(this, report) || !in->Prepare(this, main, multi, report))
  {
    vtkErrorMacro(<< report.GetError());
    return;
  }
  vtkImageData* image = in->Input.GetImage();
  // GetTransformedInput and GetBoundsFromPort see the input, as after the base class's
  // validation.
  this->CloneInput(image, 0);
  // Progressive path tracing: what is left of the render's budget for the tracing.
  const vtkFerroVolumeRefinement::Settings refining = in->Settings.Refining(this);
  double traceBudget = 0.0;
  if (this->RenderMode == RENDER_MODE_PATH_TRACE)
  {
    if (!in->Refinement.BeginTracing(refining, win, *in->Slot.Renderer, report, traceBudget))
    {
      vtkErrorMacro(<< report.GetError());
      return;
    }
  }
  else
  {
    in->Refinement.Stop();
  }
  const bool progressive = in->Refinement.IsTracing();
  in->Settings.SetIntermixing(multi != nullptr);
  switch (
    in->Settings.Apply(this, ren, main, in->Input, *in->Slot.Renderer, traceBudget, report))
  {
    case vtkFerroVolumeSettings::Result::Failed:
      vtkErrorMacro(<< report.GetError());
      return;
    case vtkFerroVolumeSettings::Result::NothingVisible:
      return;
    case vtkFerroVolumeSettings::Result::Ready:
      break;
  }

  // Camera and lights for this viewport.
  vtkFerroVolumeFrameRequest req;
  if (!req.ForViewport(ren, vol, win))
  {
    return;
  }
  if (!in->Settings.ApplyView(
        this, ren, req.ViewportW, req.ViewportH, *in->Slot.Renderer, report))
  {
    vtkErrorMacro(<< report.GetError());
    return;
  }

  // Render at the resolution ImageSampleDistance reduces the viewport to (whether
  // AutoAdjustSampleDistances is on or off, as VTK 9.2), through the output path.
  req.RenderW = std::max(1, static_cast<int>(req.ViewportW / this->ImageSampleDistance));
  req.RenderH = std::max(1, static_cast<int>(req.ViewportH / this->ImageSampleDistance));
  req.ColorScale = 1.0f / this->FinalColorWindow;
  req.ColorBias = 0.5f - this->FinalColorLevel / this->FinalColorWindow;
  if (peeling && !selector && !this->RenderToImage)
  {
    if (!in->Peeling.Draw(peeling, this, vol, *in->Slot.Renderer, req, report))
    {
      vtkErrorMacro(<< report.GetError());
      return;
    }
    this->LastRenderSize[0] = req.RenderW;
    this->LastRenderSize[1] = req.RenderH;
    this->LastRenderDrew = 1;
    return;
  }
  std::string warning;
  // (a frame summed across processes is read back, and the sum written into its texture)
  const int outputPath = in->PieceSum.Pending() ? OUTPUT_PATH_READBACK : this->OutputPath;
  if (!in->Output.Render(outputPath, *in->Slot.Renderer, req, report, warning))
  {
    vtkErrorMacro(<< report.GetError());
    return;
  }
  if (!warning.empty())
  {
    report.WarnOnce(warning);
  }
  bool draw = true;
  if (!in->PieceSum.Add(in->Output.ColorTexture(), req.RenderW, req.RenderH, draw, report))
  {
    vtkErrorMacro(<< report.GetError());
    return;
  }
  this->LastRenderSize[0] = req.RenderW;
  this->LastRenderSize[1] = req.RenderH;
  if (!draw)
  {
    this->LastRenderDrew = 1; // another process draws the sum this frame joined
    return;
  }

  // The part of the viewport the volume can cover (where the frame is composited).
  int rect[4] = { 0, 0, req.ViewportW, req.ViewportH };
  if (!in->Settings.CoversViewport())
  {
    const double* spacing = image->GetSpacing();
    const double pad = vtkFerroVolumeLookupTables::MatrixScale(vol) *
      std::max({ std::fabs(spacing[0]), std::fabs(spacing[1]), std::fabs(spacing[2]) });
    vtkFerroVolumeOutput::ProjectedRect(ren, vol, pad, req.ViewportW, req.ViewportH, rect);
  }
  if (selector)
  {
    if (!DrawSelection(in->Output, ren, main, image, selector, req, rect, report))
    {
      vtkErrorMacro(<< report.GetError());
      return;
    }
    this->LastRenderDrew = 1;
    return;
  }
  if (this->RenderToImage)
  {
    // The frame goes into the images, not the window.
    int depthType = this->DepthImageScalarType;
    if (!vtkFerroVolumeRenderToImage::IsDepthType(depthType))
    {
      if (in->Report.FirstTime("depth-image-type"))
      {
        vtkWarningMacro(<< "DepthImageScalarType " << depthType
                        << " is not supported (unsigned char, unsigned short and float are): "
                           "the depth image is float");
      }
      depthType = VTK_FLOAT;
    }
    vtkNew<vtkMatrix4x4> boxToClip;
    vtkFerroVolumeRenderToImage::BoxToClip(ren, main, image, boxToClip);
    if (!in->Image.Capture(req, in->Output.ColorTexture(), in->Output.DepthTexture(), depthType,
          boxToClip, this->ClampDepthToBackface != 0, report))
    {
      vtkErrorMacro(<< report.GetError());
      return;
    }
  }
  else
  {
    switch (in->Output.Composite(req, rect, report))
    {
      case vtkFerroVolumeOutput::Composited::Failed:
        vtkErrorMacro(<< report.GetError());
        return;
      case vtkFerroVolumeOutput::Composited::OffScreen:
        this->LastRenderDrew = 1; // nothing to composite
        return;
      case vtkFerroVolumeOutput::Composited::Drawn:
        break;
    }
    if (this->GeneratingCanonicalView && this->CanonicalViewImageData)
    {
      // CreateCanonicalView: the window as drawn so far (its other props are hidden).
      int dims[3];
      this->CanonicalViewImageData->GetDimensions(dims);
      vtkUnsignedCharArray* pixels = vtkUnsignedCharArray::SafeDownCast(
        this->CanonicalViewImageData->GetPointData()->GetScalars());
      if (pixels && pixels->GetNumberOfComponents() == 3)
      {
        win->GetPixelData(0, 0, dims[0] - 1, dims[1] - 1, 0, pixels, 0);
      }
    }
  }
  this->LastRenderDrew = 1;
  if (progressive)
  {
    // Refine while the accumulation is short of SamplesPerPixel.
    if (!in->Refinement.EndTracing(
          refining, this, win, req.RenderW, req.RenderH, *in->Slot.Renderer, report))
    {
      vtkErrorMacro(<< report.GetError());
      return;
    }
    this->LastRenderProgressive = 1;
  }
}
