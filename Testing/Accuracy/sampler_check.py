#!/usr/bin/env python3
"""The Sobol' sampler against independent random numbers, on the five
reference scenes: error at equal samples, time per sample, and the time to
an equal error.

    Testing/Accuracy/sampler_check.py [--spp 16 64] [--seeds 11 12 13] [--only NAME ...]

Needs the references of make_references.py (256 x 256). Error: the relative
RMSE against the reference (its own variance subtracted), over `--seeds`
renders of 256 x 256 at each `--spp` (root mean square over the seeds);
shadow scale 1 (unbiased), as the references. Time: 128 x 128, 32 spp, one
thread, the two samplers in turns four times, median (the machine is
shared: turns put its noise on both alike). Both samplers are unbiased, so
the time to an equal error scales as time x error^2: the speed-up is
(e_independent / e_sobol)^2 / (t_sobol / t_independent).
"""

import argparse
import statistics

import numpy as np

import mmrtm_accuracy as acc

SAMPLERS = ("independent", "sobol")


def errors(name, ref, spp, seeds):
    out = {}
    for sampler in SAMPLERS:
        e = [acc.relative_rmse(acc.render(acc.SCENES[name]["args"], 256, 256, spp, seed=seed,
                                          extra=["--shadow-scale", "1", "--sampler", sampler]).mean, ref[0], ref[1])
             for seed in seeds]
        out[sampler] = float(np.sqrt(np.mean(np.square(e))))
    return out


def seconds_per_render(name, turns=4):
    times = {s: [] for s in SAMPLERS}
    for _ in range(turns):
        for sampler in SAMPLERS:
            r = acc.render(acc.SCENES[name]["args"], 128, 128, 32, extra=["--threads", "1", "--sampler", sampler])
            times[sampler].append(r.seconds)
    return {s: statistics.median(t) for s, t in times.items()}


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--spp", type=int, nargs="+", default=[16, 64])
    parser.add_argument("--seeds", type=int, nargs="+", default=[11, 12, 13])
    parser.add_argument("--only", nargs="*", choices=sorted(acc.SCENES))
    args = parser.parse_args()
    header = " | ".join(f"error {spp} spp: indep. / Sobol' (ratio^2)" for spp in args.spp)
    lines = [f"| scene | {header} | time: indep. / Sobol' | speed-up at {args.spp[-1]} spp |",
             "|---|" + "---|" * len(args.spp) + "---|---|"]
    for name in args.only or list(acc.SCENES):
        ref = acc.load_reference(name)
        if ref is None:
            raise SystemExit(f"no reference for {name} in {acc.REFERENCE_DIR}: run make_references.py first")
        cells, ratio = [], 1.0
        for spp in args.spp:
            e = errors(name, ref, spp, args.seeds)
            ratio = (e["independent"] / e["sobol"]) ** 2
            cells.append(f"{e['independent']:.4f} / {e['sobol']:.4f} ({ratio:.2f})")
        t = seconds_per_render(name)
        cost = t["sobol"] / t["independent"]
        lines.append(f"| {acc.SCENES[name]['title']} | {' | '.join(cells)} | {t['independent']:.3f} s / "
                     f"{t['sobol']:.3f} s ({cost:.3f}) | {ratio / cost:.2f} |")
        print(lines[-1], flush=True)
    print("\n".join(lines))


if __name__ == "__main__":
    main()
