#!/usr/bin/env python3
"""Renders the converged reference images of the accuracy report.

    Testing/Accuracy/make_references.py [--spp N] [--only NAME ...]

For each scene of mmrtm_accuracy.SCENES: 256 x 256, delta tracking with the
octree (the unbiased default), a fixed seed, written to MMRTM_REFERENCE_DIR
(default build/references, not committed) as NAME.pfm (linear mean),
NAME_variance.pfm (variance of that mean), NAME.png (to look at) and
NAME.json (the render's statistics), and Documentation/images/references.png
(all five side by side). The seed differs from every seed the
speed charts use, so a reference and a measured image are independent.

The default of 2048 samples per pixel takes about half an hour on 2 cores for
all five scenes; --spp 16384 is an overnight run (8 times longer, noise down
by 2.8).
"""

import argparse
import time

from PIL import Image

import mmrtm_accuracy as acc

REFERENCE_SEED = 1000003


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--spp", type=int, default=2048)
    parser.add_argument("--size", type=int, default=acc.REFERENCE_SIZE)
    parser.add_argument("--only", nargs="*", choices=sorted(acc.SCENES), help="render only these scenes")
    args = parser.parse_args()
    acc.REFERENCE_DIR.mkdir(parents=True, exist_ok=True)
    names = args.only or list(acc.SCENES)
    for i, name in enumerate(names):
        start = time.time()
        print(f"[{i + 1}/{len(names)}] {name}: {args.size}^2, {args.spp} spp ...", flush=True)
        r = acc.render(acc.SCENES[name]["args"], args.size, args.size, args.spp, seed=REFERENCE_SEED,
                       extra=["--shadow-scale", "1"], keep=acc.REFERENCE_DIR / name)
        print(f"    {time.time() - start:.0f} s; relative noise {acc.relative_noise(r.mean, r.variance):.4f}, "
              f"mean {r.mean.mean():.4f} -> {acc.REFERENCE_DIR / name}.pfm", flush=True)
    montage()


def montage():
    """Documentation/images/references.png: the five references side by side."""
    images = [Image.open(acc.REFERENCE_DIR / f"{name}.png") for name in acc.SCENES
              if (acc.REFERENCE_DIR / f"{name}.png").exists()]
    if not images:
        return
    w, h = images[0].size
    sheet = Image.new("RGB", (len(images) * (w + 4) - 4, h), (255, 255, 255))
    for i, im in enumerate(images):
        sheet.paste(im, (i * (w + 4), 0))
    sheet.save(acc.DOC_IMAGES / "references.png")


if __name__ == "__main__":
    main()
