#!/usr/bin/env bash
# The test "sanitizers-address-undefined": builds the project with
# AddressSanitizer and UndefinedBehaviorSanitizer (MMRTM_SANITIZE) in BUILD
# and runs its C++ tests there (the GoogleTest suite, the regression image
# program, the command line, the viewer): any report fails (no recovery;
# leaks too where no OpenGL driver is loaded, but for the suppressions in
# lsan.supp, each with its reason).
# Left out: the Python suites (CPython and VTK's Python are not
# instrumented) and the accuracy checks (minutes of rendering, unchanged by
# the sanitizers). Documentation/reliability.md gives the figures.
#
# Usage: run_sanitized_suite.sh SOURCE_DIR BUILD_DIR
set -euo pipefail
source="$1" build="$2"
here="$(cd "$(dirname "$0")" && pwd)"
start=$SECONDS
cmake -S "$source" -B "$build" -DCMAKE_BUILD_TYPE=RelWithDebInfo -DMMRTM_SANITIZE=address,undefined \
  -DMMRTM_WRAP_PYTHON=OFF > "$build.configure.log" 2>&1 || { cat "$build.configure.log"; exit 1; }
cmake --build "$build" -j"$(nproc)" > "$build.build.log" 2>&1 || { tail -50 "$build.build.log"; exit 1; }
echo "built with address,undefined in $((SECONDS - start)) s"
export LSAN_OPTIONS="suppressions=$here/lsan.supp:print_suppressions=0"
export UBSAN_OPTIONS="print_stacktrace=1:halt_on_error=1"
# Leaks are checked where no OpenGL driver is loaded: Mesa's drivers are
# unloaded at exit and their allocations show as leaks of an unknown module.
gl="viewer-|vtkMapper-|example-"
ASAN_OPTIONS="detect_leaks=1:detect_stack_use_after_return=0" \
  ctest --test-dir "$build" -j"$(nproc)" --output-on-failure -E "accuracy|vtk96|$gl" --timeout 900
ASAN_OPTIONS="detect_leaks=0:detect_stack_use_after_return=0" \
  ctest --test-dir "$build" -j"$(nproc)" --output-on-failure -R "$gl" --timeout 900
echo "sanitized suite done in $((SECONDS - start)) s"
