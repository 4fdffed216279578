"""vtkMultiMaterialVolumeMapper driven from Python as a ParaView-style script
would: build a pipeline and render; change nothing and the samples
accumulate; change a transfer function, the camera or the data and the
mapper redoes exactly the work that change needs (counted by the mapper).

Run by ctest under Testing/headless.sh (its own Xvfb) with /usr/bin/python3 (python3-vtk9) and the
build tree's mmrtm package on PYTHONPATH.
"""
import math
import os
import subprocess
import sys
import tempfile
import unittest

from vtkmodules.vtkCommonCore import vtkCommand, vtkFloatArray, vtkIdList
from vtkmodules.vtkCommonDataModel import vtkImageData, vtkPiecewiseFunction, vtkPlane, vtkPlaneCollection
from vtkmodules.vtkImagingCore import vtkImageAppendComponents, vtkImageShiftScale, vtkImageThreshold
from vtkmodules.vtkIOImage import vtkNrrdReader, vtkPNGReader
from vtkmodules.vtkFiltersSources import vtkSphereSource
from vtkmodules.vtkRenderingCore import (vtkActor, vtkTexture, vtkPolyDataMapper, vtkColorTransferFunction, vtkRenderer, vtkRenderWindow, vtkVolume,
                                         vtkVolumeProperty, vtkWindowToImageFilter)
import vtkmodules.vtkRenderingOpenGL2  # noqa: F401  (the OpenGL render window)
import vtkmodules.vtkRenderingVolumeOpenGL2  # noqa: F401  (the image display helper)

from vtkmodules.util.vtkConstants import (VTK_FLOAT, VTK_INT, VTK_SHORT, VTK_STRING, VTK_UNSIGNED_CHAR,
                                           VTK_UNSIGNED_SHORT)

from mmrtm import vtkMultiMaterialProperty, vtkMultiMaterialVolumeMapper, vtkMultiMaterialVolumeReader

DATA = os.environ["MMRTM_SHARED_DATA_DIR"]
BACKGROUND = (0.1, 0.1, 0.15)


class Scene:
    """A head CT (64 x 64 x 93) with a bone transfer function, 128 x 128."""

    def __init__(self):
        self.reader = vtkNrrdReader()
        self.reader.SetFileName(os.path.join(DATA, "ct_head_headsq.nrrd"))
        self.shift = vtkImageShiftScale()  # a pipeline stage whose change is a data change
        self.shift.SetInputConnection(self.reader.GetOutputPort())
        self.mapper = vtkMultiMaterialVolumeMapper()
        self.mapper.SetInputConnection(self.shift.GetOutputPort())
        self.mapper.SetSamplesPerRender(2)
        self.mapper.SetMaximumSamples(8)
        self.mapper.SetSeed(3)
        self.mapper.SetBackendToCPU()
        self.opacity = vtkPiecewiseFunction()
        self.opacity.AddPoint(1100, 0.0)
        self.opacity.AddPoint(2000, 0.8)
        self.color = vtkColorTransferFunction()
        self.color.AddRGBPoint(1100, 0.9, 0.6, 0.5)
        self.color.AddRGBPoint(2000, 1.0, 0.95, 0.9)
        self.property = vtkVolumeProperty()
        self.property.SetScalarOpacity(self.opacity)
        self.property.SetColor(self.color)
        self.property.ShadeOn()
        self.property.SetAmbient(0.3)
        self.volume = vtkVolume()
        self.volume.SetMapper(self.mapper)
        self.volume.SetProperty(self.property)
        self.renderer = vtkRenderer()
        self.renderer.AddVolume(self.volume)
        self.renderer.SetBackground(*BACKGROUND)
        self.window = vtkRenderWindow()
        self.window.SetOffScreenRendering(1)
        self.window.AddRenderer(self.renderer)
        self.window.SetSize(128, 128)
        self.renderer.ResetCamera()
        self.renderer.GetActiveCamera().Elevation(-80)
        self.renderer.GetActiveCamera().OrthogonalizeViewUp()

    def add_bone_labels(self, color):
        """A label map on the CT's grid (label 1 where it is above 1500: the
        bone) as the mapper's mask, label 1 coloured `color` (r, g, b).
        Returns the threshold filter and the colour function."""
        threshold = vtkImageThreshold()
        threshold.SetInputConnection(self.reader.GetOutputPort())
        threshold.ThresholdByUpper(1500)
        threshold.SetInValue(1)
        threshold.SetOutValue(0)
        threshold.SetOutputScalarTypeToUnsignedChar()
        threshold.Update()
        self.mapper.SetMaskInput(threshold.GetOutput())
        self.mapper.SetMaskTypeToLabelMap()
        function = vtkColorTransferFunction()
        function.AddRGBPoint(0, *color)
        self.property.SetLabelColor(1, function)
        return threshold, function

    def add_sphere(self, color=(0.0, 1.0, 0.0)):
        """An opaque sphere through the side of the head: partly outside the
        skull, partly inside (hidden by the bone in front)."""
        sphere = vtkSphereSource()
        x, y, z = self.reader.GetOutput().GetCenter()
        sphere.SetCenter(x + 80, y, z)
        sphere.SetRadius(45)
        mapper = vtkPolyDataMapper()
        mapper.SetInputConnection(sphere.GetOutputPort())
        actor = vtkActor()
        actor.SetMapper(mapper)
        actor.GetProperty().SetColor(*color)
        self.renderer.AddActor(actor)
        return actor

    def render(self):
        self.window.Render()

    def counts(self):
        m = self.mapper
        return m.GetNumberOfSceneBuilds(), m.GetNumberOfRefits(), m.GetNumberOfRestarts()

    def pixels(self):
        grab = vtkWindowToImageFilter()
        grab.SetInput(self.window)
        grab.ReadFrontBufferOff()
        grab.Update()
        a = grab.GetOutput().GetPointData().GetScalars()
        n = a.GetNumberOfComponents()
        return [a.GetValue(i) for i in range(a.GetNumberOfTuples() * n) if i % n < 3]


class ErrorCatcher:
    """Collects the messages of an object's ErrorEvent (instead of printing them)."""

    CallDataType = VTK_STRING  # VTK passes the message to __call__

    def __init__(self):
        self.messages = []

    def __call__(self, obj, event, message):
        self.messages.append(message)


def mean_abs_difference(a, b):
    return sum(abs(x - y) for x, y in zip(a, b)) / len(a) / 255.0


def coverage(pixels):
    covered = 0
    for i in range(0, len(pixels), 3):
        if max(abs(pixels[i + c] / 255.0 - BACKGROUND[c]) for c in range(3)) > 0.08:
            covered += 1
    return covered / (len(pixels) / 3)


