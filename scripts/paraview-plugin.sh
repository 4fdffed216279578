#!/usr/bin/env bash
# Builds the ParaView plugin (ParaView/) in the ParaView root and runs its
# tests there with ctest (Documentation/paraview.md). Called by .ci/run;
# needs root (debootstrap, chroot, namespaces).
#
#   scripts/paraview-plugin.sh
#
# The build is build-paraview/build; test images, films and logs are under
# build-paraview/build/Testing/output.
set -euo pipefail
here="$(cd "$(dirname "$0")/.." && pwd)"
start=$(date +%s)
"$here/scripts/paraview-root.sh" ensure
echo "paraview-plugin.sh: root ready ($(( $(date +%s) - start )) s); building the plugin" >&2
"$here/scripts/paraview-root.sh" run bash -euo pipefail -c '
  cd "$1"
  log=build-paraview/build.log
  mkdir -p build-paraview
  { cmake -S ParaView -B build-paraview/build -G Ninja -DCMAKE_BUILD_TYPE=Release &&
    cmake --build build-paraview/build; } >"$log" 2>&1 \
    || { grep -E "error|Error|FAILED" "$log" | head -40; echo "the plugin build failed (log: $log)"; exit 1; }
  # Serially: the MPI tests use both cores.
  ctest --test-dir build-paraview/build --output-on-failure -V 2>&1 \
    | grep -E "^[0-9]+: (ok|FAIL|first render|.*samples a pixel)|Test +#|tests passed|tests failed|Failed|\*\*\*"
' paraview-plugin "$here"
echo "paraview-plugin.sh: passed in $(( $(date +%s) - start )) s" >&2
