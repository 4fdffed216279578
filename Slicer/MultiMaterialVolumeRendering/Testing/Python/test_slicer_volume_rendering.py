"""Path tracing (MM-RTM) as a rendering method of 3D Slicer's Volume Rendering
module, tested headless on the PyPI Slicer core (slicer-core 5.11, slicer-
layer-dm 2.0, vtk 9.6) as a user would use it: volumes loaded by Slicer's
volumes logic, display nodes made by the Volume Rendering logic, rendered by
the displayable managers of a 3D view (LayerDM's, and Slicer's own volume
rendering manager, which must ignore our node).

Run by ctest under Testing/headless.sh (its own Xvfb) with the .venv-vtk96 interpreter, after the
mmrtm wheel (with its Slicer classes) was built and installed there.
"""
import os
import subprocess
import sys
import tempfile
import time
import unittest

from vtkmodules.vtkCommonDataModel import vtkImageData
from vtkmodules.vtkRenderingCore import vtkRenderer, vtkRenderWindow, vtkVolume
from vtkmodules.vtkCommonMath import vtkMatrix4x4

from slicer import (vtkMRMLLinearTransformNode, vtkMRMLMarkupsROINode, vtkMRMLMultiMaterialVolumeRenderingDisplayNode,
                    vtkMRMLScene, vtkMRMLSegmentationNode)
from mmrtm import vtkMultiMaterialVolumeMapper

from slicer_test_scene import (CPU_METHOD, DATA, METHOD, SlicerScene, covered, intersection_over_union,
                               mean_abs_difference, presets_directory)

NEEDS_PRESETS = unittest.skipUnless(presets_directory(), "Slicer's presets.xml comes with trame-slicer, not installed")


def film(mapper):
    image = vtkImageData()
    mapper.GetAccumulatedImage(image)
    return bytes(memoryview(image.GetPointData().GetScalars())) if image.GetNumberOfPoints() else b""


def head_ct(s, **settings):
    volume = s.load_volume(os.path.join(DATA, "ct_head_cranium.nrrd"), "head")
    display = s.show_with_path_tracing(volume, **settings)
    return volume, display


class MethodTest(unittest.TestCase):
    def test_registered_with_the_volume_rendering_module(self):
        s = SlicerScene()
        self.assertIs(s.logic.GetVolumeRenderingLogic(), s.volume_rendering,
                      "found through the application logic, as in Slicer")
        self.assertTrue(s.logic.IsRenderingMethodRegistered())
        self.assertTrue(s.scene.IsNodeClassRegistered(METHOD))
        self.assertEqual(s.logic.GetRenderingMethodName(), "Path tracing (MM-RTM)")

    @NEEDS_PRESETS
    def test_our_method_chosen_before_our_logic_is_registered_renders(self):
        """trame-slicer registers the module logics it knows; a script that
        sets our method as Volume Rendering's default without registering
        ours made CreateDefaultVolumeRenderingNodes dereference a null node
        (a segfault, exit 139). The package's import lets any scene create
        the node by class name: the node is ours and the view path traces.
        In a child process, so that a crash fails this test only."""
        script = (
            "from slicer_test_scene import SlicerScene, DATA\n"
            "import os\n"
            "s = SlicerScene(with_our_logic=False)\n"
            "assert not s.scene.IsNodeClassRegistered('%s')\n"
            "view = s.add_view()\n"
            "volume = s.load_volume(os.path.join(DATA, 'ct_head_cranium.nrrd'), 'head')\n"
            "display = s.show_with_path_tracing(volume)\n"
            "view.look_at_volume(azimuth=180)\n"
            "view.refine()\n"
            "print(display.GetClassName(), view.mapper().GetAccumulatedSamples())\n" % METHOD)
        child = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True, timeout=300,
                               cwd=os.path.dirname(os.path.abspath(__file__)))
        self.assertEqual(child.returncode, 0, child.stderr[-2000:])
        self.assertEqual(child.stdout.split()[-2:], [METHOD, "8"])

    def test_from_slicer_import(self):
        import slicer
        self.assertIs(slicer.vtkMRMLMultiMaterialVolumeRenderingDisplayNode, vtkMRMLMultiMaterialVolumeRenderingDisplayNode)
        self.assertTrue(hasattr(slicer, "vtkSlicerMultiMaterialVolumeRenderingLogic"))
        self.assertTrue(hasattr(slicer, "vtkMRMLMultiMaterialVolumeRenderingPipeline"))


