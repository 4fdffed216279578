"""Side by side in one process (a benchmark, not a test): VTK's
vtkFixedPointVolumeRayCastMapper against vtkMultiMaterialVolumeMapper at
one sample per pixel per render, with the same vtkVolumeProperty (shading
on), camera, lights and window (512 x 512). Three volumes: the head CT, the
chest CT DICOM series and the bonsai. For each, the median seconds of a
frame over several frames of each mapper (the first frame of each, which
builds its structures, is timed apart), and the ratio ours / VTK's. The
mappers alternate frame by frame, so that the noise of a shared machine
falls on all alike.

    MMRTM_SHARED_DATA_DIR=../shared/data PYTHONPATH=build/lib/python3/dist-packages \\
        Testing/headless.sh 1024x768x24 /usr/bin/python3 Testing/Benchmarks/bench_side_by_side.py [--frames 7] [--json out.json]
"""
import argparse
import json
import os
import statistics
import sys
import time

from vtkmodules.vtkCommonDataModel import vtkPiecewiseFunction
from vtkmodules.vtkIOImage import vtkNIFTIImageReader, vtkNrrdReader, vtkPNGWriter
from vtkmodules.vtkRenderingCore import (vtkColorTransferFunction, vtkRenderer, vtkRenderWindow, vtkVolume,
                                         vtkVolumeProperty, vtkWindowToImageFilter)
from vtkmodules.vtkRenderingVolume import vtkFixedPointVolumeRayCastMapper
import vtkmodules.vtkRenderingOpenGL2  # noqa: F401  (the OpenGL render window)
import vtkmodules.vtkRenderingVolumeOpenGL2  # noqa: F401  (the image display helper)

from mmrtm import vtkMultiMaterialVolumeMapper, vtkMultiMaterialVolumeReader

DATA = os.environ.get("MMRTM_SHARED_DATA_DIR", os.path.join(os.path.dirname(__file__), "..", "..", "..", "shared", "data"))


def bone_ramp(low, high):
    """The CT bone ramp of bench_mapper.py, in the volume's units."""
    opacity = vtkPiecewiseFunction()
    opacity.AddPoint(low, 0.0)
    opacity.AddPoint(high, 0.8)
    color = vtkColorTransferFunction()
    color.AddRGBPoint(low, 0.9, 0.6, 0.5)
    color.AddRGBPoint(high, 1.0, 0.95, 0.9)
    return opacity, color


def volume_property(opacity, color):
    p = vtkVolumeProperty()
    p.SetScalarOpacity(opacity)
    p.SetColor(color)
    p.ShadeOn()
    p.SetAmbient(0.3)
    p.SetDiffuse(0.7)
    p.SetSpecular(0.2)
    p.SetInterpolationTypeToLinear()
    return p


def head_ct():
    r = vtkNrrdReader()
    r.SetFileName(os.path.join(DATA, "ct_head_cranium.nrrd"))
    return r, bone_ramp(200.0, 1200.0)  # Hounsfield units


def chest_ct():
    r = vtkMultiMaterialVolumeReader()
    r.SetFileName(os.path.join(DATA, "ct_chest_dicom"))
    return r, bone_ramp(200.0, 1200.0)  # Hounsfield units (the reader rescales)


def bonsai():
    r = vtkNIFTIImageReader()
    r.SetFileName(os.path.join(DATA, "bonsai.nii.gz"))
    opacity = vtkPiecewiseFunction()  # uint8: trunk and leaves above the haze
    opacity.AddPoint(40, 0.0)
    opacity.AddPoint(80, 0.3)
    opacity.AddPoint(255, 0.9)
    color = vtkColorTransferFunction()
    color.AddRGBPoint(40, 0.3, 0.6, 0.2)
    color.AddRGBPoint(120, 0.5, 0.4, 0.25)
    color.AddRGBPoint(255, 0.9, 0.85, 0.7)
    return r, (opacity, color)


