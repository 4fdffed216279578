"""VTK's volume conventions, feature by feature: one scene per feature
rendered by VTK's GPU ray caster (Mesa llvmpipe here), VTK's fixed-point
ray caster and vtkMultiMaterialVolumeMapper, in one process, with the same
input, property, camera and window. Each case asserts what its feature must
do to the image with every mapper (a clipping plane removes pixels, a user
transform turns the silhouette) and how close our silhouette is to VTK's
GPU mapper's (IoU of the pixels above 12/255). Features where we are known
to differ are rows of their own, named and measured, not failures; the
table of all rows (written to $MMRTM_CONFORMANCE_TABLE when set) is the
list in Documentation/vtk-mapper.md of what a VTK user can rely on.

What it catches: a feature of VTK's that we stop honouring (a clipping
plane, a crop, a transform, a scalar type or a resize ignored), and a
documented difference that silently changed.

Runs with either VTK flavour (Debian 9.1 under Xvfb; the 9.6 wheel), under
Testing/headless.sh, through Testing/run_unittest.py.
"""
import math
import os
import unittest

from vtkmodules.vtkCommonCore import vtkDoubleArray
from vtkmodules.vtkCommonDataModel import vtkImageData, vtkPiecewiseFunction, vtkPlane, vtkRectilinearGrid
from vtkmodules.vtkCommonExecutionModel import vtkTrivialProducer
from vtkmodules.vtkCommonTransforms import vtkTransform
from vtkmodules.vtkImagingCore import vtkExtractVOI, vtkImageAppendComponents, vtkImageCast, vtkImageShiftScale
from vtkmodules.vtkIOImage import vtkNrrdReader
from vtkmodules.vtkRenderingCore import (vtkColorTransferFunction, vtkRenderer, vtkRenderWindow, vtkVolume,
                                         vtkVolumeProperty, vtkWindowToImageFilter)
from vtkmodules.vtkRenderingVolume import vtkFixedPointVolumeRayCastMapper, vtkVolumeMapper
import vtkmodules.vtkRenderingOpenGL2  # noqa: F401  (the OpenGL render window)
from vtkmodules.vtkRenderingVolumeOpenGL2 import vtkOpenGLGPUVolumeRayCastMapper

from mmrtm import vtkMultiMaterialVolumeMapper

DATA = os.environ["MMRTM_SHARED_DATA_DIR"]
SIZE = 128
THRESHOLD = 12  # a pixel is covered when a channel exceeds it (0-255)
MAPPERS = ("gpu", "fixed-point", "ours")
# vtkVolumeMapper.h's cropping flag sets (macros, not wrapped).
VTK_CROP_FENCE, VTK_CROP_INVERTED_FENCE, VTK_CROP_CROSS, VTK_CROP_INVERTED_CROSS = (0x2ebfeba, 0x5140145, 0x0417410,
                                                                                   0x7be8bef)


def make_mapper(kind):
    if kind == "gpu":
        return vtkOpenGLGPUVolumeRayCastMapper()
    if kind == "fixed-point":
        return vtkFixedPointVolumeRayCastMapper()
    m = vtkMultiMaterialVolumeMapper()
    m.SetBackendToCPU()
    m.SetSeed(7)
    m.SetSamplesPerRender(8)
    m.SetMaximumSamples(8)
    return m


def head_property():
    """Skin and bone of the headsq CT (values 0-3926), unshaded."""
    opacity = vtkPiecewiseFunction()
    opacity.AddPoint(0, 0.0)
    opacity.AddPoint(600, 0.0)
    opacity.AddPoint(900, 0.15)
    opacity.AddPoint(1200, 0.0)
    opacity.AddPoint(1500, 0.6)
    opacity.AddPoint(3926, 0.8)
    color = vtkColorTransferFunction()
    color.AddRGBPoint(600, 0.9, 0.6, 0.5)
    color.AddRGBPoint(1500, 1.0, 1.0, 0.9)
    prop = vtkVolumeProperty()
    prop.SetScalarOpacity(opacity)
    prop.SetColor(color)
    prop.SetInterpolationTypeToLinear()
    return prop


