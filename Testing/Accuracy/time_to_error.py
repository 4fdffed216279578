#!/usr/bin/env python3
"""Time to the error that 64 spp gave at the baseline commit c669328, on the five reference
scenes, measured: the renderer as it was (one light chosen uniformly,
uniform sampling, independent random numbers), with next-event estimation
by resampling, with the Sobol' sampler on top (both the default now), and
with adaptive sampling on top of that.

    Testing/Accuracy/time_to_error.py [--spp 64] [--ladder 4,8,16,32,64,128]
        [--repeats 2] [--only NAME ...] [--baseline-binary OLD/bin/mmrtm-render]

Needs the references of make_references.py (256 x 256). The target is the
first method's relative RMSE (against the reference, its own variance
subtracted) at `--spp` samples per pixel. Every method renders a ladder of
sample counts (`--ladder`; a mean count with adaptive sampling), the
methods taking turns `--repeats` times so that the machine's noise falls on
all of them alike (the median render time counts). A method's time to the
target is read off its measured curve: between the two rungs whose errors
bracket the target, by interpolating log error against log time; "<=" marks
a target met already at the lowest rung, ">" one not met at the highest.
Nothing is extrapolated: Sobol' samples and adaptive sampling need not
follow 1 / sqrt(time), and the table gives each method's measured slope of
log error against log time (-0.5 for plain Monte Carlo) beside the
extrapolation from its 64-spp error that the table used to print.
Prints a Markdown table and writes MMRTM_REFERENCE_DIR/time_to_error.json.

With --baseline-binary, a first method renders with that mmrtm-render: a build
of the baseline commit (c669328), the "today" of its
goal, which lacks the option of later builds and the speed work between:

    git worktree add /tmp/baseline c669328
    cmake -S /tmp/baseline -B /tmp/baseline/build -DCMAKE_BUILD_TYPE=Release -DMMRTM_ENABLE_CUDA=OFF
    cmake --build /tmp/baseline/build --target mmrtm-render
    Testing/Accuracy/time_to_error.py --baseline-binary /tmp/baseline/build/bin/mmrtm-render

The speed-ups are then against that first method.
"""

import argparse
import json
import math
import statistics

import mmrtm_accuracy as acc

SEED = 11  # not the references' seed

METHODS = [
    ("before: one light chosen, uniform, independent numbers", ["--light-sampling", "one", "--sampler", "independent"]),
    ("resampled lights, independent numbers", ["--light-sampling", "resampled", "--sampler", "independent"]),
    ("resampled lights, Sobol' pairs (default)", ["--light-sampling", "resampled", "--sampler", "sobol"]),
    ("default, adaptive sampling", ["--light-sampling", "resampled", "--sampler", "sobol", "--sampling", "adaptive"]),
]


def time_to_target(points, target):
    """(seconds, marker) at which the measured curve [(seconds, error), ...],
    in ladder order, first reaches `target`: interpolated in log-log between
    the bracketing rungs; marker "<=" or ">" where the ladder does not
    bracket it."""
    for k, (t, e) in enumerate(points):
        if e <= target:
            if k == 0:
                return t, "<="
            t0, e0 = points[k - 1]
            if e == e0:
                return t, ""
            slope = (math.log(t) - math.log(t0)) / (math.log(e) - math.log(e0))
            return math.exp(math.log(t0) + (math.log(target) - math.log(e0)) * slope), ""
    return points[-1][0], ">"


def fitted_slope(points):
    """Least-squares slope of log error against log time."""
    xs = [math.log(t) for t, _ in points]
    ys = [math.log(e) for _, e in points]
    mx, my = sum(xs) / len(xs), sum(ys) / len(ys)
    sxx = sum((x - mx) ** 2 for x in xs)
    return sum((x - mx) * (y - my) for x, y in zip(xs, ys)) / sxx if sxx > 0 else float("nan")


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--spp", type=int, default=64, help="the first method's samples per pixel: the target")
    parser.add_argument("--ladder", default="4,8,16,32,64,128", help="sample counts every method renders")
    parser.add_argument("--repeats", type=int, default=2)
    parser.add_argument("--only", nargs="*", choices=sorted(acc.SCENES))
    parser.add_argument("--baseline-binary", help="mmrtm-render built at the baseline commit, c669328")
    args = parser.parse_args()
    ladder = sorted({int(v) for v in args.ladder.split(",")} | {args.spp})
    methods = [(label, options, None) for label, options in METHODS]
    if args.baseline_binary:
        methods.insert(0, ("when issue 15 was filed (c669328)", [], args.baseline_binary))  # the stored label
    results = {}
    lines = ["| scene | method | target error (the first row's at --spp) | time to it (measured) | "
             "speed-up | extrapolated from 64 spp | slope of log error / log time |",
             "|---|---|---|---|---|---|---|"]
    for name in args.only or list(acc.SCENES):
        ref = acc.load_reference(name)
        if ref is None:
            raise SystemExit(f"no reference for {name} in {acc.REFERENCE_DIR}: run make_references.py first")
        ref_mean, ref_var, _ = ref
        times = {(label, spp): [] for label, _, _ in methods for spp in ladder}
        errors = {}
        # Alternating methods: the machine's noise falls on all of them alike.
        for _ in range(args.repeats):
            for spp in ladder:
                for label, options, binary in methods:
                    r = acc.render(acc.SCENES[name]["args"], ref_mean.shape[1], ref_mean.shape[0], spp, seed=SEED,
                                   extra=["--shadow-scale", "1", *options], binary=binary)
                    times[(label, spp)].append(r.seconds)
                    errors[(label, spp)] = acc.relative_rmse(r.mean, ref_mean, ref_var)  # the same every repeat
        first = methods[0][0]
        target = errors[(first, args.spp)]
        t_first = statistics.median(times[(first, args.spp)])
        results[name] = {"target_rel_rmse": target, "first_method_seconds": t_first, "methods": {}}
        for label, _, _ in methods:
            points = [(statistics.median(times[(label, spp)]), errors[(label, spp)]) for spp in ladder]
            reach, marker = time_to_target(points, target)
            t64, e64 = statistics.median(times[(label, args.spp)]), errors[(label, args.spp)]
            extrapolated = t64 * (e64 / target) ** 2
            slope = fitted_slope(points)
            results[name]["methods"][label] = {
                "ladder": [{"spp": spp, "seconds": t, "all_seconds": times[(label, spp)], "rel_rmse": e}
                           for spp, (t, e) in zip(ladder, points)],
                "time_to_target": reach, "bound": marker, "speedup": t_first / reach,
                "extrapolated_time": extrapolated, "extrapolated_speedup": t_first / extrapolated,
                "slope": slope}
            speedup = {"<=": ">=", ">": "<", "": ""}[marker] + f"{t_first / reach:.2f}"
            lines.append(f"| {acc.SCENES[name]['title']} | {label} | {target:.4f} | {marker}{reach:.2f} s | "
                         f"{speedup} | {t_first / extrapolated:.2f} | {slope:.2f} |")
            print(lines[-1], flush=True)
    (acc.REFERENCE_DIR / "time_to_error.json").write_text(json.dumps(results, indent=1))
    print("\n".join(lines))


if __name__ == "__main__":
    main()