@NEEDS_PRESETS
class RenderTest(unittest.TestCase):
    def render_and_compare(self, load, preset, azimuth, name):
        s = SlicerScene()
        view = s.add_view()
        volume = load(s)
        display = s.show_with_path_tracing(volume, preset=preset)
        view.look_at_volume(azimuth=azimuth)
        renders = view.refine()
        mapper = view.mapper()
        self.assertEqual(mapper.GetAccumulatedSamples(), 8)
        self.assertEqual(renders, 2, "4 samples per render up to 8")
        self.assertEqual(len(view.volumes()), 1, "Slicer's own volume rendering manager ignores the node")
        ours = view.pixels()
        coverage = sum(covered(ours)) / len(ours)
        self.assertTrue(0.05 < coverage < 0.95, "coverage %.3f: an empty or full image" % coverage)

        # The same volume, property, geometry and camera with the mapper alone,
        # outside Slicer: the same film to the bit (one seed, one translation).
        renderer = vtkRenderer()
        window = vtkRenderWindow()
        window.SetOffScreenRendering(1)
        window.AddRenderer(renderer)
        window.SetSize(*view.window.GetSize())
        alone = vtkMultiMaterialVolumeMapper()
        alone.SetInputData(volume.GetImageData())
        alone.SetSamplesPerRender(4)
        alone.SetMaximumSamples(8)
        alone.SetSeed(5)
        alone.SetBackendToCPU()
        prop = vtkVolume()
        prop.SetMapper(alone)
        prop.SetProperty(display.GetVolumePropertyNode().GetVolumeProperty())
        ijk_to_ras = vtkMatrix4x4()
        volume.GetIJKToRASMatrix(ijk_to_ras)
        prop.SetUserMatrix(ijk_to_ras)
        renderer.AddVolume(prop)
        renderer.GetActiveCamera().DeepCopy(view.renderer.GetActiveCamera())
        renderer.ResetCameraClippingRange()
        window.Render()
        window.Render()
        self.assertEqual(alone.GetAccumulatedSamples(), 8)
        self.assertEqual(film(alone), film(mapper), "the mapper's own film of the same volume and property")

        # Slicer's CPU ray cast of the same display node covers the same pixels.
        s.volume_rendering.ChangeVolumeRenderingMethod(CPU_METHOD)
        view.render()
        view.render()
        self.assertEqual([v.GetMapper().GetClassName() for v in view.volumes() if v.GetVisibility()],
                         ["vtkFixedPointVolumeRayCastMapper"])
        iou = intersection_over_union(covered(ours), covered(view.pixels()))
        print("%s: coverage %.3f, IoU with Slicer's CPU ray cast %.3f" % (name, coverage, iou))
        self.assertGreater(iou, 0.85)
        return s

    def test_head_ct_nrrd(self):
        self.render_and_compare(lambda s: s.load_volume(os.path.join(DATA, "ct_head_cranium.nrrd"), "head"),
                                "CT-Bone", 180, "head")

    def test_chest_ct_dicom_series(self):
        self.render_and_compare(lambda s: s.load_dicom_series(os.path.join(DATA, "ct_chest_dicom"), "chest"),
                                "CT-Bone", 0, "chest")


