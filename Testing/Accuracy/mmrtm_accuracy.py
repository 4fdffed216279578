"""Shared pieces of the accuracy and speed scripts: where things are, how a
render is run, PFM images, and the error measure.

The scripts call the command-line renderer (`mmrtm-render`) rather than a
library, so what they measure is what a user runs. Paths come from the
environment when set:

  MMRTM_BUILD_DIR       the CMake build folder (default: <repo>/build)
  MMRTM_SHARED_DATA     the shared datasets (default: <repo>/../shared/data)
  MMRTM_REFERENCE_DIR   converged reference images (default: <build>/references)
"""

import json
import os
import subprocess
import sys
import tempfile
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[2]
BUILD = Path(os.environ.get("MMRTM_BUILD_DIR", ROOT / "build"))
DATA = Path(os.environ.get("MMRTM_SHARED_DATA", ROOT.parent / "shared" / "data"))
REFERENCE_DIR = Path(os.environ.get("MMRTM_REFERENCE_DIR", BUILD / "references"))
RENDER = BUILD / "bin" / "mmrtm-render"
DOC_IMAGES = ROOT / "Documentation" / "images"

# Mitsuba's vectorised LLVM variant loads libLLVM at run time; Debian 12's
# libllvm16 is the one that works with the pinned Dr.Jit (requirements.txt).
LIBLLVM = Path("/usr/lib/x86_64-linux-gnu/libLLVM-16.so.1")


def mitsuba_variant():
    """The Mitsuba variant to compare with: llvm_ad_rgb (vectorised) where
    libLLVM 16 is installed, else scalar_rgb. Call before importing mitsuba."""
    if os.environ.get("DRJIT_LIBLLVM_PATH") or LIBLLVM.exists():
        os.environ.setdefault("DRJIT_LIBLLVM_PATH", str(LIBLLVM))
        return "llvm_ad_rgb"
    return "scalar_rgb"


def data_path(name):
    return str(DATA / name)


# The reference scenes of Documentation/accuracy.md (reference_scenes.json,
# which the C++ tests read too), as title and mmrtm-render arguments. Every
# one is 256 x 256 and uses the scene's own camera.
def _reference_scenes():
    with open(Path(__file__).with_name("reference_scenes.json")) as f:
        listed = {name: scene for name, scene in json.load(f).items() if not name.startswith("_")}
    scenes = {}
    for name, s in listed.items():
        args = [data_path(s["volume"])]
        if "labels" in s:
            args += ["--labels", data_path(s["labels"])]
        if "preset" in s:
            args += ["--preset", s["preset"]]
        if "scene" in s:
            args += ["--scene", str(ROOT / s["scene"])]
        scenes[name] = {"title": s["title"], "args": args}
    return scenes


SCENES = _reference_scenes()

REFERENCE_SIZE = 256


def read_pfm(path):
    """A colour PFM as a (height, width, 3) float64 array, row 0 at the top."""
    with open(path, "rb") as f:
        kind = f.readline().strip()
        if kind != b"PF":
            raise ValueError(f"{path}: not a colour PFM (header {kind!r})")
        width, height = (int(v) for v in f.readline().split())
        scale = float(f.readline())
        dtype = "<f4" if scale < 0 else ">f4"
        data = np.fromfile(f, dtype=dtype, count=width * height * 3)
    if data.size != width * height * 3:
        raise ValueError(f"{path}: truncated ({data.size} of {width * height * 3} floats)")
    return np.flipud(data.reshape(height, width, 3)).astype(np.float64)


def write_pfm(path, image):
    image = np.asarray(image, dtype="<f4")
    height, width, _ = image.shape
    tmp = str(path) + ".partial"
    with open(tmp, "wb") as f:
        f.write(f"PF\n{width} {height}\n-1.0\n".encode())
        np.flipud(image).tofile(f)
    os.replace(tmp, path)


class Render:
    """One run of mmrtm-render: mean image, variance of the mean, and its
    --stats-json; for replicates (render_replicates) also their images."""

    def __init__(self, mean, variance, stats, replicates=None):
        self.mean, self.variance, self.stats, self.replicates = mean, variance, stats, replicates

    @property
    def seconds(self):
        return self.stats["seconds"]["render"]


