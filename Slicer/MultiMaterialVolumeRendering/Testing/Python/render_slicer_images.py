"""Renders the images of Documentation/slicer.md in a headless Slicer 3D
view: the head CT with Slicer's CT-Bone preset by the path tracer and by
Slicer's CPU ray cast of the same display node, side by side; and
ct_abdomen's 61-segment TotalSegmentator segmentation as materials in the CT
(CT-Bone preset for the rest of the volume), next to the same with one
segment (the liver) hidden.

    xvfb-run -a .venv-vtk96/bin/python Slicer/MultiMaterialVolumeRendering/Testing/Python/render_slicer_images.py OUT_DIR
"""
import os
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))

from vtkmodules.vtkFiltersCore import vtkImageAppend  # noqa: E402
from vtkmodules.vtkIOImage import vtkPNGWriter  # noqa: E402
from vtkmodules.vtkRenderingCore import vtkWindowToImageFilter  # noqa: E402

from slicer_test_scene import CPU_METHOD, DATA, SlicerScene  # noqa: E402

SIZE = 384
SAMPLES = 64


def grab(view):
    g = vtkWindowToImageFilter()
    g.SetInput(view.window)
    g.ReadFrontBufferOff()
    g.Update()
    return g.GetOutput()


def side_by_side(images, path):
    append = vtkImageAppend()
    append.SetAppendAxis(0)
    for image in images:
        append.AddInputData(image)
    writer = vtkPNGWriter()
    writer.SetInputConnection(append.GetOutputPort())
    writer.SetFileName(path)
    writer.Write()
    print("wrote", path)


def head(out):
    s = SlicerScene()
    view = s.add_view(size=SIZE)
    volume = s.load_volume(os.path.join(DATA, "ct_head_cranium.nrrd"), "head")
    s.show_with_path_tracing(volume, preset="CT-Bone", samples_per_render=16, maximum_samples=SAMPLES)
    view.look_at_volume(azimuth=200, elevation=15)
    view.refine()
    ours = grab(view)
    s.volume_rendering.ChangeVolumeRenderingMethod(CPU_METHOD)
    view.render()
    side_by_side([ours, grab(view)], os.path.join(out, "slicer-head-ct-bone.png"))


def abdomen(out):
    s = SlicerScene()
    view = s.add_view(size=SIZE)
    ct, segmentation = s.load_abdomen_with_segments()
    display = s.show_with_path_tracing(ct, preset="CT-Bone", samples_per_render=16, maximum_samples=SAMPLES)
    display.SetAndObserveSegmentationNodeID(segmentation.GetID())
    view.look_at_volume(azimuth=-30, elevation=10)
    view.refine()
    everything = grab(view)
    segments = segmentation.GetSegmentation()
    liver = [segments.GetNthSegmentID(i) for i in range(segments.GetNumberOfSegments())
             if segments.GetNthSegment(i).GetLabelValue() == 5][0]
    segmentation.GetDisplayNode().SetSegmentVisibility(liver, False)
    view.refine()
    side_by_side([everything, grab(view)], os.path.join(out, "slicer-abdomen-segments.png"))


if __name__ == "__main__":
    out = sys.argv[1] if len(sys.argv) > 1 else "."
    head(out)
    abdomen(out)
