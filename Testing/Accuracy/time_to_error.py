#!/usr/bin/env python3
"""Time to the error that 64 spp gave before issue 15, on the five reference
scenes: the renderer as it was (one light chosen uniformly, uniform
sampling, independent random numbers), with next-event estimation by
resampling, with the Sobol' sampler on top (both the default now), and with
adaptive sampling on top of that.

    Testing/Accuracy/time_to_error.py [--spp 64] [--repeats 2] [--only NAME ...]
        [--issue-binary OLD/bin/mmrtm-render]

Needs the references of make_references.py (256 x 256). Each method renders
`--spp` samples per pixel (a mean of that many with adaptive sampling); the
methods take turns, `--repeats` times, so that the machine's noise falls on
all of them alike, and the median render time counts. The error is the
relative RMSE against the reference (its own variance subtracted). Every
estimator here is unbiased, so its error falls as 1 / sqrt(time): the time
a method needs to reach the first method's error is t (e / e_before)^2.
Prints a Markdown table and writes MMRTM_REFERENCE_DIR/time_to_error.json.

With --issue-binary, a first method renders with that mmrtm-render: a build
of the commit on which issue 15 was filed (c669328), the "today" of its
goal, which lacks the option of later builds and the speed work between:

    git worktree add /tmp/issue15 c669328
    cmake -S /tmp/issue15 -B /tmp/issue15/build -DCMAKE_BUILD_TYPE=Release -DMMRTM_ENABLE_CUDA=OFF
    cmake --build /tmp/issue15/build --target mmrtm-render
    Testing/Accuracy/time_to_error.py --issue-binary /tmp/issue15/build/bin/mmrtm-render

The speed-ups are then against that first method.
"""

import argparse
import json
import statistics

import mmrtm_accuracy as acc

SEED = 11  # not the references' seed

METHODS = [
    ("before: one light chosen, uniform, independent numbers", ["--light-sampling", "one", "--sampler", "independent"]),
    ("resampled lights, independent numbers", ["--light-sampling", "resampled", "--sampler", "independent"]),
    ("resampled lights, Sobol' pairs (default)", ["--light-sampling", "resampled", "--sampler", "sobol"]),
    ("default, adaptive sampling", ["--light-sampling", "resampled", "--sampler", "sobol", "--sampling", "adaptive"]),
]


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--spp", type=int, default=64)
    parser.add_argument("--repeats", type=int, default=2)
    parser.add_argument("--only", nargs="*", choices=sorted(acc.SCENES))
    parser.add_argument("--issue-binary", help="mmrtm-render built at the commit issue 15 was filed on")
    args = parser.parse_args()
    methods = [(label, options, None) for label, options in METHODS]
    if args.issue_binary:
        methods.insert(0, ("when issue 15 was filed (c669328)", [], args.issue_binary))
    results = {}
    lines = ["| scene | method | render s | rel. RMSE | time to the first row's error | speed-up |", "|---|---|---|---|---|---|"]
    for name in args.only or list(acc.SCENES):
        ref = acc.load_reference(name)
        if ref is None:
            raise SystemExit(f"no reference for {name} in {acc.REFERENCE_DIR}: run make_references.py first")
        ref_mean, ref_var, _ = ref
        times = {label: [] for label, _, _ in methods}
        errors = {}
        # Alternating methods: the machine's noise falls on all of them alike.
        for _ in range(args.repeats):
            for label, options, binary in methods:
                r = acc.render(acc.SCENES[name]["args"], ref_mean.shape[1], ref_mean.shape[0], args.spp, seed=SEED,
                               extra=["--shadow-scale", "1", *options], binary=binary)
                times[label].append(r.seconds)
                errors[label] = acc.relative_rmse(r.mean, ref_mean, ref_var)  # the same image every repeat
        before = methods[0][0]
        t0, e0 = statistics.median(times[before]), errors[before]
        results[name] = {}
        for label, _, _ in methods:
            t, e = statistics.median(times[label]), errors[label]
            reach = t * (e / e0) ** 2
            results[name][label] = {"seconds": t, "all_seconds": times[label], "rel_rmse": e,
                                    "time_to_before_error": reach, "speedup": t0 / reach}
            lines.append(f"| {acc.SCENES[name]['title']} | {label} | {t:.2f} | {e:.4f} | {reach:.2f} s | "
                         f"{t0 / reach:.2f} |")
            print(lines[-1], flush=True)
    (acc.REFERENCE_DIR / "time_to_error.json").write_text(json.dumps(results, indent=1))
    print("\n".join(lines))


if __name__ == "__main__":
    main()