class MapperTest(unittest.TestCase):
    def test_renders_something(self):
        s = Scene()
        s.render()
        self.assertEqual(s.mapper.GetAccumulatedSamples(), 2)
        self.assertTrue(s.mapper.GetBackendDescription().startswith("cpu"))
        c = coverage(s.pixels())
        self.assertGreater(c, 0.05, "the volume covers almost nothing: a black or empty image")
        self.assertLess(c, 0.9)

    def test_unchanged_scene_accumulates_up_to_the_maximum(self):
        s = Scene()
        samples = []
        for _ in range(6):
            s.render()
            samples.append(s.mapper.GetAccumulatedSamples())
        self.assertEqual(samples, [2, 4, 6, 8, 8, 8])
        self.assertEqual(s.counts(), (1, 1, 1), "nothing changed: no rebuild, refit or restart")
        s.pixels()  # a screenshot renders with a copy of the camera: no restart
        self.assertEqual(s.counts(), (1, 1, 1))
        s.mapper.ResetAccumulation()
        s.render()
        self.assertEqual(s.mapper.GetAccumulatedSamples(), 2)

    def test_a_magnified_screenshot_keeps_the_view_accumulating(self):
        """vtkWindowToImageFilter::SetScale(2) renders the window as 2 x 2
        tiles: each tile is traced with as many samples as the view had, and
        the view goes on accumulating after the screenshot instead of
        starting again. Catches tiles traced with SamplesPerRender only (a
        screenshot noisier than the view), and the view's film lost to the
        tiles."""
        s = Scene()
        for _ in range(3):
            s.render()
        self.assertEqual(s.mapper.GetAccumulatedSamples(), 6)
        grab = vtkWindowToImageFilter()
        grab.SetInput(s.window)
        grab.SetScale(2)
        grab.ReadFrontBufferOff()
        tile_samples = []
        s.renderer.AddObserver("EndEvent", lambda *_: tile_samples.append(s.mapper.GetAccumulatedSamples()))
        grab.Update()
        self.assertEqual(grab.GetOutput().GetDimensions()[:2], (256, 256))
        self.assertEqual(tile_samples[-4:], [6, 6, 6, 6], "each tile as many samples as the view")
        self.assertEqual(s.counts(), (1, 1, 5), "a restart per tile")
        s.render()
        self.assertEqual(s.mapper.GetAccumulatedSamples(), 8, "the view went on from its 6 samples")
        self.assertEqual(s.counts(), (1, 1, 5))

    def test_a_mapper_shared_by_two_renderers_converges_in_each(self):
        """One mapper on one volume shown in two renderers (two viewports,
        cameras from two sides): each renderer's view keeps its own
        accumulation. Catches the views restarting each other at every
        render (each stayed at SamplesPerRender)."""
        s = Scene()
        s.renderer.SetViewport(0, 0, 0.5, 1)
        other = vtkRenderer()
        other.SetViewport(0.5, 0, 1, 1)
        other.AddVolume(s.volume)
        s.window.AddRenderer(other)
        other.ResetCamera()
        other.GetActiveCamera().Azimuth(90)
        seen = {}
        for ren in (s.renderer, other):
            ren.AddObserver("EndEvent", lambda r, _e: seen.setdefault(r, []).append(s.mapper.GetAccumulatedSamples()))
        for _ in range(5):
            s.render()
        self.assertEqual(seen[s.renderer], [2, 4, 6, 8, 8])
        self.assertEqual(seen[other], [2, 4, 6, 8, 8])
        self.assertEqual(s.counts(), (1, 1, 2), "one restart per view")
        self.assertGreater(coverage(s.pixels()), 0.05)

    def test_automatic_tone_mapping_is_off_for_a_property_and_the_description_s_for_a_preset(self):
        """The default tone mapping draws a vtkVolumeProperty's scene as VTK
        writes colours (no curve: the same pixels as OFF) and a preset's
        description with its own curve (filmic: the same pixels as FILMIC),
        without restarting the accumulation. Catches a preset drawn without
        the curve it is made for (the C++ example's skull went dark) and a
        property drawn through it (VTK's colours lost)."""
        def drawn(s, mode):
            s.mapper.SetToneMapping(mode)
            s.render()  # converged: a redraw
            return s.pixels()

        def converged(s):
            for _ in range(4):
                s.render()
            self.assertTrue(s.mapper.IsConverged())

        s = Scene()
        converged(s)
        auto = drawn(s, vtkMultiMaterialVolumeMapper.AUTOMATIC_TONE_MAPPING)
        self.assertEqual(auto, drawn(s, vtkMultiMaterialVolumeMapper.TONE_MAPPING_OFF))
        self.assertGreater(mean_abs_difference(auto, drawn(s, vtkMultiMaterialVolumeMapper.FILMIC_TONE_MAPPING)), 0.01)
        materials = vtkMultiMaterialProperty()
        self.assertTrue(materials.SetPreset("ct-bone"))
        p = Scene()
        p.mapper.SetMultiMaterialProperty(materials)
        converged(p)
        auto = drawn(p, vtkMultiMaterialVolumeMapper.AUTOMATIC_TONE_MAPPING)
        restarts = p.mapper.GetNumberOfRestarts()
        self.assertEqual(auto, drawn(p, vtkMultiMaterialVolumeMapper.FILMIC_TONE_MAPPING))
        self.assertGreater(mean_abs_difference(auto, drawn(p, vtkMultiMaterialVolumeMapper.TONE_MAPPING_OFF)), 0.01)
        self.assertEqual(p.mapper.GetNumberOfRestarts(), restarts, "a tone mapping change redraws, no restart")

    def test_a_projection_blend_mode_is_one_sample(self):
        """Maximum intensity is a projection: one sample per pixel through
        the pixel's centre is the whole image, so the mapper traces one and
        stops; its image differs from the composite one, and going back to
        composite restarts the path tracing. Catches a projection traced
        SamplesPerRender times per render (identical samples), and a blend
        mode change that does not restart."""
        s = Scene()
        s.render()
        composite = s.pixels()
        s.mapper.SetBlendModeToMaximumIntensity()
        for _ in range(3):
            s.render()
        self.assertEqual(s.mapper.GetAccumulatedSamples(), 1)
        self.assertTrue(s.mapper.IsConverged())
        # The unshaded composite glows (its colour an emission); a projection
        # reads the colour as the albedo: one translation, no rebuild.
        self.assertEqual(s.counts(), (1, 2, 2), "the blend mode restarts and translates, nothing else")
        mip = s.pixels()
        self.assertGreater(coverage(mip), 0.05)
        self.assertGreater(mean_abs_difference(composite, mip), 0.01)
        s.mapper.SetBlendModeToComposite()
        s.render()
        self.assertEqual(s.mapper.GetAccumulatedSamples(), 2)
        self.assertFalse(s.mapper.IsConverged())
        # Over a multi-material description (its own materials; the
        # average normalises by the input's value range, kept from the
        # build: lost, the image is black).
        materials = vtkMultiMaterialProperty()
        self.assertTrue(materials.SetPreset("ct-bone"))
        self.assertTrue(materials.MergeSceneJSON(
            '{"materials": {"bone": {"tfs": {"density": [{"type": "cctf", "proxy": "scalars",'
            ' "points": [[1100, 0], [1500, 0.5], [2500, 1]]}]}}}}'))
        s.mapper.SetMultiMaterialProperty(materials)
        s.mapper.SetBlendModeToAverageIntensity()
        s.mapper.SetAverageIPScalarRange(1100, 4000)  # the bone's samples only
        s.render()
        self.assertEqual(s.mapper.GetAccumulatedSamples(), 1)
        average = s.pixels()
        self.assertGreater(coverage(average), 0.05)
        # 88 here; a lost range makes the average black and leaves the
        # background's 38 as the brightest channel.
        self.assertGreater(max(average), 60, "the average is not black")

    def test_transfer_function_change_refits_and_restarts(self):
        s = Scene()
        for _ in range(3):
            s.render()
        before = s.pixels()
        # Editing a function does not change the property's own MTime; the
        # mapper must notice anyway.
        s.opacity.AddPoint(1500, 0.0)
        s.color.AddRGBPoint(2000, 0.2, 0.4, 1.0)
        s.render()
        self.assertEqual(s.counts(), (1, 2, 2))
        self.assertEqual(s.mapper.GetAccumulatedSamples(), 2)
        self.assertGreater(mean_abs_difference(before, s.pixels()), 0.005, "the image did not change")

    def test_camera_change_restarts_only(self):
        """A camera move or a window resize restarts the accumulation and
        does nothing else: no translation, no refit of the majorants (every
        render used to refit them: 2 ms on the head CT, 309 ms with the
        voxel-value refit)."""
        s = Scene()
        s.render()
        s.render()
        refits = s.mapper.GetNumberOfMajorantGridRefits()
        self.assertEqual(refits, 1)
        s.renderer.GetActiveCamera().Azimuth(20)
        s.render()
        self.assertEqual(s.counts(), (1, 1, 2))
        self.assertEqual(s.mapper.GetAccumulatedSamples(), 2)
        s.window.SetSize(96, 80)
        s.render()
        self.assertEqual(s.counts(), (1, 1, 3))
        self.assertEqual(s.mapper.GetNumberOfMajorantGridRefits(), refits)

    def test_a_new_volume_reports_its_summary_build_as_progress(self):
        """The first render of a volume builds the majorant grid's summaries
        (every voxel read: seconds for gigabytes); the mapper reports it as
        VTK's ProgressEvent, up to 1, on the render thread. A camera move
        reads no voxels: no progress. Catches a build that tells the
        application nothing."""
        s = Scene()
        fractions = []
        s.mapper.AddObserver("ProgressEvent", lambda mapper, event: fractions.append(mapper.GetProgress()))
        s.render()
        self.assertGreater(len(fractions), 1)
        self.assertEqual(fractions, sorted(fractions))
        self.assertEqual(fractions[-1], 1.0)
        fractions.clear()
        s.renderer.GetActiveCamera().Azimuth(10)
        s.render()
        self.assertEqual(fractions, [], "a camera move builds nothing")

    def test_data_change_rebuilds(self):
        s = Scene()
        s.render()
        s.shift.SetShift(200.0)  # every value +200: the bone grows
        s.render()
        self.assertEqual(s.counts(), (2, 2, 2))
        s.render()
        self.assertEqual(s.counts(), (2, 2, 2))

    def test_label_function_edit_refits(self):
        # The bone as label 1, coloured blue.
        s = Scene()
        threshold, blue = s.add_bone_labels((0.1, 0.2, 0.9))
        s.render()
        s.render()
        self.assertEqual(s.counts(), (1, 1, 1))
        before = s.pixels()
        # VTK's gotcha: editing the label's function leaves the property's
        # MTime alone. The mapper watches the function itself.
        blue.AddRGBPoint(0, 0.9, 0.8, 0.1)
        s.render()
        self.assertEqual(s.counts(), (1, 2, 2))
        self.assertGreater(mean_abs_difference(before, s.pixels()), 0.005)
        # A new mask is a data change.
        threshold.SetInValue(2)
        threshold.Update()
        s.render()
        self.assertEqual(s.counts(), (2, 3, 3))

    def test_label_material_parameters(self):
        # The bone (label 1) as a glowing, purely volumetric material.
        s = Scene()
        s.add_bone_labels((0.5, 0.5, 0.5))
        s.render()
        plain = s.pixels()
        s.mapper.SetLabelMaterialParameters(1, '{"emission": [0, 4, 0], "surface_probability": 0}')
        self.assertEqual(s.mapper.GetLabelMaterialParameters(1), '{"emission": [0, 4, 0], "surface_probability": 0}')
        s.render()
        self.assertEqual(s.counts()[1], 2, "new parameters: a refit")
        glowing = s.pixels()
        greener = sum(glowing[i + 1] - plain[i + 1] for i in range(0, len(plain), 3)) / (len(plain) / 3)
        self.assertGreater(greener, 2, "the emission shows")
        s.render()
        self.assertEqual(s.counts()[1], 2, "unchanged parameters: no refit")
        # A bad key is an error that names it; the render keeps the last image.
        errors = ErrorCatcher()
        s.mapper.AddObserver("ErrorEvent", errors)
        s.mapper.SetLabelMaterialParameters(1, '{"shininess": 3}')
        s.render()
        self.assertTrue(any("shininess" in m for m in errors.messages), errors.messages)
        s.mapper.SetLabelMaterialParameters(1, None)
        self.assertIsNone(s.mapper.GetLabelMaterialParameters(1))
        s.render()
        self.assertLess(mean_abs_difference(plain, s.pixels()), 0.002, "removed: the plain label again")

    def test_opaque_geometry_hides_and_moving_it_restarts(self):
        s = Scene()
        s.render()
        actor = s.add_sphere()  # green
        s.render()
        self.assertEqual(s.counts(), (1, 1, 2), "new geometry: a restart")

        def green(pixels):
            return sum(1 for i in range(0, len(pixels), 3) if pixels[i + 1] > pixels[i] + 40)

        with_volume = green(s.pixels())
        s.volume.VisibilityOff()
        s.render()
        alone = green(s.pixels())
        s.volume.VisibilityOn()
        s.render()
        self.assertGreater(with_volume, 0.5 * alone, "the sphere in front of the bone shows")
        self.assertLess(with_volume, alone - 20, "the bone in front hides part of the sphere")
        count = s.counts()
        s.render()
        self.assertEqual(s.counts(), count, "unchanged geometry: no restart")
        actor.SetPosition(5, 0, 0)
        s.render()
        self.assertEqual(s.counts()[2], count[2] + 1, "moved geometry: a restart")

    def test_interaction_renders_a_preview_then_refines(self):
        s = Scene()
        s.render()
        s.render()
        self.assertEqual(s.mapper.GetAccumulatedSamples(), 4)
        # vtkRenderWindowInteractor asks for 15 frames per second while the camera moves.
        s.window.SetDesiredUpdateRate(15.0)
        s.renderer.GetActiveCamera().Azimuth(10)
        s.render()
        self.assertEqual(s.mapper.GetNumberOfInteractiveRenders(), 1)
        self.assertEqual(s.mapper.GetAccumulatedSamples(), 0, "a preview does not accumulate")
        self.assertGreater(coverage(s.pixels()), 0.05, "the preview shows the volume")  # renders a preview again
        restarts = s.mapper.GetNumberOfRestarts()
        s.render()
        self.assertEqual(s.mapper.GetNumberOfRestarts(), restarts,
                         "previews with nothing changed between them restart nothing")
        previews = s.mapper.GetNumberOfInteractiveRenders()
        # When the camera stops, the full-resolution accumulation starts again.
        s.window.SetDesiredUpdateRate(0.0001)
        s.render()
        self.assertEqual(s.mapper.GetAccumulatedSamples(), 2)
        self.assertEqual(s.mapper.GetNumberOfInteractiveRenders(), previews)

    def test_depth_peeling_for_volumes_traces_once_per_frame(self):
        """With the renderer's depth peeling for volumes and a translucent
        sphere, VTK calls Render once per peel. Catches a frame traced more
        than once (each call restarting on the depth it read inside the
        peel: a garbled image), a translucent actor that no longer shows
        over the volume, and a volume that no longer shows."""
        s = Scene()
        s.window.SetMultiSamples(0)  # VTK peels only without multisampling
        sphere = vtkSphereSource()  # in front of the face, partly over it
        c = s.volume.GetCenter()
        sphere.SetCenter(c[0] + 30, -10, c[2])
        sphere.SetRadius(30)
        mapper = vtkPolyDataMapper()
        mapper.SetInputConnection(sphere.GetOutputPort())
        actor = vtkActor()
        actor.SetMapper(mapper)
        actor.GetProperty().SetColor(0.0, 0.0, 1.0)
        actor.GetProperty().SetOpacity(0.5)
        s.renderer.AddActor(actor)
        s.renderer.SetUseDepthPeeling(1)
        s.renderer.SetUseDepthPeelingForVolumes(1)
        calls = []
        s.mapper.AddObserver(vtkCommand.VolumeMapperRenderStartEvent, lambda *args: calls.append(1))
        for frame in range(1, 4):
            before = len(calls)
            s.render()
            self.assertGreater(len(calls) - before, 1, "VTK peels the volume: Render is called per peel")
            self.assertEqual(s.mapper.GetNumberOfTracedPasses(), frame, "one traced pass per frame")
            self.assertEqual(s.mapper.GetAccumulatedSamples(), 2 * frame, "the frames accumulate")
        self.assertEqual(s.mapper.GetNumberOfRestarts(), 1, "the depth read in the peels is the same each frame")
        pixels = s.pixels()
        blue = sum(1 for i in range(0, len(pixels), 3) if pixels[i + 2] > pixels[i] + 40)
        self.assertGreater(blue, 0.02 * len(pixels) / 3, "the translucent sphere shows (547 of 16384 pixels)")
        s.renderer.RemoveActor(actor)
        s.render()
        self.assertGreater(coverage(s.pixels()), 0.05, "the volume shows")

    def test_image_sample_distance_and_auto_adjust(self):
        """VTK's ImageSampleDistance and AutoAdjustSampleDistances, counted
        by film sizes: catches a distance that is ignored (a still film of
        the viewport's size at distance 2 with AutoAdjust off), a still
        render that does not go back to full resolution with AutoAdjust on,
        and a preview that adapts when AutoAdjust is off."""
        s = Scene()
        size = [0, 0]
        s.mapper.SetImageSampleDistance(2.0)
        s.render()
        s.mapper.GetLastFilmSize(size)
        self.assertEqual(size, [128, 128], "AutoAdjust on: a still render at the minimum distance, 1")
        s.mapper.AutoAdjustSampleDistancesOff()
        s.render()
        s.mapper.GetLastFilmSize(size)
        self.assertEqual(size, [64, 64], "AutoAdjust off: ImageSampleDistance 2 gives a film of half the size")
        image = vtkImageData()
        s.mapper.GetAccumulatedImage(image)
        self.assertEqual(image.GetDimensions()[:2], (64, 64))
        self.assertGreater(coverage(s.pixels()), 0.05, "the half-size film is stretched over the viewport")
        s.mapper.SetImageSampleDistance(3.0)
        s.render()
        s.mapper.GetLastFilmSize(size)
        self.assertEqual(size, [43, 43], "a distance that does not divide the viewport rounds up")
        # Previews at a budget no frame can meet (1 us: a 16 x 16 frame
        # takes a fraction of a millisecond, so 1 ms was met on a fast or
        # idle machine): fixed with AutoAdjust off, coarser with it on.
        s.window.SetDesiredUpdateRate(1.0e6)
        sizes = set()
        for _ in range(4):
            s.renderer.GetActiveCamera().Azimuth(5)
            s.render()
            s.mapper.GetLastFilmSize(size)
            sizes.add(tuple(size))
        self.assertEqual(sizes, {(43, 43)}, "AutoAdjust off: the preview keeps ImageSampleDistance")
        s.mapper.AutoAdjustSampleDistancesOn()
        s.mapper.SetMaximumImageSampleDistance(8.0)
        for _ in range(30):
            s.renderer.GetActiveCamera().Azimuth(5)
            s.render()
        s.mapper.GetLastFilmSize(size)
        self.assertEqual(size, [16, 16], "AutoAdjust on: an impossible budget ends at the maximum distance, 8")
        self.assertGreater(s.volume.GetAllocatedRenderTime(), 0.0)
        self.assertLess(s.volume.GetAllocatedRenderTime(), 0.01, "the budget comes from the update rate")
        s.window.SetDesiredUpdateRate(0.0001)
        s.render()
        s.mapper.GetLastFilmSize(size)
        self.assertEqual(size, [128, 128], "the still render after the interaction is at full resolution")

    def test_clipping_and_cropping(self):
        s = Scene()
        s.render()
        whole = coverage(s.pixels())
        # A clipping plane through the middle (world space; the normal's side stays).
        plane = vtkPlane()
        plane.SetOrigin(s.reader.GetOutput().GetCenter())
        plane.SetNormal(1, 0, 0)
        s.mapper.AddClippingPlane(plane)
        s.render()
        clipped = coverage(s.pixels())
        self.assertLess(clipped, 0.8 * whole)
        self.assertGreater(clipped, 0.2 * whole)
        restarts = s.counts()[2]
        plane.SetOrigin(0, 0, 0)  # editing the plane object restarts too
        s.render()
        self.assertEqual(s.counts()[2], restarts + 1)
        s.mapper.RemoveAllClippingPlanes()
        # Subvolume cropping (data coordinates): the half with the lower x only.
        x0, x1, y0, y1, z0, z1 = s.reader.GetOutput().GetBounds()
        s.mapper.SetCroppingRegionPlanes(x0, (x0 + x1) / 2, y0, y1, z0, z1)
        s.mapper.SetCroppingRegionFlagsToSubVolume()
        s.mapper.CroppingOn()
        s.render()
        cropped = coverage(s.pixels())
        self.assertLess(cropped, 0.7 * whole)
        self.assertGreater(cropped, 0.3 * whole)

    def test_multi_material_property_with_a_preset(self):
        s = Scene()
        s.render()
        before = s.pixels()
        materials = vtkMultiMaterialProperty()
        self.assertFalse(materials.SetPreset("no-such-preset"))
        self.assertTrue(materials.SetPreset("ct-bone"))
        # headsq is not in Hounsfield units (0..3926): move the preset's bone up.
        self.assertTrue(materials.MergeSceneJSON(
            '{"materials": {"bone": {"tfs": {"density": [{"type": "cctf", "proxy": "scalars",'
            ' "points": [[1100, 0], [1500, 0.5], [2500, 1]]}]}}}}'))
        s.mapper.SetMultiMaterialProperty(materials)
        s.render()
        builds, refits, restarts = s.counts()
        self.assertEqual(builds, 2)
        after = s.pixels()
        self.assertGreater(coverage(after), 0.05)
        self.assertGreater(mean_abs_difference(before, after), 0.005, "the preset's materials and lights show")
        s.render()
        self.assertEqual(s.counts(), (builds, refits, restarts), "unchanged description: samples accumulate")
        # An edit of the description over the same data: a refit that keeps
        # the majorant grid's summaries, not a rebuild.
        grids = s.mapper.GetNumberOfMajorantGridBuilds()
        self.assertGreaterEqual(grids, 1)
        materials.MergeSceneJSON('{"materials": {"bone": {"albedo": [0.2, 0.3, 0.9]}}}')
        s.render()
        self.assertEqual(s.counts(), (builds, refits + 1, restarts + 1))
        self.assertEqual(s.mapper.GetNumberOfMajorantGridBuilds(), grids, "the summaries were kept")
        edited = s.pixels()
        self.assertGreater(mean_abs_difference(after, edited), 0.005)
        # The refitted scene renders as a scene built from scratch would.
        fresh = Scene()
        fresh_materials = vtkMultiMaterialProperty()
        fresh_materials.SetSceneJSON(materials.GetSceneJSON())
        fresh.mapper.SetMultiMaterialProperty(fresh_materials)
        fresh.render()
        self.assertEqual(fresh.pixels(), edited)

    def test_environment_texture_lights_the_volume(self):
        s = Scene()
        s.render()

        def blueness(pixels):
            return sum(pixels[i + 2] - pixels[i] for i in range(0, len(pixels), 3)) / (len(pixels) / 3)

        plain = blueness(s.pixels())
        # An equirectangular sky: strong blue everywhere (float = linear radiance).
        sky = vtkImageData()
        sky.SetDimensions(32, 16, 1)
        texels = vtkFloatArray()
        texels.SetNumberOfComponents(3)
        for _ in range(32 * 16):
            texels.InsertNextTuple3(0.1, 0.3, 3.0)
        sky.GetPointData().SetScalars(texels)
        texture = vtkTexture()
        texture.SetInputData(sky)
        s.mapper.SetEnvironmentTexture(texture)
        restarts = s.counts()[2]
        s.render()
        self.assertEqual(s.counts()[2], restarts + 1)
        lit = blueness(s.pixels())
        self.assertGreater(lit, plain + 2, "a blue sky makes the volume bluer")
        s.mapper.SetEnvironmentIntensity(0.0)
        s.render()
        self.assertLess(blueness(s.pixels()), lit - 2)

    def test_2d_transfer_function(self):
        s = Scene()

        def table(alpha_of, rgb):
            # x: scalar 0..4000 in 41 columns; y: gradient magnitude 0..1000 in 11 rows.
            image = vtkImageData()
            image.SetDimensions(41, 11, 1)
            image.SetOrigin(0, 0, 0)
            image.SetSpacing(100, 100, 1)
            values = vtkFloatArray()
            values.SetNumberOfComponents(4)
            for j in range(11):
                for i in range(41):
                    values.InsertNextTuple4(*rgb, alpha_of(100.0 * i, 100.0 * j))
            image.GetPointData().SetScalars(values)
            return image

        s.property.SetTransferFunction2D(table(lambda x, g: 0.0, (1, 1, 1)))
        s.property.SetTransferFunctionMode(1)  # vtkVolumeProperty.TF_2D
        s.render()
        self.assertLess(coverage(s.pixels()), 0.01, "a 2D function without opacity shows nothing")
        # Bone (scalar >= 1500) at every gradient, green.
        bone = table(lambda x, g: 0.9 if x >= 1500 else 0.0, (0.1, 0.9, 0.2))
        s.property.SetTransferFunction2D(bone)
        refits = s.counts()[1]
        s.render()
        self.assertEqual(s.counts()[1], refits + 1)
        pixels = s.pixels()
        self.assertGreater(coverage(pixels), 0.05)
        green = sum(1 for i in range(0, len(pixels), 3) if pixels[i + 1] > pixels[i] + 20)
        self.assertGreater(green, 0.5 * coverage(pixels) * len(pixels) / 3, "the 2D colours show")
        # Only where the gradient is small (inside the bone, not its surface):
        # less is seen than with every gradient.
        s.property.SetTransferFunction2D(table(lambda x, g: 0.9 if x >= 1500 and g < 100 else 0.0, (0.1, 0.9, 0.2)))
        s.render()
        self.assertLess(coverage(s.pixels()), coverage(pixels))

    def test_independent_components_mix(self):
        # Two components: the CT, and the CT shifted down by 1000 (so that its
        # soft tissue reaches the bone window); each with its own functions.
        s = Scene()
        shifted = vtkImageShiftScale()
        shifted.SetInputConnection(s.reader.GetOutputPort())
        shifted.SetShift(-1000.0)
        shifted.SetOutputScalarTypeToShort()
        both = vtkImageAppendComponents()
        both.AddInputConnection(s.reader.GetOutputPort())
        both.AddInputConnection(shifted.GetOutputPort())
        s.mapper.SetInputConnection(both.GetOutputPort())
        green = vtkColorTransferFunction()
        green.AddRGBPoint(0, 0.1, 0.9, 0.2)
        second = vtkPiecewiseFunction()
        second.AddPoint(-1000, 0.0)
        second.AddPoint(1500, 0.0)
        s.property.SetScalarOpacity(1, second)
        s.property.SetColor(1, green)
        s.render()
        self.assertEqual(s.counts()[0], 1)
        alone = coverage(s.pixels())
        self.assertGreater(alone, 0.05, "component 0 alone: the bone")
        # Component 1 opaque from 0 (the CT's 1000): more of the head shows, in green.
        second.AddPoint(0, 0.0)
        second.AddPoint(300, 0.6)
        s.render()
        self.assertEqual(s.counts()[1], 2, "editing component 1's function refits")
        pixels = s.pixels()
        self.assertGreater(coverage(pixels), alone + 0.02)
        greenish = sum(1 for i in range(0, len(pixels), 3) if pixels[i + 1] > pixels[i] + 20)
        self.assertGreater(greenish, 50)
        # Component 1's gradient opacity (only its edges) is its own: less of it shows.
        covered = coverage(pixels)
        edges = vtkPiecewiseFunction()
        edges.AddPoint(0, 0.0)
        edges.AddPoint(2000, 1.0)
        s.property.SetGradientOpacity(1, edges)
        s.render()
        self.assertEqual(s.counts()[0], 2, "a component's gradient proxy: a rebuild")
        self.assertLess(coverage(s.pixels()), covered)
        s.property.DisableGradientOpacityOn(1)
        # A weight of 0 removes component 1 again.
        s.property.SetComponentWeight(1, 0.0)
        s.render()
        self.assertLess(abs(coverage(s.pixels()) - alone), 0.01)

    def test_rendering_leaves_the_property_as_it_was(self):
        """A render reads the vtkVolumeProperty without creating VTK's default
        functions in it (its getters do, and the grey and RGB ones call
        Modified): the property's MTime stays, so an application watching it
        sees no edit it did not make. Catches a getter that creates (the
        MTime moved during the first render: the property holds functions
        for component 0 only)."""
        s = Scene()
        before = s.property.GetMTime()
        s.render()
        s.render()
        self.assertEqual(s.property.GetMTime(), before)
        self.assertGreater(coverage(s.pixels()), 0.05, "the head was rendered")
        # Component 0's colour as grey (no function set): VTK's default ramp,
        # made by the mapper, not in the property.
        grey = vtkVolumeProperty()
        grey.SetScalarOpacity(s.opacity)
        s.volume.SetProperty(grey)
        before = grey.GetMTime()
        s.render()
        self.assertEqual(grey.GetMTime(), before)
        self.assertGreater(coverage(s.pixels()), 0.05, "the head was rendered with the default colour")

    def test_a_label_material_is_the_label_functions_of_its_look(self):
        """SetLabelMaterial (the one label rule: density 2.5/mm x opacity, the
        colour as albedo) renders as VTK label functions of that look do:
        a constant colour and the opacity 1 - exp(-2.5 o d) per unit distance
        d, which the mapper turns back into 2.5 o. The materials differ in
        form (a constant against a curve), so their majorants and random
        numbers may differ: the images' mean brightness is compared, with
        its standard error from 6 seeds of each (limit |z| < 4.5). Power: a
        look 20 % fainter (opacity 0.08 instead of 0.1) gives z = 6.6 here,
        and the test requires it to fail.
        """
        colour, opacity = (0.2, 0.4, 0.9), 0.1  # translucent: the opacity shows

        def brightness(seed, look_opacity=None):
            s = Scene()
            s.mapper.SetLookToFilmic()  # the look the power was measured in (z 3.7 in the VTK look's glow)
            s.mapper.SetSeed(seed)
            s.add_bone_labels(colour)
            if look_opacity is None:
                unit = s.property.GetScalarOpacityUnitDistance()
                a = 1.0 - math.exp(-vtkMultiMaterialVolumeMapper.GetLabelDensityAtFullOpacity() * opacity * unit)
                f = vtkPiecewiseFunction()
                f.AddPoint(0, a)
                s.property.SetLabelScalarOpacity(1, f)
            else:
                s.mapper.SetLabelMaterial(1, *colour, look_opacity)
            for _ in range(4):
                s.render()
            pixels = s.pixels()
            self.assertGreater(coverage(pixels), 0.05, "the bone label shows")
            return sum(pixels) / len(pixels)

        def z(a, b):
            def mean_var(x):
                m = sum(x) / len(x)
                return m, sum((v - m) ** 2 for v in x) / (len(x) - 1) / len(x)
            (ma, va), (mb, vb) = mean_var(a), mean_var(b)
            return (mb - ma) / math.sqrt(va + vb)

        seeds = range(10, 16)
        functions = [brightness(seed) for seed in seeds]
        look = [brightness(seed, opacity) for seed in seeds]
        fainter = [brightness(seed, 0.08) for seed in seeds]
        print("label functions %.3f, label material %.3f (z %.2f), at opacity 0.08 %.3f (z %.2f)" % (
            sum(functions) / 6, sum(look) / 6, z(functions, look), sum(fainter) / 6, z(functions, fainter)))
        self.assertLess(abs(z(functions, look)), 4.5)
        self.assertGreater(abs(z(functions, fainter)), 4.5, "the check sees the lower opacity")

    def test_the_labels_present_in_a_label_map(self):
        """GetLabelsPresent, the front ends' one label scan (the viewer's
        label list, ParaView's label-map array): the distinct non-zero
        values, ascending, for each voxel type; an image of fractional
        values, of two components or without scalars is refused with a
        warning and no labels. Catches label 0 counted, a label missed or
        repeated, and a fractional value truncated into a label."""
        def label_map(vtk_type, values, components=1):
            image = vtkImageData()
            image.SetDimensions(len(values) // components, 1, 1)
            image.AllocateScalars(vtk_type, components)
            scalars = image.GetPointData().GetScalars()
            for i, v in enumerate(values):
                scalars.SetValue(i, v)
            return image

        def present(image):
            ids = vtkIdList()
            ids.InsertNextId(99)  # emptied first
            found = vtkMultiMaterialVolumeMapper.GetLabelsPresent(image, ids)
            return found, [ids.GetId(i) for i in range(ids.GetNumberOfIds())]

        for vtk_type in (VTK_UNSIGNED_CHAR, VTK_SHORT, VTK_UNSIGNED_SHORT, VTK_INT, VTK_FLOAT):
            self.assertEqual(present(label_map(vtk_type, [0, 7, 3, 7, 0, 12, 3])), (True, [3, 7, 12]), vtk_type)
        # Refused, each with a warning on VTK's output window.
        self.assertEqual(present(label_map(VTK_FLOAT, [0, 1.5, 2])), (False, []))
        self.assertEqual(present(label_map(VTK_UNSIGNED_CHAR, [0, 1, 2, 3], components=2)), (False, []))
        self.assertEqual(present(vtkImageData()), (False, []))

    def test_each_warning_once_for_its_own_cause(self):
        """Each of the mapper's warnings is said once when its cause appears,
        not on every render, and the others are still said after it. Catches
        one flag shared by the warnings (after the first, the others were
        never said) and a warning repeated on every render."""
        s = Scene()
        warnings = ErrorCatcher()
        s.mapper.AddObserver(vtkCommand.WarningEvent, warnings)

        def said(text):
            return sum(1 for m in warnings.messages if text in m)

        s.mapper.SetBlendModeToIsoSurface()
        s.render()
        s.render()
        self.assertEqual(said("isosurface"), 0, warnings.messages)  # isosurfaces of one component are traced
        s.mapper.SetCroppingRegionPlanes(*s.mapper.GetBounds())
        s.mapper.SetCroppingRegionFlagsToFence()
        s.mapper.CroppingOn()
        s.render()
        s.render()
        self.assertEqual(said("cropping"), 0, warnings.messages)  # every cropping region is supported
        s.mapper.CroppingOff()
        # Five independent components: the CT five times.
        five = vtkImageAppendComponents()
        for _ in range(5):
            five.AddInputConnection(s.reader.GetOutputPort())
        s.mapper.SetInputConnection(five.GetOutputPort())
        s.property.IndependentComponentsOn()
        s.render()
        s.render()
        self.assertEqual(said("only the first 4 of 5 independent components"), 1, warnings.messages)
        self.assertEqual(said("isosurface blending of 5 components is not supported"), 1, warnings.messages)
        # A mask as well: its own warning; the components' cause still holds, not said again.
        s.add_bone_labels((1.0, 0.2, 0.2))
        s.render()
        s.render()
        self.assertEqual(said("with independent components, the mask is not used"), 1, warnings.messages)
        self.assertEqual(said("only the first 4 of 5 independent components"), 1, warnings.messages)
        # A cause that goes away and comes back is said again.
        s.mapper.SetBlendModeToComposite()
        s.render()
        s.mapper.SetBlendModeToIsoSurface()
        s.render()
        self.assertEqual(said("isosurface blending of 5 components is not supported"), 2, warnings.messages)
        # More clipping planes than the tracer takes (12): its own warning, once.
        planes = vtkPlaneCollection()
        bounds = s.mapper.GetBounds()
        for _ in range(13):
            plane = vtkPlane()
            plane.SetOrigin(bounds[0], bounds[2], bounds[4])
            plane.SetNormal(1, 0, 0)  # keeps the whole volume
            planes.AddItem(plane)
        s.mapper.SetClippingPlanes(planes)
        s.render()
        s.render()
        self.assertEqual(said("clipping and cropping planes are used"), 1, warnings.messages)
        self.assertEqual(len(warnings.messages), 5, warnings.messages)

    def test_noise_target_stops_the_refinement(self):
        s = Scene()
        s.mapper.SetMaximumSamples(0)  # no sample limit: only the noise target stops
        s.render()
        s.render()
        noise4 = s.mapper.GetRelativeNoise()
        self.assertGreater(noise4, 0.0)
        self.assertFalse(s.mapper.IsConverged())
        # Noise falls as 1/sqrt(samples): 0.7 of it needs about 8 samples.
        s.mapper.SetNoiseTarget(0.7 * noise4)
        samples = []
        while not s.mapper.IsConverged() and len(samples) < 50:
            s.render()
            samples.append(s.mapper.GetAccumulatedSamples())
        self.assertTrue(s.mapper.IsConverged(), "the noise target was never reached")
        self.assertLessEqual(s.mapper.GetRelativeNoise(), 0.7 * noise4)
        self.assertTrue(6 <= samples[-1] <= 16, samples)
        s.render()
        self.assertEqual(s.mapper.GetAccumulatedSamples(), samples[-1], "converged: no more samples")

    def test_choosing_another_scalar_array_rebuilds(self):
        """The array the mapper renders (SelectScalarArray, as ParaView's
        ColorBy sets it) is part of what the proxies are made of: choosing
        another array of the same image rebuilds and shows it. Catches a
        mapper that notices only the image's modification time (it kept
        rendering the first array)."""
        s = Scene()
        s.shift.Update()
        image = vtkImageData()
        image.DeepCopy(s.shift.GetOutput())
        ct = image.GetPointData().GetScalars()
        ct.SetName("ct")
        empty = vtkFloatArray()
        empty.SetName("empty")
        empty.SetNumberOfTuples(ct.GetNumberOfTuples())
        empty.Fill(0.0)
        image.GetPointData().AddArray(empty)
        s.mapper.SetInputData(image)
        s.mapper.SetScalarModeToUsePointFieldData()
        s.mapper.SelectScalarArray("ct")
        s.render()
        self.assertGreater(coverage(s.pixels()), 0.05, "the CT array shows")
        builds = s.counts()[0]
        s.mapper.SelectScalarArray("empty")
        s.render()
        self.assertEqual(s.counts()[0], builds + 1, "another array: a rebuild")
        self.assertLess(coverage(s.pixels()), 0.01, "the empty array shows nothing")

    def test_bounces_and_accelerator(self):
        s = Scene()
        s.render()
        lit = s.pixels()
        # Without bounces nothing scatters light toward the camera: darker.
        s.mapper.SetMaximumBounces(0)
        s.render()
        self.assertEqual(s.counts()[2], 2, "a setting: a restart")
        dark = s.pixels()
        self.assertLess(sum(dark), 0.9 * sum(lit))
        # The accelerators are all unbiased: the same image up to noise, as
        # far from the octree's as another seed of the octree is.
        s.mapper.SetMaximumBounces(32)

        def converged():
            for _ in range(4):
                s.render()
            return s.pixels()
        octree = converged()
        s.mapper.SetSeed(4)
        other_seed = mean_abs_difference(octree, converged())
        s.mapper.SetSeed(3)
        s.mapper.SetAcceleratorToNone()
        global_majorant = converged()
        self.assertGreater(coverage(global_majorant), 0.05)
        self.assertGreater(other_seed, 0.0)
        self.assertLess(mean_abs_difference(octree, global_majorant), 1.5 * other_seed)
        # So are both samplers (Sobol' pairs by default, or independent
        # numbers): other numbers, the same image up to noise.
        self.assertEqual(s.mapper.GetSampler(), s.mapper.SOBOL)
        s.mapper.SetAcceleratorToOctree()
        s.mapper.SetSamplerToIndependent()
        independent = converged()
        self.assertNotEqual(independent, octree)
        self.assertLess(mean_abs_difference(octree, independent), 1.5 * other_seed)

    def test_asynchronous_refinement_gives_the_same_image(self):
        import time
        sync, asynchronous = Scene(), Scene()
        asynchronous.mapper.AsynchronousRefinementOn()
        for _ in range(4):
            sync.render()
        # The first render after the start is synchronous; the others start
        # a pass in the background and return at once.
        asynchronous.render()
        self.assertEqual(asynchronous.mapper.GetAccumulatedSamples(), 2)
        renders = 0
        while asynchronous.mapper.GetAccumulatedSamples() < 8 and renders < 2000:
            asynchronous.render()
            renders += 1
            time.sleep(0.005)
        self.assertEqual(asynchronous.mapper.GetAccumulatedSamples(), 8)
        self.assertFalse(asynchronous.mapper.IsRefining())
        self.assertEqual(asynchronous.pixels(), sync.pixels(), "one seed, one image")
        self.assertEqual(asynchronous.counts(), (1, 1, 1))
        # A camera change while a pass is in flight stops it and restarts.
        asynchronous.mapper.SetMaximumSamples(64)
        asynchronous.render()
        asynchronous.render()
        self.assertTrue(asynchronous.mapper.IsRefining())
        asynchronous.renderer.GetActiveCamera().Azimuth(30)
        asynchronous.render()
        self.assertEqual(asynchronous.counts()[2], 2)  # the camera's (the maximum's change keeps the samples)
        self.assertEqual(asynchronous.mapper.GetAccumulatedSamples(), 2)

    def test_settings_that_leave_the_converged_image_keep_the_samples(self):
        """The samples per render, the maximum samples, the noise target, the
        threads and asynchronous refinement do not change the converged
        image: a change of any of them keeps the samples accumulated, and
        the film goes on as if nothing had changed (the same bits as a film
        refined to the end without the changes). Catches a setter that
        restarts (a converged view thrown away when a front end raises its
        maximum), and one that keeps samples a change should discard (the
        seed's change restarts)."""
        s = Scene()
        for _ in range(4):
            s.render()
        self.assertTrue(s.mapper.IsConverged())
        self.assertEqual(s.mapper.GetAccumulatedSamples(), 8)
        counts = s.counts()
        s.mapper.SetMaximumSamples(16)
        s.render()
        self.assertEqual(s.mapper.GetAccumulatedSamples(), 10, "raised: refinement goes on from 8")
        s.mapper.SetSamplesPerRender(4)
        s.mapper.SetNumberOfThreads(1)
        s.render()
        self.assertEqual(s.mapper.GetAccumulatedSamples(), 14)
        s.mapper.SetNoiseTarget(0.001)
        s.mapper.AsynchronousRefinementOn()
        s.mapper.AsynchronousRefinementOff()
        s.render()
        self.assertEqual(s.mapper.GetAccumulatedSamples(), 16)
        self.assertEqual(s.counts(), counts, "no restart, rebuild or refit")
        reference = Scene()
        reference.mapper.SetMaximumSamples(16)
        for _ in range(8):
            reference.render()
        self.assertEqual(reference.mapper.GetAccumulatedSamples(), 16)
        self.assertEqual(film(s.mapper), film(reference.mapper), "the same film as one refined without changes")
        s.mapper.SetMaximumSamples(4)
        s.render()
        self.assertEqual(s.mapper.GetAccumulatedSamples(), 16, "lowered below them: the image keeps them all")
        self.assertTrue(s.mapper.IsConverged())
        s.mapper.SetSeed(4)
        s.render()
        self.assertEqual(s.counts()[2], counts[2] + 1, "another seed is another image: a restart")

    def test_same_seed_same_image(self):
        a, b = Scene(), Scene()
        a.render()
        b.render()
        self.assertEqual(a.pixels(), b.pixels())


def film(mapper):
    image = vtkImageData()
    mapper.GetAccumulatedImage(image)
    a = image.GetPointData().GetScalars()
    return bytes(memoryview(a)) if a is not None else b""


def displayed(mapper):
    image = vtkImageData()
    mapper.GetDisplayedImage(image)
    a = image.GetPointData().GetScalars()
    return [a.GetValue(i) for i in range(a.GetNumberOfTuples() * 4) if i % 4 < 3]


def roughness(values, width=128):
    """Mean absolute difference between horizontal neighbours (RGB)."""
    diffs = [abs(values[i] - values[i - 3]) for i in range(3, len(values)) if (i // 3) % width]
    return sum(diffs) / len(diffs)


class DenoisingTest(unittest.TestCase):
    """The mapper's DenoisingMode (Documentation/denoising.md) on the head CT
    at 128 x 128: what is shown, that the accumulation is the same to the
    bit in every mode and through a change of mode, when a denoise runs and
    what the status says. Catches a display that writes into the film, a
    mode change that restarts, a denoised image that is not drawn or not
    smoother, and a converged state before the last denoise."""

    @classmethod
    def setUpClass(cls):
        probe = Scene()
        probe.mapper.SetDenoisingModeToAlways()
        probe.render()
        if "Open Image Denoise not found" in probe.mapper.GetDisplayStatus():
            raise unittest.SkipTest("no Open Image Denoise library (scripts/install-dependencies.sh installs the "
                                    "pyoidn wheel)")

    def test_every_mode_accumulates_the_same_film(self):
        films, shown = {}, {}
        for mode in ("Off", "Auto", "Always"):
            s = Scene()
            getattr(s.mapper, "SetDenoisingModeTo" + mode)()
            for _ in range(4):
                s.render()
            self.assertEqual(s.mapper.GetAccumulatedSamples(), 8)
            films[mode], shown[mode] = film(s.mapper), s.mapper.IsDenoisedImageShown()
            print("%s: %s" % (mode, s.mapper.GetDisplayStatus()))
        self.assertEqual(films["Auto"], films["Off"])
        self.assertEqual(films["Always"], films["Off"])
        self.assertEqual(shown, {"Off": False, "Auto": True, "Always": True})

    def test_a_change_of_mode_keeps_the_accumulation(self):
        s = Scene()
        s.mapper.SetMaximumSamples(16)
        for _ in range(3):
            s.render()
        counts, before = s.counts(), film(s.mapper)
        self.assertRegex(s.mapper.GetDisplayStatus(), r"^unbiased, 6 samples, noise [\d.]+ %$")
        s.mapper.SetDenoisingModeToAuto()
        s.render()
        self.assertEqual(s.counts(), counts, "no restart, no refit")
        self.assertEqual(s.mapper.GetAccumulatedSamples(), 8, "the samples go on")
        self.assertEqual(s.mapper.GetDisplayStatus(), "denoised, 8 samples")
        denoised_film = displayed(s.mapper)
        s.mapper.SetDenoisingModeToOff()
        self.assertEqual(displayed(s.mapper), [v for i, v in enumerate(
            memoryview_floats(film(s.mapper))) if i % 4 < 3], "Off shows the film")
        self.assertLess(roughness(denoised_film), 0.5 * roughness(displayed(s.mapper)),
                        "the denoised image is smoother than the film it was made from")
        self.assertNotEqual(before, film(s.mapper))

    def test_converged_only_after_the_last_denoise(self):
        import time
        s = Scene()
        s.mapper.SetDenoisingModeToAlways()
        s.mapper.AsynchronousRefinementOn()
        s.render()  # the first pass, in the render: its denoise comes later, in the background
        self.assertFalse(s.mapper.IsConverged())
        renders = 0
        while not s.mapper.IsConverged() and renders < 4000:
            s.render()
            renders += 1
            time.sleep(0.005)
        self.assertTrue(s.mapper.IsConverged())
        self.assertEqual(s.mapper.GetAccumulatedSamples(), 8)
        self.assertEqual(s.mapper.GetDisplayStatus(), "denoised, 8 samples")
        self.assertGreaterEqual(s.mapper.GetNumberOfDenoises(), 2)
        self.assertGreater(s.mapper.GetDenoisingSeconds(), 0.0)
        seconds = s.mapper.GetDenoisingSeconds()
        s.render()
        self.assertEqual(s.mapper.GetDenoisingSeconds(), seconds, "converged: nothing more to denoise")

    def test_a_preview_is_denoised_and_stands_until_the_first_denoise(self):
        s = Scene()
        s.mapper.SetDenoisingModeToAuto()
        s.mapper.AsynchronousRefinementOn()
        s.render()
        s.window.SetDesiredUpdateRate(15.0)
        s.renderer.GetActiveCamera().Azimuth(10)
        s.render()
        self.assertEqual(s.mapper.GetDisplayStatus(), "preview, denoised")
        preview = s.pixels()
        s.window.SetDesiredUpdateRate(0.0001)
        s.render()  # the first pass at the camera where the drag ended: the preview still stands
        self.assertEqual(s.mapper.GetAccumulatedSamples(), 2)
        self.assertEqual(s.mapper.GetDisplayStatus(), "preview, denoised")
        self.assertEqual(s.pixels(), preview)

    def test_without_the_library_the_film_is_shown_and_the_status_says_why(self):
        script = ("import sys; sys.path.insert(0, %r)\n"
                  "from test_mapper import Scene\n"
                  "s = Scene(); s.mapper.SetDenoisingModeToAuto()\n"
                  "for _ in range(4): s.render()\n"
                  "print(s.mapper.GetDisplayStatus()); print(s.mapper.IsConverged())\n"
                  % os.path.dirname(os.path.abspath(__file__)))
        env = dict(os.environ, MMRTM_OIDN_LIBRARY="/nonexistent/libOpenImageDenoise.so.2")
        done = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True, env=env, timeout=300)
        self.assertEqual(done.returncode, 0, done.stderr)
        status, converged = done.stdout.strip().splitlines()[-2:]
        self.assertRegex(status, r"^unbiased, 8 samples, noise [\d.]+ % \(not denoised: Intel Open Image Denoise "
                                 r"not found\)$")
        self.assertEqual(converged, "True")
        self.assertEqual(done.stderr.count("Open Image Denoise not found"), 1, "warned once: " + done.stderr)


def memoryview_floats(data):
    import struct
    return struct.unpack("%df" % (len(data) // 4), data)


class ReaderTest(unittest.TestCase):
    def test_a_jpeg2000_dicom_series_reads_or_is_a_clear_error(self):
        # With ITK/GDCM (the Debian build) the series decodes in Hounsfield
        # units; without (the PyPI VTK wheel's flavour: uncompressed DICOM
        # only) the reader refuses it and names the file and the codec.
        reader = vtkMultiMaterialVolumeReader()
        reader.SetFileName(os.path.join(DATA, "ct_abdomen_dicom_j2k"))
        errors = ErrorCatcher()
        reader.AddObserver("ErrorEvent", errors)
        reader.Update()
        image = reader.GetOutput()
        if not vtkMultiMaterialVolumeReader.CanReadCompressedDICOM():
            self.assertEqual(image.GetNumberOfPoints(), 0)
            self.assertTrue(any("JPEG 2000" in m and "ct_abdomen_dicom_j2k" in m for m in errors.messages),
                            errors.messages)
            return
        self.assertEqual(errors.messages, [])
        self.assertEqual(image.GetDimensions(), (512, 512, 20))
        self.assertAlmostEqual(image.GetSpacing()[2], 2.0, places=3)  # from the positions, not SliceThickness
        low, high = image.GetScalarRange()
        self.assertLessEqual(low, -1000)  # air in Hounsfield units
        self.assertGreater(high, 500)
        self.assertEqual(reader.GetWarnings(), "")

    def test_a_missing_file_is_an_error_not_a_crash(self):
        reader = vtkMultiMaterialVolumeReader()
        reader.SetFileName(os.path.join(DATA, "no_such_volume.nrrd"))
        reader.Update()
        self.assertEqual(reader.GetOutput().GetNumberOfPoints(), 0)


class ExampleTest(unittest.TestCase):
    def test_dicom_example_renders_the_chest(self):
        example = os.path.join(os.path.dirname(__file__), "..", "..", "Documentation", "examples",
                               "render_dicom_ct.py")
        with tempfile.TemporaryDirectory() as tmp:
            png = os.path.join(tmp, "chest.png")
            r = subprocess.run([sys.executable, example, os.path.join(DATA, "ct_chest_dicom"), png],
                               capture_output=True, text=True, timeout=600)
            self.assertEqual(r.returncode, 0, r.stderr)
            reader = vtkPNGReader()
            reader.SetFileName(png)
            reader.Update()
            a = reader.GetOutput().GetPointData().GetScalars()
            n = a.GetNumberOfComponents()
            lit = sum(1 for i in range(a.GetNumberOfTuples()) if max(a.GetValue(i * n + c) for c in range(3)) > 40)
            fraction = lit / a.GetNumberOfTuples()
            self.assertGreater(fraction, 0.1, "the ribcage should cover part of the image")
            self.assertLess(fraction, 0.9)


if __name__ == "__main__":
    unittest.main()
