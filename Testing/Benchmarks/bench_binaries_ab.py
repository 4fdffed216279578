#!/usr/bin/env python3
"""Two builds of mmrtm-render, A and B, on the five reference scenes of
Testing/Accuracy (mmrtm_accuracy.SCENES), taking turns so that the machine's
noise falls on both alike: the median render time of each, their ratio, and
the counters per sample that say where a difference comes from (majorant
segments, density lookups) with the relative noise, which must agree for a
change that only makes samples cheaper.

    .venv/bin/python Testing/Benchmarks/bench_binaries_ab.py A/bin/mmrtm-render B/bin/mmrtm-render \\
        [--size 128] [--spp 32] [--repeats 3] [--only NAME ...] [--b-option=--sampler --b-option=independent]
        [--a-option=...]
        [--references]

Needs the shared data (MMRTM_SHARED_DATA_DIR or ../shared/data). With
--references, also the references of make_references.py: the renders are
then 256 x 256 (their size), with seeds 11 and 12 in turn, and the table
adds each build's error against the reference (the root mean square of the
two seeds' relative RMSE) and the efficiency of B over A (the ratio of
time x squared error), for a change that alters the noise as well as the time.
"""

import argparse
import statistics
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "Accuracy"))
import mmrtm_accuracy as acc  # noqa: E402


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("a")
    parser.add_argument("b")
    parser.add_argument("--size", type=int, default=128)
    parser.add_argument("--spp", type=int, default=32)
    parser.add_argument("--repeats", type=int, default=3)
    parser.add_argument("--only", nargs="*", choices=sorted(acc.SCENES))
    parser.add_argument("--a-option", action="append", default=[],
                        help="an option for A only (repeat for several), e.g. one B does not have")
    parser.add_argument("--b-option", action="append", default=[],
                        help="an option for B only (repeat for several), e.g. one A does not have")
    parser.add_argument("--references", action="store_true",
                        help="256 x 256, seeds 11 and 12, and the error against make_references.py's references")
    args = parser.parse_args()
    size, seeds = (acc.REFERENCE_SIZE, (11, 12)) if args.references else (args.size, (3,))
    extra = " rel. error, A / B | efficiency of B |" if args.references else ""
    print("| scene | A s | B s | A / B | segments per sample, A / B | lookups per sample, A / B | relative noise, A / B |"
          + extra)
    print("|---|---|---|---|---|---|---|" + ("---|---|" if args.references else ""))
    for name in args.only or list(acc.SCENES):
        if args.references:
            ref = acc.read_pfm(acc.REFERENCE_DIR / f"{name}.pfm")
            ref_variance = acc.read_pfm(acc.REFERENCE_DIR / f"{name}_variance.pfm")
        times, stats, squared = {"a": [], "b": []}, {}, {"a": [], "b": []}
        for repeat in range(args.repeats):
            for seed in seeds:
                for key in ("a", "b"):
                    r = acc.render(acc.SCENES[name]["args"], size, size, args.spp, seed=seed,
                                   extra=["--shadow-scale", "1", *(args.b_option if key == "b" else args.a_option)],
                                   binary=getattr(args, key))
                    times[key].append(r.seconds)
                    stats[key] = r.stats
                    if args.references and repeat == 0:  # the same image every repeat
                        squared[key].append(acc.relative_rmse(r.mean, ref, ref_variance) ** 2)
        ta, tb = statistics.median(times["a"]), statistics.median(times["b"])
        per = lambda key, counter: stats[key][counter] / stats[key]["samples"]  # noqa: E731
        row = (f"| {acc.SCENES[name]['title']} | {ta:.2f} | {tb:.2f} | {ta / tb:.2f} | "
               f"{per('a', 'majorant_segments'):.1f} / {per('b', 'majorant_segments'):.1f} | "
               f"{per('a', 'density_lookups'):.2f} / {per('b', 'density_lookups'):.2f} | "
               f"{stats['a']['noise']['relative']:.4f} / {stats['b']['noise']['relative']:.4f} |")
        if args.references:
            ea, eb = statistics.mean(squared["a"]), statistics.mean(squared["b"])
            row += f" {ea ** 0.5:.4f} / {eb ** 0.5:.4f} | {ta * ea / (tb * eb):.2f} |"
        print(row, flush=True)


if __name__ == "__main__":
    main()
