"""Times vtkMultiMaterialVolumeMapper (a benchmark, not a test): the head CT
of test_mapper.py with the ct-bone preset in a 512 x 512 window, 4 samples
per render, then interactive previews. Prints seconds per render.

    MMRTM_SHARED_DATA_DIR=../shared/data PYTHONPATH=build/lib/python3/dist-packages \\
        xvfb-run -a /usr/bin/python3 Testing/Python/bench_mapper.py
"""
import os
import sys
import time

sys.path.insert(0, os.path.dirname(__file__))
import test_mapper  # noqa: E402  (the test scene)
from mmrtm import vtkMultiMaterialProperty  # noqa: E402

s = test_mapper.Scene()
s.window.SetSize(512, 512)
s.mapper.SetMaximumSamples(0)
s.mapper.SetSamplesPerRender(4)
materials = vtkMultiMaterialProperty()
materials.SetPreset("ct-bone")
# headsq is not in Hounsfield units (0..3926): the preset's bone moved up.
materials.MergeSceneJSON('{"materials": {"bone": {"tfs": {"density": [{"type": "cctf", "proxy": "scalars",'
                         ' "points": [[1100, 0], [1500, 0.5], [2500, 1]]}]}}}}')
s.mapper.SetMultiMaterialProperty(materials)


def timed():
    start = time.time()
    s.window.Render()
    return time.time() - start


renders = [timed() for _ in range(6)]
print("first render (translation, majorant grid, 4 spp): %.3f s" % renders[0])
print("later renders (4 spp each): " + " ".join("%.3f" % t for t in renders[1:]) + " s")
s.window.SetDesiredUpdateRate(15.0)
previews = []
for _ in range(8):
    s.renderer.GetActiveCamera().Azimuth(3)
    previews.append(timed())
print("interactive previews: " + " ".join("%.3f" % t for t in previews) + " s")
print("backend:", s.mapper.GetBackendDescription())
