#!/usr/bin/env python3
"""An independent check of the tracer: Mitsuba 3 renders the same purely
volumetric scene, and the two images must agree within their noise.

    Testing/Accuracy/mitsuba_check.py             # 128 x 128, 2048 spp: the report's figures (~10 min)
    Testing/Accuracy/mitsuba_check.py --ci        # 48 x 48, a pass/fail test (CTest)
    Testing/Accuracy/mitsuba_check.py --volume bonsai --size 96 --spp 512   # the second volume

The scene: a volume (`--volume`: the head CT ct_head_headsq.nrrd, 64 x 64 x
93 voxels, by default; or the bonsai CT, 256^3) through a density CCTF and
an albedo CCTF, evaluated here at the voxels into two grids, an extinction
grid (sigma_t / sigma_max) and an albedo-parameter grid (the albedo is a
linear function of it). Both renderers read exactly these grids and
interpolate them trilinearly between voxel centres, so the medium is the
same point for point:
  - mmrtm-render reads them as two proxies through identity TFs (a CCTF from
    0 to 1 on the extinction, a linear colour ramp on the albedo parameter);
  - Mitsuba reads them as `gridvolume`s of a `heterogeneous` medium inside a
    `cube` with a `null` BSDF that spans the same box between the first and
    last voxel centres.
Henyey-Greenstein phase (g = 0.3), no surface scattering, a constant
environment and a directional light, a pinhole camera, a box pixel filter,
64 bounces in both and unbiased shadow rays (shadow scale 1).

Agreement is measured on 4 x 4-pixel blocks: z = (block mean A - block mean B)
/ sqrt(var A + var B), with each block's variance summed from per-pixel
variances (ours from its samples, Mitsuba's across independent batches). For
two unbiased estimates of the same image the mean z^2 over blocks and
channels is 1 with a standard deviation of sqrt(2 / K) for K terms; the check
fails above its 1e-4 quantile, and so does the mean over the covered pixels
of each channel beyond its 1e-4 limit (mmrtm_accuracy.block_agreement).
With --ci the check's power (the smallest change of a channel's mean that
fails with probability 1 - 1e-4) must be 2 % or better, and our image made
2 % darker and our render with shadow rays that see 0.9 of the extinction
(a 10 % bias on shadow rays only) must both fail, so that it is known to be
able to fail.

Speed: the time each renderer needs to reach the same relative noise, from
time x noise^2 (both are unbiased, so the error is the noise).
"""

import argparse
import json
import math
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
import mmrtm_accuracy as acc  # noqa: E402

SKIP = 77  # CTest's SKIP_RETURN_CODE

# The media, as TFs over each volume's values: the density points (x,
# density in 0..1), the extinction per mm where the density is 1, the values
# over which the albedo parameter goes from 0 to 1 and the albedos there,
# and the direction the camera looks from (world, z up).
VOLUMES = {
    # CT values 0 .. ~3300: bone and skin.
    "headsq": {"file": "ct_head_headsq.nrrd", "density_points": [(600.0, 0.0), (1000.0, 0.25), (1400.0, 1.0)],
               "sigma_max": 0.35, "albedo_range": (900.0, 1600.0),
               "albedo_low": (0.85, 0.45, 0.35), "albedo_high": (0.97, 0.95, 0.9),
               # From the anterior-left side and a little above, as a user would look at a head.
               "view_from": (0.55, -1.0, 0.35)},
    # Values 0 .. 255: leaves green, trunk and pot brown (Data/benchmarks/bonsai.json's density TF).
    "bonsai": {"file": "bonsai.nii.gz", "density_points": [(25.0, 0.0), (60.0, 0.6), (200.0, 1.0)],
               "sigma_max": 0.5, "albedo_range": (30.0, 200.0),
               "albedo_low": (0.35, 0.7, 0.25), "albedo_high": (0.7, 0.55, 0.4),
               "view_from": (0.35, -1.0, 0.3)},
}
G = 0.3
ENVIRONMENT = (0.35, 0.4, 0.5)
SUN_DIRECTION = (0.45, 0.6, -0.66)  # direction of travel, world (LPS)
SUN_IRRADIANCE = (2.0, 1.9, 1.7)
MAX_BOUNCES = 64


