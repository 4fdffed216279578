"""Renders a DICOM CT series through vtkMultiMaterialVolumeMapper with a bone
transfer function.  Usage: render_dicom_ct.py DICOM_FOLDER [OUTPUT.png]
(no OUTPUT: an interactive window). Run with /usr/bin/python3 and the build
tree's package on PYTHONPATH (see Documentation/vtk-mapper.md)."""
import sys
from vtkmodules.vtkIOImage import vtkDICOMImageReader, vtkPNGWriter
from vtkmodules.vtkRenderingCore import vtkColorTransferFunction, vtkRenderer, vtkRenderWindow, vtkVolume
from vtkmodules.vtkRenderingCore import vtkRenderWindowInteractor, vtkVolumeProperty, vtkWindowToImageFilter
from vtkmodules.vtkCommonDataModel import vtkPiecewiseFunction
import vtkmodules.vtkInteractionStyle, vtkmodules.vtkRenderingOpenGL2, vtkmodules.vtkRenderingVolumeOpenGL2  # noqa
from mmrtm import vtkMultiMaterialVolumeMapper

reader = vtkDICOMImageReader()
reader.SetDirectoryName(sys.argv[1])
mapper = vtkMultiMaterialVolumeMapper()
mapper.SetInputConnection(reader.GetOutputPort())
opacity, color = vtkPiecewiseFunction(), vtkColorTransferFunction()  # bone, in Hounsfield units
for hu, a, rgb in [(150, 0.0, (0.85, 0.55, 0.45)), (300, 0.5, (0.92, 0.84, 0.72)), (900, 1.0, (1, 1, 0.95))]:
    opacity.AddPoint(hu, a)
    color.AddRGBPoint(hu, *rgb)
prop = vtkVolumeProperty()
prop.SetScalarOpacity(opacity), prop.SetColor(color), prop.ShadeOn(), prop.SetAmbient(0.3)
volume = vtkVolume()
volume.SetMapper(mapper), volume.SetProperty(prop)
renderer = vtkRenderer()
renderer.AddVolume(volume)
window = vtkRenderWindow()
window.AddRenderer(renderer), window.SetSize(400, 400)
camera = renderer.GetActiveCamera()  # from the front: the patient's anterior side faces +y here
renderer.ResetCamera(), camera.Elevation(90), camera.OrthogonalizeViewUp(), renderer.ResetCamera()

if len(sys.argv) > 2:  # off screen: accumulate 32 samples per pixel, then save
    window.SetOffScreenRendering(1)
    mapper.SetSamplesPerRender(8), mapper.SetMaximumSamples(32)
    for _ in range(4):
        window.Render()
    grab = vtkWindowToImageFilter()
    grab.SetInput(window)
    writer = vtkPNGWriter()
    writer.SetFileName(sys.argv[2]), writer.SetInputConnection(grab.GetOutputPort()), writer.Write()
else:  # on screen: every render adds samples; a timer keeps refining
    interactor = vtkRenderWindowInteractor()
    interactor.SetRenderWindow(window)
    interactor.Initialize()
    interactor.AddObserver("TimerEvent", lambda *_: window.Render())
    interactor.CreateRepeatingTimer(50)
    interactor.Start()
