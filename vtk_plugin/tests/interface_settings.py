"""What test_interface.py checks each setting of vtkGPUVolumeRayCastMapper's interface
against: the rig (a small scene, a fresh mapper per check), the kinds of check (image,
warned, state, effect), the table of settings and the arguments of the other methods."""

import hashlib
import inspect
import math
import types

import numpy as np
import vtk
from vtk.util.numpy_support import numpy_to_vtk, vtk_to_numpy

import ferrovol
import fvtest
from fvtest import Errors

SIZE = (64, 64)


def view(cam):
    cam.Azimuth(30.0)
    cam.Elevation(20.0)
    cam.OrthogonalizeViewUp()


def make_data(maximum=255.0):
    """The 32³ wavelet at spacing 0.5 (so that AutoAdjustSampleDistances, the smallest
    spacing, differs from SampleDistance 1) with a second point array 'Other' and cell
    scalars 'Cells'."""
    img = vtk.vtkImageData()
    img.DeepCopy(fvtest.wavelet(15, maximum).GetOutput())
    img.SetSpacing(0.5, 0.5, 0.5)
    rt = vtk_to_numpy(img.GetPointData().GetScalars()).astype(np.float32)
    other = numpy_to_vtk(320.0 - rt, deep=True)
    other.SetName("Other")
    img.GetPointData().AddArray(other)
    cells = numpy_to_vtk(np.ascontiguousarray(
        rt.reshape(32, 32, 32)[:31, :31, :31][::-1].reshape(-1)), deep=True)
    cells.SetName("Cells")
    img.GetCellData().SetScalars(cells)
    return img


def make_mask(inside=255):
    """A mask of the volume's half (`inside` there, 0 elsewhere): a binary mask as VTK's masks
    are, or a label map of one label."""
    mask = vtk.vtkImageData()
    mask.SetDimensions(32, 32, 32)
    mask.SetOrigin(-7.5, -7.5, -7.5)
    mask.SetSpacing(0.5, 0.5, 0.5)
    values = np.zeros((32, 32, 32), np.uint8)
    values[:, :, :16] = inside
    mask.GetPointData().SetScalars(numpy_to_vtk(values.reshape(-1), deep=True))
    return mask


def make_property():
    """Shaded; colour and opacity functions over a part of the data range (so the NATIVE
    range types change the image), a gradient opacity function and an iso-value."""
    p = fvtest.volume_property([(100, 0.1, 0.2, 0.9), (200, 1.0, 0.8, 0.1)],
                               [(60, 0.0), (280, 0.6)])
    p.SetGradientOpacity(fvtest.opacity_function([(0, 0.2), (12, 1.0)]))
    p.SetInterpolationTypeToLinear()
    p.ShadeOn()
    p.GetIsoSurfaceValues().SetValue(0, 160.0)
    return p


class Rig:
    """One window, renderer and volume; each check renders a new mapper in it."""

    def __init__(self):
        self.data = make_data()
        self.data2 = make_data(maximum=180.0)
        self.source2 = vtk.vtkTrivialProducer()
        self.source2.SetOutput(self.data2)
        self.mask = make_mask()
        self.labels = make_mask(inside=1)
        self.prop = make_property()
        self.volume = vtk.vtkVolume()
        self.volume.SetProperty(self.prop)
        self.renderer = vtk.vtkRenderer()
        self.renderer.AddVolume(self.volume)
        self.window = fvtest.new_window()
        self.window.SetSize(*SIZE)
        self.window.AddRenderer(self.renderer)
        self.mapper = None
        m = self.new()
        self.renderer.ResetCamera()
        view(self.renderer.GetActiveCamera())
        self.renderer.ResetCameraClippingRange()
        self.camera = self.renderer.GetActiveCamera()  # (CreateCanonicalView needs a holder)
        self.done(m)

    def new(self):
        m = ferrovol.vtkFerroVolumeMapper()
        m.errors = Errors(m)
        m.progress_seen = []
        m.AddObserver("ProgressEvent", lambda o, e: o.progress_seen.append(o.GetProgress()))
        m.SetInputData(self.data)
        self.volume.SetMapper(m)
        self.mapper = m
        return m

    def render(self):
        self.window.Render()
        return fvtest.grab(self.window)

    def done(self, m):
        m.ReleaseGraphicsResources(self.window)
        self.volume.SetMapper(None)
        self.mapper = None

    def depth_image(self, m):
        img = vtk.vtkImageData()
        m.GetDepthImage(img)
        return img