class Pair:
    """One window, one renderer, one volume whose mapper is swapped."""

    def __init__(self, reader, functions, size):
        reader.Update()
        self.image = reader.GetOutput()
        self.property = volume_property(*functions)
        self.fixed = vtkFixedPointVolumeRayCastMapper()
        self.fixed.SetInputData(self.image)
        self.fixed.SetAutoAdjustSampleDistances(0)  # VTK's full-quality still frame
        self.ours = self.our_mapper()
        self.volume = vtkVolume()
        self.volume.SetProperty(self.property)
        self.renderer = vtkRenderer()
        self.renderer.AddVolume(self.volume)
        self.window = vtkRenderWindow()
        self.window.SetOffScreenRendering(1)
        self.window.AddRenderer(self.renderer)
        self.window.SetSize(size, size)
        self.volume.SetMapper(self.fixed)
        self.renderer.ResetCamera()
        self.renderer.GetActiveCamera().Elevation(-70)
        self.renderer.GetActiveCamera().OrthogonalizeViewUp()
        self.renderer.ResetCamera()

    def our_mapper(self):
        mapper = vtkMultiMaterialVolumeMapper()
        mapper.SetInputData(self.image)
        mapper.SetSamplesPerRender(1)
        mapper.SetMaximumSamples(0)
        mapper.SetBackendToCPU()
        return mapper

    def save(self, path):
        grab = vtkWindowToImageFilter()
        grab.SetInput(self.window)
        grab.ReadFrontBufferOff()
        writer = vtkPNGWriter()
        writer.SetFileName(path)
        writer.SetInputConnection(grab.GetOutputPort())
        writer.Write()

    def frame(self, mapper):
        self.volume.SetMapper(mapper)
        start = time.perf_counter()
        self.window.Render()
        return time.perf_counter() - start


def main():
    parser = argparse.ArgumentParser()
    parser.add_argument("--frames", type=int, default=7, help="timed frames of each mapper after the first")
    parser.add_argument("--size", type=int, default=512)
    parser.add_argument("--volumes", default="head,chest,bonsai")
    parser.add_argument("--json", help="write the figures here too")
    parser.add_argument("--images", help="a folder for the last frame of each mapper (PNG)")
    args = parser.parse_args()
    volumes = {"head": head_ct, "chest": chest_ct, "bonsai": bonsai}
    results = {}
    print("%-7s %12s %12s %12s %12s %7s" % ("volume", "VTK first", "ours first", "VTK frame", "ours frame", "ratio"))
    for name in args.volumes.split(","):
        reader, functions = volumes[name]()
        pair = Pair(reader, functions, args.size)
        first_fixed = pair.frame(pair.fixed)
        first_ours = pair.frame(pair.ours)
        fixed, ours = [], []
        for _ in range(args.frames):
            fixed.append(pair.frame(pair.fixed))
            ours.append(pair.frame(pair.ours))  # adds one sample per pixel (nothing changed)
        if args.images:
            os.makedirs(args.images, exist_ok=True)
            for mapper, label in ((pair.fixed, "vtk"), (pair.ours, "ours")):
                pair.frame(mapper)
                pair.save(os.path.join(args.images, "%s-%s.png" % (name, label)))
        f, o = statistics.median(fixed), statistics.median(ours)
        results[name] = {"dimensions": list(pair.image.GetDimensions()), "vtk_first_s": first_fixed,
                         "ours_first_s": first_ours, "vtk_frame_s": f, "ours_frame_s": o, "ratio": o / f,
                         "ours_samples": pair.ours.GetAccumulatedSamples(),
                         "backend": pair.ours.GetBackendDescription()}
        print("%-7s %11.3fs %11.3fs %11.3fs %11.3fs %7.2f" % (name, first_fixed, first_ours, f, o, o / f))
        sys.stdout.flush()
    if args.json:
        with open(args.json, "w") as out:
            json.dump(results, out, indent=2)


if __name__ == "__main__":
    main()
