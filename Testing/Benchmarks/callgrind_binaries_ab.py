#!/usr/bin/env python3
"""Instructions of the render part of two builds of mmrtm-render, A and B, on
the five reference scenes of Testing/Accuracy (mmrtm_accuracy.SCENES), and
whether their images are the same to the bit.

callgrind counts the same instructions for the same binary and input
whatever else the machine does, so this measures a change that makes
samples cheaper without the timing noise of a shared machine (use
bench_binaries_ab.py for the time). Only the render part is counted
(`--toggle-collect` on the CPU renderer's worker), not loading and the grid
build; one thread, shadow scale 1.

    .venv/bin/python Testing/Benchmarks/callgrind_binaries_ab.py A/bin/mmrtm-render B/bin/mmrtm-render \\
        [--size 48] [--spp 8] [--a-option=--simd --a-option=off] [--only NAME ...]

Needs valgrind and the shared data (MMRTM_SHARED_DATA_DIR or ../shared/data).
Takes about five minutes at the defaults.
"""

import argparse
import re
import subprocess
import sys
import tempfile
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "Accuracy"))
import mmrtm_accuracy as acc  # noqa: E402

RENDER_PART = "mmrtm::CpuRenderer::RenderRanges*::{lambda(int)#1}::operator()*"


def count(binary, args, size, spp, options, image):
    """The render part's instructions, and the linear image in `image`."""
    cmd = ["valgrind", "--tool=callgrind", "--callgrind-out-file=/dev/null", f"--toggle-collect={RENDER_PART}",
           str(binary), *map(str, args), "--width", str(size), "--height", str(size), "--spp", str(spp),
           "--seed", "3", "--threads", "1", "--backend", "cpu", "--shadow-scale", "1", "--quiet",
           "--output", str(image.with_suffix(".png")), "--output-linear", str(image), *options]
    done = subprocess.run(cmd, capture_output=True, text=True)
    refs = re.search(r"I\s+refs:\s+([\d,]+)", done.stderr)
    if done.returncode != 0 or not refs:
        sys.exit(f"{' '.join(cmd)} failed ({done.returncode}):\n{done.stderr[-2000:]}")
    return int(refs.group(1).replace(",", ""))


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("a")
    parser.add_argument("b")
    parser.add_argument("--size", type=int, default=48)
    parser.add_argument("--spp", type=int, default=8)
    parser.add_argument("--a-option", action="append", default=[],
                        help="an option for A only (repeat for several), e.g. one B does not have")
    parser.add_argument("--b-option", action="append", default=[], help="an option for B only")
    parser.add_argument("--only", nargs="*", choices=sorted(acc.SCENES))
    args = parser.parse_args()
    print("| scene | A instructions | B instructions | B / A | images |")
    print("|---|---|---|---|---|")
    with tempfile.TemporaryDirectory() as tmp:
        for name in args.only or list(acc.SCENES):
            images = [Path(tmp) / f"{name}_{key}.pfm" for key in ("a", "b")]
            a, b = (count(binary, acc.SCENES[name]["args"], args.size, args.spp, options, image)
                    for binary, options, image in zip((args.a, args.b), (args.a_option, args.b_option), images))
            same = images[0].read_bytes() == images[1].read_bytes()
            print(f"| {acc.SCENES[name]['title']} | {a / 1e6:.1f} M | {b / 1e6:.1f} M | {b / a:.3f} | "
                  f"{'identical' if same else 'differ'} |", flush=True)


if __name__ == "__main__":
    main()
