#!/usr/bin/env python3
"""How the denoised display denoises, measured: the denoiser's guides and
quality, and Auto's estimate, on the five reference scenes.

    Testing/Accuracy/denoise_guides.py [--only NAME ...] [--spp 1 2 4 8 16 32 64] [--json FILE]
    Testing/Accuracy/denoise_guides.py --timing     # the filters' times at three sizes (a minute)

Needs the references of make_references.py (256 x 256) and the pyoidn
wheel of .venv. Per scene and sample count, one render (seed 11, unbiased
shadows) writes the film and the denoiser's inputs (mmrtm-render
--output-denoiser-inputs: the even and odd halves, the first-hit albedo
and normal of all samples and of each half). Open Image Denoise then
denoises the film's colour

- alone ("colour");
- with the raw guides ("raw guides");
- with the albedo alone, denoised first ("albedo, clean");
- with the albedo and the normal, denoised first, as clean guides (OIDN's
  cleanAux): what the display does ("guides, clean"), at each of OIDN's
  qualities (high, balanced: the display's, fast);
- with the raw guides of a separate pass of 16 camera rays a pixel to
  their first collision (another seed, --max-bounces 0: the feature pass
  the command line had before the guides were gathered with the samples),
  whose time is given beside the render's ("feature pass");

and, for Auto's estimate, the even half with its own clean guides and with
the whole film's: each one's error against the reference next to the
estimate the display makes of it (against the odd half). Prints the
relative RMS errors (Testing/Accuracy/mmrtm_accuracy.py's measure) as
Markdown tables: Documentation/denoising.md's.
"""

import argparse
import json
import os
import tempfile

import numpy as np

import mmrtm_accuracy as acc

SEED = 11  # as time_to_error.py: not the references' seed
QUALITIES = ("high", "balanced", "fast")


class Oidn:
    """Open Image Denoise through pyoidn's filters: a filter per inputs and
    quality, kept, as the display keeps them."""

    def __init__(self):
        from pyoidn.device import Device
        from pyoidn.filter import OIDN_FORMAT_FLOAT3, Filter
        self.Filter, self.float3 = Filter, OIDN_FORMAT_FLOAT3
        self.device = Device()
        self.device.commit()
        self.filters = {}

    def run(self, inputs, quality="balanced", clean=False):
        """inputs: {"color" | "albedo" | "normal": float32 (h, w, 3)}."""
        key = (tuple(sorted(inputs)), next(iter(inputs.values())).shape, quality, clean)
        if key not in self.filters:
            f = self.Filter(self.device, "RT")
            if "color" in inputs:
                f.set_bool("hdr", True)
            if clean:
                f.set_bool("cleanAux", True)
            f.set_quality({"high": 6, "balanced": 5, "fast": 4}[quality])
            self.filters[key] = f
        f = self.filters[key]
        out = np.zeros_like(next(iter(inputs.values())), dtype=np.float32)
        kept = {name: np.ascontiguousarray(image, dtype=np.float32) for name, image in inputs.items()}
        for name, image in kept.items():
            f.set_image(name, image, self.float3)
        f.set_image("output", out, self.float3)
        f.commit()
        f.execute()
        return out

    def guided(self, color, albedo, normal=None, quality="balanced"):
        clean_albedo = self.run({"albedo": albedo}, quality)
        inputs = {"color": color, "albedo": clean_albedo}
        if normal is not None:
            inputs["normal"] = self.run({"normal": normal}, quality)
        return self.run(inputs, quality, clean=True)


def estimate(denoised_half, a, b, n0, n):
    """The display's bound of the denoised half's squared error
    (denoised_display.cpp): the mean of (D(A) - B)^2 - (A - B)^2 n0 / n,
    plus two standard errors over the pixels."""
    terms = ((denoised_half - b) ** 2 - (a - b) ** 2 * n0 / n).mean(axis=2).ravel()
    return max(0.0, terms.mean() + 2 * terms.std(ddof=1) / np.sqrt(terms.size))


def feature_pass(name, size):
    """The albedo and normal of 16 camera rays a pixel to their first
    collision (another seed), and the seconds of that pass."""
    with tempfile.TemporaryDirectory() as tmp:
        prefix = os.path.join(tmp, "f")
        r = acc.render(acc.SCENES[name]["args"], size, size, 16, seed=SEED + 1,
                       extra=["--max-bounces", "0", "--output-denoiser-inputs", prefix])
        return (acc.read_pfm(prefix + "_albedo.pfm").astype(np.float32),
                acc.read_pfm(prefix + "_normal.pfm").astype(np.float32), r.seconds)


