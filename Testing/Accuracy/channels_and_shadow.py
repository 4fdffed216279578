#!/usr/bin/env python3
"""Two modelling choices against their unbiased alternatives.

    Testing/Accuracy/channels_and_shadow.py [--part channels|shadow|both]

1. Paper section 6.5: single-channel extinction with RGB albedo (what the
   tracer does, DESIGN.md rule 3) against RGB (chromatic) extinction. The
   tracer has no chromatic extinction, so Mitsuba 3 renders both versions of
   the Mitsuba-check medium (mitsuba_check.py), with the same integrator and
   samples: the chromatic one has sigma_t,c = sigma_t k_c and albedo a. Two
   single-channel ones stand for two ways of "adjusting the TF" (the paper's
   words): extinction sigma_t k_mean with the same albedo a, or with the
   albedo that keeps each channel's scattering coefficient, a k_c / k_mean.
   Reported: the difference of the converged images, and the error of each
   at equal samples per pixel against its own converged image.
2. The shadow-ray extinction scale 0.8 (paper section 3.3, an artistic bias)
   against 1.0: on every reference scene, the mean brightening and the
   relative RMSE of the 0.8 image against the unbiased reference, beside the
   noise of the same render.

Writes Documentation/images/channels.png and shadow_scale.png, and the
numbers to MMRTM_REFERENCE_DIR/channels.json and shadow_scale.json.
"""

import argparse
import json
import sys
from pathlib import Path

import numpy as np

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

sys.path.insert(0, str(Path(__file__).resolve().parent))
import mitsuba_check as mc  # noqa: E402
import mmrtm_accuracy as acc  # noqa: E402

K = np.array([1.2, 1.0, 0.8])  # chromatic extinction: red light is stopped most (a bluish translucency)
ALBEDO = 0.7


def mitsuba_medium(density, spacing, extent, cam, size, spp, seed, config):
    import mitsuba as mi
    kmean = K.mean()
    if config == "rgb_extinction":
        sigma = density[..., None] * K[None, None, None, :]
        albedo = np.full(density.shape + (3,), ALBEDO)
        scale = mc.SIGMA_MAX
    else:
        sigma = density[..., None]
        scale = mc.SIGMA_MAX * kmean
        # "same_albedo": the mean extinction and the same albedo; "matched_scattering":
        # the albedo that keeps each channel's scattering coefficient, a k_c / k_mean.
        a = np.full(3, ALBEDO) if config == "same_albedo" else np.minimum(1.0, ALBEDO * K / kmean)
        albedo = np.broadcast_to(a, density.shape + (3,)).copy()
    scene = mc.mitsuba_scene("scalar_rgb", sigma, albedo, scale, spacing, extent, cam, size, spp)
    return np.array(mi.render(scene, spp=spp, seed=seed), dtype=np.float64)[..., :3]


CONFIGS = {"rgb_extinction": "RGB sigma_t, albedo 0.7",
           "same_albedo": "mean sigma_t, albedo 0.7",
           "matched_scattering": "mean sigma_t, albedo 0.7 k / k_mean"}


def channels(size, converged_spp, low_spp):
    density, _, spacing = mc.make_grids()
    cam, extent = mc.camera(density, spacing)
    out = {}
    images = {}
    for config in CONFIGS:
        ref = mitsuba_medium(density, spacing, extent, cam, size, converged_spp, 100, config)
        low = [mitsuba_medium(density, spacing, extent, cam, size, low_spp, 200 + i, config) for i in range(4)]
        errors = [acc.relative_rmse(im, ref) for im in low]
        images[config] = ref
        images[config + "_low"] = low[0]
        out[config] = {"rel_rmse_at_low_spp": float(np.mean(errors)), "low_spp": low_spp,
                       "mean": float(ref.mean())}
        print(f"{config}: relative RMSE at {low_spp} spp {np.mean(errors):.4f}", flush=True)
    for config in ("same_albedo", "matched_scattering"):
        out[config]["difference_to_rgb"] = acc.relative_rmse(images[config], images["rgb_extinction"])
        out[config]["mean_ratio_to_rgb"] = float(images[config].mean() / images["rgb_extinction"].mean())
    # The converged images' own noise (in each difference twice): from the
    # low-spp errors, scaled by sqrt(low / converged samples).
    out["converged_noise_estimate"] = float(out["rgb_extinction"]["rel_rmse_at_low_spp"] *
                                            np.sqrt(low_spp / converged_spp))
    out.update({"size": size, "converged_spp": converged_spp, "k": K.tolist(), "albedo": ALBEDO})
    print(json.dumps(out, indent=1))

    def show(im):
        return np.clip(im / (1 + im), 0, 1) ** (1 / 2.2)

    fig, ax = plt.subplots(2, 4, figsize=(14, 7.4))
    for row, config in enumerate(("same_albedo", "matched_scattering")):
        panels = [(CONFIGS["rgb_extinction"], show(images["rgb_extinction"])),
                  (CONFIGS[config], show(images[config])),
                  (f"|difference| x 10 (rel. RMSE {out[config]['difference_to_rgb']:.3f})",
                   np.clip(10 * np.abs(images[config] - images["rgb_extinction"]), 0, 1)),
                  (f"{CONFIGS[config]}, {low_spp} spp (error {out[config]['rel_rmse_at_low_spp']:.3f})",
                   show(images[config + "_low"]))]
        if row == 1:
            panels[0] = (f"{CONFIGS['rgb_extinction']}, {low_spp} spp (error "
                         f"{out['rgb_extinction']['rel_rmse_at_low_spp']:.3f})", show(images["rgb_extinction_low"]))
        for a, (title, im) in zip(ax[row], panels):
            a.imshow(im)
            a.set_title(title, fontsize=8)
            a.axis("off")
    fig.suptitle(f"Paper 6.5 with Mitsuba 3 volpath: RGB extinction (k = {K.tolist()}) against one channel; "
                 f"converged at {converged_spp} spp", fontsize=10)
    fig.tight_layout()
    fig.savefig(acc.DOC_IMAGES / "channels.png", dpi=90)
    plt.close(fig)
    return out


