"""Benchmark (not a test): volumes from 0.1 to 8 GiB, loaded, summarised and
rendered by mmrtm-render and by the VTK mapper, with the peak resident
memory of each process against the voxel bytes (Documentation/performance.md's table).

The volumes are the head CT (ct_head_cranium, 256 x 256 x 108 int16) tiled
along each axis into a raw int16 NRRD, written at run time under --scratch
and removed afterwards (never stored). Each case runs in a process of its
own, so each peak is its own. The baseline of the load in the same run is
vtkNrrdReader reading the same file (what the loaders used before they read
raw data themselves, and what a VTK script uses). Every load reads the file
from the page cache (read through once first).

    Testing/headless.sh 1024x768x24 /usr/bin/python3 Testing/Benchmarks/bench_scale.py \\
        [--sizes 0.1,1,8] [--scratch DIR] [--mapper] [--json out.json]

Needs the build (build/bin/mmrtm-render) and, for --mapper, the build's
Python package on PYTHONPATH (build/lib/python3/dist-packages). The 8 GiB
case needs 8 GiB of disk under --scratch and about 10 GiB of memory.
"""
import argparse
import gzip
import json
import os
import re
import subprocess
import sys
import tempfile
import time

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.normpath(os.path.join(HERE, "..", ".."))
DATA = os.environ.get("MMRTM_SHARED_DATA_DIR", os.path.join(ROOT, "..", "shared", "data"))
RENDER = os.path.join(ROOT, "build", "bin", "mmrtm-render")
GIB = 1024.0 ** 3

# Tiles of the 256 x 256 x 108 head CT along (x, y, z) for each size.
SIZES = {
    "0.1": (2, 2, 2),      # 512 x 512 x 216: 108 MiB
    "1": (4, 4, 4),        # 1024 x 1024 x 432: 864 MiB
    "8": (8, 8, 9.4815),   # 2048 x 2048 x 1024: 8 GiB
}


def read_head_ct():
    """The head CT's slices (bytes of little-endian int16, x fastest) and its
    (nx, ny, nz), from its gzip NRRD."""
    with open(os.path.join(DATA, "ct_head_cranium.nrrd"), "rb") as f:
        raw = f.read()
    end = raw.index(b"\n\n") + 2
    header = raw[:end].decode()
    assert "type: short" in header and "endian: little" in header and "encoding: gzip" in header
    nx, ny, nz = (int(v) for v in re.search(r"sizes: (.*)", header).group(1).split())
    voxels = gzip.decompress(raw[end:])
    slice_bytes = 2 * nx * ny
    return [voxels[z * slice_bytes:(z + 1) * slice_bytes] for z in range(nz)], (nx, ny, nz)


def write_tiled(path, head, tiles):
    """The head CT tiled (x, y whole times; z cut to its share) as a raw NRRD,
    slice by slice (never the whole volume in memory)."""
    slices, (nx, ny, nz) = head
    tx, ty = int(tiles[0]), int(tiles[1])
    out_x, out_y, out_z = nx * tx, ny * ty, int(round(nz * tiles[2]))
    with open(path, "wb") as f:
        f.write(("NRRD0004\ntype: short\ndimension: 3\nsizes: %d %d %d\nspace: left-posterior-superior\n"
                 "endian: little\nencoding: raw\nspace directions: (0.9570312,0,0) (0,0.9570312,0) (0,0,1.5)\n"
                 "space origin: (0,0,0)\n\n" % (out_x, out_y, out_z)).encode())
        tiled = []
        for z in range(nz):
            row = 2 * nx
            tiled.append(b"".join(slices[z][y * row:(y + 1) * row] * tx for y in range(ny)) * ty)
        for z in range(out_z):
            f.write(tiled[z % nz])
    return (out_x, out_y, out_z)


