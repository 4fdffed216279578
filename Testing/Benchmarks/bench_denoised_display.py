"""What the view shows, against time (a benchmark, not a test): the error of
the image vtkMultiMaterialVolumeMapper displays after 1, 2, 5 and 20 s with
each DenoisingMode (Off: the unbiased film; Auto; Always), on the five
reference scenes of Documentation/accuracy.md, and the interactive preview
of a drag (its frame rate and its error) with and without denoising.

    MMRTM_SHARED_DATA_DIR=../shared/data Testing/headless.sh 1024x768x24 \\
        .venv-vtk96/bin/python Testing/Benchmarks/bench_denoised_display.py \\
        [--size 256] [--seconds 20] [--only NAME ...] --json out.json
    .venv/bin/python Testing/Benchmarks/bench_denoised_display.py --chart out.json out.png

(The VTK 9.6 venv has numpy and the mmrtm wheel the tests build; the
chart is drawn with the accuracy venv's matplotlib.)

Each scene goes through the mapper as a user's script makes it: the volume
(and label map) read, the scene's preset or scene file as a
vtkMultiMaterialProperty, a 256 x 256 window, the mapper's defaults (4
samples a render, synchronous refinement) but the mode and no sample
limit. A render loop runs for the time given; after every render the image
the frame showed (GetDisplayedImage) is kept with the time it was drawn,
and at each mark the last frame drawn before it is compared with a
reference of the same view: the mapper's own film of 1024 samples (another
seed), its variance taken out (the relative RMS error of
Testing/Accuracy/mmrtm_accuracy.py). The drag: the head CT in a window of
the browser test's 3D view size, the interactor's update rate set as a
drag sets it, frames timed at a camera after the preview's resolution has
settled, and the preview's error against a reference at that camera.
"""
import argparse
import json
import os
import sys
import time

import numpy as np

if "--chart" not in sys.argv:
    from vtkmodules.vtkCommonDataModel import vtkImageData
    from vtkmodules.vtkRenderingCore import (vtkRenderer, vtkRenderWindow, vtkVolume, vtkVolumeProperty,
                                             vtkWindowToImageFilter)
    import vtkmodules.vtkRenderingOpenGL2  # noqa: F401  (the OpenGL render window)
    import vtkmodules.vtkRenderingVolumeOpenGL2  # noqa: F401  (the image display helper)
    from vtkmodules.util.numpy_support import vtk_to_numpy

    from mmrtm import vtkMultiMaterialProperty, vtkMultiMaterialVolumeMapper, vtkMultiMaterialVolumeReader

ROOT = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..")
DATA = os.environ.get("MMRTM_SHARED_DATA_DIR", os.path.join(ROOT, "..", "shared", "data"))
MODES = {"Off": 0, "Auto": 1, "Always": 2}
MARKS = (1.0, 2.0, 5.0, 20.0)
REFERENCE_SPP = 1024


def reference_scenes():
    with open(os.path.join(ROOT, "Testing", "Accuracy", "reference_scenes.json")) as f:
        return {name: s for name, s in json.load(f).items() if not name.startswith("_")}


class View:
    """One scene in one window, through a mapper of a given mode."""

    def __init__(self, scene, size):
        self.reader = vtkMultiMaterialVolumeReader()
        self.reader.SetFileName(os.path.join(DATA, scene["volume"]))
        self.reader.Update()
        self.labels = None
        if "labels" in scene:
            self.labels = vtkMultiMaterialVolumeReader()
            self.labels.SetFileName(os.path.join(DATA, scene["labels"]))
            self.labels.Update()
        self.materials = vtkMultiMaterialProperty()
        if "preset" in scene:
            self.materials.SetPreset(scene["preset"])
        else:
            self.materials.SetSceneFile(os.path.join(ROOT, scene["scene"]))
        self.volume = vtkVolume()
        self.volume.SetProperty(vtkVolumeProperty())
        self.renderer = vtkRenderer()
        self.renderer.AddVolume(self.volume)
        self.window = vtkRenderWindow()
        self.window.SetOffScreenRendering(1)
        self.window.AddRenderer(self.renderer)
        self.window.SetSize(*size)
        self.volume.SetMapper(self.mapper(0))
        camera = self.renderer.GetActiveCamera()
        camera.SetPosition(0, -1, 0)  # from the front (anterior is -y in LPS), head up
        camera.SetFocalPoint(0, 0, 0)
        camera.SetViewUp(0, 0, 1)
        self.renderer.ResetCamera()

    def mapper(self, mode, seed=0):
        m = vtkMultiMaterialVolumeMapper()
        m.SetInputData(self.reader.GetOutput())
        if self.labels:
            m.SetMaskInput(self.labels.GetOutput())
            m.SetMaskTypeToLabelMap()
        m.SetMultiMaterialProperty(self.materials)
        m.SetMaximumSamples(0)
        m.SetSeed(seed)
        m.SetDenoisingMode(mode)
        return m

    def use(self, mapper):
        self.volume.SetMapper(mapper)
        return mapper


