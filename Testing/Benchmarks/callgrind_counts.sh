#!/usr/bin/env bash
# Instruction counts of mmrtm-render (callgrind: the same for the same binary
# and input whatever else the machine does), for before/after comparisons
# in Documentation/performance.md. The ct-bone preset's curves resampled at
# 256 evenly spaced keys, as the VTK mapper samples VTK's functions.
#
#   Testing/Benchmarks/callgrind_counts.sh MMRTM_RENDER VOLUME [WIDTH SPP]
#   e.g. ... build/bin/mmrtm-render ../shared/data/ct_head_cranium.nrrd 96 2
#        ... build/bin/mmrtm-render ../shared/data/ct_chest_dicom 32 1
set -euo pipefail
render="$1" volume="$2" width="${3:-96}" spp="${4:-2}"
work="$(mktemp -d)"
trap 'rm -rf "$work"' EXIT
python3 - "$work/table256.json" <<'PY'
import json, sys
def curve(points, x):
    if x <= points[0][0]: return points[0][1:]
    if x >= points[-1][0]: return points[-1][1:]
    for a, b in zip(points, points[1:]):
        if a[0] <= x <= b[0]:
            t = (x - a[0]) / (b[0] - a[0])
            return [p + (q - p) * t for p, q in zip(a[1:], b[1:])]
xs = [-1024.0 + (2986.0 + 1024.0) * i / 255 for i in range(256)]
density = [[160, 0], [300, 0.35], [700, 1]]                    # as Data/presets/ct-bone.json
albedo = [[200, 0.85, 0.72, 0.62], [900, 1, 1, 1]]
tf = lambda pts: [{"type": "cctf", "proxy": "scalars", "points": [[x] + curve(pts, x) for x in xs]}]
json.dump({"materials": {"bone": {"tfs": {"density": tf(density), "albedo": tf(albedo)}}}}, open(sys.argv[1], "w"))
PY
valgrind --tool=callgrind --callgrind-out-file="$work/callgrind.out" "$render" "$volume" --preset ct-bone \
  --scene "$work/table256.json" --width "$width" --height "$width" --spp "$spp" --threads 1 --backend cpu \
  --output "$work/image.png" 2>&1 | grep Collected
callgrind_annotate --inclusive=yes "$work/callgrind.out" 2>/dev/null |
  grep -E "SummarizeLeaf|ValueRange|mmrtm::Li\(|Classifier::Classify\(" | sed 's/(std::.*//; s/(mmrtm::.*//'
sha256sum "$work/image.png" | cut -c1-16  # the image: equal before and after
