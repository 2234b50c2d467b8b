#!/usr/bin/env bash
# Builds the libFuzzer targets (fuzz/) with clang-14 into ./build-fuzz and runs each for
# SECONDS (default 20), two at a time, starting from the seeds in tests/fuzz_corpus/.
#
#   scripts/fuzz.sh [SECONDS] [--all]
#
# By default (the CI run) only the readers (off obj ply stl) and the pipeline parser are
# fuzzed: they build from a handful of files. --all adds the structuring-element parser and
# the kernel/morphology target, which need the whole library (several minutes to build).
# Fails (exit 1) on any crash, sanitizer report, leak, timeout or out-of-memory; the input
# is saved in build-fuzz/artifacts/ -- add it to tests/fuzz_corpus/<target>/ as a
# regression seed (replayed by tests/fault_test.cpp) once fixed.
set -euo pipefail
cd "$(dirname "$0")/.."
root=$(pwd)

seconds=20
all=0
for arg in "$@"; do
  case "$arg" in
    --all) all=1 ;;
    ''|*[!0-9]*) echo "usage: scripts/fuzz.sh [SECONDS] [--all]" >&2; exit 2 ;;
    *) seconds="$arg" ;;
  esac
done

targets=(read_off read_obj read_ply read_stl pipeline)
[ "$all" -eq 1 ] && targets+=(se_spec kernel)

jobs=2
start=$(date +%s)
CC=clang-14 CXX=clang++-14 cmake -S . -B build-fuzz -DCMAKE_BUILD_TYPE=RelWithDebInfo \
  -DCMAKE_CXX_FLAGS_RELWITHDEBINFO="-O1 -g1" -DMORPH_BUILD_FUZZERS=ON -DMORPH_BUILD_APPS=OFF \
  -DMORPH_BUILD_TESTS=OFF -DMORPH_BUILD_BENCHMARKS=OFF >/dev/null
cmake --build build-fuzz -j"$jobs" --target "${targets[@]/#/fuzz_}" >/dev/null
echo "fuzz: built ${#targets[@]} targets in $(( $(date +%s) - start )) s"

work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
mkdir -p build-fuzz/artifacts
empty="$work/cwd"  # the SE fuzzer runs where no file could be named by a spec
mkdir -p "$empty"

run() {
  local target=$1 timeout=10
  [ "$target" = se_spec ] && timeout=60   # a level-7 icosphere takes seconds under ASan
  [ "$target" = kernel ] && timeout=30
  mkdir -p "$work/$target"
  if (cd "$empty" && "$root/build-fuzz/fuzz/fuzz_$target" -max_total_time="$seconds" \
        -timeout="$timeout" -rss_limit_mb=2560 -print_final_stats=1 \
        -artifact_prefix="$root/build-fuzz/artifacts/$target-" \
        "$work/$target" "$root/tests/fuzz_corpus/$target") >"$work/$target.log" 2>&1; then
    echo "fuzz: $target ok, $(grep -o 'stat::number_of_executed_units: *[0-9]*' "$work/$target.log" | grep -o '[0-9]*$') runs"
  else
    echo "fuzz: $target FAILED" >&2
    grep -v '^#[0-9]' "$work/$target.log" | tail -40 >&2
    return 1
  fi
}

failed=0
pids=()
for target in "${targets[@]}"; do
  run "$target" &
  pids+=($!)
  if [ "${#pids[@]}" -ge "$jobs" ]; then
    wait "${pids[0]}" || failed=1
    pids=("${pids[@]:1}")
  fi
done
for pid in "${pids[@]}"; do wait "$pid" || failed=1; done
echo "fuzz: done in $(( $(date +%s) - start )) s"
exit "$failed"