def read_nrrd(path):
    """The few NRRD fields ct_head_headsq.nrrd uses: type short, gzip, spacings."""
    import gzip
    with open(path, "rb") as f:
        raw = f.read()
    header, _, body = raw.partition(b"\n\n")
    fields = {}
    for line in header.decode().splitlines()[1:]:
        if ":" in line and not line.startswith("#"):
            key, value = line.split(":", 1)
            fields[key.strip()] = value.strip()
    if fields.get("type") != "short" or fields.get("encoding") != "gzip":
        raise SystemExit(f"{path}: expected a gzip-encoded short NRRD")
    sizes = [int(v) for v in fields["sizes"].split()]
    spacing = [float(v) for v in fields["spacings"].split()]
    data = np.frombuffer(gzip.decompress(body), dtype="<i2").reshape(sizes[::-1])  # (z, y, x)
    return data.astype(np.float64), spacing


def read_nifti_uint8(path):
    """The few NIfTI-1 fields bonsai.nii.gz uses: gzip, uint8, no scaling."""
    import gzip
    import struct
    raw = gzip.open(path, "rb").read()
    dim = struct.unpack("<8h", raw[40:56])
    datatype = struct.unpack("<h", raw[70:72])[0]
    spacing = list(struct.unpack("<3f", raw[80:92]))
    offset = int(struct.unpack("<f", raw[108:112])[0])
    if dim[0] != 3 or datatype != 2:
        raise SystemExit(f"{path}: expected a 3D uint8 NIfTI volume")
    data = np.frombuffer(raw, dtype=np.uint8, offset=offset, count=dim[1] * dim[2] * dim[3])
    return data.reshape(dim[3], dim[2], dim[1]).astype(np.float64), spacing  # (z, y, x)


def write_nrrd(path, grid, spacing):
    """A float NRRD with LPS geometry, origin 0, axis-aligned."""
    nz, ny, nx = grid.shape
    header = ("NRRD0004\ntype: float\ndimension: 3\nspace: left-posterior-superior\n"
              f"sizes: {nx} {ny} {nz}\n"
              f"space directions: ({spacing[0]},0,0) (0,{spacing[1]},0) (0,0,{spacing[2]})\n"
              "space origin: (0,0,0)\nendian: little\nencoding: raw\n\n")
    with open(path, "wb") as f:
        f.write(header.encode())
        f.write(np.ascontiguousarray(grid, dtype="<f4").tobytes())


def make_grids(volume):
    path = acc.DATA / volume["file"]
    values, spacing = read_nrrd(path) if path.suffix == ".nrrd" else read_nifti_uint8(path)
    xs, ys = zip(*volume["density_points"])
    density = np.interp(values, xs, ys)
    low, high = volume["albedo_range"]
    albedo_t = np.clip((values - low) / (high - low), 0.0, 1.0)
    return density, albedo_t, spacing


def camera(volume, density, spacing):
    nz, ny, nx = density.shape
    extent = np.array([(nx - 1) * spacing[0], (ny - 1) * spacing[1], (nz - 1) * spacing[2]])
    centre = extent / 2
    direction = np.array(volume["view_from"])
    direction /= np.linalg.norm(direction)
    position = centre + direction * 1.5 * np.linalg.norm(extent)
    return {"position": position.tolist(), "look_at": centre.tolist(), "up": [0.0, 0.0, 1.0], "fov": 30.0}, extent