@NEEDS_PRESETS
class ViewTest(unittest.TestCase):
    def setUp(self):
        self.s = SlicerScene()
        self.view = self.s.add_view()
        self.volume, self.display = head_ct(self.s)
        self.view.look_at_volume(azimuth=180)
        self.view.refine()
        self.before = self.view.pixels()

    def counts(self):
        m = self.view.mapper()
        return m.GetNumberOfSceneBuilds(), m.GetNumberOfRefits(), m.GetNumberOfRestarts()

    def test_a_transform_moves_the_image(self):
        transform = self.s.scene.AddNewNodeByClass("vtkMRMLLinearTransformNode", "move")
        matrix = vtkMatrix4x4()
        matrix.SetElement(0, 3, -60.0)  # 60 mm to the patient's right: to the left on screen from behind
        transform.SetMatrixTransformToParent(matrix)
        restarts = self.counts()[2]
        self.volume.SetAndObserveTransformNodeID(transform.GetID())
        self.view.refine()
        self.assertEqual(self.counts()[2], restarts + 1, "a new matrix restarts")
        after = self.view.pixels()

        def centre_x(pixels):
            size = self.view.window.GetSize()[0]
            xs = [i % size for i, c in enumerate(covered(pixels)) if c]
            return sum(xs) / len(xs)
        shift = centre_x(after) - centre_x(self.before)
        self.assertGreater(abs(shift), 5, "the volume moved on screen (%.1f pixels)" % shift)
        # Editing the transform moves it again.
        matrix.SetElement(0, 3, 0.0)
        transform.SetMatrixTransformToParent(matrix)
        self.view.refine()
        self.assertLess(abs(centre_x(self.view.pixels()) - centre_x(self.before)), 1.0)

    def test_the_roi_crops(self):
        roi = self.s.scene.AddNewNodeByClass("vtkMRMLMarkupsROINode", "crop")
        bounds = [0.0] * 6
        self.volume.GetRASBounds(bounds)
        # The half of the volume with the larger R (patient's left).
        roi.SetXYZ((bounds[0] + bounds[1]) / 2 + (bounds[1] - bounds[0]) / 4, (bounds[2] + bounds[3]) / 2,
                   (bounds[4] + bounds[5]) / 2)
        roi.SetRadiusXYZ((bounds[1] - bounds[0]) / 4, (bounds[3] - bounds[2]) / 2 + 1, (bounds[5] - bounds[4]) / 2 + 1)
        self.display.SetAndObserveROINodeID(roi.GetID())
        self.display.SetCroppingEnabled(True)
        self.view.refine()
        whole = sum(covered(self.before))
        cropped = sum(covered(self.view.pixels()))
        self.assertLess(cropped, 0.75 * whole)
        self.assertGreater(cropped, 0.25 * whole)
        # Moving the ROI changes the crop; cropping off shows it all again.
        self.display.SetCroppingEnabled(False)
        self.view.refine()
        self.assertEqual(self.view.pixels(), self.before, "cropping off: the same image as before")

    def test_the_same_roi_and_matrix_again_restart_nothing(self):
        """The pipeline sets the ROI's planes and the volume's matrix on
        every update, without comparing them with the last; the mapper
        compares them by value. An update with nothing changed (the ROI, the
        volume and the display node modified, their values the same) keeps
        the converged samples. Catches a mapper that restarts on a plane or
        matrix set again (the film thrown away at every node event)."""
        roi = self.s.scene.AddNewNodeByClass("vtkMRMLMarkupsROINode", "crop")
        bounds = [0.0] * 6
        self.volume.GetRASBounds(bounds)
        roi.SetXYZ((bounds[0] + bounds[1]) / 2, (bounds[2] + bounds[3]) / 2, (bounds[4] + bounds[5]) / 2)
        roi.SetRadiusXYZ((bounds[1] - bounds[0]) / 3, (bounds[3] - bounds[2]) / 3, (bounds[5] - bounds[4]) / 3)
        self.display.SetAndObserveROINodeID(roi.GetID())
        self.display.SetCroppingEnabled(True)
        self.view.refine()
        mapper = self.view.mapper()
        self.assertTrue(mapper.IsConverged())
        converged, counts = mapper.GetAccumulatedSamples(), self.counts()
        planes = mapper.GetClippingPlanes().GetNumberOfItems()
        self.assertEqual(planes, 6, "the ROI's six faces")
        first = mapper.GetClippingPlanes().GetItem(0)  # held: a new plane cannot take its address
        roi.Modified()
        self.volume.Modified()
        self.display.Modified()
        self.view.render()
        self.assertEqual(mapper.GetClippingPlanes().GetNumberOfItems(), planes)
        self.assertIsNot(mapper.GetClippingPlanes().GetItem(0), first, "the pipeline set the planes again")
        self.assertEqual(self.counts(), counts, "no restart")
        self.assertEqual(mapper.GetAccumulatedSamples(), converged, "the converged samples kept")
        # A moved ROI still restarts.
        roi.SetXYZ((bounds[0] + bounds[1]) / 2 + 5.0, (bounds[2] + bounds[3]) / 2, (bounds[4] + bounds[5]) / 2)
        self.view.render()
        self.assertEqual(self.counts()[2], counts[2] + 1, "a moved ROI restarts")

    def test_hidden_in_one_view_only(self):
        second = self.s.add_view("View2")
        second.renderer.GetActiveCamera().DeepCopy(self.view.renderer.GetActiveCamera())
        self.display.SetViewNodeIDs([self.view.node.GetID()])
        self.view.refine()
        second.refine()
        self.assertGreater(sum(covered(self.view.pixels())), 0.05 * len(self.before), "shown where listed")
        self.assertEqual(sum(covered(second.pixels())), 0, "hidden in the other view")
        self.display.SetViewNodeIDs([])
        second.refine()
        self.assertGreater(sum(covered(second.pixels())), 0.05 * len(self.before), "shown everywhere again")
        self.display.SetVisibility(False)
        self.view.render()
        self.assertEqual(sum(covered(self.view.pixels())), 0, "display node hidden")

    def test_preset_switch_refits_and_property_edit_restarts(self):
        builds, refits, restarts = self.counts()
        self.s.apply_preset(self.display, "CT-Soft-Tissue")
        self.view.render()
        self.assertEqual(self.counts(), (builds, refits + 1, restarts + 1), "a new preset: a refit, no rebuild")
        self.view.refine()
        soft = self.view.pixels()
        self.assertGreater(mean_abs_difference(soft, self.before), 0.01, "the preset changes the image")
        # An edit of the property's opacity function restarts the accumulation.
        opacity = self.display.GetVolumePropertyNode().GetVolumeProperty().GetScalarOpacity()
        opacity.AddPoint(100.0, 0.0)
        self.view.render()
        self.assertEqual(self.view.mapper().GetAccumulatedSamples(), 4, "restarted")
        self.assertEqual(self.counts()[1], refits + 2)

    def test_background_refinement_is_a_display_node_setting(self):
        """AsynchronousRefinement on the display node reaches the mapper: a
        render returns at once while the next pass runs, and the image still
        converges to the same film. Catches a setting that is stored but not
        applied."""
        synchronous = film(self.view.mapper())
        self.display.SetAsynchronousRefinement(True)
        self.view.render()
        mapper = self.view.mapper()
        self.assertTrue(mapper.GetAsynchronousRefinement())
        deadline = time.monotonic() + 60
        while not mapper.IsConverged() and time.monotonic() < deadline:
            time.sleep(0.02)
            self.view.render()
        self.assertTrue(mapper.IsConverged())
        self.assertEqual(mapper.GetAccumulatedSamples(), 8)
        self.assertEqual(film(mapper), synchronous, "the same film in the background")

    def test_a_higher_maximum_keeps_the_samples(self):
        """The display node's maximum samples raised on a converged view:
        refinement goes on from the samples it has. Catches a display node
        or displayable manager whose setting restarts the view (the
        converged image thrown away)."""
        mapper = self.view.mapper()
        self.assertTrue(mapper.IsConverged())
        converged, counts = mapper.GetAccumulatedSamples(), self.counts()
        self.display.SetMaximumSamples(2 * converged)
        self.display.SetNoiseTarget(0.0001)
        self.view.render()
        self.assertGreater(mapper.GetAccumulatedSamples(), converged)
        self.assertEqual(self.counts(), counts, "no restart")
        self.view.refine()
        self.assertEqual(mapper.GetAccumulatedSamples(), 2 * converged)

    def test_refinement_stops_at_the_noise_target(self):
        self.display.SetMaximumSamples(0)
        # Half the noise of the converged view, which refines on from its
        # samples: about four times as many.
        self.display.SetNoiseTarget(0.5 * self.view.mapper().GetRelativeNoise())
        renders = self.view.refine(limit=40)
        self.assertTrue(self.view.mapper().IsConverged())
        self.assertLessEqual(self.view.mapper().GetRelativeNoise(), self.display.GetNoiseTarget())
        self.assertGreater(renders, 1)


