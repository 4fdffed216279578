"""Renders the head CT with the representation "Path Traced (MM-RTM)" and
keeps the linear image (radiance and its variance, .vtk) for the tests of
sample-parallel rendering. Serially:

    pvbatch render_film.py --samples 32 --out serial.vtk

and under MPI, where every process runs this script (pvbatch --symmetric),
so that a test can change one process only:

    mpirun -np 2 pvbatch --symmetric render_film.py --samples 32 --out mpi.vtk
        [--shadow-scale-on-rank R S] [--outline-on-rank R]

Prints one line of JSON (from the first process): samples, counters, the
seconds of the render and the image's mean.
"""
import argparse
import json
import os
import sys
import time

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import pv_scene  # noqa: E402
from paraview import simple as pv  # noqa: E402

parser = argparse.ArgumentParser()
parser.add_argument("--samples", type=int, default=32, help="samples per pixel of the image (all processes)")
parser.add_argument("--seed", type=int, default=0)
parser.add_argument("--size", type=int, default=128)
parser.add_argument("--out", required=True, help="the linear image (.vtk), written by the first process")
parser.add_argument("--shadow-scale-on-rank", nargs=2, type=float, metavar=("RANK", "SCALE"),
                    help="a biased process: this rank alone uses another shadow extinction scale")
parser.add_argument("--outline-on-rank", type=int,
                    help="this rank alone draws the volume's level of detail (its outline), not the mapper")
parser.add_argument("--bounces", type=int, default=4)
parser.add_argument("--threads", type=int, default=0, help="CPU threads of each process (0: automatic)")
parser.add_argument("--warm-up", action="store_true",
                    help="render 1 sample a process first (data, majorant grid), so that the timed render "
                         "measures the samples alone")
parser.add_argument("--representation", help="another representation type (default: the path-traced one)")
args = parser.parse_args()

pv_scene.load_plugin()
rank, size = pv_scene.rank_and_size()
s = pv_scene.Scene(size=(args.size, args.size))
s.use(args.representation or pv_scene.PATH_TRACED)
d = s.display
d.SamplesPerRender = args.samples
d.MaximumSamples = args.samples
d.Seed = args.seed
d.MaximumBounces = args.bounces
d.ShadowExtinctionScale = 1.0
# Independent numbers: the z-tests take each pixel's sample variance for its
# error, which the default Sobol' pairs overstate (their mean z^2 was 0.77).
d.Sampler = "Independent"
d.NumberOfThreads = args.threads
if rank == 0:
    d.LinearImageFile = args.out
if args.shadow_scale_on_rank and rank == int(args.shadow_scale_on_rank[0]):
    d.ShadowExtinctionScale = args.shadow_scale_on_rank[1]
if args.outline_on_rank is not None:
    # The data first (its update sets the actor's full level of detail),
    # then this process's actor alone draws its outline: the mapper's
    # Render is skipped there, as in a level-of-detail render. (Hiding the
    # representation on one process only would hang ParaView itself: its
    # ordered compositing gathers from the processes where it is visible.)
    s.view.Update()
    if rank == args.outline_on_rank:
        volumes = s.view.GetClientSideObject().GetRenderer().GetVolumes()
        volumes.InitTraversal()
        volumes.GetNextVolume().SetEnableLOD(1)
if args.warm_up:
    d.SamplesPerRender = size
    d.MaximumSamples = size
    pv.Render(s.view)
    d.SamplesPerRender = args.samples  # a restart: a new film, the same grid
    d.MaximumSamples = args.samples
start = time.time()
pv.Render(s.view)
seconds = time.time() - start
if rank == 0:
    print(json.dumps({
        "processes": size,
        "seconds": seconds,
        "samples": s.counter("AccumulatedSamples"),
        "combined_renders": s.counter("NumberOfCombinedRenders"),
        "local_renders": s.counter("NumberOfLocalRenders"),
    }))