def render_ours(volume, folder, cam, size, spp, seed, shadow_scale=1.0):
    scene = {
        "volumes": {"scalars": {"file": "extinction.nrrd"}, "albedo_t": {"file": "albedo_t.nrrd"}},
        "materials": {"medium": {
            "density": volume["sigma_max"], "albedo": [1, 1, 1], "anisotropy": G, "surface_probability": 0,
            "tfs": {"density": [{"type": "cctf", "proxy": "scalars", "points": [[0, 0], [1, 1]]}],
                    "albedo": [{"type": "cctf", "proxy": "albedo_t",
                                "points": [[0, *volume["albedo_low"]], [1, *volume["albedo_high"]]]}]}}},
        "lights": [{"type": "environment", "color": list(ENVIRONMENT)},
                   {"type": "directional", "direction": list(SUN_DIRECTION), "color": list(SUN_IRRADIANCE),
                    "intensity": 1.0}],
        "camera": {"projection": "perspective", **cam},
        # Independent numbers: the z-test and the speed figure take each
        # pixel's sample variance for its error, which the default Sobol'
        # sampler's stratified samples overstate (decisions.md).
        "render": {"max_bounces": MAX_BOUNCES, "shadow_extinction_scale": shadow_scale, "background": True,
                   "sampler": "independent"},
    }
    path = Path(folder) / "scene.json"
    path.write_text(json.dumps(scene, indent=1))
    return acc.render(["--scene", path], size, size, spp, seed=seed)


def mitsuba_scene(variant, sigma_t, albedo, scale, spacing, extent, cam, size, spp):
    """The check's scene in Mitsuba 3: grids (z, y, x, channels) of extinction
    (times `scale`) and albedo in a null-BSDF cube, the lights and camera."""
    import mitsuba as mi
    mi.set_variant(variant)
    T = mi.ScalarTransform4f
    # A gridvolume puts voxel i's value at (i + 0.5) / n of its unit cube, so
    # the cube is widened by half a voxel to put voxel centres where ours are.
    half_voxel = np.array(spacing) / 2
    volume_to_world = T().translate((-half_voxel).tolist()).scale((extent + 2 * half_voxel).tolist())
    grid = {"to_world": volume_to_world, "filter_type": "trilinear"}
    return mi.load_dict({
        "type": "scene",
        "integrator": {"type": "volpath", "max_depth": MAX_BOUNCES + 1, "rr_depth": 5},
        "sensor": {"type": "perspective", "fov": cam["fov"], "fov_axis": "y",
                   "to_world": T().look_at(origin=cam["position"], target=cam["look_at"], up=cam["up"]),
                   "sampler": {"type": "independent", "sample_count": spp},
                   "film": {"type": "hdrfilm", "width": size, "height": size, "rfilter": {"type": "box"},
                            "pixel_format": "rgb"}},
        "environment": {"type": "constant", "radiance": {"type": "rgb", "value": list(ENVIRONMENT)}},
        "sun": {"type": "directional", "direction": list(SUN_DIRECTION),
                "irradiance": {"type": "rgb", "value": list(SUN_IRRADIANCE)}},
        "medium_box": {
            "type": "cube", "to_world": T().translate((extent / 2).tolist()).scale((extent / 2).tolist()),
            "bsdf": {"type": "null"},
            "interior": {"type": "heterogeneous", "scale": float(scale), "phase": {"type": "hg", "g": G},
                         "sigma_t": {"type": "gridvolume", "grid": mi.VolumeGrid(sigma_t.astype(np.float32)), **grid},
                         "albedo": {"type": "gridvolume", "grid": mi.VolumeGrid(albedo.astype(np.float32)), **grid}}},
    })


def render_mitsuba(variant, volume, density, albedo_t, spacing, extent, cam, size, spp, batches):
    import mitsuba as mi
    low, high = np.array(volume["albedo_low"]), np.array(volume["albedo_high"])
    albedo = low + albedo_t[..., None] * (high - low)
    scene = mitsuba_scene(variant, density[..., None], albedo, volume["sigma_max"], spacing, extent, cam, size, spp)
    images, seconds = [], 0.0
    for b in range(batches):
        start = time.time()
        image = np.array(mi.render(scene, spp=spp, seed=1 + b), dtype=np.float64)[..., :3]
        if b > 0 or not variant.startswith("llvm"):  # the first LLVM batch includes the kernel compilation
            seconds += time.time() - start
        images.append(image)
    images = np.stack(images)
    timed_batches = batches if not variant.startswith("llvm") else batches - 1
    mean = images.mean(axis=0)
    variance_of_mean = images.var(axis=0, ddof=1) / batches
    return mean, variance_of_mean, images, seconds / max(timed_batches, 1) * batches


