"""The scene the plugin's tests and examples share: the head CT in a
ParaView render view, with a bone ramp (ParaView's transfer functions),
shown with the representation "Path Traced (MM-RTM)" or ParaView's own
"Volume". Run under pvbatch (paraview.simple)."""
import os
import sys

from paraview import simple as pv

HERE = os.path.dirname(os.path.abspath(__file__))
SOURCE_DIR = os.path.dirname(os.path.dirname(HERE))
DATA_DIR = os.environ.get("MMRTM_SHARED_DATA_DIR", os.path.join(SOURCE_DIR, "..", "shared", "data"))
PATH_TRACED = "Path Traced (MM-RTM)"


def plugin_path():
    """The plugin library in the build tree (MMRTM_PARAVIEW_PLUGIN overrides)."""
    path = os.environ.get("MMRTM_PARAVIEW_PLUGIN")
    if not path:
        sys.exit("set MMRTM_PARAVIEW_PLUGIN to the built MMRTMPathTracing.so")
    return path


def load_plugin():
    pv.LoadPlugin(plugin_path(), remote=True, ns=globals())


def rank_and_size():
    from paraview.modules.vtkRemotingCore import vtkProcessModule
    pm = vtkProcessModule.GetProcessModule()
    return pm.GetPartitionId(), pm.GetNumberOfLocalPartitions()


class Scene:
    """The head CT, a camera looking at the face, a bone ramp."""

    def __init__(self, size=(256, 256), path="ct_head_cranium.nrrd"):
        self.reader = pv.OpenDataFile(os.path.join(DATA_DIR, path))
        if self.reader is None:
            sys.exit("ParaView could not open " + os.path.join(DATA_DIR, path))
        self.view = pv.CreateRenderView()
        self.view.ViewSize = list(size)
        self.view.OrientationAxesVisibility = 0
        self.view.Background = [0.0, 0.0, 0.0]
        # ParaView 5.11 may draw a gradient or palette background: plain black.
        if hasattr(self.view, "UseColorPaletteForBackground"):
            self.view.UseColorPaletteForBackground = 0
        self.display = pv.Show(self.reader, self.view)
        array = self.reader.PointData.keys()[0]
        pv.ColorBy(self.display, ("POINTS", array))
        self.array = array
        self.lut = pv.GetColorTransferFunction(array)
        self.pwf = pv.GetOpacityTransferFunction(array)
        self.set_bone_ramp()
        self.face_camera()

    def set_bone_ramp(self, low=150.0, high=700.0):
        """Bone: opacity from 0 at `low` HU to 0.8 at `high`; ivory."""
        self.lut.RGBPoints = [-1024.0, 0.9, 0.85, 0.75, low, 0.9, 0.85, 0.75, high, 1.0, 0.97, 0.9, 3000.0, 1.0, 1.0, 1.0]
        self.pwf.Points = [-1024.0, 0.0, 0.5, 0.0, low, 0.0, 0.5, 0.0, high, 0.8, 0.5, 0.0, 3000.0, 0.8, 0.5, 0.0]
        self.lut.ScalarRangeInitialized = 1
        self.pwf.ScalarRangeInitialized = 1

    def use(self, representation):
        self.display.SetRepresentationType(representation)

    def counter(self, name):
        """A counter of the path-traced representation (AccumulatedSamples,
        NumberOfRefits, NumberOfRestarts, NumberOfCombinedRenders,
        NumberOfLocalRenders): the first process's value."""
        self.display.UpdatePropertyInformation()
        return int(self.display.GetProperty(name).GetData())

    def face_camera(self):
        """A view of the face: LPS data, so from -y (anterior), head up."""
        self.view.ResetCamera()
        cam = self.view.GetActiveCamera()
        fx, fy, fz = cam.GetFocalPoint()
        d = cam.GetDistance()
        cam.SetPosition(fx, fy - d, fz)
        cam.SetViewUp(0.0, 0.0, 1.0)
        self.view.ResetCamera()

    def capture(self, path=None):
        """The view's image (SaveScreenshot, which renders the view again)
        as a numpy array, rows top first, RGB; also kept at `path`."""
        import tempfile
        import numpy as np
        from vtkmodules.util.numpy_support import vtk_to_numpy
        from vtkmodules.vtkIOImage import vtkPNGReader
        if path is None:
            handle, path = tempfile.mkstemp(suffix=".png")
            os.close(handle)
        pv.SaveScreenshot(path, self.view, ImageResolution=list(self.view.ViewSize), TransparentBackground=0)
        reader = vtkPNGReader()
        reader.SetFileName(path)
        reader.Update()
        image = reader.GetOutput()
        w, h, _ = image.GetDimensions()
        pixels = vtk_to_numpy(image.GetPointData().GetScalars()).reshape(h, w, -1)[::-1, :, :3]
        return np.ascontiguousarray(pixels)
