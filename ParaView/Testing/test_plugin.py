"""The plugin in pvbatch (serially): it loads, the representation type is
offered for image data, the head CT renders non-blank with the silhouette
of ParaView's own "Volume" representation of the same transfer functions,
a transfer-function edit from Python refits and restarts the accumulation,
a camera change restarts it without a refit, and each kind of edit does
exactly its work (the table).

    pvbatch test_plugin.py OUTDIR     (in the ParaView root, under X)
"""
import os
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import numpy as np  # noqa: E402
import pv_scene  # noqa: E402
from paraview import simple as pv  # noqa: E402

out = sys.argv[1] if len(sys.argv) > 1 else "."
os.makedirs(out, exist_ok=True)
failures = []


def check(ok, what):
    print(("ok   " if ok else "FAIL ") + what)
    if not ok:
        failures.append(what)


pv_scene.load_plugin()
s = pv_scene.Scene(size=(256, 256))
offered = list(s.display.Representation.Available)
check(pv_scene.PATH_TRACED in offered, "the representation type is offered: %s" % offered)

s.use("Volume")
volume = s.capture(os.path.join(out, "paraview-volume.png"))
s.use(pv_scene.PATH_TRACED)
traced = s.capture(os.path.join(out, "path-traced.png"))

# Silhouettes: pixels brighter than a tenth of the image's brightest
# (luminance), against a black background.
def silhouette(image):
    lum = image.astype(np.float64) @ np.array([0.2126, 0.7152, 0.0722])
    return lum > 0.1 * lum.max()


a, b = silhouette(traced), silhouette(volume)
iou = float((a & b).sum()) / max(1, float((a | b).sum()))
check(traced.max() > 100 and a.mean() > 0.05,
      "the path-traced head CT is not blank (max %d, %.0f %% of the pixels)" % (traced.max(), 100 * a.mean()))
check(traced.mean() < 200, "nor blown out (mean %.1f)" % traced.mean())
check(iou > 0.85, "its silhouette matches ParaView's Volume representation: IoU %.3f" % iou)
check(s.display.Denoise == "Auto", "the view is denoised while that is closer by default (Denoise %s)"
      % s.display.Denoise)
samples = s.counter("AccumulatedSamples")
check(samples == 64, "one still render gives the default 64 samples a pixel (%d)" % samples)

refits, restarts = s.counter("NumberOfRefits"), s.counter("NumberOfRestarts")
s.set_bone_ramp(low=400.0, high=900.0)  # a transfer-function edit
pv.Render(s.view)
# The bone ramp sets the colour and the opacity function: one or two
# translations, never none (the table below counts single edits exactly).
check(refits < s.counter("NumberOfRefits") <= refits + 2 and s.counter("NumberOfRestarts") > restarts,
      "a transfer-function edit refits and restarts (refits %d -> %d, restarts %d -> %d)"
      % (refits, s.counter("NumberOfRefits"), restarts, s.counter("NumberOfRestarts")))
edited = s.capture(os.path.join(out, "path-traced-edited.png"))
check(silhouette(edited).sum() < a.sum(), "the higher bone threshold shows less (%d < %d pixels)"
      % (silhouette(edited).sum(), a.sum()))

refits, restarts = s.counter("NumberOfRefits"), s.counter("NumberOfRestarts")
s.view.GetActiveCamera().Azimuth(30)
pv.Render(s.view)
check(s.counter("NumberOfRestarts") == restarts + 1 and s.counter("NumberOfRefits") == refits,
      "a camera change restarts without a refit (restarts %d -> %d, refits %d -> %d)"
      % (restarts, s.counter("NumberOfRestarts"), refits, s.counter("NumberOfRefits")))

# Each kind of edit a ParaView user makes, one render after it, and the
# work the mapper did: scene builds, translations of the property, restarts,
# majorant grid builds and refits. Catches work an edit does not need (a
# refit after a colour, a restart after the exposure or after nothing) and
# an edit that does not reach the tracer.
WORK = ("NumberOfSceneBuilds", "NumberOfRefits", "NumberOfRestarts", "NumberOfMajorantGridBuilds",
        "NumberOfMajorantGridRefits")


def work():
    return tuple(s.counter(name) for name in WORK)


def edit_colour():
    points = list(s.lut.RGBPoints)
    points[5] = 0.5  # the second point's green
    s.lut.RGBPoints = points


def edit_opacity():
    points = list(s.pwf.Points)
    points[9] = 0.6  # the third point's opacity
    s.pwf.Points = points


pv.Render(s.view)
for name, edit, expected in (
        ("unchanged", lambda: None, (0, 0, 0, 0, 0)),
        ("camera", lambda: s.view.GetActiveCamera().Azimuth(10), (0, 0, 1, 0, 0)),
        ("window size", lambda: setattr(s.view, "ViewSize", [240, 256]), (0, 0, 1, 0, 0)),
        ("sampling setting", lambda: setattr(s.display, "MaximumBounces", 3), (0, 0, 1, 0, 0)),
        ("exposure", lambda: setattr(s.display, "PathTracingExposure", 1.5), (0, 0, 0, 0, 0)),
        ("denoise", lambda: setattr(s.display, "Denoise", "Always"), (0, 0, 0, 0, 0)),
        ("colour point", edit_colour, (0, 1, 1, 0, 0)),
        ("opacity point", edit_opacity, (0, 1, 1, 0, 1))):
    before = work()
    edit()
    pv.Render(s.view)
    done = tuple(a - b for a, b in zip(work(), before))
    check(done == expected, "%-16s builds, translations, restarts, grid builds, grid refits: %s (expected %s)"
          % (name, done, expected))
s.view.ViewSize = [256, 256]

s.display.Preset = "ct-bone"
pv.Render(s.view)
preset = s.capture(os.path.join(out, "path-traced-preset.png"))
check(silhouette(preset).mean() > 0.05, "the ct-bone preset renders (%.0f %% of the pixels)"
      % (100 * silhouette(preset).mean()))

# A label map: a second point array (here made from the CT itself: 1 where
# it is above 300 HU) named as LabelMapArray. Label 1 becomes a material of
# its own, in the front ends' default colour of label 1
# (vtkMultiMaterialVolumeMapper::GetDefaultLabelColor: a violet blue, where
# the bone's colour map is warm).
s.display.Preset = ""
calc = pv.Calculator(Input=s.reader, ResultArrayName="labels", Function="%s > 300" % s.array)
labelled = pv.Show(calc, s.view)
pv.Hide(s.reader, s.view)
pv.ColorBy(labelled, ("POINTS", s.array))
labelled.SetRepresentationType(pv_scene.PATH_TRACED)
pv.Render(s.view)
plain = s.capture(os.path.join(out, "path-traced-calculator.png")).astype(np.float64)
labelled.LabelMapArray = "labels"
pv.Render(s.view)
with_labels = s.capture(os.path.join(out, "path-traced-labels.png")).astype(np.float64)


def blueness(image):
    lit = silhouette(image)
    return float(image[lit, 2].mean() / max(1e-6, image[lit, 1].mean()))


check(blueness(with_labels) > 1.5 * blueness(plain),
      "a label-map array colours its label in the default label colour (blue/green %.2f, without %.2f)"
      % (blueness(with_labels), blueness(plain)))

if failures:
    sys.exit("%d check(s) failed" % len(failures))