# ---- what each setting is expected to do -------------------------------------------------
def image(call, prepare=None):
    return ("image", prepare, call, None)


def warned(call, keyword, prepare=None):
    return ("warned", prepare, call, keyword)


def state(call, check, prepare=None):
    return ("state", prepare, call, check)


def effect(call, measure, prepare=None):
    return ("effect", prepare, call, measure)


def reads(name, value):
    """Set<name>(value), then Get<name>() is value."""
    def check(m, rig):
        got = getattr(m, "Get" + name)()
        return math.isclose(got, value) if isinstance(value, float) else got == value
    return state(lambda m, rig: getattr(m, "Set" + name)(value), check)


def interactive_image(m, rig):
    """The image (its digest) after renders with almost no time allocated (DesiredUpdateRate
    10⁶): with AutoAdjustSampleDistances the step lengthens render by render to the coarsest
    that MaximumImageSampleDistance allows. (MinimumImageSampleDistance bounds the finest:
    a still render after the first.)"""
    rate = rig.window.GetDesiredUpdateRate()
    rig.window.SetDesiredUpdateRate(1e6)
    try:
        for _ in range(5):
            img = rig.render()
    finally:
        rig.window.SetDesiredUpdateRate(rate)
    return hashlib.sha1(img.tobytes()).hexdigest()


def calls(*steps):
    """A sequence of calls (name, args...) as one prepare/call step."""
    def run(m, rig):
        for name, *args in steps:
            getattr(m, name)(*[a(rig) if callable(a) else a for a in args])
    return run


def label_one_red(m, rig):
    """The label map of rig.labels, its label 1 red on the rig's property."""
    red = vtk.vtkColorTransferFunction()
    red.AddRGBPoint(0.0, 1.0, 0.0, 0.0)
    rig.prop.SetLabelColor(1, red)
    m.SetMaskInput(rig.labels)
    m.SetMaskTypeToLabelMap()


def progress_events(m, rig):
    m.progress_seen.clear()
    rig.render()
    return len(m.progress_seen)


def depth_type(m, rig):
    rig.render()
    return rig.depth_image(m).GetScalarType()


def depth_coverage(m, rig):
    rig.render()
    img = rig.depth_image(m)
    return float((vtk_to_numpy(img.GetPointData().GetScalars()) < 1.0).mean())


def observed(m, rig):
    return m.HasObserver("UserEvent") == 0


def slice_plane(m, rig):
    """The property's SliceFunction: a plane through the data's centre."""
    p = vtk.vtkPlane()
    p.SetOrigin(rig.data.GetCenter())
    p.SetNormal(0.2, 0.3, 1.0)
    rig.prop.SetSliceFunction(p)


def plane(rig):
    p = vtk.vtkPlane()
    p.SetOrigin(0.0, 0.0, 0.0)
    p.SetNormal(1.0, 0.3, 0.0)
    rig.plane = p
    return p


def planes(rig):
    c = vtk.vtkPlaneCollection()
    c.AddItem(plane(rig))
    return c


RTI = ("RenderToImageOn",)
CROPPED = ("CroppingOn",)
CROP_MID = ("SetCroppingRegionPlanes", -2.0, 4.0, -2.0, 4.0, -2.0, 4.0)
AUTO_OFF = ("AutoAdjustSampleDistancesOff",)
SD4 = ("SetSampleDistance", 4.0)
POINT_FIELD = ("SetScalarModeToUsePointFieldData",)
SMALL_BUDGET = ("SetMaxMemoryInBytes", 64 * 1024)
UCHAR = ("SetDepthImageScalarTypeToUnsignedChar",)


