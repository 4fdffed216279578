"""A headless 3D Slicer core for the tests: an MRML scene with the
application logic and the module logics Volume Rendering needs (Colors,
Volumes, Volume Rendering with Slicer's presets, Segmentations, and ours),
and 3D views whose displayable manager groups render off screen, as
trame-slicer and qMRMLThreeDView build them (Slicer's own volume rendering
displayable manager included, which must ignore our display node).

Runs on the PyPI Slicer core (slicer-core, slicer-layer-dm, vtk 9.6) with the
mmrtm wheel built with its Slicer classes.
"""
import os

from vtkmodules.vtkCommonCore import vtkCollection
from vtkmodules.vtkRenderingCore import (vtkRenderer, vtkRenderWindow, vtkRenderWindowInteractor,
                                         vtkWindowToImageFilter)
import vtkmodules.vtkRenderingOpenGL2  # noqa: F401  (the OpenGL render window)
import vtkmodules.vtkRenderingVolumeOpenGL2  # noqa: F401  (the image display helper)

from slicer import (vtkMRMLColorLogic, vtkMRMLDisplayableManagerGroup, vtkMRMLScene,
                    vtkMRMLThreeDViewDisplayableManagerFactory, vtkMRMLViewLogic, vtkSlicerApplicationLogic,
                    vtkSlicerSegmentationsModuleLogic, vtkSlicerVolumeRenderingLogic, vtkSlicerVolumesLogic)
from slicer import vtkMRMLMultiMaterialVolumeRenderingDisplayNode, vtkSlicerMultiMaterialVolumeRenderingLogic

DATA = os.environ.get("MMRTM_SHARED_DATA_DIR", os.path.join(os.path.dirname(__file__), "..", "..", "..", "..", "..",
                                                           "shared", "data"))
METHOD = "vtkMRMLMultiMaterialVolumeRenderingDisplayNode"
CPU_METHOD = "vtkMRMLCPURayCastVolumeRenderingDisplayNode"
DISPLAYABLE_MANAGERS = ("vtkMRMLCameraDisplayableManager", "vtkMRMLVolumeRenderingDisplayableManager",
                        "vtkMRMLLayerDisplayableManager")


def presets_directory():
    """Slicer's presets.xml: slicer-core does not ship it, trame-slicer does."""
    try:
        import trame_slicer
    except ImportError:
        return None
    folder = os.path.join(os.path.dirname(trame_slicer.__file__), "resources")
    return folder if os.path.isfile(os.path.join(folder, "presets.xml")) else None


class SlicerScene:
    def __init__(self, with_our_logic=True):
        self.scene = vtkMRMLScene()
        self.app = vtkSlicerApplicationLogic()
        self.app.SetMRMLScene(self.scene)
        self.app.GetColorLogic().SetMRMLScene(self.scene)
        self.app.GetColorLogic().AddDefaultColorNodes()
        self.app.SetSliceLogics(vtkCollection())
        self.app.SetViewLogics(vtkCollection())
        vtkMRMLThreeDViewDisplayableManagerFactory.GetInstance().SetMRMLApplicationLogic(self.app)
        self.colors = self.register(vtkMRMLColorLogic(), "Colors")
        self.volumes = self.register(vtkSlicerVolumesLogic(), "Volumes")
        self.volume_rendering = self.register(vtkSlicerVolumeRenderingLogic(), "VolumeRendering",
                                              presets_directory())
        self.segmentations = self.register(vtkSlicerSegmentationsModuleLogic(), "Segmentations")
        # Ours last, as a Slicer module after its dependencies: it finds the
        # Volume Rendering logic through the application logic. Without it,
        # as trame-slicer starts, only the package's import has run.
        self.logic = None
        if with_our_logic:
            self.logic = self.register(vtkSlicerMultiMaterialVolumeRenderingLogic(), "MultiMaterialVolumeRendering")
        self.views = []

    def register(self, logic, name, share_directory=None):
        # As Slicer's module setup: application logic, share folder, then scene.
        logic.SetMRMLApplicationLogic(self.app)
        if share_directory:
            logic.SetModuleShareDirectory(share_directory)
        logic.SetMRMLScene(self.scene)
        self.app.SetModuleLogic(name, logic)
        return logic

    def add_view(self, name="View1", size=160):
        view = View(self, name, size)
        self.views.append(view)
        return view

    def load_volume(self, path, name, labelmap=False):
        node = self.volumes.AddArchetypeVolume(path, name, 1 if labelmap else 0)
        assert node is not None, "Slicer's volumes logic could not read " + path
        return node

    def load_abdomen_with_segments(self):
        """ct_abdomen and its 61-label map (TotalSegmentator) imported as a
        segmentation, as a user imports a label map in Segmentations.
        Returns the CT's volume node and the segmentation node."""
        ct = self.load_volume(os.path.join(DATA, "ct_abdomen.nii.gz"), "abdomen")
        labels = self.load_volume(os.path.join(DATA, "ct_abdomen_labels.nii.gz"), "labels", labelmap=True)
        segmentation = self.scene.AddNewNodeByClass("vtkMRMLSegmentationNode", "organs")
        segmentation.CreateDefaultDisplayNodes()
        assert self.segmentations.ImportLabelmapToSegmentationNode(labels, segmentation), "the label map imports"
        return ct, segmentation

    def load_dicom_series(self, folder, name):
        """A DICOM series as Slicer's DICOM module loads it
        (DICOMScalarVolumePlugin): the files sorted along the slice normal by
        their ImagePositionPatient, given to the volumes logic as a list."""
        import pydicom  # comes with trame-slicer
        from vtkmodules.vtkCommonCore import vtkStringArray
        files = [os.path.join(folder, f) for f in os.listdir(folder)]
        headers = {f: pydicom.dcmread(f, stop_before_pixels=True) for f in files}
        o = [float(v) for v in headers[files[0]].ImageOrientationPatient]
        normal = (o[1] * o[5] - o[2] * o[4], o[2] * o[3] - o[0] * o[5], o[0] * o[4] - o[1] * o[3])
        files.sort(key=lambda f: sum(n * float(p) for n, p in zip(normal, headers[f].ImagePositionPatient)))
        names = vtkStringArray()
        for f in files:
            names.InsertNextValue(f)
        node = self.volumes.AddArchetypeScalarVolume(files[0], name, 0, names)
        assert node is not None, "Slicer's volumes logic could not read " + folder
        return node

    def show_with_path_tracing(self, volume, preset="CT-Bone", samples_per_render=4, maximum_samples=8, seed=5):
        """Volume Rendering of `volume` with our method, as the module does:
        the default method, then CreateDefaultVolumeRenderingNodes."""
        self.volume_rendering.SetDefaultRenderingMethod(METHOD)
        display = self.volume_rendering.CreateDefaultVolumeRenderingNodes(volume)
        assert display.IsA(METHOD), display.GetClassName()
        if preset:
            self.apply_preset(display, preset)
        display.SetSamplesPerRender(samples_per_render)
        display.SetMaximumSamples(maximum_samples)
        display.SetSeed(seed)
        display.SetBackend(display.CPU)
        display.SetVisibility(True)
        return display

    def apply_preset(self, display, name):
        preset = self.volume_rendering.GetPresetByName(name)
        assert preset is not None, "no Volume Rendering preset " + name
        display.GetVolumePropertyNode().Copy(preset)


