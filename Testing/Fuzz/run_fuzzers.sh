#!/usr/bin/env bash
# Builds the libFuzzer targets (clang-14, ASan + UBSan, MMRTM_FUZZ) in BUILD
# and runs each for SECONDS seconds, as many at once as there are cores;
# the test "fuzz-short" runs it for 30 s each. Seeds: the corpora
# make_seed_corpora.py makes from the shared data, the hand-written seeds/
# and the past findings in regressions/. The corpus each run grows is kept
# in BUILD/corpus/<target> (a later run starts from it).
#
# Any finding (crash, sanitizer report, leak, hang over 20 s, an allocation
# over 1 GiB or 2 GiB resident) fails the run; its input is in
# BUILD/artifacts/<target>/. Keep it as Testing/Fuzz/regressions/<target>/<name>
# (ctest then replays it in every build) and fix the code. A slow unit or a
# hang that replays alone in under 10 s is the machine's load and is
# reported, not counted (replay_slow_units).
#
# Runs are deterministic: libFuzzer's seed is MMRTM_FUZZ_SEED (default 1; 0
# picks one at random), so a run from an empty corpus of the same code
# repeats its inputs and a finding can be replayed.
#
# MMRTM_FUZZ_FAIL_ON=ours (ctest's fuzz-short) fails only on findings whose
# first stack frame is the project's code (classify_finding.py): the
# readers of VTK, metaio and GDCM give a new crash every few seconds of a
# fresh run (Documentation/reliability.md has the figures), which would
# block every change; those are printed, and fixed by pre-checks from the
# longer runs here. The default, all, fails on any finding.
#
# MMRTM_FUZZ_KEEP_GOING=1 runs libFuzzer's fork mode (-fork=1 with crashes,
# hangs and out-of-memory ignored): the run lasts its whole time and keeps
# every finding's input, instead of stopping at the first. For the long runs
# of the reader targets, where the third-party readers fail often.
#
# Usage: run_fuzzers.sh SOURCE_DIR BUILD_DIR SECONDS [TARGET...]
# Writes BUILD/fuzz-summary.tsv: target, executions, corpus files, coverage
# (edges), features, findings.
set -euo pipefail
source="$(cd "$1" && pwd)" build="$2" seconds="$3"
shift 3
here="$source/Testing/Fuzz"
data="${MMRTM_SHARED_DATA_DIR:-$source/../shared/data}"
mkdir -p "$build"
build="$(cd "$build" && pwd)"
start=$SECONDS

CC=clang-14 CXX=clang++-14 cmake -S "$source" -B "$build" -DCMAKE_BUILD_TYPE=RelWithDebInfo \
  -DMMRTM_FUZZ=ON -DMMRTM_SANITIZE=address,undefined -DMMRTM_BUILD_TESTING=OFF -DMMRTM_BUILD_APPLICATIONS=OFF \
  -DMMRTM_WRAP_PYTHON=OFF -DMMRTM_ENABLE_QT6=OFF -DMMRTM_ENABLE_CUDA=OFF \
  > "$build/configure.log" 2>&1 || { cat "$build/configure.log"; exit 1; }
cmake --build "$build" --target mmrtm-fuzzers -j"$(nproc)" > "$build/build.log" 2>&1 ||
  { tail -50 "$build/build.log"; exit 1; }
echo "fuzz targets built in $((SECONDS - start)) s"

rm -rf "$build/seeds"
if [ -d "$data" ]; then
  /usr/bin/python3 "$here/make_seed_corpora.py" "$data" "$source" "$build/seeds"
else
  echo "$data: no shared data; seeds from Testing/Fuzz only"
fi

