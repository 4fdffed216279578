#!/usr/bin/env python3
"""Charts of the failure cases (Documentation/accuracy.md, "Where methods fail").

    Testing/Accuracy/failure_charts.py

Runs build/bin/mmrtm-bench-failure-cases (the scenes of TestFailureCases),
keeps its numbers in MMRTM_REFERENCE_DIR/failure_cases.json and draws
Documentation/images/failure_cases.png.
"""

import json
import subprocess

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

import mmrtm_accuracy as acc  # noqa: E402


def main():
    bench = acc.BUILD / "bin" / "mmrtm-bench-failure-cases"
    data = json.loads(subprocess.run([str(bench)], check=True, capture_output=True, text=True).stdout)
    acc.REFERENCE_DIR.mkdir(parents=True, exist_ok=True)
    (acc.REFERENCE_DIR / "failure_cases.json").write_text(json.dumps(data, indent=1))

    fig, ax = plt.subplots(2, 3, figsize=(15, 8.5))

    # 1. Narrow TF peak: transmittance against the ray-marching step.
    a = ax[0, 0]
    peak = data["narrow_peak"]
    rm = peak["ray_marching"]
    exact = rm[0]["exact"]
    a.errorbar([r["step"] for r in rm], [r["T"] for r in rm], yerr=[3 * r["se"] for r in rm], marker="o",
               color="tab:purple", label="ray marching (jittered)")
    a.axhline(exact, color="k", lw=1, label=f"exact T = {exact:.3f}")
    a.axhline(peak["delta_octree"]["T"], color="tab:green", ls="--", label="delta tracking, octree")
    a.axhline(peak["delta_voxelmax"]["T"], color="tab:olive", ls=":", label="delta tracking, voxel-max majorant")
    a.set_xscale("log")
    a.set_xlabel("ray-marching step, mm")
    a.set_ylabel("transmittance")
    a.set_title("narrow TF peak (0.2 value units wide, between voxel values)", fontsize=9)
    a.legend(fontsize=7)

    # 2. Sparse dense block: lookups per ray against the volume size.
    a = ax[0, 1]
    for name, colour in (("none", "tab:gray"), ("macrocell", "tab:blue"), ("octree", "tab:green")):
        rows = data["sparse_block"][name]
        a.loglog([r["n"] for r in rows], [r["lookups_per_ray"] for r in rows], marker="o", color=colour,
                 label=f"{name}: max |T - exact| / se = "
                       f"{max(abs(r['T'] - r['exact']) / r['se'] for r in rows):.1f}")
    a.set_xlabel("volume size n (n^3 voxels, one 2^3 dense block)")
    a.set_ylabel("density lookups per shadow ray")
    a.set_title("sparse dense structure in an empty volume", fontsize=9)
    a.legend(fontsize=7)

    # 3. Very dense media: lookups and real collisions per path against density.
    a = ax[0, 2]
    for key, colour, label in (("auto_leaves", "tab:green", "octree, automatic leaves (1 cell here)"),
                               ("leaf_level_4", "tab:cyan", "octree, leaf level 4 (2-cell leaves)")):
        rows = data["dense_media"][key]
        a.loglog([r["density"] for r in rows], [r["lookups_per_path"] for r in rows], marker="o", color=colour,
                 label=f"lookups / path, {label}")
    rows = data["dense_media"]["auto_leaves"]
    a.loglog([r["density"] for r in rows], [r["real_per_path"] for r in rows], marker="s", color="tab:red",
             label="real collisions / path (albedo 0.8)")
    a.set_xlabel("extinction at TF value 1, per mm")
    a.set_ylabel("per path")
    a.set_title("very dense media (a ball, 1 mm voxels)", fontsize=9)
    a.legend(fontsize=7)

    # 4. The bounce limit with albedo 1 (Russian roulette cannot end such paths).
    a = ax[1, 0]
    rows = data["dense_media"]["albedo_one_bounce_limit"]
    a.plot([r["max_bounces"] for r in rows], [r["max_real_per_path"] for r in rows], marker="o",
           color="tab:red", label="most real collisions in one path")
    a.plot([r["max_bounces"] for r in rows], [r["real_per_path"] for r in rows], marker="s", color="tab:orange",
           label="mean real collisions per path")
    a.plot([r["max_bounces"] for r in rows], [r["max_bounces"] + 1 for r in rows], "k:", label="bounce limit + 1")
    a.set_xlabel("max_bounces")
    a.set_ylabel("real collisions")
    a.set_title("albedo 1, extinction 1e4 / mm: only the bounce limit ends paths", fontsize=9)
    a.legend(fontsize=7)

    # 5. Grazing rays along a one-voxel sheet on a node face.
    a = ax[1, 1]
    for name, colour, marker in (("macrocell", "tab:blue", "o"), ("octree", "tab:green", "x")):
        rows = data["grazing"][name]
        a.plot(range(len(rows)), [(r["T"] - r["exact"]) / r["se"] for r in rows], marker=marker, ls="",
               color=colour, label=name)
    labels = [f"{r['dz']:g}" for r in data["grazing"]["octree"]]
    a.set_xticks(range(len(labels)), labels, fontsize=7)
    a.axhspan(-4, 4, color="0.9", label="within 4 standard errors")
    a.set_xlabel("ray height above the sheet's slice (on a node face), voxels")
    a.set_ylabel("(T - exact) / standard error")
    a.set_title("grazing rays along a slice", fontsize=9)
    a.legend(fontsize=7)

    # 6. Degenerate TFs.
    a = ax[1, 2]
    cases = ("all_zero", "all_one", "step_at_maximum")
    names = ("none", "macrocell", "octree")
    for i, name in enumerate(names):
        zs = [(data["degenerate_tf"][c][name]["T"] - data["degenerate_tf"][c][name]["exact"]) /
              max(data["degenerate_tf"][c][name]["se"], 1e-9) for c in cases]
        a.bar([j + 0.25 * (i - 1) for j in range(3)], zs, width=0.25, label=name)
    a.axhspan(-4, 4, color="0.9", zorder=0)
    a.set_xticks(range(3), ["all zero", "all one", "step at data max"])
    a.set_ylabel("(T - exact) / standard error")
    a.set_title("degenerate TFs (no majorant violation in any)", fontsize=9)
    a.legend(fontsize=7)

    fig.suptitle("Where methods fail: each panel is a test in TestFailureCases")
    fig.tight_layout()
    out = acc.DOC_IMAGES / "failure_cases.png"
    fig.savefig(out, dpi=100)
    print(f"wrote {out}")


if __name__ == "__main__":
    main()