def displayed(mapper):
    image = vtkImageData()
    mapper.GetDisplayedImage(image)
    return vtk_to_numpy(image.GetPointData().GetScalars())[:, :3].astype(np.float64)


def relative_error(image, reference, reference_variance):
    squared = max(0.0, float(np.mean((image - reference) ** 2)) - reference_variance)
    return float(np.sqrt(squared) / np.mean(reference))


def reference_of(view, spp=REFERENCE_SPP):
    """The mapper's film of `spp` samples at the view's camera (another
    seed), and the mean variance of its pixels' channels."""
    m = view.use(view.mapper(0, seed=1000003))
    m.SetSamplesPerRender(64)
    m.SetMaximumSamples(spp)
    while not m.IsConverged():
        view.window.Render()
    image = displayed(m)
    # The film's relative noise is of its luminance; its square times the
    # mean's square stands for the channels' mean variance.
    variance = (m.GetRelativeNoise() * np.mean(image)) ** 2
    return image, variance


def timeline(view, mode, seconds):
    """(time, samples, shown denoised, image) of every frame of `seconds`
    of rendering."""
    m = view.use(view.mapper(MODES[mode]))
    frames = []
    start = time.perf_counter()
    while True:
        view.window.Render()
        now = time.perf_counter() - start
        frames.append((now, m.GetAccumulatedSamples(), m.IsDenoisedImageShown(), displayed(m)))
        if now >= seconds:
            return frames, m


def measure_scene(name, scene, size, seconds):
    view = View(scene, (size, size))
    reference, variance = reference_of(view)
    rows = {}
    for mode in MODES:
        frames, m = timeline(view, mode, seconds)
        curve = [(t, n, d, relative_error(image, reference, variance)) for t, n, d, image in frames]
        marks = []
        for mark in MARKS:
            shown = [c for c in curve if c[0] <= mark]
            t, n, d, e = shown[-1] if shown else (mark, 0, False, float("nan"))
            marks.append({"seconds": mark, "samples": n, "denoised": d, "rel_rmse": e})
        rows[mode] = {"curve": curve, "marks": marks, "denoises": m.GetNumberOfDenoises(),
                      "denoise_seconds": m.GetDenoisingSeconds(), "status": m.GetDisplayStatus()}
        print("%-13s %-6s " % (name, mode) + "  ".join(
            "%4.0f s: %4d spp %s %.4f" % (k["seconds"], k["samples"], "D" if k["denoised"] else "U", k["rel_rmse"])
            for k in marks) + "   denoising %.1f s of %.0f s (%d runs)"
            % (rows[mode]["denoise_seconds"], seconds, rows[mode]["denoises"]), flush=True)
    return rows


def measure_drag(size, frames=12):
    """The head CT's interactive preview: frames at a camera once the
    preview's resolution has settled, with and without denoising."""
    scene = reference_scenes()["head_ct_bone"]
    view = View(scene, size)
    results = {}
    for azimuth in (20, 40):
        view.renderer.GetActiveCamera().Azimuth(azimuth)
        reference, variance = reference_of(view, 256)
        for mode in ("Off", "Auto"):
            m = view.use(view.mapper(MODES[mode]))
            view.window.Render()  # the scene built and a still pass: not a drag's cost
            view.window.SetDesiredUpdateRate(15.0)  # as vtkRenderWindowInteractor sets it while the camera moves
            times = []
            for i in range(frames):
                start = time.perf_counter()
                view.window.Render()
                times.append(time.perf_counter() - start)
            film = [0, 0]
            m.GetLastFilmSize(film)
            # The preview is drawn stretched over the window: compared at the
            # window's size, read back from the frame buffer.
            grab = vtkWindowToImageFilter()
            grab.SetInput(view.window)
            grab.SetInputBufferTypeToRGB()
            grab.ReadFrontBufferOff()
            grab.Update()
            frame = vtk_to_numpy(grab.GetOutput().GetPointData().GetScalars()).astype(np.float64) / 255.0
            view.window.SetDesiredUpdateRate(0.0001)
            results.setdefault(mode, []).append({"azimuth": azimuth, "frame_seconds": float(np.median(times[4:])),
                                                 "film": list(film), "frame": frame})
        # The reference drawn as the still frame draws it (tone mapped, over the background).
        m = view.use(view.mapper(0, seed=1000003))
        m.SetSamplesPerRender(64)
        m.SetMaximumSamples(256)
        while not m.IsConverged():
            view.window.Render()
        grab = vtkWindowToImageFilter()
        grab.SetInput(view.window)
        grab.SetInputBufferTypeToRGB()
        grab.ReadFrontBufferOff()
        grab.Update()
        still = vtk_to_numpy(grab.GetOutput().GetPointData().GetScalars()).astype(np.float64) / 255.0
        for mode in ("Off", "Auto"):
            r = results[mode][-1]
            r["rms_levels"] = float(255 * np.sqrt(np.mean((r.pop("frame") - still) ** 2)))
            print("drag %-4s azimuth %d: %.1f frames a second (preview %d x %d), RMS difference from the still "
                  "image %.1f levels" % (mode, azimuth, 1 / r["frame_seconds"], r["film"][0], r["film"][1],
                                         r["rms_levels"]), flush=True)
    return results


