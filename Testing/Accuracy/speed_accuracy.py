#!/usr/bin/env python3
"""Speed against accuracy: relative RMSE against render time and against
samples per pixel, for delta tracking with each accelerator and for ray
marching at several step sizes, on every reference scene.

    Testing/Accuracy/speed_accuracy.py [--max-spp N] [--only NAME ...]
        [--baseline-binary OLD/bin/mmrtm-render]

Needs the references of make_references.py. Writes
Documentation/images/speed_accuracy_NAME.png and the numbers to
MMRTM_REFERENCE_DIR/speed_accuracy.json. The reference's own variance is
subtracted from each squared error (mmrtm_accuracy.relative_rmse), and the
reference's relative noise is drawn as a dotted line. A third panel takes the
measured render's own variance out as well: what remains is its bias (about
0 for the unbiased estimators, a plateau for ray marching). Every render uses the
unbiased shadow rays (--shadow-scale 1), as the references do.

With --baseline-binary (a build of c669328, the baseline of the light
sampling and Sobol' work; time_to_error.py's help says how to build it), that renderer is drawn too,
as "before", and the table's speed-ups are against it; without it, against
today's octree with one light chosen uniformly and independent numbers.
"""

import argparse
import json

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

import mmrtm_accuracy as acc  # noqa: E402

SEED = 7  # differs from make_references.REFERENCE_SEED: independent noise
BASELINE_BUILD = "when issue 15 was filed (c669328)"  # the label stored results carry
ONE_LIGHT = "delta, octree, one light chosen, independent numbers"
DEFAULT = "delta, octree (default)"

METHODS = [
    # label, options, colour, line style
    ("delta, no accelerator", ["--accelerator", "none"], "tab:gray", "-"),
    ("delta, macrocell", ["--accelerator", "macrocell"], "tab:blue", "-"),
    (DEFAULT, ["--accelerator", "octree"], "tab:green", "-"),
    # The estimator of the baseline's next-event estimation and sampling (one
    # light chosen uniformly, independent numbers), on today's code.
    (ONE_LIGHT, ["--accelerator", "octree", "--light-sampling", "one", "--sampler", "independent"], "black", "-."),
    ("delta, octree, adaptive sampling", ["--accelerator", "octree", "--sampling", "adaptive"], "tab:cyan", "-"),
    ("delta, octree-voxelmax", ["--accelerator", "octree-voxelmax"], "tab:olive", "--"),
    ("ray marching 2 mm", ["--estimator", "raymarch", "--ray-march-step", "2"], "tab:red", ":"),
    ("ray marching 1 mm", ["--estimator", "raymarch", "--ray-march-step", "1"], "tab:orange", ":"),
    ("ray marching 0.5 mm", ["--estimator", "raymarch", "--ray-march-step", "0.5"], "tab:purple", ":"),
    ("ray marching 0.25 mm", ["--estimator", "raymarch", "--ray-march-step", "0.25"], "tab:brown", ":"),
]


def methods(baseline_binary):
    """(label, options, colour, style, binary): METHODS, and first the
    baseline build when `baseline_binary` is given (its path; the charts and
    the table pass True when stored results have it)."""
    rows = [(label, options, colour, style, None) for label, options, colour, style in METHODS]
    if baseline_binary:
        rows.insert(0, (BASELINE_BUILD, [], "magenta", "-.", baseline_binary))
    return rows


def before_label(result):
    """The method the speed-ups are against: the baseline build if it was measured."""
    for label in (BASELINE_BUILD, ONE_LIGHT, DEFAULT):
        if result["methods"].get(label):
            return label
    raise KeyError("no method to compare with")


def measure(name, max_spp, size, budget, baseline_binary=None):
    ref = acc.load_reference(name)
    if ref is None:
        raise SystemExit(f"no reference for {name} in {acc.REFERENCE_DIR}: run make_references.py first")
    ref_mean, ref_var, ref_meta = ref
    if ref_mean.shape[0] != size:
        raise SystemExit(f"reference {name} is {ref_mean.shape[1]}x{ref_mean.shape[0]}, not {size}^2")
    result = {"reference_spp": ref_meta["spp"], "reference_noise": acc.relative_noise(ref_mean, ref_var),
              "methods": {}}
    ladder = [s for s in (1, 2, 4, 8, 16, 32, 64, 128, 256, 512) if s <= max_spp]
    # Every method doubles its samples up to max_spp, or until one render would exceed the time budget.
    for label, options, _, _, binary in methods(baseline_binary):
        rows = []
        for spp in ladder:
            r = acc.render(acc.SCENES[name]["args"], size, size, spp, seed=SEED,
                           extra=["--shadow-scale", "1", *options], binary=binary)
            rows.append({"spp": spp, "seconds": r.seconds,
                         "rel_rmse": acc.relative_rmse(r.mean, ref_mean, ref_var),
                         # The render's own noise taken out as well: what is left is its bias.
                         "rel_bias": acc.relative_rmse(r.mean, ref_mean, ref_var + r.variance),
                         "noise": acc.relative_noise(r.mean, r.variance),
                         "density_lookups": r.stats["density_lookups"],
                         "real_collisions": r.stats["real_collisions"]})
            print(f"  {name:13s} {label:26s} {spp:4d} spp {r.seconds:7.2f} s  rel. RMSE {rows[-1]['rel_rmse']:.4f}",
                  flush=True)
            if r.seconds * 2 > budget:  # the next rung would take more than the budget
                break
        result["methods"][label] = rows
    return result