targets=("$@")
if [ ${#targets[@]} -eq 0 ]; then
  for program in "$build"/bin/fuzz-*; do targets+=("${program##*/fuzz-}"); done
fi

export ASAN_OPTIONS="detect_leaks=1:allocator_may_return_null=0"
export UBSAN_OPTIONS="print_stacktrace=1:halt_on_error=1"
export LSAN_OPTIONS="suppressions=$source/Testing/Sanitizers/lsan.supp:print_suppressions=0"
run_one() {
  local target="$1" build="$2" here="$3" seconds="$4"
  local corpus="$build/corpus/$target" artifacts="$build/artifacts/$target"
  rm -rf "$artifacts"
  mkdir -p "$corpus" "$artifacts" "$build/logs"
  local inputs=()
  for folder in "$build/seeds/$target" "$here/seeds/$target" "$here/regressions/$target"; do
    [ -d "$folder" ] && inputs+=("$folder")
  done
  # Inputs up to 64 KiB (a DICOM slice up to 1 MiB: its seeds are whole slices).
  local max_len=65536
  [ "$target" = dicom ] && max_len=1048576
  local options=(-max_total_time="$seconds" -seed="${MMRTM_FUZZ_SEED:-1}" -timeout=20 -rss_limit_mb=2048 -malloc_limit_mb=1024
                 -max_len=$max_len -print_final_stats=1 -artifact_prefix="$artifacts/")
  [ -f "$here/dictionaries/$target.dict" ] && options+=(-dict="$here/dictionaries/$target.dict")
  [ "${MMRTM_FUZZ_KEEP_GOING:-0}" = 1 ] && options+=(-fork=1 -ignore_crashes=1 -ignore_timeouts=1 -ignore_ooms=1)
  leaks_are_ours "$target" || options+=(-detect_leaks=0)
  # Runs from an empty folder: a target may write files relative to it.
  (cd "$artifacts" && ASAN_OPTIONS="$(asan_options_for "$target")" "$build/bin/fuzz-$target" "${options[@]}" "$corpus" "${inputs[@]}") \
    > "$build/logs/$target.log" 2>&1 || true
}
# Leaks count where the code is ours. VTK's readers and GDCM leak a few
# hundred bytes on some error paths (reliability.md lists those found):
# not ours to fix, and they would stop every run of these targets. Both
# switches are needed: libFuzzer's flag stops the check after each input,
# ASAN_OPTIONS the one at exit (which reports the run's total otherwise).
leaks_are_ours() {
  case "$1" in nrrd|nifti|metaimage|vtk-image|dicom) return 1 ;; esac
}
asan_options_for() {
  if leaks_are_ours "$1"; then echo "$ASAN_OPTIONS"; else echo "${ASAN_OPTIONS/detect_leaks=1/detect_leaks=0}"; fi
}
export -f run_one leaks_are_ours asan_options_for

# A slow unit (over libFuzzer's 10 s) or a hang is measured in wall-clock
# time, which a loaded machine stretches: ctest runs the sanitizer builds
# beside fuzz-short, and CI once reported a PNG that decodes in 2 ms as a
# 23 s unit. Each is replayed alone; one that then runs in under 10 s is
# renamed unconfirmed-* and reported as the machine's load, not a finding.
replay_slow_units() {
  local target="$1" artifacts="$build/artifacts/$1" unit name ms
  for unit in "$artifacts"/slow-unit-* "$artifacts"/timeout-*; do
    [ -f "$unit" ] || continue
    name="${unit##*/}"
    ms=$( (cd "$artifacts" && ASAN_OPTIONS="$(asan_options_for "$target")" \
             timeout 60 "$build/bin/fuzz-$target" -timeout=20 "$unit") 2>&1 |
          tee "$build/logs/$target.replay-$name.log" | sed -n 's/^Executed .* in \([0-9]*\) ms$/\1/p') || true
    if [ -n "$ms" ] && [ "$ms" -lt 10000 ]; then
      mv "$unit" "$artifacts/unconfirmed-$name"
      echo "=== fuzz-$target: $name ran in $ms ms replayed alone: the machine's load, not a finding ==="
    fi
  done
}
printf '%s\n' "${targets[@]}" | xargs -P "$(nproc)" -I{} bash -c 'run_one "$@"' _ {} "$build" "$here" "$seconds"

# The summary: libFuzzer's final statistics and the findings.
failed=0
printf 'target\texecutions\tcorpus\tcoverage\tfeatures\tfindings\n' > "$build/fuzz-summary.tsv"
for target in "${targets[@]}"; do
  replay_slow_units "$target"
  log="$build/logs/$target.log"
  runs=$(sed -n 's/^stat::number_of_executed_units: *//p' "$log" | tail -1)
  # Fork mode prints no final statistics: its status lines count the executions.
  [ -z "$runs" ] && runs=$(grep -oE '^#[0-9]+: cov' "$log" | tail -1 | tr -dc '0-9' || true)
  last=$(grep -E '^#[0-9]+' "$log" | grep -o 'cov: [0-9]* ft: [0-9]*' | tail -1)
  cov=$(echo "$last" | awk '{print $2}') ft=$(echo "$last" | awk '{print $4}')
  corpus=$(find "$build/corpus/$target" -type f | wc -l)
  findings=$(find "$build/artifacts/$target" -type f \( -name 'crash-*' -o -name 'leak-*' -o -name 'timeout-*' \
    -o -name 'oom-*' -o -name 'slow-unit-*' \) | wc -l)
  if [ -z "$runs" ] && [ "$findings" -eq 0 ]; then findings=1; fi  # it did not finish: see the log
  printf '%s\t%s\t%s\t%s\t%s\t%s\n' "$target" "${runs:-?}" "$corpus" "${cov:-?}" "${ft:-?}" "$findings" \
    >> "$build/fuzz-summary.tsv"
  if [ "$findings" -ne 0 ]; then
    owner=$(/usr/bin/python3 "$here/classify_finding.py" "$log")
    if [ "${MMRTM_FUZZ_FAIL_ON:-all}" = ours ] && [ "${owner%%:*}" = third-party ]; then
      echo "=== fuzz-$target: a finding in a third-party library, reported, not failing (MMRTM_FUZZ_FAIL_ON=ours) ==="
      echo "=== $owner"
    else
      failed=1
    fi
    echo "=== fuzz-$target: a finding (input in $build/artifacts/$target/) ==="
    grep -E -A30 'ERROR|==[0-9]+==|terminate called|deadly signal|Sanitizer' "$log" | head -60 || tail -30 "$log"
  fi
done
column -t -s $'\t' "$build/fuzz-summary.tsv"
echo "fuzzing done in $((SECONDS - start)) s"
exit $failed
