"""Benchmark (not a test): how closely the interactive preview keeps to the
volume's share of the frame. The window asks for an interactive rate (its
DesiredUpdateRate, as vtkRenderWindowInteractor sets it while the camera
moves); VTK's renderer gives the volume AllocatedRenderTime of it, and the
mapper adapts the preview's image sample distance to that budget. Prints,
per preview while the camera turns, the budget, the mapper's Render time
(GetTimeToDraw) and the film's width, then the medians after the first
`--settle` previews (the distance starts at 4 and adapts).

    xvfb-run -a -s "-noreset -screen 0 1024x768x24" python3 Testing/Benchmarks/bench_preview_budget.py [--size 512] [--rate 15] [--previews 40]

Needs the Debian build's Python package (PYTHONPATH=build/lib/python3/dist-packages).
"""
import argparse
import os
import statistics

from vtkmodules.vtkCommonDataModel import vtkPiecewiseFunction
from vtkmodules.vtkIOImage import vtkNrrdReader
from vtkmodules.vtkRenderingCore import vtkColorTransferFunction, vtkRenderer, vtkRenderWindow, vtkVolume, vtkVolumeProperty
import vtkmodules.vtkRenderingOpenGL2  # noqa: F401
import vtkmodules.vtkRenderingVolumeOpenGL2  # noqa: F401

from mmrtm import vtkMultiMaterialVolumeMapper

DATA = os.environ.get("MMRTM_SHARED_DATA_DIR", os.path.join(os.path.dirname(__file__), "..", "..", "..", "shared", "data"))


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--size", type=int, default=512)
    parser.add_argument("--rate", type=float, default=15.0, help="the window's DesiredUpdateRate while interacting")
    parser.add_argument("--previews", type=int, default=40)
    parser.add_argument("--settle", type=int, default=10, help="previews left out of the medians")
    args = parser.parse_args()

    reader = vtkNrrdReader()
    reader.SetFileName(os.path.join(DATA, "ct_head_headsq.nrrd"))
    mapper = vtkMultiMaterialVolumeMapper()
    mapper.SetInputConnection(reader.GetOutputPort())
    mapper.SetBackendToCPU()
    opacity = vtkPiecewiseFunction()  # the bone of test_mapper.py's scene
    opacity.AddPoint(1100, 0.0)
    opacity.AddPoint(2000, 0.8)
    color = vtkColorTransferFunction()
    color.AddRGBPoint(1100, 0.9, 0.6, 0.5)
    color.AddRGBPoint(2000, 1.0, 0.95, 0.9)
    prop = vtkVolumeProperty()
    prop.SetScalarOpacity(opacity)
    prop.SetColor(color)
    prop.ShadeOn()
    volume = vtkVolume()
    volume.SetMapper(mapper)
    volume.SetProperty(prop)
    renderer = vtkRenderer()
    renderer.AddVolume(volume)
    window = vtkRenderWindow()
    window.SetOffScreenRendering(1)
    window.AddRenderer(renderer)
    window.SetSize(args.size, args.size)
    renderer.ResetCamera()
    window.Render()  # the scene and the grid, at the still rate

    window.SetDesiredUpdateRate(args.rate)
    rows = []
    size = [0, 0]
    for i in range(args.previews):
        renderer.GetActiveCamera().Azimuth(3)
        window.Render()
        mapper.GetLastFilmSize(size)
        rows.append((volume.GetAllocatedRenderTime(), mapper.GetTimeToDraw(), size[0]))
        print("preview %2d: budget %.1f ms, mapper %.1f ms, film %d px wide"
              % (i, 1e3 * rows[-1][0], 1e3 * rows[-1][1], rows[-1][2]))
    kept = rows[args.settle:]
    budget = statistics.median(r[0] for r in kept)
    spent = statistics.median(r[1] for r in kept)
    print("median over previews %d-%d: budget %.1f ms, mapper %.1f ms (%.2f of the budget), film %d-%d px wide; "
          "%d previews counted by the mapper"
          % (args.settle, args.previews - 1, 1e3 * budget, 1e3 * spent, spent / budget, min(r[2] for r in kept),
             max(r[2] for r in kept), mapper.GetNumberOfInteractiveRenders()))


if __name__ == "__main__":
    main()
