#!/usr/bin/env python3
"""Memory per voxel for each dataset against the size of its raw data.

    Testing/Accuracy/memory_table.py

Renders each dataset once (32 x 32, 1 spp: only the scene's set-up matters)
and reads the "memory" block of mmrtm-render --stats-json: the proxies'
voxels as kept (native types, only proxies some TF reads), the majorant grid
(all levels; a float majorant and a byte minorant per node), the grid's
per-leaf value summaries (host only; refits read them) and the TF tables,
against the input volumes as read. Prints a Markdown table, and one of the
distinct leaf summaries against the leaves, and keeps the numbers in
MMRTM_REFERENCE_DIR/memory.json.
"""

import json

import mmrtm_accuracy as acc

DATASETS = [
    # name, mmrtm-render arguments
    *[(name, scene["args"]) for name, scene in acc.SCENES.items()],
    ("ct_head_headsq (small CT)", [acc.data_path("ct_head_headsq.nrrd"), "--preset", "ct-bone"]),
    ("ct_abdomen + 31 labels (ct-organs)", [acc.data_path("ct_abdomen.nii.gz"), "--labels",
                                            acc.data_path("ct_abdomen_labels.nii.gz"), "--label-table",
                                            acc.data_path("ct_abdomen_labels.txt"), "--preset", "ct-organs"]),
]


def main():
    rows = {}
    print("| dataset | voxels | input MiB | input B/voxel | proxies MiB | majorants MiB | summaries MiB | "
          "held B/voxel | held / input |")
    print("|---|---|---|---|---|---|---|---|---|")
    mib = 1 << 20
    for name, args in DATASETS:
        m = acc.render(args, 32, 32, 1).stats["memory"]
        rows[name] = m
        held = m["bytes_per_voxel"] * m["voxels"]
        print(f"| {name} | {m['voxels']:,.0f} | {m['input_voxel_bytes'] / mib:.1f} | {m['input_bytes_per_voxel']:.2f} | "
              f"{m['proxy_voxel_bytes'] / mib:.1f} | {(m['majorant_bytes'] + m['minorant_bytes']) / mib:.2f} | "
              f"{m['summary_bytes'] / mib:.1f} | "
              f"{m['bytes_per_voxel']:.2f} | {held / m['input_voxel_bytes']:.2f} |", flush=True)
    # The summaries' memory follows the distinct leaf summaries (each stored
    # once) and the leaves (an id each).
    print("\n| dataset | distinct leaf summaries | leaves |")
    print("|---|---|---|")
    for name, m in rows.items():
        print(f"| {name} | {m['distinct_leaf_summaries']:,} | {m['grid_leaves']:,} |")
    acc.REFERENCE_DIR.mkdir(parents=True, exist_ok=True)
    (acc.REFERENCE_DIR / "memory.json").write_text(json.dumps(rows, indent=1))


if __name__ == "__main__":
    main()
