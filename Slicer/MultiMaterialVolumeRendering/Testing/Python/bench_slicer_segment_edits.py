"""Benchmark (not a test): what a segment edit costs in a headless Slicer 3D
view. ct_abdomen with its 61-label map imported as a segmentation, shown
with the path tracer over the CT-Soft-Tissue preset. For each kind of edit
(a segment's colour, its 3D opacity, its visibility, and no edit) the median
wall time of the render that takes the edit in, and the mapper's work it
caused (scene builds, refits, restarts). One sample per render on a small
view, so that the edit's own cost (the pipeline, the translation, the refit)
is what the time shows.

    xvfb-run -a .venv-vtk96/bin/python Slicer/MultiMaterialVolumeRendering/Testing/Python/bench_slicer_segment_edits.py
"""
import os
import statistics
import sys
import time

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))

from slicer_test_scene import SlicerScene  # noqa: E402

SIZE = int(os.environ.get("BENCH_SIZE", "96"))
REPEATS = int(os.environ.get("BENCH_REPEATS", "15"))


def main():
    s = SlicerScene()
    view = s.add_view(size=SIZE)
    ct, segmentation = s.load_abdomen_with_segments()
    display = s.show_with_path_tracing(ct, preset="CT-Soft-Tissue", samples_per_render=1, maximum_samples=0)
    display.SetAndObserveSegmentationNodeID(segmentation.GetID())
    view.look_at_volume()
    view.render()
    view.render()
    mapper = view.mapper()
    seg_display = segmentation.GetDisplayNode()
    segment = segmentation.GetSegmentation().GetNthSegmentID(4)

    def counts():
        return (mapper.GetNumberOfSceneBuilds(), mapper.GetNumberOfRefits(), mapper.GetNumberOfRestarts())

    edits = {
        "colour": lambda i: seg_display.SetSegmentOverrideColor(segment, 0.1 * (i % 10), 0.2, 0.9),
        "3D opacity": lambda i: seg_display.SetSegmentOpacity3D(segment, 0.5 + 0.05 * (i % 10)),
        "visibility": lambda i: seg_display.SetSegmentVisibility(segment, i % 2 == 1),
        "none": lambda i: None,
    }
    print("ct_abdomen, 61 segments, %d x %d, 1 sample per render, medians of %d" % (SIZE, SIZE, REPEATS))
    for name, edit in edits.items():
        times = []
        before = counts()
        for i in range(REPEATS):
            edit(i)
            start = time.perf_counter()
            view.render()
            times.append(time.perf_counter() - start)
        after = counts()
        work = tuple((a - b) / REPEATS for a, b in zip(after, before))
        print("%-10s %7.1f ms a render; per edit: builds %.2f, refits %.2f, restarts %.2f"
              % (name, 1000 * statistics.median(times), *work))


if __name__ == "__main__":
    main()
