#!/usr/bin/env bash
# The tests "sanitizers-address-undefined" and "sanitizers-thread": builds
# the project with the given sanitizers (MMRTM_SANITIZE) in BUILD and runs
# its C++ tests there: the GoogleTest suite, the regression image program,
# the mapper's soak, the command line, the viewer. Any report fails (no
# recovery).
#
# address,undefined: every C++ test; leaks too where no OpenGL driver is
# loaded, but for the suppressions in lsan.supp, each with its reason.
# thread: the tests that start the project's threads (each render on the
# CPU tile pool, the majorant build, the mapper's asynchronous refinement
# and the soak), but the viewer's and the statistical ones, with the
# suppressions in tsan.supp. The
# viewer's QTests are left out: Qt 6 synchronises its threads through
# futexes that TSan cannot see in Debian's uninstrumented Qt, so every
# queued signal reads as a race;
# the viewer's refinement thread is the mapper's, which the soak covers.
# Left out: the Python suites (CPython and VTK's Python are not
# instrumented) and the accuracy checks (minutes of rendering, unchanged by
# the sanitizers). Documentation/reliability.md gives the figures.
#
# Usage: run_sanitized_suite.sh SOURCE_DIR BUILD_DIR [SANITIZERS]   (default address,undefined)
set -euo pipefail
source="$1" build="$2" sanitizers="${3:-address,undefined}"
here="$(cd "$(dirname "$0")" && pwd)"
start=$SECONDS
# ASan+UBSan at -O1, as the sanitizers' authors advise: with -g1
# (CMakeLists.txt) its build takes a third of -O2 -g's time
# (TestMajorantGrid.cpp: 21 s against 58 s) and its tests lose little
# (515 s against 455 s). TSan stays at -O2: its compile is cheap (16 s for
# that file) and its tests are the long part (at -O1, beside the ASan
# suite, 1956 s, the soak 651 s of it; reliability.md). It leaves out the
# viewer it never runs (below).
level=-O1 options=()
if [ "$sanitizers" = thread ]; then level=-O2 options=(-DMMRTM_ENABLE_QT6=OFF -DMMRTM_SOAK_ITERATIONS=150); fi
options+=(-DCMAKE_CXX_FLAGS_RELWITHDEBINFO="$level -DNDEBUG" -DCMAKE_C_FLAGS_RELWITHDEBINFO="$level -DNDEBUG")
cmake -S "$source" -B "$build" -DCMAKE_BUILD_TYPE=RelWithDebInfo -DMMRTM_SANITIZE="$sanitizers" \
  -DMMRTM_WRAP_PYTHON=OFF "${options[@]}" > "$build.configure.log" 2>&1 || { cat "$build.configure.log"; exit 1; }
cmake --build "$build" -j"$(nproc)" > "$build.build.log" 2>&1 || { tail -50 "$build.build.log"; exit 1; }
echo "built with $sanitizers in $((SECONDS - start)) s"
export UBSAN_OPTIONS="print_stacktrace=1:halt_on_error=1"
# Tests that load uninstrumented libraries which the sanitizer runtimes
# refuse skip that part (the CLI's denoised preview: OIDN's TBB dlopens with
# RTLD_DEEPBIND), saying so.
export MMRTM_SANITIZED="$sanitizers"
gl="viewer-|vtkMapper-|example-"
if [ "$sanitizers" = thread ]; then
  # The soak is the one rendering test that checks leaks itself (before its
  # exit, with the OpenGL driver still loaded): TSan has no leak checker.
  export TSAN_OPTIONS="halt_on_error=1:second_deadlock_stack=1:suppressions=$here/tsan.supp:print_suppressions=0"
  # Without address-space randomisation where we may turn it off: GCC 12's
  # TSan dies ("unexpected memory mapping") on kernels that randomise with
  # more than 28 bits (vm.mmap_rnd_bits), as newer ones do.
  norandom=()
  if setarch "$(uname -m)" -R true 2>/dev/null; then norandom=(setarch "$(uname -m)" -R); fi
  # The statistical tests (replicated renders to a power of 1-2 %, minutes
  # each under TSan) are left out: they render on the same tile pool as the
  # other two hundred tests here, and what TSan looks for is in the threads,
  # not in the number of samples. ASan+UBSan runs them.
  statistical="ImageCT\.|Furnace|Unbiased\.|SurfaceScene\.|LightSampling\.EveryMode|AdaptiveSampling\.Agrees"
  statistical+="|vtkMapper-(ct-bone|oblique|labels|rgba|mesh)$"
  # Also left out: the programs that start no thread of the project's (label
  # single-threaded: samplers, BSDFs, parsers of tables), and the C++
  # example, whose synchronous render of the head CT through the mapper the
  # vtkMapper tests make too. The soak runs 150 iterations here (the build's
  # MMRTM_SOAK_ITERATIONS, above): some 25 edits during a refinement in flight.
  "${norandom[@]}" ctest --test-dir "$build" -j"$(nproc)" --output-on-failure \
    -E "accuracy|vtk96|viewer-|example-|$statistical" -LE single-threaded --timeout 1800
else
  export LSAN_OPTIONS="suppressions=$here/lsan.supp:print_suppressions=0"
  # Leaks are checked where no OpenGL driver is loaded: Mesa's drivers are
  # unloaded at exit and their allocations show as leaks of an unknown
  # module. The soak checks its own before it exits (the driver loaded).
  ASAN_OPTIONS="detect_leaks=1:detect_stack_use_after_return=0" \
    ctest --test-dir "$build" -j"$(nproc)" --output-on-failure -E "accuracy|vtk96|$gl" --timeout 900
  ASAN_OPTIONS="detect_leaks=0:detect_stack_use_after_return=0" \
    ctest --test-dir "$build" -j"$(nproc)" --output-on-failure -R "$gl" -E soak --timeout 900
  ASAN_OPTIONS="detect_leaks=1:detect_stack_use_after_return=0" \
    ctest --test-dir "$build" --output-on-failure -R soak --timeout 1800
fi
echo "sanitized suite ($sanitizers) done in $((SECONDS - start)) s"