@NEEDS_PRESETS
class SegmentationTest(unittest.TestCase):
    """ct_abdomen with its 61-label map (TotalSegmentator) as a segmentation."""

    LIVER = 5

    def setUp(self):
        s = self.s = SlicerScene()
        self.view = s.add_view()
        self.ct, self.segmentation = s.load_abdomen_with_segments()
        segments = self.segmentation.GetSegmentation()
        self.assertEqual(segments.GetNumberOfSegments(), 61)
        self.liver = [segments.GetNthSegmentID(i) for i in range(61)
                      if segments.GetNthSegment(i).GetLabelValue() == self.LIVER][0]
        self.display = s.show_with_path_tracing(self.ct, preset="CT-Soft-Tissue", maximum_samples=4)
        # Only the segments show: the volume property itself transparent.
        self.display.GetVolumePropertyNode().GetVolumeProperty().GetScalarOpacity().RemoveAllPoints()
        self.display.GetVolumePropertyNode().GetVolumeProperty().GetScalarOpacity().AddPoint(0, 0.0)
        self.display.SetAndObserveSegmentationNodeID(self.segmentation.GetID())
        self.seg_display = self.segmentation.GetDisplayNode()
        for i in range(61):
            self.seg_display.SetSegmentOverrideColor(segments.GetNthSegmentID(i), 1.0, 0.0, 0.0)
        self.view.look_at_volume()
        self.view.refine()

    def colours(self):
        pixels = self.view.pixels()
        red = sum(1 for r, g, b in pixels if r > 40 and r > 2 * g and r > 2 * b)
        blue = sum(1 for r, g, b in pixels if b > 40 and b > 2 * r and b > 2 * g)
        return red, blue

    def counts(self):
        m = self.view.mapper()
        return m.GetNumberOfSceneBuilds(), m.GetNumberOfRefits(), m.GetNumberOfRestarts()

    def test_segments_render_in_their_colours(self):
        red, blue = self.colours()
        self.assertGreater(red, 0.05 * len(self.view.pixels()), "the red segments show")
        self.assertEqual(blue, 0)
        builds, refits, restarts = self.counts()
        self.seg_display.SetSegmentOverrideColor(self.liver, 0.0, 0.0, 1.0)
        self.view.render()
        self.assertEqual(self.counts(), (builds, refits + 1, restarts + 1), "a colour: a refit, no rebuild")
        self.view.refine()
        red2, blue2 = self.colours()
        print("red %d, blue %d pixels after the liver turned blue (red %d before)" % (red2, blue2, red))
        self.assertGreater(blue2, 200, "the liver is blue")
        self.assertGreater(red2, 0.3 * red, "the other segments stay red")

    def test_hiding_a_segment_removes_it_and_leaves_the_others(self):
        self.seg_display.SetSegmentOverrideColor(self.liver, 0.0, 0.0, 1.0)
        self.view.refine()
        red, blue = self.colours()
        self.assertGreater(blue, 200)
        self.seg_display.SetSegmentVisibility(self.liver, False)
        self.view.refine()
        red2, blue2 = self.colours()
        self.assertLess(blue2, 0.02 * blue, "the hidden liver is gone")
        self.assertGreater(red2, 0.9 * red, "the other segments stay (and show behind the liver)")

    def test_segment_edits_do_only_their_work(self):
        """A segment's colour, 3D opacity and visibility reach the mapper as
        its label material (the one label rule), each edit a refit and a
        restart, never a rebuild or a new label map; a render without an
        edit does nothing; the volume property node's property is the
        mapper's own, and rendering leaves its modification time alone.
        Catches a pipeline that copies or edits the property per edit, or
        exports the label map again for a look change."""
        m = self.view.mapper()
        prop = self.display.GetVolumePropertyNode().GetVolumeProperty()
        self.assertIs(self.view.path_traced_volume().GetProperty(), prop, "no copy of the property")
        rgbo = [0.0] * 4
        self.assertTrue(m.GetLabelMaterial(self.LIVER, rgbo))
        self.assertEqual(rgbo, [1.0, 0.0, 0.0, 1.0])
        before = prop.GetMTime()
        counts = self.counts()
        self.view.render()
        self.assertEqual(self.counts(), counts, "an unchanged render does nothing")
        label_map_time = m.GetMaskInput().GetMTime()
        for edit, expected in (
                (lambda: self.seg_display.SetSegmentOverrideColor(self.liver, 0.0, 0.0, 1.0), [0.0, 0.0, 1.0, 1.0]),
                (lambda: self.seg_display.SetSegmentOpacity3D(self.liver, 0.4), [0.0, 0.0, 1.0, 0.4]),
                (lambda: self.seg_display.SetSegmentVisibility(self.liver, False), None)):
            builds, refits, restarts = self.counts()
            edit()
            self.view.render()
            self.assertEqual(self.counts(), (builds, refits + 1, restarts + 1))
            self.assertEqual(m.GetMaskInput().GetMTime(), label_map_time, "the label map stays")
            if expected is None:
                self.assertFalse(m.GetLabelMaterial(self.LIVER, rgbo), "a hidden segment has no material")
            else:
                self.assertTrue(m.GetLabelMaterial(self.LIVER, rgbo))
                self.assertEqual([round(v, 6) for v in rgbo], expected)
        self.assertEqual(prop.GetMTime(), before, "rendering left the property alone")

    def test_each_kind_of_edit_does_only_its_work(self):
        """Each kind of edit a Slicer user makes, one render after it, and
        the work the mapper did: scene builds, translations, restarts,
        majorant grid builds and refits. A camera, window or sampling edit
        restarts only; a colour (of the volume property or of a segment)
        translates without a grid refit (the majorants read extinction
        only); an opacity point or a hidden segment refits; edited voxels
        rebuild; an unchanged render does nothing. (Exposure is not a
        Slicer display-node setting: the mapper's table, vtkMapper-edits,
        has it.) Catches work an edit does not need (a refit after a
        colour, a rebuild after a look change, a restart after nothing) and
        an edit that does not reach the tracer."""
        m = self.view.mapper()
        prop = self.display.GetVolumePropertyNode().GetVolumeProperty()
        image = self.ct.GetImageData()

        def voxels():
            scalars = image.GetPointData().GetScalars()
            scalars.SetTuple1(0, scalars.GetTuple1(0) + 1)
            scalars.Modified()
            image.Modified()

        table = (
            ("unchanged", lambda: None, (0, 0, 0, 0, 0)),
            ("camera", lambda: self.view.renderer.GetActiveCamera().Azimuth(10), (0, 0, 1, 0, 0)),
            ("window size", lambda: self.view.window.SetSize(150, 140), (0, 0, 1, 0, 0)),
            ("sampling setting", lambda: self.display.SetMaximumBounces(2), (0, 0, 1, 0, 0)),
            ("opacity point", lambda: prop.GetScalarOpacity().AddPoint(400, 0.2), (0, 1, 1, 0, 1)),
            ("colour point", lambda: prop.GetRGBTransferFunction().AddRGBPoint(100, 0.2, 0.9, 0.1), (0, 1, 1, 0, 0)),
            ("segment colour", lambda: self.seg_display.SetSegmentOverrideColor(self.liver, 0.0, 0.0, 1.0),
             (0, 1, 1, 0, 0)),
            ("segment hidden", lambda: self.seg_display.SetSegmentVisibility(self.liver, False), (0, 1, 1, 0, 1)),
            ("voxels edited", voxels, (1, 1, 1, 1, 1)),
        )

        def work():
            return (m.GetNumberOfSceneBuilds(), m.GetNumberOfRefits(), m.GetNumberOfRestarts(),
                    m.GetNumberOfMajorantGridBuilds(), m.GetNumberOfMajorantGridRefits())

        for name, edit, expected in table:
            before = work()
            edit()
            self.view.render()
            done = tuple(after - b for after, b in zip(work(), before))
            print("%-16s builds, translations, restarts, grid builds, grid refits: %s" % (name, done))
            self.assertEqual(done, expected, name)
            self.assertIs(self.view.mapper(), m, "the same mapper")

    def test_segment_material_parameters(self):
        before = self.view.pixels()
        self.display.SetSegmentMaterialParameters(self.liver, '{"emission": [0, 3, 0]}')
        self.view.refine()
        self.assertEqual(self.view.mapper().GetLabelMaterialParameters(self.LIVER), '{"emission": [0, 3, 0]}')
        greener = sum(p[1] - q[1] for p, q in zip(self.view.pixels(), before)) / len(before)
        self.assertGreater(greener, 0.5, "the liver glows green")