def render(args, width, height, spp, seed=0, extra=(), keep=None, binary=None):
    """Runs mmrtm-render with `args` (input and scene options) and returns a Render.

    `keep`, a path prefix, also keeps PREFIX.pfm, PREFIX_variance.pfm,
    PREFIX.png and PREFIX.json; otherwise everything goes to a temporary folder.
    `binary`: another mmrtm-render (an older build, to compare with).
    """
    binary = Path(binary) if binary else RENDER
    if not binary.exists():
        sys.exit(f"{binary}: not built (cmake --build build)")
    with tempfile.TemporaryDirectory() as tmp:
        prefix = Path(keep) if keep else Path(tmp) / "render"
        cmd = [str(binary), *map(str, args), "--width", str(width), "--height", str(height),
               "--spp", str(spp), "--seed", str(seed), "--quiet",
               "--output", f"{prefix}.png", "--output-linear", f"{prefix}.pfm",
               "--output-variance", f"{prefix}_variance.pfm", "--stats-json", f"{prefix}.json", *map(str, extra)]
        done = subprocess.run(cmd, capture_output=True, text=True)
        if done.returncode != 0:
            raise RuntimeError(f"mmrtm-render failed ({done.returncode}): {' '.join(cmd)}\n{done.stderr}")
        with open(f"{prefix}.json") as f:
            stats = json.load(f)
        return Render(read_pfm(f"{prefix}.pfm"), read_pfm(f"{prefix}_variance.pfm"), stats)


def render_replicates(args, width, height, spp, seeds, extra=(), binary=None):
    """Independent replicates of one image: a render per seed (independently
    scrambled Sobol' nets, or independent streams), `spp` samples each.
    Returns a Render whose mean is theirs and whose variance is that mean's,
    from their spread (degrees of freedom: len(seeds) - 1), and whose stats
    are the first render's with the render seconds summed."""
    renders = [render(args, width, height, spp, seed=seed, extra=extra, binary=binary) for seed in seeds]
    means = np.stack([r.mean for r in renders])
    stats = dict(renders[0].stats)
    stats["seconds"] = dict(stats["seconds"], render=sum(r.seconds for r in renders))
    return Render(means.mean(axis=0), means.var(axis=0, ddof=1) / len(renders), stats, replicates=means)


def relative_rmse(image, reference, reference_variance=None):
    """RMSE over pixels and channels divided by the reference's mean value.

    With `reference_variance` (the variance of the reference's per-pixel mean),
    the reference's own noise is taken out: E[(a - r)^2] = E[(a - R)^2] + Var[r]
    for a reference r of true value R that is independent of a, so the
    variance is subtracted from the mean squared error (clamped at 0).
    """
    squared = np.mean((image - reference) ** 2)
    if reference_variance is not None:
        squared = max(0.0, squared - np.mean(reference_variance))
    return float(np.sqrt(squared) / np.mean(reference))


def relative_noise(image, variance):
    """An image's relative RMS noise from the variance of its per-pixel means
    (same scale as relative_rmse)."""
    return float(np.sqrt(np.mean(variance)) / np.mean(image))


