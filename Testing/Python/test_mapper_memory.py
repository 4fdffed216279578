"""The mapper reads the caller's voxels where they are (Documentation/vtk-mapper.md,
"What the mapper holds"): a volume that Slicer, ParaView or a script holds
is not held a second time, and an edit of it reaches the image through
Modified() as any data change does. vtkMultiMaterialVolumeReader's output
is its loaded volume itself.

Run by ctest under Testing/headless.sh with /usr/bin/python3 (python3-vtk9)
and the build tree's mmrtm package on PYTHONPATH. The large volume is made
at run time (the head CT tiled by vtkImageWrapPad), never stored.
"""
import math
import os
import resource
import unittest

from vtkmodules.vtkCommonCore import vtkFloatArray
from vtkmodules.vtkCommonDataModel import vtkImageData, vtkPiecewiseFunction
from vtkmodules.vtkImagingCore import vtkImageWrapPad
from vtkmodules.vtkIOImage import vtkNrrdReader
from vtkmodules.vtkRenderingCore import (vtkColorTransferFunction, vtkRenderer, vtkRenderWindow, vtkVolume,
                                         vtkVolumeProperty, vtkWindowToImageFilter)
import vtkmodules.vtkRenderingOpenGL2  # noqa: F401  (the OpenGL render window)
import vtkmodules.vtkRenderingVolumeOpenGL2  # noqa: F401  (the image display helper)

from mmrtm import vtkMultiMaterialVolumeMapper, vtkMultiMaterialVolumeReader

DATA = os.environ["MMRTM_SHARED_DATA_DIR"]
BACKGROUND = (0.1, 0.1, 0.15)
# Beyond what the caller holds, the mapper's proxies, label maps and grid
# may take at most 0.15 x the caller's voxel bytes.
ALLOWED_EXTRA = 0.15


def head_ct():
    """The head CT (64 x 64 x 93 int16) as an image of the caller's own."""
    reader = vtkNrrdReader()
    reader.SetFileName(os.path.join(DATA, "ct_head_headsq.nrrd"))
    reader.Update()
    image = vtkImageData()
    image.ShallowCopy(reader.GetOutput())
    return image


def resident_bytes():
    with open("/proc/self/status") as status:
        for line in status:
            if line.startswith("VmRSS:"):
                return int(line.split()[1]) * 1024
    raise RuntimeError("no VmRSS in /proc/self/status")


def peak_resident_bytes():
    return resource.getrusage(resource.RUSAGE_SELF).ru_maxrss * 1024


def reset_peak():
    """Starts the peak anew from what is resident now (Linux 4.0+: clear_refs 5).
    Where that is refused, the peak since the start is a bound from above."""
    try:
        with open("/proc/self/clear_refs", "w") as f:
            f.write("5")
    except OSError:
        pass


class View:
    """The mapper on the CPU in a 64 x 64 window, with a bone transfer function."""

    def __init__(self, image):
        self.mapper = vtkMultiMaterialVolumeMapper()
        self.mapper.SetInputData(image)
        self.mapper.SetBackendToCPU()
        self.mapper.SetSamplesPerRender(1)
        self.mapper.SetMaximumSamples(4)
        self.mapper.SetSeed(3)
        opacity = vtkPiecewiseFunction()
        opacity.AddPoint(1100, 0.0)
        opacity.AddPoint(2000, 0.8)
        color = vtkColorTransferFunction()
        color.AddRGBPoint(1100, 0.9, 0.6, 0.5)
        color.AddRGBPoint(2000, 1.0, 0.95, 0.9)
        self.property = vtkVolumeProperty()
        self.property.SetScalarOpacity(opacity)
        self.property.SetColor(color)
        self.property.ShadeOn()
        volume = vtkVolume()
        volume.SetMapper(self.mapper)
        volume.SetProperty(self.property)
        self.renderer = vtkRenderer()
        self.renderer.AddVolume(volume)
        self.renderer.SetBackground(*BACKGROUND)
        self.window = vtkRenderWindow()
        self.window.SetOffScreenRendering(1)
        self.window.AddRenderer(self.renderer)
        self.window.SetSize(64, 64)
        self.renderer.ResetCamera()

    def render(self):
        self.window.Render()

    def builds(self):
        return self.mapper.GetNumberOfSceneBuilds()

    def coverage(self):
        """The share of pixels that are not the background."""
        grab = vtkWindowToImageFilter()
        grab.SetInput(self.window)
        grab.ReadFrontBufferOff()
        grab.Update()
        a = grab.GetOutput().GetPointData().GetScalars()
        n = a.GetNumberOfComponents()
        pixels = a.GetNumberOfTuples()
        covered = sum(
            1 for i in range(pixels)
            if max(abs(a.GetValue(i * n + c) / 255.0 - BACKGROUND[c]) for c in range(3)) > 0.08)
        return covered / pixels