@NEEDS_PRESETS
class SceneFileTest(unittest.TestCase):
    def test_saved_scene_reloads_to_the_same_render(self):
        s = SlicerScene()
        view = s.add_view()
        volume, display = head_ct(s, seed=11)
        display.SetMaximumBounces(5)
        display.SetShadowExtinctionScale(1.0)
        display.SetAccelerator(display.Macrocell)
        display.SetSegmentMaterialParameters("S_x=1;", '{"roughness": 0.25}')
        view.look_at_volume(azimuth=180)
        view.refine()
        first = film(view.mapper())
        display.SetAsynchronousRefinement(True)  # saved; set off again below, to refine in step
        with tempfile.TemporaryDirectory() as folder:
            self.assertTrue(s.app.SaveSceneToSlicerDataBundleDirectory(folder, None))
            mrml = [f for f in os.listdir(folder) if f.endswith(".mrml")][0]
            t = SlicerScene()
            t.scene.SetURL(os.path.join(folder, mrml))
            self.assertEqual(t.scene.Import(), 1)
            nodes = t.scene.GetNodesByClass(METHOD)
            self.assertEqual(nodes.GetNumberOfItems(), 1)
            loaded = nodes.GetItemAsObject(0)
            self.assertEqual((loaded.GetSeed(), loaded.GetMaximumBounces(), loaded.GetShadowExtinctionScale(),
                              loaded.GetAccelerator(), loaded.GetSamplesPerRender(), loaded.GetMaximumSamples()),
                             (11, 5, 1.0, display.Macrocell, 4, 8))
            self.assertEqual(loaded.GetSegmentMaterialParameters("S_x=1;"), '{"roughness": 0.25}')
            self.assertTrue(loaded.GetAsynchronousRefinement())
            loaded.SetAsynchronousRefinement(False)
            other = t.add_view()
            other.render()
            other.renderer.GetActiveCamera().DeepCopy(view.renderer.GetActiveCamera())
            other.refine()
            self.assertEqual(film(other.mapper()), first, "the same film after a save and a load")