def tagged(m, rig):
    m.tag = m.AddObserver("UserEvent", lambda o, e: None)


SETTINGS = {
    # vtkObject, vtkAlgorithm: bookkeeping that no volume mapper draws
    "AbortExecuteOn": state(calls(("AbortExecuteOn",)), lambda m, r: m.GetAbortExecute() == 1),
    "AbortExecuteOff": state(calls(("AbortExecuteOff",)), lambda m, r: m.GetAbortExecute() == 0,
                             prepare=calls(("AbortExecuteOn",))),
    "SetAbortExecute": reads("AbortExecute", 1),
    "SetAbortExecuteAndUpdateTime": state(calls(("SetAbortExecuteAndUpdateTime",)),
                                          lambda m, r: m.GetAbortExecute() == 1),
    "SetAbortOutput": reads("AbortOutput", True),
    # (VTK >= 9.3: keys of the output ports' information; a mapper has none)
    "SetNoPriorTemporalAccessInformationKey": state(
        calls(("SetNoPriorTemporalAccessInformationKey",)),
        lambda m, r: m.GetNumberOfOutputPorts() == 0),
    "RemoveNoPriorTemporalAccessInformationKey": state(
        calls(("RemoveNoPriorTemporalAccessInformationKey",)),
        lambda m, r: m.GetNumberOfOutputPorts() == 0),
    "DebugOn": state(calls(("DebugOn",)), lambda m, r: m.GetDebug()),
    "DebugOff": state(calls(("DebugOff",)), lambda m, r: not m.GetDebug(),
                      prepare=calls(("DebugOn",))),
    "SetDebug": reads("Debug", True),
    "GlobalWarningDisplayOff": state(calls(("GlobalWarningDisplayOff",)),
                                     lambda m, r: m.GetGlobalWarningDisplay() == 0),
    "GlobalWarningDisplayOn": state(calls(("GlobalWarningDisplayOn",)),
                                    lambda m, r: m.GetGlobalWarningDisplay() == 1,
                                    prepare=calls(("GlobalWarningDisplayOff",))),
    "SetGlobalWarningDisplay": reads("GlobalWarningDisplay", 0),
    "SetObjectName": reads("ObjectName", "named"),
    "SetProgressText": reads("ProgressText", "loading"),
    "SetProgressShiftScale": state(calls(("SetProgressShiftScale", 0.25, 0.5)),
                                   lambda m, r: (m.GetProgressShift(), m.GetProgressScale())
                                   == (0.25, 0.5)),
    "SetProgressObserver": state(
        lambda m, r: setattr(m, "po", vtk.vtkProgressObserver()) or m.SetProgressObserver(m.po),
        lambda m, r: m.GetProgressObserver() is m.po),
    "SetReferenceCount": state(lambda m, r: m.SetReferenceCount(m.GetReferenceCount()),
                               lambda m, r: m.GetReferenceCount() >= 1),
    # (a mapper has no output port: vtkExecutive refuses the flag, as for VTK's mapper)
    "SetReleaseDataFlag": state(calls(("SetReleaseDataFlag", 1)),
                                lambda m, r: m.GetReleaseDataFlag() == 0),
    "ReleaseDataFlagOn": state(calls(("ReleaseDataFlagOn",)),
                               lambda m, r: m.GetReleaseDataFlag() == 0),
    "ReleaseDataFlagOff": state(calls(("ReleaseDataFlagOff",)),
                                lambda m, r: m.GetReleaseDataFlag() == 0),
    "SetContainerAlgorithm": state(
        lambda m, r: setattr(m, "ca", vtk.vtkImageShiftScale()) or m.SetContainerAlgorithm(m.ca),
        lambda m, r: m.GetContainerAlgorithm() is m.ca),
    "SetDefaultExecutivePrototype": state(
        calls(("SetDefaultExecutivePrototype", vtk.vtkStreamingDemandDrivenPipeline())),
        lambda m, r: ferrovol.vtkFerroVolumeMapper().GetExecutive().IsA(
            "vtkStreamingDemandDrivenPipeline")),
    "SetExecutive": state(
        lambda m, r: setattr(m, "ex", vtk.vtkCompositeDataPipeline()) or m.SetExecutive(m.ex),
        lambda m, r: m.GetExecutive() is m.ex),
    "SetInformation": state(
        lambda m, r: setattr(m, "info", vtk.vtkInformation()) or m.SetInformation(m.info),
        lambda m, r: m.GetInformation() is m.info),
    "SetInputArrayToProcess": state(
        calls(("SetInputArrayToProcess", 0, 0, 0, 0, "Other")),
        lambda m, r: m.GetInputArrayInformation(0).Get(vtk.vtkDataObject.FIELD_NAME())
        == "Other"),
    # (VTK 9.2 without memkind: nothing to use, for VTK's mapper too)
    "SetMemkindDirectory": state(calls(("SetMemkindDirectory", None)),
                                 lambda m, r: not m.GetUsingMemkind()),
    "AddObserver": state(tagged, lambda m, r: m.HasObserver("UserEvent") == 1),
    "RemoveObserver": state(lambda m, r: m.RemoveObserver(m.tag), observed, prepare=tagged),
    "RemoveObservers": state(calls(("RemoveObservers", "UserEvent")), observed, prepare=tagged),
    "RemoveAllObservers": state(calls(("RemoveAllObservers",)), observed, prepare=tagged),

    # the input
    "SetInputData": image(calls(("SetInputData", lambda r: r.data2))),
    "SetInputDataObject": image(calls(("SetInputDataObject", lambda r: r.data2))),
    "SetInputConnection": image(calls(("SetInputConnection",
                                       lambda r: r.source2.GetOutputPort()))),
    "AddInputConnection": warned(calls(("AddInputConnection", 1,
                                        lambda r: r.source2.GetOutputPort())), "port 1"),
    "AddInputDataObject": warned(calls(("AddInputDataObject", 1, lambda r: r.data2)),
                                 "port 1"),
    "RemoveAllInputConnections": image(calls(("RemoveAllInputConnections", 0))),
    "RemoveAllInputs": image(calls(("RemoveAllInputs",))),
    "RemoveInputConnection": image(calls(("RemoveInputConnection", 0, 0))),
    "SetScalarMode": image(calls(("SetScalarMode", vtk.VTK_SCALAR_MODE_USE_CELL_DATA))),
    "SetScalarModeToUseCellData": image(calls(("SetScalarModeToUseCellData",))),
    "SetScalarModeToUsePointData": image(calls(("SetScalarModeToUsePointData",)),
                                         prepare=calls(("SetScalarModeToUseCellData",))),
    "SetScalarModeToDefault": image(calls(("SetScalarModeToDefault",)),
                                    prepare=calls(("SetScalarModeToUseCellData",))),
    "SetScalarModeToUsePointFieldData": image(calls(POINT_FIELD),
                                              prepare=calls(("SelectScalarArray", "Other"))),
    "SetScalarModeToUseCellFieldData": image(calls(("SetScalarModeToUseCellFieldData",)),
                                             prepare=calls(("SelectScalarArray", "Cells"))),
    "SelectScalarArray": image(calls(("SelectScalarArray", "Other")),
                               prepare=calls(POINT_FIELD, ("SelectScalarArray", "RTData"))),
    # (VTK >= 9.6 wraps the array's setters)
    "SetArrayName": image(calls(("SetArrayName", "Other")),
                          prepare=calls(POINT_FIELD, ("SelectScalarArray", "RTData"))),
    "SetArrayId": image(calls(("SetArrayId", 1)),
                        prepare=calls(POINT_FIELD, ("SelectScalarArray", 0))),
    "SetArrayAccessMode": image(calls(("SetArrayAccessMode", vtk.VTK_GET_ARRAY_BY_ID)),
                                prepare=calls(POINT_FIELD, ("SelectScalarArray", 0),
                                              ("SelectScalarArray", "Other"))),

    # vtkVolumeMapper, vtkAbstractMapper
    "SetBlendMode": image(calls(("SetBlendMode", vtk.vtkVolumeMapper.MAXIMUM_INTENSITY_BLEND))),
    "SetBlendModeToComposite": image(calls(("SetBlendModeToComposite",)),
                                     prepare=calls(("SetBlendModeToMaximumIntensity",))),
    "SetBlendModeToMaximumIntensity": image(calls(("SetBlendModeToMaximumIntensity",))),
    "SetBlendModeToMinimumIntensity": image(calls(("SetBlendModeToMinimumIntensity",))),
    "SetBlendModeToAverageIntensity": image(calls(("SetBlendModeToAverageIntensity",))),
    "SetBlendModeToAdditive": image(calls(("SetBlendModeToAdditive",))),
    "SetBlendModeToIsoSurface": image(calls(("SetBlendModeToIsoSurface",))),
    "SetBlendModeToSlice": image(calls(("SetBlendModeToSlice",)), prepare=slice_plane),
    "SetAverageIPScalarRange": image(calls(("SetAverageIPScalarRange", 150.0, 220.0)),
                                     prepare=calls(("SetBlendModeToAverageIntensity",))),
    "SetCropping": image(calls(("SetCropping", 1)), prepare=calls(CROP_MID)),
    "CroppingOn": image(calls(("CroppingOn",)), prepare=calls(CROP_MID)),
    "CroppingOff": image(calls(("CroppingOff",)), prepare=calls(CROP_MID, ("CroppingOn",))),
    "SetCroppingRegionPlanes": image(calls(CROP_MID), prepare=calls(("CroppingOn",))),
    "SetCroppingRegionFlags": image(calls(("SetCroppingRegionFlags", 0x0FFFEFF)),
                                    prepare=calls(CROP_MID, ("CroppingOn",))),
    "SetCroppingRegionFlagsToSubVolume": image(
        calls(("SetCroppingRegionFlagsToSubVolume",)),
        prepare=calls(CROP_MID, ("CroppingOn",), ("SetCroppingRegionFlagsToFence",))),
    "SetCroppingRegionFlagsToFence": image(calls(("SetCroppingRegionFlagsToFence",)),
                                           prepare=calls(CROP_MID, ("CroppingOn",))),
    "SetCroppingRegionFlagsToInvertedFence": image(
        calls(("SetCroppingRegionFlagsToInvertedFence",)), prepare=calls(CROP_MID, CROPPED)),
    "SetCroppingRegionFlagsToCross": image(calls(("SetCroppingRegionFlagsToCross",)),
                                           prepare=calls(CROP_MID, ("CroppingOn",))),
    "SetCroppingRegionFlagsToInvertedCross": image(
        calls(("SetCroppingRegionFlagsToInvertedCross",)), prepare=calls(CROP_MID, CROPPED)),
    "SetClippingPlanes": image(calls(("SetClippingPlanes", planes))),
    "AddClippingPlane": image(calls(("AddClippingPlane", plane))),
    "RemoveClippingPlane": image(calls(("RemoveClippingPlane", lambda r: r.plane)),
                                 prepare=calls(("AddClippingPlane", plane))),
    "RemoveAllClippingPlanes": image(calls(("RemoveAllClippingPlanes",)),
                                     prepare=calls(("AddClippingPlane", plane))),
    "SetComputeNormalFromOpacity": image(calls(("SetComputeNormalFromOpacity", 1))),
    "ComputeNormalFromOpacityOn": image(calls(("ComputeNormalFromOpacityOn",))),
    "ComputeNormalFromOpacityOff": image(calls(("ComputeNormalFromOpacityOff",)),
                                         prepare=calls(("ComputeNormalFromOpacityOn",))),

    # vtkGPUVolumeRayCastMapper: sampling
    "SetAutoAdjustSampleDistances": image(calls(("SetAutoAdjustSampleDistances", 0))),
    "AutoAdjustSampleDistancesOff": image(calls(AUTO_OFF)),
    "AutoAdjustSampleDistancesOn": image(calls(("AutoAdjustSampleDistancesOn",)),
                                         prepare=calls(AUTO_OFF)),
    "SetSampleDistance": image(calls(SD4), prepare=calls(AUTO_OFF)),
    "SetLockSampleDistanceToInputSpacing": image(
        calls(("SetLockSampleDistanceToInputSpacing", 1)), prepare=calls(AUTO_OFF, SD4)),
    "LockSampleDistanceToInputSpacingOn": image(
        calls(("LockSampleDistanceToInputSpacingOn",)), prepare=calls(AUTO_OFF, SD4)),
    "LockSampleDistanceToInputSpacingOff": image(
        calls(("LockSampleDistanceToInputSpacingOff",)),
        prepare=calls(AUTO_OFF, SD4, ("LockSampleDistanceToInputSpacingOn",))),
    "SetImageSampleDistance": image(calls(("SetImageSampleDistance", 3.0))),
    "SetMinimumImageSampleDistance": image(calls(("SetMinimumImageSampleDistance", 2.0))),
    "SetMaximumImageSampleDistance": effect(calls(("SetMaximumImageSampleDistance", 4.0)),
                                            interactive_image),
    "SetUseJittering": image(calls(("SetUseJittering", 1))),
    "UseJitteringOn": image(calls(("UseJitteringOn",))),
    "UseJitteringOff": image(calls(("UseJitteringOff",)), prepare=calls(("UseJitteringOn",))),
    "SetFinalColorWindow": image(calls(("SetFinalColorWindow", 0.5))),
    "SetFinalColorLevel": image(calls(("SetFinalColorLevel", 0.3))),
    "SetColorRangeType": image(calls(("SetColorRangeType", vtk.vtkGPUVolumeRayCastMapper.NATIVE))),
    "SetScalarOpacityRangeType": image(
        calls(("SetScalarOpacityRangeType", vtk.vtkGPUVolumeRayCastMapper.NATIVE))),
    "SetGradientOpacityRangeType": image(
        calls(("SetGradientOpacityRangeType", vtk.vtkGPUVolumeRayCastMapper.NATIVE))),
    "SetVolumetricScatteringBlending": image(calls(("SetVolumetricScatteringBlending", 1.0))),
    "SetGlobalIlluminationReach": image(calls(("SetGlobalIlluminationReach", 1.0)),
                                        prepare=calls(("SetVolumetricScatteringBlending", 1.0))),

    # memory and progress (a budget below the volume streams it: the same image)
    "SetMaxMemoryInBytes": effect(calls(SMALL_BUDGET), progress_events),
    "SetMaxMemoryFraction": effect(calls(("SetMaxMemoryFraction", 0.1)), progress_events,
                                   prepare=calls(("SetMaxMemoryInBytes", 256 * 1024))),
    "SetReportProgress": effect(calls(("SetReportProgress", False)), progress_events,
                                prepare=calls(SMALL_BUDGET)),

    # RenderToImage
    "SetRenderToImage": image(calls(("SetRenderToImage", 1))),
    "RenderToImageOn": image(calls(RTI)),
    "RenderToImageOff": image(calls(("RenderToImageOff",)), prepare=calls(RTI)),
    "SetDepthImageScalarType": effect(calls(("SetDepthImageScalarType", vtk.VTK_UNSIGNED_SHORT)),
                                      depth_type, prepare=calls(RTI)),
    "SetDepthImageScalarTypeToUnsignedChar": effect(calls(UCHAR), depth_type,
                                                    prepare=calls(RTI)),
    "SetDepthImageScalarTypeToUnsignedShort": effect(
        calls(("SetDepthImageScalarTypeToUnsignedShort",)), depth_type, prepare=calls(RTI)),
    "SetDepthImageScalarTypeToFloat": effect(calls(("SetDepthImageScalarTypeToFloat",)),
                                             depth_type, prepare=calls(RTI, UCHAR)),
    "SetClampDepthToBackface": effect(calls(("SetClampDepthToBackface", 1)), depth_coverage,
                                      prepare=calls(RTI, CROP_MID, ("CroppingOn",))),
    "ClampDepthToBackfaceOn": effect(calls(("ClampDepthToBackfaceOn",)), depth_coverage,
                                     prepare=calls(RTI, CROP_MID, ("CroppingOn",))),
    "ClampDepthToBackfaceOff": effect(calls(("ClampDepthToBackfaceOff",)), depth_coverage,
                                      prepare=calls(RTI, CROP_MID, ("CroppingOn",),
                                                    ("ClampDepthToBackfaceOn",))),

    # masks (a binary mask of half the volume; a label map of it with label 1 red)
    "SetMaskInput": image(calls(("SetMaskInput", lambda r: r.mask)),
                          prepare=calls(("SetMaskTypeToBinary",))),
    "SetMaskType": image(calls(("SetMaskType", 0)),
                         prepare=calls(("SetMaskInput", lambda r: r.mask))),
    "SetMaskTypeToBinary": image(calls(("SetMaskTypeToBinary",)),
                                 prepare=calls(("SetMaskInput", lambda r: r.mask))),
    "SetMaskTypeToLabelMap": image(calls(("SetMaskTypeToLabelMap",)),
                                   prepare=calls(("SetMaskInput", lambda r: r.mask),
                                                 ("SetMaskTypeToBinary",))),
    "SetMaskBlendFactor": image(calls(("SetMaskBlendFactor", 0.5)), prepare=label_one_red),

    # not supported: warned
    "SetDepthPassContourValues": state(
        lambda m, r: m.SetDepthPassContourValues(contour_values(150.0)),
        lambda m, r: m.GetDepthPassContourValues().GetValue(0) == 150.0),
    "SetUseDepthPass": warned(calls(("SetUseDepthPass", 1)), "UseDepthPass"),
    "UseDepthPassOn": warned(calls(("UseDepthPassOn",)), "UseDepthPass"),
    "UseDepthPassOff": state(calls(("UseDepthPassOff",)), lambda m, r: m.GetUseDepthPass() == 0,
                             prepare=calls(("UseDepthPassOn",))),
    "SetTransfer2DYAxisArray": warned(calls(("SetTransfer2DYAxisArray", "Other")),
                                      "Transfer2DYAxisArray"),
    # (VTK >= 9.6 wraps it: the active input ports' bookkeeping, kept as VTK keeps it)
    "SetPorts": state(calls(("SetPorts", [0])), lambda m, r: tuple(m.GetPorts()) == (0,)),
    "SetPartitions": warned(calls(("SetPartitions", 2, 2, 2)), "SetPartitions"),
    "SetSharedDepthTexture": warned(calls(("SetSharedDepthTexture", vtk.vtkTextureObject())),
                                    "SetSharedDepthTexture"),
}


