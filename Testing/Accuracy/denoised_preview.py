#!/usr/bin/env python3
"""The denoised preview (mmrtm-render --denoised-preview) against the
unbiased image: relative RMSE against the references as a function of time,
on the five reference scenes.

    Testing/Accuracy/denoised_preview.py [--max-spp 64] [--only NAME ...]

Needs the references of make_references.py (256 x 256). For each samples per
pixel of 1, 2, 4 ... --max-spp, one render writes both the unbiased image
and its preview denoised on colour only (the default); a second render adds
the guide of 16 first-hit feature samples per pixel (--preview-features 16).
The unbiased image's time is its render time; a preview's adds the feature
pass and the denoiser. The preview is biased: its error stops falling where
the denoiser's blur dominates, which the chart shows.

Writes Documentation/images/denoised_preview.png (error against time),
Documentation/images/denoised_preview_images.png (what the head CT and the
bonsai look like at 4 spp, denoised, at 64 spp, and the reference) and the
numbers to MMRTM_REFERENCE_DIR/denoised_preview.json; prints a Markdown table.
"""

import argparse
import json
import tempfile
from pathlib import Path

import matplotlib
import numpy as np

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

import mmrtm_accuracy as acc  # noqa: E402

SEED = 11  # as time_to_error.py: not the references' seed
VARIANTS = [
    # label, extra options, colour, line style
    ("unbiased (default)", None, "tab:green", "-"),
    ("denoised preview, colour only", [], "tab:red", "--"),
    ("denoised preview, 16 feature spp", ["--preview-features", "16"], "tab:purple", "--"),
]


def measure(name, max_spp, keep):
    ref_mean, ref_var, _ = acc.load_reference(name)
    size = ref_mean.shape[0]
    rows = {label: [] for label, _, _, _ in VARIANTS}
    for spp in [s for s in (1, 2, 4, 8, 16, 32, 64, 128) if s <= max_spp]:
        for label, options, _, _ in VARIANTS[1:]:
            preview = keep / f"{name}_{spp}_{len(options)}.pfm"
            r = acc.render(acc.SCENES[name]["args"], size, size, spp, seed=SEED,
                           extra=["--shadow-scale", "1", "--denoised-preview", str(preview), *options],
                           keep=str(keep / f"{name}_{spp}") if not options else None)
            p = r.stats["denoised_preview"]
            seconds = r.seconds + p["seconds"]["features"] + p["seconds"]["denoise"]
            rows[label].append({"spp": spp, "seconds": seconds, "denoise_seconds": p["seconds"]["denoise"],
                                "feature_seconds": p["seconds"]["features"],
                                "rel_rmse": acc.relative_rmse(acc.read_pfm(preview), ref_mean, ref_var)})
            if not options:  # the unbiased image of the same render
                rows[VARIANTS[0][0]].append({"spp": spp, "seconds": r.seconds,
                                             "rel_rmse": acc.relative_rmse(r.mean, ref_mean, ref_var)})
        line = "  ".join(f"{label.split(',')[-1].strip()} {rows[label][-1]['rel_rmse']:.4f} "
                         f"({rows[label][-1]['seconds']:.2f} s)" for label, _, _, _ in VARIANTS)
        print(f"  {name:13s} {spp:3d} spp  {line}", flush=True)
    return rows


def first_reaching(rows, target):
    """The first measured row whose error is at most `target`, or None."""
    return next((r for r in rows if r["rel_rmse"] <= target), None)


def table(results):
    """Markdown: per scene, the unbiased 64-spp error and time, and the
    preview's first measured time at or below that error."""
    lines = ["| scene | unbiased, last rung: spp, s, rel. RMSE | preview reaching that error first | "
             "its time | speed-up | the preview's lowest error |", "|---|---|---|---|---|---|"]
    for name, rows in results.items():
        last = rows[VARIANTS[0][0]][-1]
        best = None
        for label, _, _, _ in VARIANTS[1:]:
            r = first_reaching(rows[label], last["rel_rmse"])
            if r is not None and (best is None or r["seconds"] < best[1]):
                best = (f"{label.split(', ')[-1]}, {r['spp']} spp", r["seconds"])
        lowest = min(r["rel_rmse"] for label, _, _, _ in VARIANTS[1:] for r in rows[label])
        reach = (best[0], f"{best[1]:.2f} s", f"{last['seconds'] / best[1]:.1f}") if best else ("none", "", "")
        lines.append(f"| {acc.SCENES[name]['title']} | {last['spp']}, {last['seconds']:.2f} s, {last['rel_rmse']:.4f} | "
                     f"{reach[0]} | {reach[1]} | {reach[2]} | {lowest:.4f} |")
    return "\n".join(lines)


def chart(results, path):
    names = list(results)
    fig, axes = plt.subplots(1, len(names), figsize=(4.2 * len(names), 4), squeeze=False)
    for ax, name in zip(axes[0], names):
        for label, _, colour, style in VARIANTS:
            rows = results[name][label]
            ax.loglog([r["seconds"] for r in rows], [r["rel_rmse"] for r in rows], style, color=colour, marker="o",
                      ms=3, label=label)
        ax.set_title(acc.SCENES[name]["title"], fontsize=9)
        ax.set_xlabel("seconds (render + features + denoising), 2 cores")
        ax.grid(True, which="both", lw=0.3)
    axes[0][0].set_ylabel("relative RMSE against the reference")
    axes[0][0].legend(fontsize=7, loc="lower left")
    fig.suptitle("Denoised preview (biased) against the unbiased image, 1 to 64 spp, 256 x 256")
    fig.tight_layout()
    fig.savefig(path, dpi=100)
    plt.close(fig)


def tone(image):
    return np.clip(image / (1 + image), 0, 1) ** (1 / 2.2)


def images(keep, names, path):
    fig, axes = plt.subplots(len(names), 4, figsize=(12, 3.1 * len(names)), squeeze=False)
    for row, name in zip(axes, names):
        panels = [("4 spp, unbiased", acc.read_pfm(keep / f"{name}_4.pfm")),
                  ("4 spp, denoised preview", acc.read_pfm(keep / f"{name}_4_0.pfm")),
                  ("64 spp, unbiased", acc.read_pfm(keep / f"{name}_64.pfm")),
                  ("reference (2048 spp)", acc.load_reference(name)[0])]
        for ax, (title, image) in zip(row, panels):
            ax.imshow(tone(image)[32:224, 32:224])
            ax.set_title(f"{acc.SCENES[name]['title'].split(',')[0]}: {title}", fontsize=8)
            ax.axis("off")
    fig.tight_layout()
    fig.savefig(path, dpi=90)
    plt.close(fig)


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--max-spp", type=int, default=64)
    parser.add_argument("--only", nargs="*", choices=sorted(acc.SCENES))
    args = parser.parse_args()
    names = args.only or list(acc.SCENES)
    for name in names:
        if acc.load_reference(name) is None:
            raise SystemExit(f"no reference for {name} in {acc.REFERENCE_DIR}: run make_references.py first")
    results = {}
    with tempfile.TemporaryDirectory() as tmp:
        keep = Path(tmp)
        for name in names:
            results[name] = measure(name, args.max_spp, keep)
        (acc.REFERENCE_DIR / "denoised_preview.json").write_text(json.dumps(results, indent=1))
        chart(results, acc.DOC_IMAGES / "denoised_preview.png")
        shown = [n for n in ("head_ct_bone", "bonsai") if n in names]
        if shown and args.max_spp >= 64:
            images(keep, shown, acc.DOC_IMAGES / "denoised_preview_images.png")
    print(table(results))


if __name__ == "__main__":
    main()