def chart(name, result, path):
    fig, axes = plt.subplots(1, 3, figsize=(16, 4.4))
    for label, _, colour, style, _ in methods(BASELINE_BUILD in result["methods"]):
        rows = result["methods"].get(label)
        if not rows:
            continue
        axes[0].loglog([r["seconds"] for r in rows], [r["rel_rmse"] for r in rows], style, color=colour,
                       marker="o", ms=3, label=label)
        axes[1].loglog([r["spp"] for r in rows], [r["rel_rmse"] for r in rows], style, color=colour, marker="o",
                       ms=3, label=label)
        # Per-pixel variances from fewer samples are too noisy to subtract reliably.
        biased = [r for r in rows if r["spp"] >= 8]
        axes[2].semilogx([r["spp"] for r in biased], [r["rel_bias"] for r in biased], style, color=colour,
                         marker="o", ms=3, label=label)
    for ax in axes[:2]:
        ax.axhline(result["reference_noise"], color="k", lw=0.8, ls=(0, (1, 3)),
                   label=f"reference's own noise ({result['reference_spp']} spp)")
        ax.set_ylabel("relative RMSE (reference variance subtracted)")
    for ax in axes:
        ax.grid(True, which="both", lw=0.3)
    axes[0].set_xlabel("render time, s (2 CPU cores)")
    axes[1].set_xlabel("samples per pixel")
    axes[2].set_xlabel("samples per pixel")
    axes[2].set_ylabel("relative bias (both variances subtracted)")
    axes[2].set_ylim(bottom=0)
    axes[2].set_xticks([8, 16, 32, 64], ["8", "16", "32", "64"])
    axes[2].minorticks_off()
    axes[1].legend(fontsize=7, loc="lower left")
    fig.suptitle(f"{acc.SCENES[name]['title']}: error against time and samples (256 x 256)")
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)


def table(results):
    """Markdown: per scene and method, the last measured rung, and the time each
    method needs to reach the error of the baseline renderer (its build,
    or else one light chosen uniformly and independent numbers on the octree)
    at its last rung (64 spp): t e^2 / e0^2, valid
    while the error is still falling as 1 / sqrt(samples); a method whose
    error has stopped falling above that error never reaches it."""
    lines = ["| scene | method | spp | render s | rel. RMSE | rel. bias | time to before's error | speed-up |",
             "|---|---|---|---|---|---|---|---|"]
    for name, result in results.items():
        target = result["methods"][before_label(result)][-1]
        for label, _, _, _, _ in methods(BASELINE_BUILD in result["methods"]):
            rows = result["methods"].get(label)
            if not rows:
                continue
            last = rows[-1]
            falling = len(rows) < 2 or last["rel_rmse"] < 0.85 * rows[-2]["rel_rmse"]
            seconds = last["seconds"] * (last["rel_rmse"] / target["rel_rmse"]) ** 2
            if last["rel_rmse"] <= target["rel_rmse"]:
                reach, speedup = f"{seconds:.1f} s", f"{target['seconds'] / seconds:.2f}"
            elif falling:
                reach, speedup = f"~{seconds:.0f} s", f"~{target['seconds'] / seconds:.2f}"
            else:
                reach, speedup = "never (bias)", ""
            lines.append(f"| {acc.SCENES[name]['title']} | {label} | {last['spp']} | {last['seconds']:.1f} | "
                         f"{last['rel_rmse']:.4f} | {last['rel_bias']:.4f} | {reach} | {speedup} |")
    return "\n".join(lines)


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--max-spp", type=int, default=64)
    parser.add_argument("--budget", type=float, default=30.0,
                        help="seconds: a method's samples stop doubling before one render would take longer")
    parser.add_argument("--only", nargs="*", choices=sorted(acc.SCENES))
    parser.add_argument("--charts-only", action="store_true", help="redraw from speed_accuracy.json")
    parser.add_argument("--baseline-binary", help="mmrtm-render built at the baseline commit, c669328")
    args = parser.parse_args()
    store = acc.REFERENCE_DIR / "speed_accuracy.json"
    results = json.loads(store.read_text()) if store.exists() else {}
    for name in args.only or list(acc.SCENES):
        if not args.charts_only:
            results[name] = measure(name, args.max_spp, acc.REFERENCE_SIZE, args.budget, args.baseline_binary)
            store.write_text(json.dumps(results, indent=1))
        if name in results:
            chart(name, results[name], acc.DOC_IMAGES / f"speed_accuracy_{name}.png")
            print(f"wrote {acc.DOC_IMAGES / f'speed_accuracy_{name}.png'}")
    print(table({n: results[n] for n in (args.only or list(acc.SCENES)) if n in results}))


if __name__ == "__main__":
    main()
