"""Renders a DICOM CT series through vtkMultiMaterialVolumeMapper with a preset.
Usage: render_dicom_ct.py DICOM_FOLDER [OUTPUT.png] [PRESET]  (no OUTPUT: a window)
Run with /usr/bin/python3 and the package on PYTHONPATH (Documentation/vtk-mapper.md)."""
import sys
from vtkmodules.vtkIOImage import vtkPNGWriter
from vtkmodules.vtkRenderingCore import vtkRenderer, vtkRenderWindow, vtkRenderWindowInteractor, vtkVolume
from vtkmodules.vtkRenderingCore import vtkVolumeProperty, vtkWindowToImageFilter
import vtkmodules.vtkInteractionStyle, vtkmodules.vtkRenderingOpenGL2, vtkmodules.vtkRenderingVolumeOpenGL2  # noqa
from mmrtm import vtkMultiMaterialProperty, vtkMultiMaterialVolumeMapper, vtkMultiMaterialVolumeReader

reader = vtkMultiMaterialVolumeReader()        # ITK/GDCM: any transfer syntax, Hounsfield units, LPS
reader.SetFileName(sys.argv[1])
mapper = vtkMultiMaterialVolumeMapper()
mapper.SetInputConnection(reader.GetOutputPort())
materials = vtkMultiMaterialProperty()
materials.SetPreset(sys.argv[3] if len(sys.argv) > 3 else "ct-bone")   # Data/presets
mapper.SetMultiMaterialProperty(materials)
volume = vtkVolume()
volume.SetMapper(mapper), volume.SetProperty(vtkVolumeProperty())
renderer = vtkRenderer()
renderer.AddVolume(volume)
window = vtkRenderWindow()
window.AddRenderer(renderer), window.SetSize(400, 400)
camera = renderer.GetActiveCamera()            # from the front (anterior is -y in LPS), head up
camera.SetPosition(0, -1, 0), camera.SetFocalPoint(0, 0, 0), camera.SetViewUp(0, 0, 1), renderer.ResetCamera()

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