def shadow(spp):
    out = {}
    for name in acc.SCENES:
        ref = acc.load_reference(name)
        if ref is None:
            raise SystemExit(f"no reference for {name}: run make_references.py first")
        ref_mean, ref_var, _ = ref
        row = {}
        for scale in (0.8, 1.0):
            r = acc.render(acc.SCENES[name]["args"], acc.REFERENCE_SIZE, acc.REFERENCE_SIZE, spp, seed=11,
                           extra=["--shadow-scale", str(scale)])
            row[str(scale)] = {"rel_rmse": acc.relative_rmse(r.mean, ref_mean, ref_var),
                               "mean_ratio": float(r.mean.mean() / ref_mean.mean()),
                               "noise": acc.relative_noise(r.mean, r.variance), "seconds": r.seconds}
        out[name] = row
        print(f"{name:13s} scale 0.8: mean x{row['0.8']['mean_ratio']:.3f}, rel. RMSE {row['0.8']['rel_rmse']:.4f}; "
              f"scale 1: mean x{row['1.0']['mean_ratio']:.3f}, rel. RMSE {row['1.0']['rel_rmse']:.4f} "
              f"(noise {row['1.0']['noise']:.4f})", flush=True)
    fig, a = plt.subplots(figsize=(8, 3.8))
    names = list(out)
    x = np.arange(len(names))
    a.bar(x - 0.2, [out[n]["0.8"]["rel_rmse"] for n in names], 0.4, label="shadow scale 0.8 (default)")
    a.bar(x + 0.2, [out[n]["1.0"]["rel_rmse"] for n in names], 0.4, label="shadow scale 1 (unbiased)")
    for i, n in enumerate(names):
        a.text(i - 0.2, out[n]["0.8"]["rel_rmse"], f"x{out[n]['0.8']['mean_ratio']:.3f}", ha="center",
               va="bottom", fontsize=7)
    a.set_xticks(x, [acc.SCENES[n]["title"] for n in names], fontsize=7, rotation=12)
    a.set_ylabel(f"relative RMSE against the reference ({spp} spp)")
    a.set_title("Shadow extinction scale: the error it adds (labels: mean brightness vs reference)", fontsize=9)
    a.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(acc.DOC_IMAGES / "shadow_scale.png", dpi=100)
    plt.close(fig)
    return out


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--part", choices=("channels", "shadow", "both"), default="both")
    parser.add_argument("--size", type=int, default=96)
    parser.add_argument("--converged-spp", type=int, default=1024)
    parser.add_argument("--low-spp", type=int, default=16)
    parser.add_argument("--shadow-spp", type=int, default=256)
    args = parser.parse_args()
    acc.REFERENCE_DIR.mkdir(parents=True, exist_ok=True)
    if args.part in ("channels", "both"):
        result = channels(args.size, args.converged_spp, args.low_spp)
        (acc.REFERENCE_DIR / "channels.json").write_text(json.dumps(result, indent=1))
    if args.part in ("shadow", "both"):
        result = shadow(args.shadow_spp)
        (acc.REFERENCE_DIR / "shadow_scale.json").write_text(json.dumps(result, indent=1))


if __name__ == "__main__":
    main()