def table(results):
    """Markdown: per scene and display, at each mark the samples, what was
    shown (D denoised, U the film) and its error; the denoiser's share."""
    lines = ["| scene | display | " + " | ".join("%g s" % m for m in MARKS) + " | denoising |",
             "|---|---|" + "---|" * len(MARKS) + "---|"]
    for name, rows in results.items():
        for mode, row in rows.items():
            cells = ["%d spp, %s %.3f" % (k["samples"], "D" if k["denoised"] else "U", k["rel_rmse"])
                     if k["samples"] else "(no frame yet)" for k in row["marks"]]
            lines.append("| %s | %s | %s | %.1f s (%d runs) |" % (name, mode, " | ".join(cells),
                                                                  row["denoise_seconds"], row["denoises"]))
    return "\n".join(lines)


def chart(results, path):
    """Error against time, a panel a scene (results as --json writes them)."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    names = list(results)
    fig, axes = plt.subplots(1, len(names), figsize=(3.2 * len(names), 3.2), squeeze=False)
    colours = {"Off": "tab:green", "Auto": "tab:blue", "Always": "tab:red"}
    for ax, name in zip(axes[0], names):
        for mode, row in results[name].items():
            t = [c[0] for c in row["curve"]]
            e = [c[3] for c in row["curve"]]
            ax.plot(t, e, color=colours[mode], lw=1.2, label=mode, ls="--" if mode == "Always" else "-")
            ax.plot([k["seconds"] for k in row["marks"]], [k["rel_rmse"] for k in row["marks"]], "o",
                    color=colours[mode], ms=3)
        ax.set_xscale("log")
        ax.set_yscale("log")
        ax.set_xlabel("seconds")
        ax.set_title(name, fontsize=9)
        ax.grid(True, which="both", lw=0.3)
    axes[0][0].set_ylabel("relative RMSE of the image shown")
    axes[0][0].legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(path, dpi=110)


def main():
    parser = argparse.ArgumentParser()
    parser.add_argument("--size", type=int, default=256)
    parser.add_argument("--seconds", type=float, default=20.0)
    parser.add_argument("--only", nargs="*", help="these reference scenes")
    parser.add_argument("--drag-size", default="880x700", help="the drag's window (the browser test's 3D view)")
    parser.add_argument("--no-drag", action="store_true")
    parser.add_argument("--json", help="write the figures here too")
    parser.add_argument("--chart", nargs=2, metavar=("JSON", "PNG"),
                        help="only draw the chart of a --json run")
    args = parser.parse_args()
    if args.chart:
        with open(args.chart[0]) as f:
            scenes = json.load(f)["scenes"]
        chart(scenes, args.chart[1])
        print(table(scenes))
        return
    scenes = reference_scenes()
    results = {}
    for name in args.only or scenes:
        results[name] = measure_scene(name, scenes[name], args.size, args.seconds)
    drag = None if args.no_drag else measure_drag(tuple(int(v) for v in args.drag_size.split("x")))
    if args.json:
        with open(args.json, "w") as out:
            json.dump({"scenes": {n: {m: {k: v for k, v in r.items() if k != "curve"} | {
                "curve": [c[:4] for c in r["curve"]]} for m, r in rows.items()} for n, rows in results.items()},
                "drag": drag}, out, indent=1)


if __name__ == "__main__":
    sys.exit(main())