class Render:
    """One mapper's render of the head, with hooks for the feature."""

    def __init__(self, kind, configure=None, size=SIZE, scale=1):
        self.reader = vtkNrrdReader()
        self.reader.SetFileName(os.path.join(DATA, "ct_head_headsq.nrrd"))
        self.source = self.reader
        self.mapper = make_mapper(kind)
        self.volume = vtkVolume()
        self.volume.SetProperty(head_property())
        self.volume.SetMapper(self.mapper)
        self.renderer = vtkRenderer()
        self.renderer.SetBackground(0, 0, 0)
        self.renderer.AddVolume(self.volume)
        self.window = vtkRenderWindow()
        self.window.SetOffScreenRendering(1)
        self.window.SetMultiSamples(0)
        self.window.AddRenderer(self.renderer)
        self.window.SetSize(size, size)
        self.scale = scale
        self.place_camera = None  # a feature's camera, after the common one
        if configure:
            configure(self)
        self.mapper.SetInputConnection(self.source.GetOutputPort())
        self.renderer.ResetCamera()
        camera = self.renderer.GetActiveCamera()
        camera.Elevation(-90)  # from the face (the data's -y side)
        camera.OrthogonalizeViewUp()
        camera.Azimuth(20)
        self.renderer.ResetCamera()
        if self.place_camera:
            self.place_camera(camera)
        self.renderer.ResetCameraClippingRange()

    def pixels(self):
        """The window's image as rows of (r, g, b), after one render."""
        self.window.Render()
        grab = vtkWindowToImageFilter()
        grab.SetInput(self.window)
        if self.scale != 1:
            grab.SetScale(self.scale)
        grab.ReadFrontBufferOff()
        grab.Update()
        scalars = grab.GetOutput().GetPointData().GetScalars()
        n = scalars.GetNumberOfComponents()
        data = bytes(memoryview(scalars))
        return [tuple(data[i:i + 3]) for i in range(0, len(data), n)]