def block_sums(image, block):
    h, w, c = image.shape
    return image[:h - h % block, :w - w % block].reshape(h // block, block, w // block, block, c).sum(axis=(1, 3))


FALSE_FAILURE = 1e-4  # probability that two estimates of one image fail block_agreement


def block_agreement(mean_a, var_a, mean_b, var_b, block=4, df_a=None, df_b=None, replicates_a=None,
                    replicates_b=None, false_failure=FALSE_FAILURE):
    """Whether two independent, unbiased estimates of one image agree within
    noise, with the comparison's power: the same statistics as the C++
    tests' Testing/Cxx/ImageAgreement.h (Documentation/accuracy.md).

    The variances must be the error of each per-pixel mean: the spread of
    independent samples (--sampler independent; df = samples - 1) or of
    independent batches or replicates (df = replicates - 1), never a Sobol'
    render's own spread, which overstates its error. `df_a`, `df_b`: those
    degrees of freedom (None: many). `replicates_a`, `replicates_b`: the
    replicates' images (R x H x W x 3) where there are any: a block's
    variance then comes from their block means (close to normal), not from
    few-sample pixel variances of heavy-tailed path samples, whose sum makes
    z^2 larger than F(1, nu) says. Without replicates, compare renders of
    many samples or use larger blocks.

    Two tests, each given half of `false_failure`:
      - global: per channel, the mean over covered pixels (those with noise)
        of a - b in standard errors, N(0, 1) when they agree; limit two-sided
        over the channels;
      - blocks: on block x block pixel blocks, the mean over blocks of
        z^2 = (a - b)^2 / (var a + var b) averaged over the channels, each
        block's variance summed from the per-pixel ones. Each channel's z^2
        is F(1, nu) (nu from Welch-Satterthwaite); the channels move
        together, so a block's term has that mean and at most that variance;
        the limit is the Wilson-Hilferty quantile of the sum over blocks.
    `power`: the smallest relative change of one channel's covered-pixel
    mean that the global test catches with probability 1 - false_failure.
    Blocks without noise (float rounding leaves ~1e-17 there, e.g. where
    only the constant environment is seen) must agree to float precision;
    a block counts as noiseless only below (1e-7 of its value)^2.
    """
    from statistics import NormalDist
    normal = NormalDist()
    alpha = false_failure / 2
    channels = mean_a.shape[2]
    global_limit = normal.inv_cdf(1 - alpha / (2 * channels))
    z_power = normal.inv_cdf(1 - false_failure)

    def noiseless(var, value):
        return var <= (1e-7 * (np.abs(value) + 1e-3)) ** 2

    pixel_var = var_a + var_b
    covered = np.any(~noiseless(pixel_var, mean_b), axis=2)
    global_z, power = [], 0.0
    for c in range(channels):
        diff = float(np.sum((mean_a - mean_b)[..., c][covered]))
        var = float(np.sum(pixel_var[..., c][covered]))
        level = float(np.sum(mean_b[..., c][covered]))
        global_z.append(diff / np.sqrt(var) if var > 0 else (0.0 if diff == 0 else float("inf")))
        power = max(power, (global_limit + z_power) * np.sqrt(var) / level if level > 0 else float("inf"))

    n = block * block
    a, b = block_sums(mean_a, block) / n, block_sums(mean_b, block) / n

    def block_variance(var_pixels, df, replicates):
        """A block's variance of the mean and its degrees of freedom."""
        if replicates is not None and len(replicates) >= 2:
            means = np.stack([block_sums(r, block) / n for r in replicates])
            return means.var(axis=0, ddof=1) / len(replicates), np.full(means.shape[1:], len(replicates) - 1.0)
        v = block_sums(var_pixels, block) / n ** 2
        if not df:
            return v, np.full(v.shape, 1e9)
        squares = block_sums(var_pixels ** 2, block) / n ** 4
        return v, np.where(squares > 0, v * v / np.maximum(squares, 1e-300) * df, 1e9)

    va, dfa = block_variance(var_a, df_a, replicates_a)
    vb, dfb = block_variance(var_b, df_b, replicates_b)
    var = va + vb
    # Welch-Satterthwaite degrees of freedom of each block's variance.
    denominator = va * va / dfa + vb * vb / dfb
    nu = np.where(denominator > 0, var * var / np.maximum(denominator, 1e-300), 1e9)
    nu = np.maximum(nu, 5.0)
    noisy = ~noiseless(var, b)
    silent_mismatch = int(np.sum(~noisy & (np.abs(a - b) > 1e-5 * np.abs(b) + 1e-7)))
    # A block's channels come from the same paths and move together: they
    # count as one term, the mean of their z^2, whose variance is at most
    # that of one channel's.
    z2_channels = np.where(noisy, (a - b) ** 2 / np.where(noisy, var, 1.0), 0.0)
    term_mean = np.where(noisy, nu / (nu - 2), 0.0)
    term_sd = np.where(noisy, np.sqrt(2 * nu ** 2 * (nu - 1) / ((nu - 2) ** 2 * (nu - 4))), 0.0)
    channels_noisy = noisy.sum(axis=2)
    blocks = channels_noisy > 0
    k = int(blocks.sum())
    if k:
        count = channels_noisy[blocks]
        z2 = z2_channels.sum(axis=2)[blocks] / count
        means = term_mean.sum(axis=2)[blocks] / count
        sds = term_sd.sum(axis=2)[blocks] / count
        z = normal.inv_cdf(1 - alpha)
        wh = (1 - 2 / (9 * k) + z * np.sqrt(2 / (9 * k))) ** 3
        limit = float(means.mean() + (wh - 1) * np.sqrt((sds ** 2).sum() / (2 * k)))
        max_abs = float(np.sqrt(z2_channels[noisy]).max())
    else:
        z2, limit, max_abs = np.zeros(0), 0.0, 0.0
    return {"mean_z2": float(z2.mean()) if k else 0.0, "terms": k, "limit": limit,
            "global_z": [float(g) for g in global_z], "global_limit": float(global_limit),
            "power": float(power), "covered_pixels": int(np.sum(covered)),
            "noiseless_blocks_that_differ": silent_mismatch,
            "max_abs_block_z": max_abs}


def agrees(result):
    return (result["mean_z2"] <= result["limit"] and result["noiseless_blocks_that_differ"] == 0
            and all(abs(z) <= result["global_limit"] for z in result["global_z"]))


def describe(result):
    """One line: the scores, their limits and the power."""
    zs = " ".join(f"{z:+.2f}" for z in result["global_z"])
    return (f"global z {zs} (limit {result['global_limit']:.2f}, power {100 * result['power']:.2f} %); "
            f"block mean z^2 {result['mean_z2']:.3f} (limit {result['limit']:.3f}, {result['terms']} terms, "
            f"max |z| {result['max_abs_block_z']:.1f}); noiseless blocks that differ: "
            f"{result['noiseless_blocks_that_differ']}")


def load_reference(name):
    """(mean, variance, metadata) of a reference made by make_references.py, or None."""
    mean = REFERENCE_DIR / f"{name}.pfm"
    if not mean.exists():
        return None
    with open(REFERENCE_DIR / f"{name}.json") as f:
        meta = json.load(f)
    return read_pfm(mean), read_pfm(REFERENCE_DIR / f"{name}_variance.pfm"), meta
