"""Benchmark (not a test): the path tracer in a headless Slicer 3D view
against Slicer's CPU ray cast (vtkFixedPointVolumeRayCastMapper) of the same
display node, on the same volume, preset, camera and view size.

For each: the first image (the render after the display node is made: the
scene build and summaries, or the ray caster's set-up) and the median time of
the following renders (the path tracer adds SAMPLES samples per pixel each;
the ray caster draws the same frame again). Both in one process, interleaved
per volume, so that the ratio is taken on the same machine load.

    xvfb-run -a .venv-vtk96/bin/python Slicer/MultiMaterialVolumeRendering/Testing/Python/bench_slicer.py
"""
import os
import statistics
import sys
import time

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))

from slicer_test_scene import CPU_METHOD, DATA, SlicerScene  # noqa: E402

SIZE = int(os.environ.get("BENCH_SIZE", "512"))
SAMPLES = int(os.environ.get("BENCH_SAMPLES", "4"))
RENDERS = int(os.environ.get("BENCH_RENDERS", "7"))


def timed(view):
    start = time.perf_counter()
    view.render()
    return time.perf_counter() - start


def bench(name, load, preset, azimuth):
    s = SlicerScene()
    view = s.add_view(size=SIZE)
    volume = load(s)
    display = s.show_with_path_tracing(volume, preset=preset, samples_per_render=SAMPLES, maximum_samples=0)
    display.SetBackend(display.Auto)
    # The pipeline has put the volume into the renderer: frame it first.
    view.renderer.ResetCamera()
    view.renderer.GetActiveCamera().Azimuth(azimuth)
    view.renderer.ResetCameraClippingRange()
    first = timed(view)  # includes the scene build and the majorant summaries
    ours = [timed(view) for _ in range(RENDERS)]
    backend = view.mapper().GetBackendDescription()
    samples = view.mapper().GetAccumulatedSamples()

    s.volume_rendering.ChangeVolumeRenderingMethod(CPU_METHOD)
    cpu_first = timed(view)
    cpu = [timed(view) for _ in range(RENDERS)]
    dims = volume.GetImageData().GetDimensions()
    print("%-6s %4d x %4d x %4d  %3d^2  first image: MM-RTM %.2f s, CPU ray cast %.2f s;"
          "  per render: MM-RTM %.3f s (%d spp, %s), CPU ray cast %.3f s, ratio %.2f;  %d spp after %d renders"
          % (name, dims[0], dims[1], dims[2], SIZE, first, cpu_first, statistics.median(ours), SAMPLES, backend,
             statistics.median(cpu), statistics.median(ours) / statistics.median(cpu), samples, RENDERS + 1))


if __name__ == "__main__":
    bench("head", lambda s: s.load_volume(os.path.join(DATA, "ct_head_cranium.nrrd"), "head"), "CT-Bone", 180)
    bench("chest", lambda s: s.load_dicom_series(os.path.join(DATA, "ct_chest_dicom"), "chest"), "CT-Bone", 0)