def timed(command, env=None):
    """Runs command under GNU time; returns (seconds, peak resident bytes, stdout)."""
    start = time.perf_counter()
    result = subprocess.run(["/usr/bin/time", "-v"] + command, capture_output=True, text=True, env=env)
    seconds = time.perf_counter() - start
    if result.returncode != 0:
        sys.exit("failed: %s\n%s" % (" ".join(command), result.stderr[-3000:]))
    peak = int(re.search(r"Maximum resident set size \(kbytes\): (\d+)", result.stderr).group(1)) * 1024
    return seconds, peak, result.stdout


VTK_READ = """
import resource, sys, time
from vtkmodules.vtkIOImage import vtkNrrdReader
start = time.perf_counter()
reader = vtkNrrdReader()
reader.SetFileName(sys.argv[1])
reader.Update()
print(time.perf_counter() - start)
"""

# The mapper on the CPU, 256 x 256, 8 samples per pixel, a bone ramp:
# the volume comes from vtkMultiMaterialVolumeReader (the project's loader;
# the mapper reads its output in place). Prints the load and first-image
# seconds and the resident bytes after loading.
MAPPER = """
import sys, time
from vtkmodules.vtkCommonDataModel import vtkPiecewiseFunction
from vtkmodules.vtkRenderingCore import (vtkColorTransferFunction, vtkRenderer, vtkRenderWindow, vtkVolume,
                                         vtkVolumeProperty)
import vtkmodules.vtkRenderingOpenGL2  # noqa: F401
import vtkmodules.vtkRenderingVolumeOpenGL2  # noqa: F401
from mmrtm import vtkMultiMaterialVolumeMapper, vtkMultiMaterialVolumeReader

def resident():
    with open("/proc/self/status") as status:
        for line in status:
            if line.startswith("VmRSS:"):
                return int(line.split()[1]) * 1024

start = time.perf_counter()
reader = vtkMultiMaterialVolumeReader()
reader.SetFileName(sys.argv[1])
reader.Update()
loaded = time.perf_counter() - start
after_load = resident()
mapper = vtkMultiMaterialVolumeMapper()
mapper.SetInputConnection(reader.GetOutputPort())
mapper.SetBackendToCPU()
mapper.SetSamplesPerRender(8)
mapper.SetMaximumSamples(8)
opacity = vtkPiecewiseFunction()
opacity.AddPoint(1100, 0.0)
opacity.AddPoint(2000, 0.8)
color = vtkColorTransferFunction()
color.AddRGBPoint(1100, 0.9, 0.6, 0.5)
color.AddRGBPoint(2000, 1.0, 0.95, 0.9)
prop = vtkVolumeProperty()
prop.SetScalarOpacity(opacity)
prop.SetColor(color)
prop.ShadeOn()
volume = vtkVolume()
volume.SetMapper(mapper)
volume.SetProperty(prop)
renderer = vtkRenderer()
renderer.AddVolume(volume)
window = vtkRenderWindow()
window.SetOffScreenRendering(1)
window.AddRenderer(renderer)
window.SetSize(256, 256)
renderer.ResetCamera()
start = time.perf_counter()
window.Render()
print(loaded, time.perf_counter() - start, after_load)
"""


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--sizes", default="0.1,1", help="comma-separated, of " + ", ".join(SIZES) + " (GiB)")
    parser.add_argument("--scratch", default=None, help="folder for the generated volumes (default: a temp folder)")
    parser.add_argument("--mapper", action="store_true", help="also through the VTK mapper (needs DISPLAY)")
    parser.add_argument("--threads", type=int, default=0, help="render threads (0: all)")
    parser.add_argument("--json", default=None, help="write the figures here too")
    args = parser.parse_args()
    head = read_head_ct()
    rows = []
    with tempfile.TemporaryDirectory(dir=args.scratch) as scratch:
        for size in args.sizes.split(","):
            path = os.path.join(scratch, "tiled_%s.nrrd" % size)
            start = time.perf_counter()
            dims = write_tiled(path, head, SIZES[size])
            os.sync()  # on disk: no writeback during the loads
            with open(path, "rb") as f:  # and all of it in the page cache, for every reader alike
                while f.read(1 << 26):
                    pass
            voxel_bytes = 2.0 * dims[0] * dims[1] * dims[2]
            print("%s GiB: %d x %d x %d int16 (%.2f GiB) written in %.1f s" %
                  (size, *dims, voxel_bytes / GIB, time.perf_counter() - start), flush=True)
            row = {"size": size, "dims": dims, "voxel_bytes": voxel_bytes}

            # Twice: the first run's allocation makes the kernel reclaim
            # memory (evicting pages of the file read only once, which it
            # then reads from disk again); the second finds memory free.
            stats = os.path.join(scratch, "stats.json")
            for run in ("first", "again"):
                _, peak, _ = timed([RENDER, path, "--threads", str(args.threads), "--width", "256", "--height",
                                    "256", "--spp", "8", "--quiet", "--stats-json", stats, "--output",
                                    os.path.join(scratch, "a.png")])
                with open(stats) as f:
                    s = json.load(f)["seconds"]
                row["render_cli_" + run] = {"load": s["load"], "build": s["build"], "render": s["render"],
                                            "peak": peak, "load_gb_per_s": voxel_bytes / 1e9 / s["load"]}
                print("  mmrtm-render (%s run): load %.2f s (%.2f GB/s), build %.2f s, render %.2f s, peak %.0f MiB"
                      " = %.3f x" % (run, s["load"], voxel_bytes / 1e9 / s["load"], s["build"], s["render"],
                                     peak / 2**20, peak / voxel_bytes), flush=True)

            _, peak, out = timed([sys.executable, "-c", VTK_READ, path])
            row["vtk_nrrd_reader"] = {"load": float(out.split()[-1]), "peak": peak}
            print("  vtkNrrdReader (baseline): load %.2f s (%.2f GB/s), peak %.0f MiB = %.3f x"
                  % (float(out.split()[-1]), voxel_bytes / 1e9 / float(out.split()[-1]), peak / 2**20,
                     peak / voxel_bytes), flush=True)

            if args.mapper:
                _, peak, out = timed([sys.executable, "-c", MAPPER, path])
                loaded, first, after_load = (float(v) for v in out.split()[-3:])
                row["mapper"] = {"load": loaded, "first_image": first, "peak": peak, "after_load": after_load}
                print("  mapper: load %.2f s, first image %.2f s, peak %.0f MiB = %.3f x; beyond the loaded "
                      "volume's process %.0f MiB = %.3f x" % (loaded, first, peak / 2**20, peak / voxel_bytes,
                                                            (peak - after_load) / 2**20,
                                                            (peak - after_load) / voxel_bytes), flush=True)
            os.remove(path)
            rows.append(row)
    print("\n| voxels | GiB | load s (GB/s) | first run's load s | vtkNrrdReader s | build s | render s |"
          " peak / voxel bytes |" + (" mapper first image s | mapper beyond caller / voxel bytes |"
                                     if args.mapper else ""))
    print("|---|---|---|---|---|---|---|---|" + ("---|---|" if args.mapper else ""))
    for r in rows:
        c, first, v = r["render_cli_again"], r["render_cli_first"], r["vtk_nrrd_reader"]
        line = "| %d x %d x %d | %.2f | %.2f (%.2f) | %.2f | %.2f | %.2f | %.2f | %.3f |" % (
            *r["dims"], r["voxel_bytes"] / GIB, c["load"], c["load_gb_per_s"], first["load"], v["load"], c["build"],
            c["render"], c["peak"] / r["voxel_bytes"])
        if "mapper" in r:
            m = r["mapper"]
            line += " %.2f | %.3f |" % (m["first_image"], (m["peak"] - m["after_load"]) / r["voxel_bytes"])
        print(line)
    if args.json:
        with open(args.json, "w") as f:
            json.dump(rows, f, indent=2)


if __name__ == "__main__":
    main()
