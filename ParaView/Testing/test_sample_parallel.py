"""Sample-parallel rendering under MPI (mpirun on loopback, pvbatch
--symmetric): the image two processes average equals, within noise, a
serial render with as many samples (a per-pixel z-test), repeats to the
bit, and a biased process fails the same test; a process that skips the
mapper (its level of detail drawn instead) does not hang the others.

    python3 test_sample_parallel.py WORKDIR     (in the ParaView root)

The z-test: mean over pixels and channels of (a - b)^2 / (var_a + var_b),
with the variances of the two means that the renders report. For two
unbiased estimates of one image it is about 1; its spread over ~10^4 pixel
channels is a few hundredths, and heavy-tailed pixel estimates (rare bright
paths) and noisy variance estimates push it up a little. The bounds [0.8,
1.3] leave room for that. A shadow extinction scale of 0.5 on one of two
processes must fail it (0.9 does not, at 64 samples of this scene lit from
the camera: its bias is below the noise; the figures are printed). The
renders use independent numbers (render_film.py): with the default Sobol'
pairs a pixel's samples are stratified, its variance overstates its error,
and the mean z^2 of unbiased renders falls to about 0.77.
"""
import json
import os
import subprocess
import sys
import time

import numpy as np
from vtkmodules.util.numpy_support import vtk_to_numpy
from vtkmodules.vtkIOLegacy import vtkStructuredPointsReader

HERE = os.path.dirname(os.path.abspath(__file__))
SCRIPT = os.path.join(HERE, "render_film.py")
SAMPLES = 64
TIMEOUT = 120  # seconds: a hang (deadlock) fails the test instead of the CI job


def run(workdir, name, processes, symmetric, *extra):
    """pvbatch on `processes` processes; `symmetric`: every process runs the
    script (pvbatch --symmetric), so that one process may differ."""
    out = os.path.join(workdir, name + ".vtk")
    command = ["pvbatch"] + (["--symmetric"] if symmetric else []) + [SCRIPT, "--samples", str(SAMPLES),
                                                                      "--out", out] + list(extra)
    if processes > 1 or symmetric:
        command = ["mpirun", "-np", str(processes), "--oversubscribe", "--bind-to", "none"] + command
    start = time.time()
    try:
        done = subprocess.run(command, capture_output=True, text=True, timeout=TIMEOUT)
    except subprocess.TimeoutExpired:
        sys.exit("FAIL: %s did not finish in %d s (a deadlock?): %s" % (name, TIMEOUT, " ".join(command)))
    if done.returncode != 0:
        sys.exit("FAIL: %s exited with %d:\n%s\n%s" % (name, done.returncode, done.stdout[-3000:], done.stderr[-3000:]))
    line = [l for l in done.stdout.splitlines() if l.startswith("{")]
    if not line:
        sys.exit("FAIL: %s printed no result:\n%s\n%s" % (name, done.stdout[-3000:], done.stderr[-3000:]))
    result = json.loads(line[-1])
    result["wall"] = time.time() - start
    result["file"] = out
    print("%-22s %s" % (name, json.dumps(result)))
    return result


def film(path):
    reader = vtkStructuredPointsReader()
    reader.ReadAllScalarsOn()
    reader.ReadAllVectorsOn()
    reader.ReadAllFieldsOn()
    reader.SetFileName(path)
    reader.Update()
    image = reader.GetOutput()
    data = image.GetPointData()
    if data.GetArray("radiance") is None:
        sys.exit("FAIL: %s holds no linear image" % path)
    mean = vtk_to_numpy(data.GetArray("radiance")).astype(np.float64)
    var = vtk_to_numpy(data.GetArray("variance_of_mean")).astype(np.float64)
    samples = int(image.GetFieldData().GetArray("samples").GetValue(0))
    return mean, var, samples


def mean_z2(a, b):
    (ma, va, _), (mb, vb, _) = a, b
    v = va + vb
    keep = v > 1e-9
    return float(np.mean((ma[keep] - mb[keep]) ** 2 / v[keep])), int(keep.sum())


def main():
    workdir = sys.argv[1] if len(sys.argv) > 1 else "."
    os.makedirs(workdir, exist_ok=True)
    failures = []

    def check(ok, what):
        print(("ok   " if ok else "FAIL ") + what)
        if not ok:
            failures.append(what)

    # What a user runs: pvbatch, and mpirun -np 2 pvbatch.
    serial = run(workdir, "serial", 1, False, "--seed", "1000")
    mpi = run(workdir, "mpi", 2, False)
    again = run(workdir, "mpi-again", 2, False)
    # One process differs: every process runs the script. (Its images are
    # compared with a symmetric serial run: pvbatch --symmetric renders the
    # same script a little differently from plain pvbatch, even alone.)
    serial_sym = run(workdir, "serial-symmetric", 1, True, "--seed", "1000")
    unbiased_sym = run(workdir, "mpi-symmetric", 2, True)
    biased = run(workdir, "mpi-biased", 2, True, "--shadow-scale-on-rank", "1", "0.5")
    hidden1 = run(workdir, "mpi-outline-on-rank-1", 2, True, "--outline-on-rank", "1")
    hidden0 = run(workdir, "mpi-outline-on-rank-0", 2, True, "--outline-on-rank", "0")

    s, m, m2 = film(serial["file"]), film(mpi["file"]), film(again["file"])
    ss, us, b = film(serial_sym["file"]), film(unbiased_sym["file"]), film(biased["file"])
    check(s[2] == SAMPLES and m[2] == SAMPLES, "serial and combined images have %d samples a pixel (%d, %d)"
          % (SAMPLES, s[2], m[2]))
    check(float(m[0].mean()) > 1e-3, "the combined image is not black (mean radiance %.4f)" % m[0].mean())
    check(mpi["combined_renders"] > 0 and mpi["local_renders"] == 0,
          "every render under MPI combined the processes' images")
    z, n = mean_z2(m, s)
    check(0.8 < z < 1.3, "2 processes x %d samples against 1 x %d: mean z^2 = %.3f over %d pixel channels"
          % (SAMPLES // 2, SAMPLES, z, n))
    check(np.array_equal(m[0], m2[0]) and np.array_equal(m[1], m2[1]),
          "the same processes and seed repeat the image to the bit")
    zu, _ = mean_z2(us, ss)
    check(0.8 < zu < 1.3, "symmetric runs, 2 processes against 1: mean z^2 = %.3f" % zu)
    zb, _ = mean_z2(b, ss)
    check(zb > 1.3, "a process with shadow extinction scale 0.5 fails the test: mean z^2 = %.3f" % zb)
    check(hidden1["local_renders"] > 0 and hidden1["combined_renders"] == 0,
          "mapper skipped on rank 1 (outline drawn): rank 0 rendered alone, no deadlock (%.1f s)"
          % hidden1["wall"])
    h1 = film(hidden1["file"])
    check(h1[2] == SAMPLES // 2 and float(h1[0].mean()) > 1e-3,
          "mapper skipped on rank 1: rank 0's image has its own %d samples" % h1[2])
    check(hidden0["wall"] < TIMEOUT, "mapper skipped on rank 0: finished (%.1f s)" % hidden0["wall"])

    # Not a speed figure (each process reads the data and builds its grid
    # here, on all of a 2-core machine's cores): bench_sample_parallel.py is.
    print("first render, data and grid included: serial %.2f s (%d samples), 2 processes %.2f s (%d each)"
          % (serial["seconds"], SAMPLES, mpi["seconds"], SAMPLES // 2))
    if failures:
        sys.exit("%d check(s) failed" % len(failures))


if __name__ == "__main__":
    main()