class InPlaceVoxelsTest(unittest.TestCase):
    def test_peak_memory_holds_no_copy_of_the_callers_voxels(self):
        # What this catches: a copy of the caller's voxels (1.0 x their
        # bytes, as ImageDataToHostVolume once made), or any
        # other volume-sized buffer per render, such as a float proxy of the
        # int16 input (2.0 x). Fixed costs (the GL context, the thread pool,
        # the film) are paid on a small volume first, so that what is
        # measured is what the mapper holds per voxel.
        view = View(head_ct())
        view.render()
        pad = vtkImageWrapPad()  # the head tiled to 512^3 int16 (256 MiB), made in its own type
        pad.SetInputData(head_ct())
        pad.SetOutputWholeExtent(0, 511, 0, 511, 0, 511)
        pad.Update()
        big = vtkImageData()
        big.ShallowCopy(pad.GetOutput())
        del pad
        scalars = big.GetPointData().GetScalars()
        voxel_bytes = scalars.GetNumberOfValues() * scalars.GetDataTypeSize()
        self.assertEqual(voxel_bytes, 256 << 20)
        held = resident_bytes()  # the caller's volume is resident now
        reset_peak()
        view.mapper.SetInputData(big)
        view.render()
        extra = peak_resident_bytes() - held
        self.assertEqual(view.builds(), 2)
        self.assertGreater(view.coverage(), 0.05, "the large volume rendered nothing")
        self.assertLessEqual(
            extra, ALLOWED_EXTRA * voxel_bytes,
            "the render of a %d MiB volume raised the peak by %.0f MiB (%.2f x its voxels; at most %.2f x): "
            "a copy of the caller's voxels?" % (voxel_bytes >> 20, extra / 2**20, extra / voxel_bytes, ALLOWED_EXTRA))

    def test_an_edit_of_the_callers_array_shows_after_modified(self):
        image = head_ct()
        view = View(image)
        view.render()
        self.assertGreater(view.coverage(), 0.05)
        self.assertEqual(view.builds(), 1)
        scalars = image.GetPointData().GetScalars()
        scalars.Fill(0)  # all air, written into the array the mapper reads
        view.render()
        self.assertEqual(view.builds(), 1, "an array not marked modified is not read again")
        scalars.Modified()
        view.render()
        self.assertEqual(view.builds(), 2, "a modified array rebuilds the scene")
        self.assertLess(view.coverage(), 0.01, "the edit (all air) is not in the image")

    def test_the_reader_holds_its_volume_once(self):
        # What this catches: a reader that keeps the loaded volume and
        # copies it into its output (2.0 x the voxel bytes), or a loader
        # that copies out of its file reader's array (a peak of 2.0 x).
        warm = vtkMultiMaterialVolumeReader()  # the loader's libraries, loaded once
        warm.SetFileName(os.path.join(DATA, "ct_head_headsq.nrrd"))
        warm.Update()
        held = resident_bytes()
        reset_peak()
        reader = vtkMultiMaterialVolumeReader()
        reader.SetFileName(os.path.join(DATA, "frogtissue.mhd"))  # 30.5 MiB of uint8
        reader.Update()
        scalars = reader.GetOutput().GetPointData().GetScalars()
        voxel_bytes = scalars.GetNumberOfValues() * scalars.GetDataTypeSize()
        rise = peak_resident_bytes() - held
        self.assertLessEqual(rise, 1.5 * voxel_bytes,
                             "reading %d MiB raised the peak by %.2f x" % (voxel_bytes >> 20, rise / voxel_bytes))
        first = [scalars.GetValue(i) for i in range(0, scalars.GetNumberOfValues(), 99991)]
        reader.Modified()  # executes again: the file is read again, the same voxels come out
        reader.Update()
        again = reader.GetOutput().GetPointData().GetScalars()
        self.assertEqual([again.GetValue(i) for i in range(0, again.GetNumberOfValues(), 99991)], first)

    def test_nan_voxels_are_replaced_without_writing_the_callers_array(self):
        image = head_ct()
        values = vtkFloatArray()  # the CT as float with one NaN voxel
        source = image.GetPointData().GetScalars()
        values.SetNumberOfValues(source.GetNumberOfValues())
        for i in range(source.GetNumberOfValues()):
            values.SetValue(i, source.GetValue(i))
        values.SetValue(1000, math.nan)
        image.GetPointData().SetScalars(values)
        view = View(image)
        view.render()
        self.assertGreater(view.coverage(), 0.05)
        self.assertTrue(math.isnan(values.GetValue(1000)), "rendering wrote into the caller's array")


if __name__ == "__main__":
    unittest.main()
