"""Benchmark (not a test): what a render costs the VTK mapper when nothing
changed and the image is finished (MaximumSamples reached): reading the
inputs, comparing them with what the scene was made from, the scene's
build (which refits only when a refit's inputs changed) and drawing. With
each accelerator, interleaved in one process so that the ratios are taken
on the same machine load; the mapper's counters show that no refit or
restart happened.

    xvfb-run -a python3 Testing/Benchmarks/bench_unchanged_render.py [--size 256] [--renders 200]

Needs the Debian build's Python package (PYTHONPATH=build/lib/python3/dist-packages).
"""
import argparse
import os
import statistics
import time

from vtkmodules.vtkCommonDataModel import vtkPiecewiseFunction
from vtkmodules.vtkIOImage import vtkNrrdReader
from vtkmodules.vtkRenderingCore import vtkColorTransferFunction, vtkRenderer, vtkRenderWindow, vtkVolume, vtkVolumeProperty
import vtkmodules.vtkRenderingOpenGL2  # noqa: F401
import vtkmodules.vtkRenderingVolumeOpenGL2  # noqa: F401

from mmrtm import vtkMultiMaterialVolumeMapper

DATA = os.environ.get("MMRTM_SHARED_DATA_DIR", os.path.join(os.path.dirname(__file__), "..", "..", "..", "shared", "data"))


def view(accelerator, size):
    reader = vtkNrrdReader()
    reader.SetFileName(os.path.join(DATA, "ct_head_cranium.nrrd"))
    mapper = vtkMultiMaterialVolumeMapper()
    mapper.SetInputConnection(reader.GetOutputPort())
    mapper.SetBackendToCPU()
    mapper.SetMaximumSamples(4)
    mapper.SetSamplesPerRender(4)
    mapper.SetAccelerator(accelerator)
    opacity = vtkPiecewiseFunction()
    opacity.AddPoint(200, 0.0)
    opacity.AddPoint(1200, 0.8)
    color = vtkColorTransferFunction()
    color.AddRGBPoint(200, 0.9, 0.6, 0.5)
    color.AddRGBPoint(1200, 1.0, 0.95, 0.9)
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
    window.SetSize(size, size)
    renderer.ResetCamera()
    window.Render()  # the scene, the grid and the 4 samples: finished
    return window, mapper


def main():
    parser = argparse.ArgumentParser()
    parser.add_argument("--size", type=int, default=256)
    parser.add_argument("--renders", type=int, default=200)
    args = parser.parse_args()
    names = {vtkMultiMaterialVolumeMapper.OCTREE: "octree", vtkMultiMaterialVolumeMapper.MACROCELL: "macrocell",
             vtkMultiMaterialVolumeMapper.NO_ACCELERATOR: "none"}
    views = {a: view(a, args.size) for a in names}
    times = {a: [] for a in names}
    before = {a: (m.GetNumberOfRefits(), m.GetNumberOfRestarts(), m.GetNumberOfMajorantGridRefits())
              for a, (w, m) in views.items()}
    for _ in range(args.renders):
        for a, (window, _) in views.items():
            start = time.perf_counter()
            window.Render()
            times[a].append(time.perf_counter() - start)
    print("head CT (256 x 256 x 108), %d x %d, finished image, median of %d renders" % (args.size, args.size, args.renders))
    base = statistics.median(times[vtkMultiMaterialVolumeMapper.NO_ACCELERATOR])
    for a, name in names.items():
        m = views[a][1]
        work = tuple(x - y for x, y in zip((m.GetNumberOfRefits(), m.GetNumberOfRestarts(),
                                            m.GetNumberOfMajorantGridRefits()), before[a]))
        t = statistics.median(times[a])
        print("%-9s %7.3f ms a render (%.2f x none's); translations, restarts, grid refits during them: %d, %d, %d"
              % (name, 1000 * t, t / base, *work))


if __name__ == "__main__":
    main()
