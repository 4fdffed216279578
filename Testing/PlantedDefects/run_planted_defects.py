#!/usr/bin/env python3
"""The planted-defect check: every deliberate bug of cuda/include/mmrtm/
planted_defect.h must be caught by at least one test.

    run_planted_defects.py SOURCE_DIR BUILD_DIR [--table FILE] [--defect NAME ...]

Builds the project in BUILD_DIR with -DMMRTM_PLANTED_DEFECTS=ON (the
defects compiled in, CPU only, nothing but the checks' targets), runs the
checks once with no defect (all must pass, or the table means nothing),
then once per defect with MMRTM_PLANTED_DEFECT=<name>, in CHECKS' order,
until one fails. Prints the table (defect, the check that caught it, the
first line of its failure: the score) and writes it as Markdown with
--table. Exits 1 if a defect is caught by nothing or a check fails without
one.

CHECKS is the smallest set found that catches every defect, cheapest first
(Documentation/accuracy.md, "Planted defects").
"""

import argparse
import os
import re
import subprocess
import sys
import time
from pathlib import Path

# (name, executable, arguments, needs an X server): the tests that catch
# the defects, cheapest first (each defect stops at its first catch). The
# executables are targets of the build; the mapper check renders through
# VTK (headless). Measured: no defect passes them in about 40 s, and the
# denoised display's check on the reference scenes takes about a minute.
CHECKS = [
    ("TestTransferFunctions", "TestTransferFunctions", [], False),
    ("TestAdaptiveSampling AdaptiveFilm", "TestAdaptiveSampling", ["--gtest_filter=AdaptiveFilm.*"], False),
    ("TestBSDF lobes and phase", "TestBSDF",
     ["--gtest_filter=BSDF.EachLobesAlbedoIsItsIntegral:BSDF.SampledAlbedoIsTheIntegral:Phase.*"], False),
    ("TestSampling environment", "TestSampling", ["--gtest_filter=EnvironmentLight.*"], False),
    ("TestTracking", "TestTracking", [], False),
    ("TestLightSampling", "TestLightSampling", ["--gtest_filter=LightSampling.EveryModeEstimatesTheSameImage"], False),
    ("TestFurnace heterogeneous", "TestFurnace", ["--gtest_filter=Media/Furnace.ReturnsTheEnvironmentRadiance/4"],
     False),
    ("TestMajorantGrid minorants", "TestMajorantGrid", ["--gtest_filter=Accelerators/Conservative.Minorants*"], False),
    # The VTK property's translation, rule by rule (under a second): after
    # the tracer's checks, so that it takes no defect from them.
    ("TestVtkTranslation", "TestVtkTranslation", [], False),
    ("TestMapperEdits", "TestMapperEdits", [], True),
    ("TestDenoisedDisplay reference scenes", "TestDenoisedDisplay",
     ["--gtest_filter=DenoisedDisplayOnReferenceScenes.*"], False),
]

DEFECTS = ["volume_albedo", "diffuse_lobe", "specular_lobe", "phase_sign", "majorant_low", "minorant_high",
           "shadow_last_segment", "light_weights", "environment_pdf", "mapper_color_refit", "label_swap",
           "film_variance", "denoise_variance", "vtk_extinction", "vtk_color",
           "vtk_gradient_opacity", "vtk_gradient_magnitude", "vtk_component_weight", "vtk_dependent_rgb",
           "vtk_label_functions", "vtk_label_material", "vtk_ambient", "vtk_diffuse", "vtk_specular_power"]


def configure_and_build(source, build):
    start = time.time()
    subprocess.run(["cmake", "-S", source, "-B", build, "-DCMAKE_BUILD_TYPE=Release", "-DMMRTM_PLANTED_DEFECTS=ON",
                    "-DMMRTM_WRAP_PYTHON=OFF", "-DMMRTM_ENABLE_QT6=OFF", "-DMMRTM_TEST_SANITIZERS=OFF",
                    "-DMMRTM_TEST_FUZZ=OFF", "-DMMRTM_TEST_PLANTED_DEFECTS=OFF"],
                   check=True, stdout=subprocess.DEVNULL)
    targets = sorted({exe for _, exe, _, _ in CHECKS})
    subprocess.run(["cmake", "--build", build, "-j", str(os.cpu_count() or 2), "--target", *targets],
                   check=True, stdout=subprocess.DEVNULL)
    print(f"planted-defect build: {len(targets)} targets in {time.time() - start:.0f} s", flush=True)


def first_failure(output):
    """The line that says what failed and by how much (a gtest failure's
    message, or the program's own error line)."""
    lines = output.splitlines()
    generic = re.compile(r"^(Value of: .*|Actual: (true|false)|Expected: (true|false))$")
    for i, line in enumerate(lines):
        if re.search(r": Failure$", line):
            message = [l.strip() for l in lines[i + 1:i + 8] if l.strip() and not re.search(r": Failure$", l)]
            specific = [l for l in message if not generic.match(l)]
            return " ".join(specific or message)[:240]
    for line in lines:
        if re.search(r"FAIL|error|differ", line, re.IGNORECASE):
            return line.strip()[:300]
    return lines[-1].strip()[:300] if lines else "(no output)"


def run_check(build, headless, check, defect):
    """Runs a check, with `defect` planted (None: none)."""
    name, exe, args, needs_x = check
    env = dict(os.environ)
    env.pop("MMRTM_PLANTED_DEFECT", None)
    if defect:
        env["MMRTM_PLANTED_DEFECT"] = defect
    command = [str(Path(build) / "bin" / exe), *args]
    if needs_x and headless:
        command = [headless, *command]
    start = time.time()
    done = subprocess.run(command, env=env, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True,
                          timeout=900)
    return done.returncode == 0, done.stdout, time.time() - start


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("source")
    parser.add_argument("build")
    parser.add_argument("--table", help="write the table as Markdown here")
    parser.add_argument("--defect", action="append", help="only these defects (default: all)")
    parser.add_argument("--no-build", action="store_true", help="use BUILD_DIR as it is")
    args = parser.parse_args()
    headless = str(Path(args.source) / "Testing" / "headless.sh")
    if not args.no_build:
        configure_and_build(args.source, args.build)

    ok = True
    for check in CHECKS:
        passed, output, seconds = run_check(args.build, headless, check, None)
        print(f"no defect: {check[0]}: {'passes' if passed else 'FAILS'} ({seconds:.1f} s)", flush=True)
        if not passed:
            print(output[-3000:])
            ok = False
    if not ok:
        print("a check fails without a planted defect: fix that first")
        return 1

    rows = []
    for defect in args.defect or DEFECTS:
        caught = None
        for check in CHECKS:
            passed, output, seconds = run_check(args.build, headless, check, defect)
            if not passed:
                caught = (check[0], first_failure(output), seconds)
                break
        rows.append((defect, caught))
        print(f"{defect}: " + (f"caught by {caught[0]} ({caught[2]:.1f} s): {caught[1]}" if caught else "NOT CAUGHT"),
              flush=True)

    table = ["| planted defect | caught by | its score (the first failure) |", "|---|---|---|"]
    for defect, caught in rows:
        score = caught[1].replace("|", "/") if caught else ""
        table.append(f"| `{defect}` | {caught[0] if caught else '**nothing**'} | {score} |")
    print("\n".join(table))
    if args.table:
        Path(args.table).write_text("\n".join(table) + "\n")
    missed = [d for d, c in rows if not c]
    if missed:
        print(f"not caught: {', '.join(missed)}")
        return 1
    print(f"all {len(rows)} planted defects caught")
    return 0


if __name__ == "__main__":
    sys.exit(main())
