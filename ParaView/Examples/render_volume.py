"""Path-traced volume rendering in ParaView, scripted: load a volume (a
file ParaView reads, or a folder of DICOM slices), show it with the
representation "Path Traced (MM-RTM)" and a preset of the renderer, save a
screenshot. The same script runs serially or sample-parallel under MPI:

    pvbatch render_volume.py PLUGIN VOLUME OUT.png [--preset ct-bone] [--samples 64]
    mpirun -np 4 pvbatch render_volume.py PLUGIN VOLUME OUT.png

PLUGIN is the built MMRTMPathTracing.so. Without --preset, ParaView's own
colour and opacity transfer functions are rendered (here a bone ramp).
"""
import argparse
import os

from paraview import simple as pv

parser = argparse.ArgumentParser()
parser.add_argument("plugin")
parser.add_argument("volume", help="a volume file, or a folder of DICOM slices")
parser.add_argument("out")
parser.add_argument("--preset", default="", help="ct-bone, ct-soft-tissue, ct-organs, mri ... (default: ParaView's TFs)")
parser.add_argument("--samples", type=int, default=64, help="samples per pixel of the image")
parser.add_argument("--size", type=int, nargs=2, default=[512, 512])
args = parser.parse_args()

pv.LoadPlugin(args.plugin, remote=True, ns=globals())
if os.path.isdir(args.volume):
    reader = pv.DICOMReaderdirectory(FileName=args.volume)
else:
    reader = pv.OpenDataFile(args.volume)
view = pv.CreateRenderView()
view.ViewSize = args.size
view.OrientationAxesVisibility = 0
if hasattr(view, "UseColorPaletteForBackground"):
    view.UseColorPaletteForBackground = 0
view.Background = [0, 0, 0]
display = pv.Show(reader, view)
array = reader.PointData.keys()[0]
pv.ColorBy(display, ("POINTS", array))
display.SetRepresentationType("Path Traced (MM-RTM)")
lut, pwf = pv.GetColorTransferFunction(array), pv.GetOpacityTransferFunction(array)
# A bone ramp in Hounsfield units (ParaView's transfer functions).
lut.RGBPoints = [-1024, 0.9, 0.85, 0.75, 150, 0.9, 0.85, 0.75, 700, 1.0, 0.97, 0.9, 3000, 1, 1, 1]
pwf.Points = [-1024, 0, 0.5, 0, 150, 0, 0.5, 0, 700, 0.8, 0.5, 0, 3000, 0.8, 0.5, 0]
display.Preset = args.preset
display.SamplesPerRender = args.samples
display.MaximumSamples = args.samples
# A view of the face (LPS data: anterior is -y), head up.
view.ResetCamera()
camera = view.GetActiveCamera()
fx, fy, fz = camera.GetFocalPoint()
camera.SetPosition(fx, fy - camera.GetDistance(), fz)
camera.SetViewUp(0, 0, 1)
view.ResetCamera()
pv.SaveScreenshot(args.out, view, ImageResolution=args.size, TransparentBackground=0)
display.UpdatePropertyInformation()
print("%s: %d samples a pixel" % (args.out, display.GetProperty("AccumulatedSamples").GetData()))