def compare(ours_mean, ours_var, mi_mean, mi_var, ours_spp, mi_batches):
    # Our variances are the spread of independent samples, Mitsuba's of its batches.
    result = acc.block_agreement(ours_mean, ours_var, mi_mean, mi_var, block=4, df_a=ours_spp - 1,
                                 df_b=len(mi_batches) - 1, replicates_b=mi_batches)
    result.update({"mean_ratio": float(ours_mean.mean() / mi_mean.mean()),
                   "mean_ratio_sigma": float(math.sqrt(ours_var.sum() + mi_var.sum()) / ours_mean.size /
                                             mi_mean.mean())})
    return result


def figure(ours, mitsuba, result, path):
    """Both images (same tone curve), their difference and the figures."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    def show(im):
        return np.clip(im / (1 + im), 0, 1) ** (1 / 2.2)

    fig, ax = plt.subplots(1, 3, figsize=(11, 4))
    for a, (title, im) in zip(ax, [(f"mmrtm-render, {result['ours_spp']} spp, {result['ours_seconds']:.0f} s", show(ours)),
                                   (f"Mitsuba 3 {result['mitsuba_variant']}, {result['mitsuba_spp']} spp, "
                                    f"{result['mitsuba_seconds']:.0f} s", show(mitsuba)),
                                   ("|difference| x 10", np.clip(10 * np.abs(ours - mitsuba), 0, 1))]):
        a.imshow(im)
        a.set_title(title, fontsize=9)
        a.axis("off")
    fig.suptitle(f"Same medium, two renderers: mean block z^2 {result['mean_z2']:.3f} (limit {result['limit']:.3f}), "
                 f"mean ratio {result['mean_ratio']:.5f}; Mitsuba needs {result['time_to_equal_error_ratio']:.1f} x "
                 "the time for the same error", fontsize=9)
    fig.tight_layout()
    fig.savefig(path, dpi=100)
    plt.close(fig)


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--ci", action="store_true", help="48 x 48, few samples: the CTest check")
    parser.add_argument("--volume", choices=sorted(VOLUMES), default="headsq", help="the medium's volume")
    parser.add_argument("--size", type=int)
    parser.add_argument("--spp", type=int, help="our samples per pixel")
    parser.add_argument("--mitsuba-spp", type=int, help="Mitsuba's samples per pixel per batch")
    parser.add_argument("--batches", type=int, default=16, help="independent Mitsuba batches (for its variance)")
    parser.add_argument("--variant", default=acc.mitsuba_variant(),
                        help="Mitsuba variant (default: llvm_ad_rgb where libLLVM 16 is installed, else scalar_rgb)")
    parser.add_argument("--save", help="folder for both images and variances (PFM) and the figures (JSON); "
                        "without --ci also draws Documentation/images/mitsuba_check.png")
    args = parser.parse_args()
    size = args.size or (48 if args.ci else 128)
    spp = args.spp or (1024 if args.ci else 2048)
    mi_spp = args.mitsuba_spp or max(1, spp // args.batches)
    try:
        import mitsuba  # noqa: F401
    except ImportError:
        print("SKIPPED: Mitsuba 3 is not installed for this Python "
              f"({sys.executable}); scripts/install-dependencies.sh installs it in .venv")
        return SKIP
    volume = VOLUMES[args.volume]
    density, albedo_t, spacing = make_grids(volume)
    cam, extent = camera(volume, density, spacing)
    with tempfile.TemporaryDirectory() as tmp:
        write_nrrd(Path(tmp) / "extinction.nrrd", density, spacing)
        write_nrrd(Path(tmp) / "albedo_t.nrrd", albedo_t, spacing)
        start = time.time()
        ours = render_ours(volume, tmp, cam, size, spp, seed=3)
        ours_seconds = ours.seconds
        print(f"mmrtm-render: {size}^2, {spp} spp, {ours_seconds:.2f} s render ({time.time() - start:.1f} s in all)")
        # The check must be able to fail: a slightly biased render (shadow rays
        # see 0.9 of the extinction) has to be told apart from Mitsuba's.
        biased = render_ours(volume, tmp, cam, size, spp, seed=4, shadow_scale=0.9) if args.ci else None
    mi_mean, mi_var, mi_batches, mi_seconds = render_mitsuba(args.variant, volume, density, albedo_t, spacing, extent,
                                                             cam, size, mi_spp, args.batches)
    print(f"Mitsuba {args.variant}: {size}^2, {args.batches} x {mi_spp} spp, {mi_seconds:.2f} s render")
    result = compare(ours.mean, ours.variance, mi_mean, mi_var, spp, mi_batches)
    ours_noise = acc.relative_noise(ours.mean, ours.variance)
    mi_noise = acc.relative_noise(mi_mean, mi_var)
    # Time to reach a given relative noise e: t * (noise / e)^2; the ratio does not depend on e.
    result.update({"volume": args.volume, "size": size, "ours_spp": spp, "ours_seconds": ours_seconds,
                   "ours_noise": ours_noise, "mitsuba_variant": args.variant, "mitsuba_spp": mi_spp * args.batches,
                   "mitsuba_seconds": mi_seconds, "mitsuba_noise": mi_noise,
                   "time_to_equal_error_ratio": (mi_seconds * mi_noise ** 2) / (ours_seconds * ours_noise ** 2),
                   "mean_luminance": float(ours.mean.mean())})
    print(json.dumps(result, indent=1))
    if args.save:
        out = Path(args.save)
        out.mkdir(parents=True, exist_ok=True)
        acc.write_pfm(out / "mmrtm.pfm", ours.mean)
        acc.write_pfm(out / "mitsuba.pfm", mi_mean)
        acc.write_pfm(out / "mmrtm_variance.pfm", ours.variance)
        acc.write_pfm(out / "mitsuba_variance.pfm", mi_var)
        (out / "mitsuba_check.json").write_text(json.dumps(result, indent=1))
        if not args.ci:
            name = "mitsuba_check.png" if args.volume == "headsq" else f"mitsuba_check_{args.volume}.png"
            figure(ours.mean, mi_mean, result, acc.DOC_IMAGES / name)
    ok = acc.agrees(result) and result["mean_luminance"] > 0.01
    if args.ci:
        # The power (the smallest change of a channel's mean over the covered
        # pixels caught with probability 1 - 1e-4) must be 2 % or better, and
        # shown: our image made 2 % darker, and a render whose shadow rays see
        # 0.9 of the extinction, must both fail.
        ok = ok and result["power"] <= 0.02
        for what, mean, var in (("2 % darker", 0.98 * ours.mean, 0.98 ** 2 * ours.variance),
                                ("shadow scale 0.9", biased.mean, biased.variance)):
            sensitivity = acc.block_agreement(mean, var, mi_mean, mi_var, block=4, df_a=spp - 1,
                                              df_b=args.batches - 1, replicates_b=mi_batches)
            print(f"sensitivity: {what} against Mitsuba: {acc.describe(sensitivity)} (must fail)")
            ok = ok and not acc.agrees(sensitivity)
    print(("PASS" if ok else "FAIL") + f": {acc.describe(result)}; "
          f"mean ratio ours / Mitsuba {result['mean_ratio']:.4f} +- {result['mean_ratio_sigma']:.4f}; "
          f"Mitsuba needs {result['time_to_equal_error_ratio']:.2f} x our time for the same error")
    return 0 if ok else 1


if __name__ == "__main__":
    sys.exit(main())
