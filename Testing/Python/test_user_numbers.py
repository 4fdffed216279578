"""vtkMultiMaterialVolumeMapper given numbers no volume should hold, as a
Python VTK user can: NaN and infinite voxels, zero and negative spacing, a
singular direction matrix, NaN, negative and unsorted transfer-function
points, a unit distance of 0 or 1e30, a component weight of 1e30.

Each case gets a clear error (an ErrorEvent naming the problem, no image,
no crash) or is read by a documented rule with a warning (a WarningEvent),
and no accumulated image ever holds a value that is not finite.
Documentation/reliability.md lists the rules.

Run by ctest under Testing/headless.sh (its own Xvfb) with /usr/bin/python3 (python3-vtk9).
"""
import math
import unittest

from vtkmodules.vtkCommonCore import vtkCommand, vtkFloatArray
from vtkmodules.vtkCommonDataModel import vtkImageData, vtkPiecewiseFunction
from vtkmodules.vtkRenderingCore import (vtkColorTransferFunction, vtkRenderer, vtkRenderWindow, vtkVolume,
                                         vtkVolumeProperty)
import vtkmodules.vtkRenderingOpenGL2  # noqa: F401  (the OpenGL render window)
import vtkmodules.vtkRenderingVolumeOpenGL2  # noqa: F401  (the image display helper)
from vtkmodules.util.vtkConstants import VTK_STRING

from mmrtm import vtkMultiMaterialVolumeMapper


class Messages:
    """Collects an object's error or warning messages instead of printing them."""

    CallDataType = VTK_STRING

    def __init__(self):
        self.messages = []

    def __call__(self, obj, event, message):
        self.messages.append(message)

    def text(self):
        return "\n".join(self.messages)


def sphere_volume(n=24, spacing=(2.0, 2.0, 2.0)):
    """A float ball (values 0 to 1000, highest at the centre)."""
    image = vtkImageData()
    image.SetDimensions(n, n, n)
    image.SetSpacing(*spacing)
    values = vtkFloatArray()
    values.SetNumberOfTuples(n * n * n)
    c = (n - 1) / 2.0
    for k in range(n):
        for j in range(n):
            for i in range(n):
                r = math.sqrt((i - c) ** 2 + (j - c) ** 2 + (k - c) ** 2) / c
                values.SetValue(i + n * (j + n * k), max(0.0, 1000.0 * (1.0 - r)))
    image.GetPointData().SetScalars(values)
    return image


class Pipeline:
    """The ball under a ramp, 64 x 64, 2 samples per render."""

    def __init__(self, image):
        self.mapper = vtkMultiMaterialVolumeMapper()
        self.mapper.SetInputData(image)
        self.mapper.SetBackendToCPU()
        self.mapper.SetSamplesPerRender(2)
        self.mapper.SetMaximumSamples(2)
        self.mapper.SetSeed(5)
        self.opacity = vtkPiecewiseFunction()
        self.opacity.AddPoint(0, 0.0)
        self.opacity.AddPoint(1000, 0.6)
        self.color = vtkColorTransferFunction()
        self.color.AddRGBPoint(0, 0.9, 0.7, 0.6)
        self.color.AddRGBPoint(1000, 1.0, 1.0, 1.0)
        self.property = vtkVolumeProperty()
        self.property.SetScalarOpacity(self.opacity)
        self.property.SetColor(self.color)
        self.property.ShadeOn()
        volume = vtkVolume()
        volume.SetMapper(self.mapper)
        volume.SetProperty(self.property)
        self.renderer = vtkRenderer()
        self.renderer.AddVolume(volume)
        self.window = vtkRenderWindow()
        self.window.SetOffScreenRendering(1)
        self.window.AddRenderer(self.renderer)
        self.window.SetSize(64, 64)
        self.errors, self.warnings = Messages(), Messages()
        self.mapper.AddObserver(vtkCommand.ErrorEvent, self.errors)
        self.mapper.AddObserver(vtkCommand.WarningEvent, self.warnings)

    def render(self):
        self.renderer.ResetCamera()
        self.window.Render()

    def film(self):
        """The accumulated RGBA values (empty when nothing accumulated)."""
        image = vtkImageData()
        self.mapper.GetAccumulatedImage(image)
        a = image.GetPointData().GetScalars()
        if a is None:
            return []
        return [a.GetValue(i) for i in range(a.GetNumberOfValues())]