class View:
    """A 3D view node with an off-screen render window and the displayable
    manager group of a Slicer 3D view."""

    def __init__(self, slicer_scene, name, size):
        self.renderer = vtkRenderer()
        self.window = vtkRenderWindow()
        self.window.SetOffScreenRendering(1)
        self.window.AddRenderer(self.renderer)
        self.window.SetSize(size, size)
        # The displayable managers update the interactor style: a view needs one.
        self.interactor = vtkRenderWindowInteractor()
        self.interactor.SetRenderWindow(self.window)
        self.interactor.Initialize()
        factory = vtkMRMLThreeDViewDisplayableManagerFactory.GetInstance()
        for manager in DISPLAYABLE_MANAGERS:
            if not factory.IsDisplayableManagerRegistered(manager):
                factory.RegisterDisplayableManager(manager)
        self.group = vtkMRMLDisplayableManagerGroup()
        self.group.Initialize(factory, self.renderer)
        self.view_logic = vtkMRMLViewLogic()
        self.view_logic.SetMRMLApplicationLogic(slicer_scene.app)
        slicer_scene.app.GetViewLogics().AddItem(self.view_logic)
        self.view_logic.SetMRMLScene(slicer_scene.scene)
        # A scene read from a file has its view nodes already.
        self.node = (vtkMRMLViewLogic.GetViewNode(slicer_scene.scene, name)
                     or self.view_logic.AddViewNode(name))
        assert self.node is not None, "no view node " + name
        self.group.SetMRMLDisplayableNode(self.node)

    def render(self):
        self.window.Render()

    def look_at_volume(self, azimuth=0.0, elevation=0.0):
        """Fits the camera to what is visible (after a render has put the
        volume into the renderer), then turns it."""
        self.render()
        self.renderer.ResetCamera()
        camera = self.renderer.GetActiveCamera()
        camera.Azimuth(azimuth)
        camera.Elevation(elevation)
        camera.OrthogonalizeViewUp()
        self.renderer.ResetCameraClippingRange()

    def volumes(self, mapper_class=None):
        found = []
        collection = self.renderer.GetVolumes()
        for i in range(collection.GetNumberOfItems()):
            volume = collection.GetItemAsObject(i)
            if mapper_class is None or volume.GetMapper().IsA(mapper_class):
                found.append(volume)
        return found

    def path_traced_volume(self):
        found = self.volumes("vtkMultiMaterialVolumeMapper")
        assert len(found) == 1, "%d path-traced volumes in the view" % len(found)
        return found[0]

    def mapper(self):
        return self.path_traced_volume().GetMapper()

    def refine(self, limit=64):
        """Renders until the path tracer's image converges (what a Slicer view
        does while it is idle); returns the number of renders."""
        for count in range(1, limit + 1):
            self.render()
            volume = self.volumes("vtkMultiMaterialVolumeMapper")
            if not volume or not volume[0].GetVisibility() or volume[0].GetMapper().IsConverged():
                return count
        raise AssertionError("the image did not converge in %d renders" % limit)

    def pixels(self):
        grab = vtkWindowToImageFilter()
        grab.SetInput(self.window)
        grab.ReadFrontBufferOff()
        grab.Update()
        scalars = grab.GetOutput().GetPointData().GetScalars()
        n = scalars.GetNumberOfComponents()
        data = bytes(memoryview(scalars))
        return [tuple(data[i:i + 3]) for i in range(0, len(data), n)]


def covered(pixels, threshold=24):
    """Which pixels differ from the black background."""
    return [max(p) > threshold for p in pixels]


def intersection_over_union(a, b):
    inter = sum(1 for x, y in zip(a, b) if x and y)
    union = sum(1 for x, y in zip(a, b) if x or y)
    return inter / union if union else 1.0


def mean_abs_difference(a, b):
    return sum(abs(x - y) for p, q in zip(a, b) for x, y in zip(p, q)) / (3.0 * len(a) * 255.0)
