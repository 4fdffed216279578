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


# The reference scenes of Documentation/accuracy.md: input and options of
# mmrtm-render. Every one is 256 x 256 and uses the scene's own camera.
SCENES = {
    "head_ct_bone": {
        "title": "head CT, ct-bone",
        "args": [data_path("ct_head_cranium.nrrd"), "--preset", "ct-bone"],
    },
    "chest_ct": {
        "title": "chest CT (DICOM), ct-soft-tissue",
        "args": [data_path("ct_chest_dicom"), "--preset", "ct-soft-tissue"],
    },
    "cta_labels": {
        "title": "chest CTA, vessel labels as materials",
        "args": [data_path("cta_chest_aorta.nii.gz"), "--labels", data_path("cta_chest_aorta_labels.nii.gz"),
                 "--preset", "ct-angio-labels"],
    },
    "bonsai": {
        "title": "bonsai",
        "args": [data_path("bonsai.nii.gz"), "--scene", str(ROOT / "Data" / "benchmarks" / "bonsai.json")],
    },
    "mri_labels": {
        "title": "MRI head, brain and skull labels",
        "args": [data_path("mr_head.nii.gz"), "--labels", data_path("mr_head_labels.nii.gz"),
                 "--scene", str(ROOT / "Data" / "benchmarks" / "mr_head_labels.json")],
    },
}

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
    """One run of mmrtm-render: mean image, variance of the mean, and its --stats-json."""

    def __init__(self, mean, variance, stats):
        self.mean, self.variance, self.stats = mean, variance, stats

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


def block_agreement(mean_a, var_a, mean_b, var_b, block=4):
    """Whether two independent, unbiased estimates of one image agree within noise.

    On block x block pixel blocks: z = (block mean a - block mean b) /
    sqrt(var a + var b), each block's variance summed from the per-pixel
    variances of the means (so it is well estimated even from few samples per
    pixel). For agreeing images the mean of z^2 over K blocks and channels is
    1 with standard deviation sqrt(2 / K); `limit` is 1 + 5 sqrt(2 / K), a
    one-in-a-million tail, which a bias of a fraction of the noise exceeds.
    Blocks without noise (float rounding leaves ~1e-17 there, e.g. where only
    the constant environment is seen) must agree to float precision. A block
    counts as noiseless only below (1e-7 of its value)^2: a block that one
    rare collision makes noisy (a variance of ~1e-11 at the medium's edge,
    seen at 128 x 128 and 2048 spp) is z-tested, not held to 1e-5.
    """
    n = block * block
    a, b = block_sums(mean_a, block) / n, block_sums(mean_b, block) / n
    var = (block_sums(var_a, block) + block_sums(var_b, block)) / n ** 2
    noisy = var > (1e-7 * (np.abs(b) + 1e-3)) ** 2
    silent_mismatch = int(np.sum(~noisy & (np.abs(a - b) > 1e-5 * np.abs(b) + 1e-7)))
    z2 = (a - b)[noisy] ** 2 / var[noisy]
    k = int(z2.size)
    return {"mean_z2": float(z2.mean()) if k else 0.0, "terms": k, "limit": 1 + 5 * float(np.sqrt(2 / max(k, 1))),
            "noiseless_blocks_that_differ": silent_mismatch,
            "max_abs_block_z": float(np.sqrt(z2).max()) if k else 0.0}


def agrees(result):
    return result["mean_z2"] <= result["limit"] and result["noiseless_blocks_that_differ"] == 0


def load_reference(name):
    """(mean, variance, metadata) of a reference made by make_references.py, or None."""
    mean = REFERENCE_DIR / f"{name}.pfm"
    if not mean.exists():
        return None
    with open(REFERENCE_DIR / f"{name}.json") as f:
        meta = json.load(f)
    return read_pfm(mean), read_pfm(REFERENCE_DIR / f"{name}_variance.pfm"), meta
