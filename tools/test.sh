#!/usr/bin/env bash
# The whole test suite, as CI runs it (the README's second command):
#   1. the CPU-side suite under AddressSanitizer + UndefinedBehaviorSanitizer (build-asan/);
#   2. the glTF, image, RGBE, NUSSELT_brdf and MERL fuzzers for a bounded time each (build-fuzz/, clang);
#   3. the main suite: ctest on build/ (unit, GPU, render and command-line tests on the machine's
#      Vulkan device, lavapipe without a GPU, with the validation layer on).
# Needs tools/bootstrap.sh to have run (the README's first command). Stops at the first failure.
# FUZZ_SECONDS (default 30) sets the fuzzing time per fuzzer; SKIP_SANITIZE=1 / SKIP_FUZZ=1 skip.
set -euo pipefail
cd "$(dirname "$0")/.."
[ -x build/nusselt ] || { echo "build/nusselt is missing: run tools/bootstrap.sh first" >&2; exit 1; }
cmake --build build
if [ "${SKIP_SANITIZE:-0}" != 1 ]; then
  echo "== sanitizers (ASan + UBSan)"
  tools/sanitize.sh
fi
if [ "${SKIP_FUZZ:-0}" != 1 ]; then
  echo "== fuzzers (${FUZZ_SECONDS:-30} s each)"
  tools/fuzz.sh "${FUZZ_SECONDS:-30}"
fi
# Last, so that its summary ("100% tests passed, 0 tests failed out of N") closes the output.
echo "== main suite (ctest)"
# ctest starts the longest tests first when it knows their times (its cost file, written by every
# run). A fresh build has none, and then the longest test (the quadtree chi-square, ~1000 s) may
# start last and run alone at the end: seed the file with the times of the tests that take 5 s or
# more (tools/ctest-costs.txt, from a fresh-clone run of this script; only the order depends on it).
mkdir -p build/Testing/Temporary
[ -s build/Testing/Temporary/CTestCostData.txt ] || cp tools/ctest-costs.txt build/Testing/Temporary/CTestCostData.txt
ctest --test-dir build --output-on-failure -j "$(nproc)"
