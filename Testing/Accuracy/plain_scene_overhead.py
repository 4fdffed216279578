#!/usr/bin/env python3
"""No cost for features a scene does not use: the shipped renderer against a
build whose classifier hard-wires a plain scene (one proxy, one material, one
density TF), on the same plain scene.

    Testing/Accuracy/plain_scene_overhead.py [--runs N]

Runs build/bin/mmrtm-bench-plain-scene and mmrtm-bench-plain-scene-shortest
in turn (so that both see the same machine load), N times each at 256 x 256,
16 spp, and reports the median render times, their ratio, and whether the
images are bit-identical. With valgrind installed it also counts the
instructions of 2 spp at 64 x 64 (a 3-spp run minus a 1-spp run, so that
loading and set-up cancel), a measure that does not depend on the
machine's load. Numbers go to
MMRTM_REFERENCE_DIR/plain_scene_overhead.json.
"""

import argparse
import json
import re
import shutil
import statistics
import subprocess
import tempfile

import mmrtm_accuracy as acc

BENCHES = {"general": "mmrtm-bench-plain-scene", "shortest": "mmrtm-bench-plain-scene-shortest"}


def run(name, *args):
    out = subprocess.run([str(acc.BUILD / "bin" / BENCHES[name]), *args], check=True, capture_output=True, text=True)
    return json.loads(out.stdout)


def total_instructions(name, spp):
    with tempfile.TemporaryDirectory() as tmp:
        done = subprocess.run(["valgrind", "--tool=callgrind", f"--callgrind-out-file={tmp}/cg.out",
                               str(acc.BUILD / "bin" / BENCHES[name]), "--size", "64", "--spp", str(spp)],
                              capture_output=True, text=True, check=True)
        return int(re.search(r"Collected : (\d+)", done.stderr).group(1))


def instructions(name):
    # Rendering only: a 3-spp run minus a 1-spp run (loading and set-up cancel).
    return total_instructions(name, 3) - total_instructions(name, 1)


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--runs", type=int, default=7)
    args = parser.parse_args()
    seconds = {name: [] for name in BENCHES}
    checksums = {name: set() for name in BENCHES}
    for i in range(args.runs):
        for name in BENCHES:
            r = run(name, "--size", "256", "--spp", "16")
            seconds[name].append(r["seconds"])
            checksums[name].add(r["checksum"])
        print(f"run {i + 1}: general {seconds['general'][-1]:.3f} s, shortest {seconds['shortest'][-1]:.3f} s",
              flush=True)
    result = {"runs": args.runs, "seconds": seconds,
              "median_general": statistics.median(seconds["general"]),
              "median_shortest": statistics.median(seconds["shortest"]),
              "identical_images": checksums["general"] == checksums["shortest"] and len(checksums["general"]) == 1}
    result["ratio_general_over_shortest"] = result["median_general"] / result["median_shortest"]
    if shutil.which("valgrind"):
        ir = {name: instructions(name) for name in BENCHES}
        result["instructions"] = ir
        result["instruction_ratio_general_over_shortest"] = ir["general"] / ir["shortest"]
    print(json.dumps(result, indent=1))
    acc.REFERENCE_DIR.mkdir(parents=True, exist_ok=True)
    (acc.REFERENCE_DIR / "plain_scene_overhead.json").write_text(json.dumps(result, indent=1))


if __name__ == "__main__":
    main()