class UserNumbersTest(unittest.TestCase):
    def assert_finite_image(self, p, lit=True):
        film = p.film()
        self.assertTrue(film, "nothing accumulated")
        self.assertTrue(all(math.isfinite(v) for v in film), "a value that is not finite")
        alphas = film[3::4]
        if lit:
            self.assertGreater(sum(1 for a in alphas if a > 0.05), 0.05 * len(alphas), "an empty image")

    def assert_error(self, p, *fragments):
        self.assertTrue(p.errors.messages, "no error reported")
        for fragment in fragments:
            self.assertIn(fragment, p.errors.text())
        self.assertEqual(p.film(), [], "an image from bad input")

    def test_the_plain_ball_renders(self):
        p = Pipeline(sphere_volume())
        p.render()
        self.assertEqual(p.errors.messages, [])
        self.assertEqual(p.warnings.messages, [])
        self.assert_finite_image(p)

    def test_nan_voxels_render_with_one_warning(self):
        # A NaN voxel is the least value (0 here: empty): the ball renders,
        # one warning, no error. Catches a NaN that reaches the tracer (no
        # image) or a warning per render.
        image = sphere_volume()
        image.GetPointData().GetScalars().SetValue(100, float("nan"))
        p = Pipeline(image)
        p.render()
        p.render()
        self.assertEqual(p.errors.messages, [])
        self.assertIn("NaN", p.warnings.text())
        self.assertEqual(len(p.warnings.messages), 1, p.warnings.text())
        self.assert_finite_image(p)

    def test_infinite_voxels_are_errors(self):
        for bad in (float("inf"), -float("inf")):
            image = sphere_volume()
            image.GetPointData().GetScalars().SetValue(100, bad)
            p = Pipeline(image)
            p.render()
            self.assert_error(p, "non-finite voxel value")
            # Repaired data renders again.
            image.GetPointData().GetScalars().SetValue(100, 0.0)
            image.Modified()
            p.errors.messages.clear()
            p.render()
            self.assertEqual(p.errors.messages, [])
            self.assert_finite_image(p)

    def test_zero_spacing_and_singular_direction_are_errors(self):
        p = Pipeline(sphere_volume(spacing=(2.0, 0.0, 2.0)))
        p.render()
        self.assert_error(p, "singular")
        image = sphere_volume()
        image.SetDirectionMatrix(1, 0, 0, 1, 0, 0, 0, 0, 1)  # two axes along x
        p = Pipeline(image)
        p.render()
        self.assert_error(p, "singular")

    def test_negative_spacing_is_a_mirrored_grid(self):
        # A ball is its own mirror image: the same coverage either way.
        p, q = Pipeline(sphere_volume()), Pipeline(sphere_volume(spacing=(-2.0, 2.0, -2.0)))
        p.render()
        q.render()
        self.assertEqual(q.errors.messages, [])
        self.assert_finite_image(q)
        cover = lambda film: sum(1 for a in film[3::4] if a > 0.05)
        self.assertAlmostEqual(cover(q.film()), cover(p.film()), delta=0.02 * 64 * 64)

    def test_nan_transfer_function_values_are_zero_with_a_warning(self):
        # A NaN node value reads as 0 at its node: the same image, sample
        # for sample, as the functions with 0 written there.
        p, q = Pipeline(sphere_volume()), Pipeline(sphere_volume())
        p.opacity.AddPoint(300, float("nan"))
        p.color.AddRGBPoint(700, float("nan"), 0.5, 0.5)
        q.opacity.AddPoint(300, 0.0)
        q.color.AddRGBPoint(700, 0.0, 0.5, 0.5)
        p.render()
        q.render()
        self.assertEqual(p.errors.messages, [])
        self.assertIn("not finite", p.warnings.text())
        self.assertEqual(q.warnings.messages, [])
        self.assert_finite_image(p)
        self.assertEqual(p.film(), q.film())
        # The user's functions are left as they were.
        self.assertTrue(math.isnan(p.opacity.GetValue(300)))

    def test_negative_and_unsorted_points_are_clamped(self):
        p = Pipeline(sphere_volume())
        p.opacity.RemoveAllPoints()
        for x, y in ((1000, 0.6), (0, -0.5), (300, 2.0), (600, -1.0)):  # out of order, out of [0, 1]
            p.opacity.AddPoint(x, y)
        p.render()
        self.assertEqual(p.errors.messages, [])
        self.assert_finite_image(p)

    def test_unit_distance_near_zero_is_clamped_with_a_warning(self):
        p = Pipeline(sphere_volume())
        p.property.SetScalarOpacityUnitDistance(0.0)  # VTK: opacity per no distance at all
        p.render()
        self.assertEqual(p.errors.messages, [])
        self.assertIn("clamped", p.warnings.text())
        self.assert_finite_image(p)
        # Said once, not on every render.
        count = len(p.warnings.messages)
        p.mapper.SetMaximumSamples(4)
        p.window.Render()
        self.assertEqual(len(p.warnings.messages), count)

    def test_huge_unit_distance_is_an_almost_empty_volume(self):
        p = Pipeline(sphere_volume())
        p.property.SetScalarOpacityUnitDistance(1e30)
        p.render()
        self.assertEqual(p.errors.messages, [])
        self.assert_finite_image(p, lit=False)
        self.assertLess(max(p.film()[3::4]), 0.01)


if __name__ == "__main__":
    unittest.main()

    def test_huge_component_weight_is_clamped_with_a_warning(self):
        # Two independent components, the first weighted 1e30: its
        # extinction is clamped (an optical depth of 64 per voxel), said
        # once; the image is finite and the ball opaque.
        image = sphere_volume()
        ball = image.GetPointData().GetScalars()
        two = vtkFloatArray()
        two.SetNumberOfComponents(2)
        two.SetNumberOfTuples(ball.GetNumberOfTuples())
        for i in range(ball.GetNumberOfTuples()):
            two.SetTuple2(i, ball.GetValue(i), 0.0)
        image.GetPointData().SetScalars(two)
        p = Pipeline(image)
        p.property.IndependentComponentsOn()
        for c in range(2):
            p.property.SetScalarOpacity(c, p.opacity)
            p.property.SetColor(c, p.color)
        p.property.SetComponentWeight(0, 1e30)
        p.render()
        self.assertEqual(p.errors.messages, [])
        self.assertIn("clamped", p.warnings.text())
        self.assertEqual(len(p.warnings.messages), 1, p.warnings.text())
        self.assert_finite_image(p)
        self.assertGreater(max(p.film()[3::4]), 0.99)
