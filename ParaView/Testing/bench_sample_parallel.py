"""Times sample-parallel rendering (a benchmark, not a test): the head CT,
256 x 256, 128 samples a pixel, rendered by pvbatch on one thread and by
`mpirun -np 2 pvbatch` on one thread a process, after a warm-up render
(data, majorant grid), so that the times are the samples' alone (and the
combination's). Prints the time per sample per process and the parallel
efficiency. Run in the ParaView root, under X:

    python3 bench_sample_parallel.py WORKDIR
"""
import os
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import test_sample_parallel as t  # noqa: E402

t.SAMPLES = 128
workdir = sys.argv[1] if len(sys.argv) > 1 else "."
common = ["--size", "256", "--threads", "1", "--warm-up"]
rows = []
for processes in (1, 2):
    times = [t.run(workdir, "bench-%d-%d" % (processes, i), processes, False, *common)["seconds"] for i in range(3)]
    seconds = sorted(times)[1]  # the median of 3
    rows.append((processes, seconds))
    print("%d process(es), 1 thread each, %d samples a pixel in all: %.3f s (median of %s); "
          "%.1f ms per sample per process" % (processes, t.SAMPLES, seconds, ", ".join("%.3f" % x for x in times),
                                              1000 * seconds / (t.SAMPLES / processes)))
(_, one), (_, two) = rows
print("speed-up on 2 processes: %.2f; parallel efficiency %.0f %%" % (one / two, 100 * one / (2 * two)))