@NEEDS_PRESETS
class RemovalTest(unittest.TestCase):
    """Removing what a render uses while the image refines must not crash."""

    def start(self):
        s = SlicerScene()
        view = s.add_view()
        volume, display = head_ct(s, maximum_samples=64)
        view.look_at_volume()
        view.render()
        self.assertFalse(view.mapper().IsConverged())
        return s, view, volume, display

    def test_remove_the_volume(self):
        s, view, volume, display = self.start()
        s.scene.RemoveNode(volume)
        view.render()
        view.render()
        self.assertEqual(sum(covered(view.pixels())), 0)

    def test_remove_the_display_node(self):
        s, view, volume, display = self.start()
        s.scene.RemoveNode(display)
        view.render()
        self.assertEqual(view.volumes("vtkMultiMaterialVolumeMapper"), [])

    def test_remove_the_segmentation(self):
        s, view, volume, display = self.start()
        segmentation = s.scene.AddNewNodeByClass("vtkMRMLSegmentationNode", "box")
        segmentation.CreateDefaultDisplayNodes()
        segmentation.SetReferenceImageGeometryParameterFromVolumeNode(volume)
        segmentation.GetSegmentation().AddEmptySegment("box")
        display.SetAndObserveSegmentationNodeID(segmentation.GetID())
        view.render()
        s.scene.RemoveNode(segmentation)
        view.render()
        view.render()
        self.assertIsNone(display.GetSegmentationNode())

    def test_remove_the_view(self):
        s, view, volume, display = self.start()
        s.scene.RemoveNode(view.node)
        view.render()
        view.group.SetMRMLDisplayableNode(None)
        view.render()
        s.scene.Clear(0)
        view.render()


if __name__ == "__main__":
    unittest.main()