def measure(name, counts, oidn):
    ref, ref_var, _ = acc.load_reference(name)
    size = ref.shape[0]
    error = lambda image: acc.relative_rmse(image, ref, ref_var)  # noqa: E731
    feature_albedo, feature_normal, feature_seconds = feature_pass(name, size)
    rows = []
    for spp in counts:
        with tempfile.TemporaryDirectory() as tmp:
            prefix = os.path.join(tmp, "r")
            extra = ["--shadow-scale", "1"] + (["--output-denoiser-inputs", prefix] if spp >= 2 else [])
            r = acc.render(acc.SCENES[name]["args"], size, size, spp, seed=SEED, extra=extra)
            film = r.mean.astype(np.float32)
            row = {"spp": spp, "seconds": r.seconds, "film": error(film), "colour": error(oidn.run({"color": film})),
                   "feature pass": error(oidn.run({"color": film, "albedo": feature_albedo,
                                                   "normal": feature_normal})),
                   "feature pass seconds": feature_seconds}
            if spp >= 2:
                read = lambda s: acc.read_pfm(f"{prefix}_{s}.pfm").astype(np.float32)  # noqa: E731
                albedo, normal = read("albedo"), read("normal")
                row["raw guides"] = error(oidn.run({"color": film, "albedo": albedo, "normal": normal}))
                row["albedo, clean"] = error(oidn.guided(film, albedo))
                for quality in QUALITIES:
                    row["guides, clean, " + quality] = error(oidn.guided(film, albedo, normal, quality))
                a, b = read("color_even"), read("color_odd")
                n0, n = (spp + 1) // 2, spp
                mean = float(np.mean(ref))
                own = oidn.guided(a, read("albedo_even"), read("normal_even"))
                whole = oidn.guided(a, albedo, normal)
                row["half, own guides"] = error(own)
                row["its estimate"] = float(np.sqrt(estimate(own, a, b, n0, n)) / mean)
                row["half, whole film's guides"] = error(whole)
                row["its estimate, whole"] = float(np.sqrt(estimate(whole, a, b, n0, n)) / mean)
            rows.append(row)
            print(f"{name:13s} {spp:3d} spp  " + "  ".join(f"{k} {v:.4f}" for k, v in row.items() if k != "spp"),
                  flush=True)
    return rows


def tables(results):
    columns = ["film", "colour", "raw guides", "feature pass", "albedo, clean"] + [
        "guides, clean, " + q for q in QUALITIES]
    lines = ["| scene | spp (render s; feature pass s) | " + " | ".join(columns) + " |",
             "|---|---|" + "---|" * len(columns)]
    for name, rows in results.items():
        for r in rows:
            lines.append(f"| {acc.SCENES[name]['title']} | {r['spp']} ({r['seconds']:.2f}; "
                         f"{r['feature pass seconds']:.2f}) | " +
                         " | ".join(f"{r[c]:.4f}" if c in r else "" for c in columns) + " |")
    columns = ["half, own guides", "its estimate", "half, whole film's guides", "its estimate, whole"]
    lines += ["", "| scene | spp | " + " | ".join(columns) + " |", "|---|---|" + "---|" * len(columns)]
    for name, rows in results.items():
        for r in rows:
            if "its estimate" in r:
                lines.append(f"| {acc.SCENES[name]['title']} | {r['spp']} | " +
                             " | ".join(f"{r[c]:.4f}" for c in columns) + " |")
    return "\n".join(lines)


def timing(oidn, repeats=3):
    """Seconds of one run of each filter the display runs (the filter kept,
    the best of `repeats`), at 256 x 256, 512 x 512 and 1024 x 768, and what
    a denoise and one with Auto's estimate add up to."""
    import time
    rng = np.random.default_rng(1)
    print("| image | quality | colour alone | a guide | colour, clean guides | a denoise | with Auto's estimate |")
    print("|---|---|---|---|---|---|---|")
    for width, height in ((256, 256), (512, 512), (1024, 768)):
        image = lambda: rng.random((height, width, 3), dtype=np.float32)  # noqa: E731
        for quality in QUALITIES:
            def best(inputs, clean=False):
                oidn.run(inputs, quality, clean)  # the filter made and committed once
                runs = []
                for _ in range(repeats):
                    start = time.perf_counter()
                    oidn.run(inputs, quality, clean)
                    runs.append(time.perf_counter() - start)
                return min(runs)
            colour = best({"color": image()})
            guide = best({"albedo": image()})
            guided = best({"color": image(), "albedo": image(), "normal": image()}, clean=True)
            # A denoise: two guides, the colour with them, the coverage
            # (colour alone); the estimate: the half's two guides and colour.
            denoise = 2 * guide + guided + colour
            print(f"| {width} x {height} | {quality} | {colour:.2f} s | {guide:.2f} s | {guided:.2f} s | "
                  f"{denoise:.2f} s | {denoise + 2 * guide + guided:.2f} s |", flush=True)


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--only", nargs="*", choices=sorted(acc.SCENES))
    parser.add_argument("--spp", nargs="*", type=int, default=[1, 2, 4, 8, 16, 32, 64])
    parser.add_argument("--json", help="write the figures here too")
    parser.add_argument("--timing", action="store_true", help="only the filters' times")
    args = parser.parse_args()
    oidn = Oidn()
    if args.timing:
        timing(oidn)
        return
    results = {name: measure(name, args.spp, oidn) for name in args.only or acc.SCENES}
    print(tables(results))
    if args.json:
        with open(args.json, "w") as f:
            json.dump(results, f, indent=1)


if __name__ == "__main__":
    main()
