"""Renders a scene of the test suite (test_mapper.Scene, the head CT: seed
3, 8 samples per pixel, 128 x 128) and writes the mapper's accumulated
image, the linear film before tone mapping, to a file: a line
"width height samples" then width * height * 4 float32 values (RGBA, row 0
at the bottom).

Scenes: "ct" (the bone transfer function, shaded); "labels-mesh" (adds a
label map with its own colour, gradient opacity, and an opaque sphere whose
depth stops the camera rays).

Run under each VTK flavour by test_flavours_agree.py, which compares the
films: the tracer is the same code, so one seed must give the same film.

Usage: python render_film.py SCENE OUT
"""
import os
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))

from vtkmodules.vtkCommonCore import vtkVersion  # noqa: E402
from vtkmodules.vtkCommonDataModel import vtkImageData, vtkPiecewiseFunction  # noqa: E402

from test_mapper import Scene  # noqa: E402


def add_labels_and_mesh(scene):
    scene.keep = scene.add_bone_labels((0.1, 0.2, 0.9)), scene.add_sphere((1.0, 1.0, 1.0))
    edges = vtkPiecewiseFunction()
    edges.AddPoint(0, 0.2)
    edges.AddPoint(500, 1.0)
    scene.property.SetGradientOpacity(edges)


def main(name, out):
    scene = Scene()
    if name == "labels-mesh":
        add_labels_and_mesh(scene)
    elif name != "ct":
        sys.exit("unknown scene %r (ct, labels-mesh)" % name)
    while scene.mapper.GetAccumulatedSamples() < scene.mapper.GetMaximumSamples():
        scene.render()
    image = vtkImageData()
    scene.mapper.GetAccumulatedImage(image)
    width, height, _ = image.GetDimensions()
    values = bytes(memoryview(image.GetPointData().GetScalars()))
    with open(out, "wb") as f:
        f.write(b"%d %d %d\n" % (width, height, scene.mapper.GetAccumulatedSamples()))
        f.write(values)
    print("VTK %s: %d x %d, %d samples per pixel -> %s" % (
        vtkVersion.GetVTKVersion(), width, height, scene.mapper.GetAccumulatedSamples(), out))


if __name__ == "__main__":
    main(sys.argv[1], sys.argv[2])