def contour_values(*values):
    c = vtk.vtkContourValues()
    for i, v in enumerate(values):
        c.SetValue(i, v)
    return c


def is_setting(name):
    return name.startswith(("Set", "Add", "Remove", "Select")) or name.endswith(("On", "Off"))


def int_ref():
    return vtk.reference(0)


# Arguments of the other methods (no entry: called without arguments).
ARGS = {
    "ConvertTotalInputToPortConnection": lambda r: (0, int_ref(), int_ref()),
    "CreateCanonicalView": lambda r: (r.renderer, r.volume, r.canonical, 0, [0.0, 0.0, 1.0],
                                      [0.0, 1.0, 0.0]),
    "GPURender": lambda r: (r.renderer, r.volume),
    "Render": lambda r: (r.renderer, r.volume),
    "PreLoadData": lambda r: (r.renderer, r.volume),
    "GetAbstractScalars": lambda r: (r.data, 0, 0, 0, None, int_ref()),
    "GetScalars": lambda r: (r.data, 0, 0, 0, None, int_ref()),
    "GetGhostArray": lambda r: (r.data, 0, int_ref()),
    "GetAddressAsString": lambda r: ("vtkObject",),
    "GetBoundsFromPort": lambda r: (0,),
    "GetTransformedInput": lambda r: (0,),
    "GetClippingPlaneInDataCoords": lambda r: (vtk.vtkMatrix4x4(), 0, [0.0] * 4),
    "GetColorImage": lambda r: (vtk.vtkImageData(),),
    "GetDepthImage": lambda r: (vtk.vtkImageData(),),
    "GetCommand": lambda r: (r.mapper.AddObserver("UserEvent", lambda o, e: None),),
    "GetInputArrayInformation": lambda r: (0,),
    "GetInputConnection": lambda r: (0, 0),
    "GetInputDataObject": lambda r: (0, 0),
    "GetInputPortInformation": lambda r: (0,),
    "GetNumberOfGenerationsFromBase": lambda r: ("vtkObject",),
    "GetNumberOfGenerationsFromBaseType": lambda r: ("vtkObject",),
    "GetNumberOfInputConnections": lambda r: (0,),
    # (a mapper has no output port: None, with vtkAlgorithm's error, as VTK's mapper)
    "GetOutputDataObject": lambda r: (0,),
    "GetOutputInformation": lambda r: (0,),
    "GetOutputPort": lambda r: (0,),
    "GetOutputPortInformation": lambda r: (0,),
    "GetReductionRatio": lambda r: ([0.0, 0.0, 0.0],),
    "HasObserver": lambda r: ("UserEvent",),
    "InvokeEvent": lambda r: ("UserEvent",),
    "IsA": lambda r: ("vtkGPUVolumeRayCastMapper",),
    "IsTypeOf": lambda r: ("vtkObject",),
    "IsRenderSupported": lambda r: (r.window, r.prop),
    "ModifyRequest": lambda r: (vtk.vtkInformation(), 0),
    "ProcessRequest": lambda r: (vtk.vtkInformation(), vtk.vtkCollection(),
                                 vtk.vtkInformationVector()),
    "Register": lambda r: (None,),
    "UnRegister": lambda r: (None,),
    "ReleaseGraphicsResources": lambda r: (r.window,),
    "SafeDownCast": lambda r: (r.mapper,),
    "ShallowCopy": lambda r: (ferrovol.vtkFerroVolumeMapper(),),
    "UpdateExtent": lambda r: ((0, 1, 0, 1, 0, 1),),
    "UpdateExtentIsEmpty": lambda r: (vtk.vtkInformation(), 0),
    "UpdatePiece": lambda r: (0, 1, 0),
    "UpdateProgress": lambda r: (0.5,),
    "UpdateTimeStep": lambda r: (0.0,),
    "override": lambda r: (None,),
}
# Called on a mapper of their own: FastDelete takes a reference (one is added first).
OWN_MAPPER = {"FastDelete": lambda m: m.Register(None)}
# Getters whose value on a new mapper may differ from VTK's: object identities and
# addresses, timestamps, and MaxMemoryInBytes (ferrovol's default 0 is the device's limit;
# VTK probes the GPU).
DEFAULTS_DIFFER = {"GetMaxMemoryInBytes", "GetMTime", "GetClassName", "GetAddressAsString",
                   "GetObjectDescription", "GetReferenceCount", "GetNumberOfGenerationsFromBase"}


def wrapped_properties(obj):
    """The snake_case properties VTK >= 9.4's wrapping adds for Set/Get methods (some
    write-only): descriptors of the class, not methods or constants."""
    return {n for n in dir(obj) if not n.startswith("_") and isinstance(
        inspect.getattr_static(type(obj), n, None), types.GetSetDescriptorType)}


def plain(value):
    return isinstance(value, (int, float, str, tuple, bool)) or value is None