def write_side_by_side(path, images):
    """The mappers' images left to right (gpu, fixed-point, ours) as a PNG."""
    from vtkmodules.vtkCommonCore import vtkUnsignedCharArray
    from vtkmodules.vtkCommonDataModel import vtkImageData
    from vtkmodules.vtkIOImage import vtkPNGWriter
    width = SIZE * len(MAPPERS)
    values = vtkUnsignedCharArray()
    values.SetNumberOfComponents(3)
    values.SetNumberOfTuples(width * SIZE)
    values.Fill(0)
    for m, kind in enumerate(MAPPERS):
        for i, p in enumerate(images[kind] or ()):  # the window's rows, bottom first, as VTK keeps them
            values.SetTypedTuple((i // SIZE) * width + m * SIZE + i % SIZE, p)
    image = vtkImageData()
    image.SetDimensions(width, SIZE, 1)
    image.GetPointData().SetScalars(values)
    writer = vtkPNGWriter()
    writer.SetFileName(path)
    writer.SetInputData(image)
    writer.Write()


def covered(pixels):
    return [max(p) > THRESHOLD for p in pixels]


def iou(a, b):
    ca, cb = covered(a), covered(b)
    union = sum(1 for x, y in zip(ca, cb) if x or y)
    both = sum(1 for x, y in zip(ca, cb) if x and y)
    return both / union if union else 1.0


def colour_difference(a, b):
    """Mean absolute channel difference (0-255) over the pixels either covers."""
    ca, cb = covered(a), covered(b)
    diffs = [sum(abs(p[c] - q[c]) for c in range(3)) / 3.0 for p, q, x, y in zip(a, b, ca, cb) if x or y]
    return sum(diffs) / len(diffs) if diffs else 0.0


def mean_colour(pixels):
    """The mean (r, g, b) over the covered pixels."""
    kept = [p for p, c in zip(pixels, covered(pixels)) if c]
    return [sum(p[c] for p in kept) / max(1, len(kept)) for c in range(3)]


def coverage(pixels):
    return sum(covered(pixels)) / float(len(pixels))


# The features. Each: a name, how it is set up (on a Render, for every
# mapper), the least IoU with VTK's GPU mapper for a row that agrees, or a
# named difference (then only measured), and what the feature must do to
# every mapper's image compared with the plain render (`effect(plain, image)`).
def clip(r):
    plane = vtkPlane()
    b = r.reader
    b.Update()
    bounds = b.GetOutput().GetBounds()
    plane.SetOrigin(0.5 * (bounds[0] + bounds[1]), 0, 0)
    plane.SetNormal(-1, 0, 0)
    r.mapper.AddClippingPlane(plane)


def crop(r):
    r.reader.Update()
    b = r.reader.GetOutput().GetBounds()
    r.mapper.SetCropping(1)
    r.mapper.SetCroppingRegionPlanes(b[0], 0.5 * (b[0] + b[1]), b[2], b[3], b[4], b[5])
    r.mapper.SetCroppingRegionFlagsToSubVolume()


def cropping_regions(flags, half=20):
    """Planes `half` mm either side of the volume's centre on each axis, and
    one of VTK's flag sets for the 27 regions they make."""
    def configure(r):
        r.reader.Update()
        b = r.reader.GetOutput().GetBounds()
        mx, my, mz = (0.5 * (b[0] + b[1]), 0.5 * (b[2] + b[3]), 0.5 * (b[4] + b[5]))
        r.mapper.SetCropping(1)
        r.mapper.SetCroppingRegionPlanes(mx - half, mx + half, my - half, my + half, mz - half, mz + half)
        r.mapper.SetCroppingRegionFlags(flags)
    return configure


def shaded(r):
    """Shading on with the property's defaults (ambient 0.1, diffuse 0.7,
    specular 0.2, power 10) under VTK's headlight."""
    r.volume.GetProperty().ShadeOn()


def more_samples(r, samples=32):
    """Our image at `samples` per pixel: a colour bound below the noise of 8."""
    if isinstance(r.mapper, vtkMultiMaterialVolumeMapper):
        r.mapper.SetSamplesPerRender(samples)
        r.mapper.SetMaximumSamples(samples)


def shaded_local(r):
    """Shaded, with our global illumination off: VTK's local lighting."""
    shaded(r)
    more_samples(r)
    if isinstance(r.mapper, vtkMultiMaterialVolumeMapper):
        r.mapper.GlobalIlluminationOff()


def camera_inside(parallel):
    """The camera 6 % of the way from the head's centre to where it was:
    inside the soft tissue (a parallel one showing a slab of 120 mm)."""
    def configure(r):
        if not parallel:
            shaded(r)
            more_samples(r)

        def place(camera):
            p, f = camera.GetPosition(), camera.GetFocalPoint()
            camera.SetPosition(*[f[i] + 0.06 * (p[i] - f[i]) for i in range(3)])
            if parallel:
                camera.ParallelProjectionOn()
                camera.SetParallelScale(60)
        r.place_camera = place
    return configure


def user_transform(r):
    t = vtkTransform()
    t.RotateZ(40)
    r.volume.SetUserTransform(t)


def as_float(r):
    cast = vtkImageCast()
    cast.SetInputConnection(r.reader.GetOutputPort())
    cast.SetOutputScalarTypeToFloat()
    r.source = cast


def as_unsigned_char(r):
    cast = vtkImageCast()
    cast.SetInputConnection(r.reader.GetOutputPort())
    cast.SetOutputScalarTypeToUnsignedChar()
    cast.ClampOverflowOn()
    r.source = cast
    opacity = vtkPiecewiseFunction()
    opacity.AddPoint(0, 0.0)
    opacity.AddPoint(100, 0.0)
    opacity.AddPoint(255, 0.6)
    r.volume.GetProperty().SetScalarOpacity(opacity)


def blend(mode, shade=False):
    def configure(r):
        r.mapper.SetBlendMode(mode)
        if shade:
            shaded(r)
        if mode == vtkVolumeMapper.ISOSURFACE_BLEND:
            r.volume.GetProperty().GetIsoSurfaceValues().SetValue(0, 1300)
        if mode == vtkVolumeMapper.MINIMUM_INTENSITY_BLEND:
            air_visible(r)
        if mode == vtkVolumeMapper.AVERAGE_INTENSITY_BLEND:
            r.mapper.SetAverageIPScalarRange(600, 4000)  # air left out: a mean that is not near black
        if mode == vtkVolumeMapper.ADDITIVE_BLEND:
            faint(r)
    return configure


def faint(r):
    """Opacity a fiftieth of the head's: the additive sum along a ray stays
    below 1 instead of saturating to white."""
    opacity = r.volume.GetProperty().GetScalarOpacity()
    for i in range(opacity.GetSize()):
        node = [0.0] * 4
        opacity.GetNodeValue(i, node)
        node[1] /= 50.0
        opacity.SetNodeValue(i, node)


def air_visible(r):
    """The least value along a ray is air's: MinIP shows nothing unless air has opacity."""
    r.volume.GetProperty().GetScalarOpacity().AddPoint(0, 0.5)


def head_labels(image):
    """A label map on the head's grid: 2 on the half x >= the middle, 1 on
    the top third of the other half, 0 elsewhere (unsigned char)."""
    from vtkmodules.vtkCommonCore import vtkUnsignedCharArray
    from vtkmodules.vtkCommonDataModel import vtkImageData
    nx, ny, nz = image.GetDimensions()
    row = bytes([0] * (nx // 2) + [2] * (nx - nx // 2))
    top = bytes([1] * (nx // 2) + [2] * (nx - nx // 2))
    values = b"".join((top if k >= 2 * nz // 3 else row) * ny for k in range(nz))
    array = vtkUnsignedCharArray()
    array.SetNumberOfTuples(len(values))
    for i, v in enumerate(values):
        array.SetValue(i, v)
    mask = vtkImageData()
    mask.CopyStructure(image)
    mask.GetPointData().SetScalars(array)
    return mask


def label_map(r):
    """Label 2 shows only the bone, in blue; label 1's opacity is 0: both
    hide the skin over them, as VTK's label functions replace the volume's."""
    r.reader.Update()
    r.mask = head_labels(r.reader.GetOutput())
    r.mapper.SetMaskInput(r.mask)
    r.mapper.SetMaskTypeToLabelMap()
    prop = r.volume.GetProperty()
    bone = vtkPiecewiseFunction()
    for x, a in ((0, 0.0), (1200, 0.0), (1500, 0.6), (3926, 0.8)):
        bone.AddPoint(x, a)
    blue = vtkColorTransferFunction()
    blue.AddRGBPoint(0, 0.3, 0.5, 1.0)
    prop.SetLabelScalarOpacity(2, bone)
    prop.SetLabelColor(2, blue)
    nothing = vtkPiecewiseFunction()
    nothing.AddPoint(0, 0.0)
    nothing.AddPoint(3926, 0.0)
    prop.SetLabelScalarOpacity(1, nothing)


def two_components(weight):
    """The head as two independent components, the second shifted by -1000
    and shown in green (the first transparent), the second weighted."""
    def configure(r):
        shifted = vtkImageShiftScale()
        shifted.SetInputConnection(r.reader.GetOutputPort())
        shifted.SetShift(-1000.0)
        shifted.SetOutputScalarTypeToShort()
        both = vtkImageAppendComponents()
        both.AddInputConnection(r.reader.GetOutputPort())
        both.AddInputConnection(shifted.GetOutputPort())
        r.filters = (shifted, both)
        r.source = both
        prop = r.volume.GetProperty()
        prop.IndependentComponentsOn()
        nothing = vtkPiecewiseFunction()
        nothing.AddPoint(-1000, 0.0)
        nothing.AddPoint(3926, 0.0)
        prop.SetScalarOpacity(0, nothing)
        opacity = vtkPiecewiseFunction()
        for x, a in ((-1000, 0.0), (-400, 0.0), (-100, 0.15), (200, 0.0), (500, 0.6), (2926, 0.8)):
            opacity.AddPoint(x, a)
        green = vtkColorTransferFunction()
        green.AddRGBPoint(-1000, 0.1, 0.9, 0.2)
        prop.SetScalarOpacity(1, opacity)
        prop.SetColor(1, green)
        prop.SetComponentWeight(1, weight)
    return configure


def mean_green(pixels):
    green = [p[1] for p in pixels if max(p) > THRESHOLD]
    return sum(green) / float(len(green)) if green else 0.0


def darker(base, image):
    """Less than half the green of the unweighted component (VTK's GPU
    mapper: a quarter, the weight squared)."""
    return mean_green(image) < 0.5 * mean_green(base)


def as_data(r, data):
    """`data` as the mapper's input (through a producer, as Render connects it)."""
    producer = vtkTrivialProducer()
    producer.SetOutput(data)
    r.source, r.data = producer, data


def head_image(r):
    r.reader.Update()
    return r.reader.GetOutput()


def cell_scalars(r):
    """The head's values as the cell scalars of an image one point larger
    along each axis, its cell centres on the head's points."""
    image = head_image(r)
    s, o, d = image.GetSpacing(), image.GetOrigin(), image.GetDimensions()
    cells = vtkImageData()
    cells.SetDimensions(d[0] + 1, d[1] + 1, d[2] + 1)
    cells.SetSpacing(s)
    cells.SetOrigin(o[0] - 0.5 * s[0], o[1] - 0.5 * s[1], o[2] - 0.5 * s[2])
    cells.GetCellData().SetScalars(image.GetPointData().GetScalars())
    as_data(r, cells)


def rectilinear_grid(r):
    """The head's values on a vtkRectilinearGrid whose x coordinates are
    finer in the middle (|2t - 1|^1.5 from the centre), y and z uniform."""
    image = head_image(r)
    s, o, d = image.GetSpacing(), image.GetOrigin(), image.GetDimensions()
    grid = vtkRectilinearGrid()
    grid.SetDimensions(d)
    for axis, setter in enumerate((grid.SetXCoordinates, grid.SetYCoordinates, grid.SetZCoordinates)):
        coordinates = vtkDoubleArray()
        for i in range(d[axis]):
            t = i / (d[axis] - 1.0)
            if axis == 0:
                t = 0.5 + 0.5 * math.copysign(abs(2 * t - 1) ** 1.5, 2 * t - 1)
            coordinates.InsertNextValue(o[axis] + s[axis] * (d[axis] - 1) * t)
        setter(coordinates)
    grid.GetPointData().SetScalars(image.GetPointData().GetScalars())
    as_data(r, grid)


def nan_voxel(r):
    """The head as float with one NaN voxel in the middle."""
    cast = vtkImageCast()
    cast.SetInputData(head_image(r))
    cast.SetOutputScalarTypeToFloat()
    cast.Update()
    image = cast.GetOutput()
    d = image.GetDimensions()
    image.GetPointData().GetScalars().SetValue(d[0] // 2 + d[0] * (d[1] // 2 + d[1] * (d[2] // 2)), float("nan"))
    as_data(r, image)


def translucent_sphere_peeled(r):
    """A blue sphere at opacity 0.5 in front of the face, partly over it,
    with the renderer's depth peeling for volumes."""
    from vtkmodules.vtkFiltersSources import vtkSphereSource
    from vtkmodules.vtkRenderingCore import vtkActor, vtkPolyDataMapper
    b = head_image(r).GetBounds()
    sphere = vtkSphereSource()
    sphere.SetThetaResolution(48)
    sphere.SetPhiResolution(48)
    sphere.SetCenter(b[0] + 0.75 * (b[1] - b[0]), b[2] + 0.1 * (b[3] - b[2]), 0.5 * (b[4] + b[5]))
    sphere.SetRadius(0.25 * (b[1] - b[0]))
    mapper = vtkPolyDataMapper()
    mapper.SetInputConnection(sphere.GetOutputPort())
    actor = vtkActor()
    actor.SetMapper(mapper)
    actor.GetProperty().SetColor(0.2, 0.4, 1.0)
    actor.GetProperty().SetOpacity(0.5)
    r.renderer.AddActor(actor)
    r.renderer.SetUseDepthPeeling(1)
    r.renderer.SetUseDepthPeelingForVolumes(1)
    r.sphere = (sphere, mapper, actor)


def blue_pixels(pixels):
    return sum(1 for p in pixels if p[2] > p[0] + 40)


def translucent_actor_shows(plain, image):
    """The sphere shows: blue pixels, at least 3 % of the image (none in the plain render)."""
    return blue_pixels(image) > blue_pixels(plain) + 0.03 * len(image)


def fewer_pixels(plain, image):
    return coverage(image) < 0.9 * coverage(plain)


def turned(plain, image):
    return iou(plain, image) < 0.9


def same_silhouette(plain, image):
    return iou(plain, image) > 0.85


def changed(plain, image):
    return iou(plain, image) < 0.97 or colour_difference(plain, image) > 5


class Case:
    """A feature: how it is set up (on each mapper's Render), the least IoU
    of our image with VTK's GPU mapper's for a row that agrees (None: a
    named difference, measured only), what it must do to the image
    (`effect(plain, image)`) and on which mappers' images."""

    def __init__(self, name, configure, least_iou, effect=None, difference="", effect_on=None, fixed_point=True,
                 baseline=None, most_dc=None, note="", full=False):
        self.name, self.configure, self.least_iou, self.effect = name, configure, least_iou, effect
        # The largest colour difference with VTK's GPU mapper (None: not
        # bounded), for rows whose colours must be VTK's: the projections
        # and the unshaded glow exactly, shaded ones within their shadows.
        self.most_dc = most_dc
        self.baseline = baseline  # the render the effect is measured against (None: the plain one)
        self.note = note  # what differs besides, for the table
        self.full = full  # VTK's image may fill the window (a camera inside the volume)
        self.difference = difference
        self.mappers = MAPPERS if fixed_point else ("gpu", "ours")  # the fixed-point mapper lacks some modes
        self.effect_on = effect_on or tuple(m for m in self.mappers if least_iou is not None or m != "ours")


CASES = [
    # Unshaded, VTK's colour glows unlit (emission and absorption): ours
    # estimates the same integral. As a volume scattering the headlight
    # with the filmic tone mapping (the look before) dC was 27.2.
    Case("plain (unshaded)", None, 0.85, most_dc=10),
    # Shaded: ours has shadows (the headlight's way in through translucent
    # tissue) and multiple scattering that VTK's local shading leaves out.
    Case("shaded: headlight, ambient, diffuse, specular", shaded, 0.85, changed,
         note="colours differ: global illumination darkens translucent tissue (next row: off)"),
    # Global illumination off is VTK's local lighting: the same integral
    # but for the BSDF (GGX, no Phong highlight) and ambient occlusion.
    Case("shaded, global illumination off (VTK's local lighting)", shaded_local, 0.85, changed, most_dc=25),
    Case("clipping plane", clip, 0.85, fewer_pixels),
    Case("cropping: subvolume", crop, 0.85, fewer_pixels),
    Case("user transform", user_transform, 0.85, turned),
    Case("float scalars", as_float, 0.85, same_silhouette),
    Case("unsigned char scalars", as_unsigned_char, 0.8),
    Case("cropping: fence", cropping_regions(VTK_CROP_FENCE), 0.85, changed),
    Case("cropping: inverted fence", cropping_regions(VTK_CROP_INVERTED_FENCE), 0.85, changed),
    Case("cropping: cross", cropping_regions(VTK_CROP_CROSS), 0.85, changed),
    # A wider cross, so that the hole it cuts through the middle shows; what
    # is left are thin pillars (VTK's two mappers agree on them to IoU 0.87).
    Case("cropping: inverted cross", cropping_regions(VTK_CROP_INVERTED_CROSS, half=45), 0.78, changed),
    # The projections: VTK's colour and opacity of the extreme value, the
    # mean or the sum along the ray. As composite they were IoU 0.87, 0.95,
    # 0.29 and 0.91 with dC 52-167.
    Case("blend mode: maximum intensity", blend(vtkVolumeMapper.MAXIMUM_INTENSITY_BLEND), 0.9, changed,
         most_dc=5),
    Case("blend mode: minimum intensity", blend(vtkVolumeMapper.MINIMUM_INTENSITY_BLEND), 0.9, changed,
         effect_on=("gpu", "ours"), baseline=air_visible, most_dc=5),
    Case("blend mode: average intensity", blend(vtkVolumeMapper.AVERAGE_INTENSITY_BLEND), 0.9, changed,
         fixed_point=False, most_dc=5),
    # The sum depends on how many samples a ray takes: ours steps at the
    # smallest voxel spacing (1.5 mm here), and VTK's GPU sum is 1.5 times
    # ours in the bright parts whatever its SampleDistance (1 or 1.5): not
    # yet explained, so the colours are bounded loosely (dC 15.7 measured).
    Case("blend mode: additive", blend(vtkVolumeMapper.ADDITIVE_BLEND), 0.9, changed, effect_on=("gpu", "ours"),
         most_dc=20),
    # Surfaces where the scalars cross the iso-value (1300, between skin and
    # bone here), shaded, each crossing as opaque as the scalar opacity
    # there. As composite it was IoU 0.760, dC 78.6. Ours is more opaque at
    # grazing angles (a thin film), VTK's the same at every angle: unshaded
    # that shows (dC 53, ours brighter), shaded much less.
    Case("blend mode: isosurface (shaded)", blend(vtkVolumeMapper.ISOSURFACE_BLEND, shade=True), 0.85, changed,
         fixed_point=False, most_dc=30, baseline=shaded),
    # The headlight leaves from the camera: the tissue behind the camera
    # does not shadow it (from infinitely far it did: IoU 0.022, black).
    # VTK's two mappers differ by dC 34 here.
    Case("camera inside the head (perspective, shaded)", camera_inside(parallel=False), 0.85, changed,
         most_dc=40, full=True),
    Case("camera inside the head (parallel)", camera_inside(parallel=True), 0.85, changed, most_dc=10, full=True),
    # Labels whose opacity is 0 over the skin are empty there (VTK does not
    # fall back to the volume's functions): the skin of half the head goes.
    # Falling back gave the plain silhouette (coverage 0.210 of 0.211) and
    # IoU 0.73. VTK's fixed-point mapper has no label maps.
    Case("label map: a label's functions alone", label_map, 0.85, fewer_pixels, fixed_point=False),
    # A component weight of 0.5 darkens the component to a quarter in VTK's
    # GPU mapper (mean green 58 of 219), ours to 0.29 (51 of 176); VTK's
    # fixed-point mapper hardly changes it (205 of 209). Weight as a thinner
    # extinction gave 174 of 176 here.
    Case("independent components: weight 0.5", two_components(0.5), 0.85, darker, effect_on=("gpu", "ours"),
         baseline=two_components(1.0)),
    # Inputs VTK renders that ours refused (no image: IoU 0). VTK's
    # fixed-point mapper crashes on cell scalars and takes no rectilinear
    # grid.
    Case("cell scalars", cell_scalars, 0.85, same_silhouette, fixed_point=False),
    Case("vtkRectilinearGrid input (resampled)", rectilinear_grid, 0.85, fixed_point=False),
    Case("one NaN voxel (rendered as the least value)", nan_voxel, 0.85, same_silhouette),
    # VTK calls the mapper once per peel. Ours is traced once a frame and
    # drawn under the translucent layers (the sphere in front shows over
    # the head, as in VTK's GPU mapper; geometry behind the volume would
    # too). VTK's fixed-point mapper draws garbage here (IoU 0.43).
    Case("depth peeling for volumes: a translucent sphere in front", translucent_sphere_peeled, 0.85,
         translucent_actor_shows, effect_on=("gpu", "ours")),
]


class ConformanceTest(unittest.TestCase):
    """One test for all rows: the renders are shared between the checks."""

    def test_each_feature_as_vtk_has_it(self):
        rows = []
        plain = {kind: Render(kind).pixels() for kind in MAPPERS}
        for case in CASES:
            name = case.name
            images = {kind: Render(kind, case.configure).pixels() for kind in case.mappers}
            images.setdefault("fixed-point", None)
            if os.environ.get("MMRTM_CONFORMANCE_IMAGES"):
                write_side_by_side(os.path.join(os.environ["MMRTM_CONFORMANCE_IMAGES"],
                                                name.replace(" ", "-").replace(":", "") + ".png"), images)
            base = {kind: Render(kind, case.baseline).pixels() for kind in case.mappers} if case.baseline else plain
            effects = {kind: case.effect(base[kind], images[kind]) for kind in case.mappers} if case.effect else {}
            status = "agrees" if case.least_iou is not None else "differs: " + case.difference
            status += "; " + case.note if case.note else ""
            rows.append(self.row(name, images["ours"], images["gpu"], images["fixed-point"], status, effects))
            self.assertGreater(coverage(images["gpu"]), 0.02, name + ": VTK's GPU image is not blank")
            if not case.full:
                self.assertLess(coverage(images["gpu"]), 0.95, name + ": nor full")
            for kind in case.effect_on if case.effect else ():
                self.assertTrue(effects[kind], "%s: the feature's effect on the %s mapper's image" % (name, kind))
            if case.least_iou is not None:
                self.assertGreater(iou(images["ours"], images["gpu"]), case.least_iou,
                                   name + ": our silhouette against VTK's GPU mapper's")
                if case.most_dc is not None:
                    self.assertLess(colour_difference(images["ours"], images["gpu"]), case.most_dc,
                                    name + ": our colours against VTK's GPU mapper's")
            elif case.effect:
                self.assertFalse(effects["ours"], name + ": the documented difference no longer holds; make the "
                                 "row agree and update Documentation/vtk-mapper.md")

        # A magnified screenshot (vtkWindowToImageFilter::SetScale, as
        # Slicer's Screen Capture takes; rendered as 2 x 2 tiles) against
        # a render at that size.
        large = {kind: Render(kind, size=2 * SIZE).pixels() for kind in MAPPERS}
        scaled = {kind: Render(kind, scale=2).pixels() for kind in MAPPERS}
        effects = {kind: iou(scaled[kind], large[kind]) > 0.9 for kind in MAPPERS}
        rows.append(self.row("magnified screenshot (SetScale(2))", scaled["ours"], scaled["gpu"],
                             scaled["fixed-point"], "agrees", effects))
        print("magnified screenshot: mean colour %s, of the large render %s" % (
            ["%.1f" % c for c in mean_colour(scaled["ours"])], ["%.1f" % c for c in mean_colour(large["ours"])]))
        for kind in MAPPERS:
            self.assertTrue(effects[kind], "%s mapper: a magnified screenshot is the large render" % kind)
        self.assertGreater(iou(scaled["ours"], scaled["gpu"]), 0.85, "magnified screenshots: ours against VTK's GPU")
        # Per pixel the two differ by their noise (8 samples); their mean
        # colours differ when tiles miss samples or light.
        self.assertLess(max(abs(a - b) for a, b in zip(mean_colour(scaled["ours"]), mean_colour(large["ours"]))), 3,
                        "magnified screenshots: the mean colour of our large render")

        table = ["| feature | IoU with VTK's GPU mapper | colour difference dC (0-255) | VTK's fixed-point vs GPU IoU "
                 "| status |", "|---|---|---|---|---|"]
        table += ["| %s | %.3f | %.1f | %s | %s |" % row for row in rows]
        path = os.environ.get("MMRTM_CONFORMANCE_TABLE")
        if path:
            with open(path, "w") as out:
                out.write("\n".join(table) + "\n")
        print("\n".join(table))

    def test_a_single_slice_is_a_slab(self):
        """A single slice (64 x 1 x 93, seen face on) renders as a slab one
        voxel thick, without an error. VTK's two mappers render nothing here
        (coverage 0), so this is ours alone: catches the refusal ("at least
        2 voxels along every axis", no image) that it replaced."""
        from vtkmodules.vtkCommonCore import vtkCommand
        errors = []

        def one_slice(r):
            voi = vtkExtractVOI()
            voi.SetInputData(head_image(r))
            voi.SetVOI(0, 63, 20, 20, 0, 92)
            voi.Update()
            as_data(r, voi.GetOutput())
            r.mapper.AddObserver(vtkCommand.ErrorEvent, lambda *args: errors.append(args))

        coverages = {kind: coverage(Render(kind, one_slice).pixels()) for kind in MAPPERS}
        print("single slice: coverage %s" % ", ".join("%s %.3f" % kv for kv in coverages.items()))
        self.assertEqual(errors, [])
        self.assertGreater(coverages["ours"], 0.1, "the slab shows the slice")

    @staticmethod
    def row(name, ours, gpu, fixed_point, status, effects):
        with_gpu, dc = iou(ours, gpu), colour_difference(ours, gpu)
        vtk_pair = "%.3f" % iou(fixed_point, gpu) if fixed_point else "not in the fixed-point mapper"
        print("%-36s IoU with VTK's GPU mapper %.3f, dC %.1f (fixed-point vs GPU: IoU %s); %s%s"
              % (name, with_gpu, dc, vtk_pair, status,
                 "; effect " + ", ".join("%s %s" % (k, "yes" if v else "no") for k, v in effects.items())
                 if effects else ""))
        return (name, with_gpu, dc, vtk_pair, status)


if __name__ == "__main__":
    unittest.main()
