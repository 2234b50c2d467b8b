#!/usr/bin/env bash
# Builds the test suite with AddressSanitizer + UndefinedBehaviorSanitizer
# (-DMORPH_SANITIZE=ON) into ./build-asan and runs it with ctest. Any sanitizer report
# aborts the test that triggered it, so ctest (and this script) fail.
#
#   scripts/sanitize.sh [extra ctest arguments, e.g. -R io]
#
# The CLI tests (tests/apps) need the apps; they run too unless MORPH_SANITIZE_APPS=OFF.
set -euo pipefail
cd "$(dirname "$0")/.."
start=$(date +%s)
cmake -S . -B build-asan -DCMAKE_BUILD_TYPE=RelWithDebInfo -DCMAKE_CXX_FLAGS_RELWITHDEBINFO="-O1 -g1" \
  -DMORPH_SANITIZE=ON -DMORPH_BUILD_APPS="${MORPH_SANITIZE_APPS:-ON}" -DMORPH_BUILD_BENCHMARKS=OFF >/dev/null
cmake --build build-asan -j"$(nproc)"
echo "sanitize: built in $(( $(date +%s) - start )) s"
export ASAN_OPTIONS=${ASAN_OPTIONS:-abort_on_error=1:detect_leaks=1:strict_string_checks=1:detect_stack_use_after_return=1}
export UBSAN_OPTIONS=${UBSAN_OPTIONS:-print_stacktrace=1:halt_on_error=1}
ctest --test-dir build-asan --output-on-failure -j"$(nproc)" --timeout 900 "$@"
echo "sanitize: done in $(( $(date +%s) - start )) s"
