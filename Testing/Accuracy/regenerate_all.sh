#!/usr/bin/env bash
# Regenerates every figure and chart of Documentation/accuracy.md and the
# speed-accuracy part of Documentation/performance.md, in order. Needs a
# Release build in build/ and the .venv of scripts/install-dependencies.sh.
# About 2.5 hours on 2 cores with the defaults; REFERENCE_SPP=16384 makes it
# an overnight run with references 2.8 times less noisy.
set -euo pipefail
cd "$(dirname "$0")"
py=../../.venv/bin/python
[ -x "$py" ] || { echo "regenerate_all.sh: no $py; run scripts/install-dependencies.sh" >&2; exit 1; }
mkdir -p ../../build/references
log() { echo "== $* ($(date +%H:%M:%S))" >&2; }
log "references";            "$py" make_references.py --spp "${REFERENCE_SPP:-2048}"
# MMRTM_ISSUE15_RENDER: a build of c669328 (time_to_error.py's help), drawn as "before".
log "speed against accuracy"; "$py" speed_accuracy.py ${MMRTM_ISSUE15_RENDER:+--issue-binary "$MMRTM_ISSUE15_RENDER"}
log "Mitsuba 3 check";       "$py" mitsuba_check.py --save ../../build/references/mitsuba | tee ../../build/references/mitsuba.log
log "noise target";          "$py" noise_target_check.py --json ../../build/references/noise_target.json
log "failure cases";         "$py" failure_charts.py
log "channels and shadow";   "$py" channels_and_shadow.py
log "plain-scene overhead";  "$py" plain_scene_overhead.py
log "memory";                "$py" memory_table.py | tee ../../build/references/memory.md
log "done"
