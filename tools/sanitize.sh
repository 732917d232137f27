#!/usr/bin/env bash
# Builds nusselt with AddressSanitizer + UndefinedBehaviorSanitizer (-DNUSSELT_SANITIZE=ON) into
# build-asan/ and runs the CPU-side test suite (ctest label "unit") under it. Any sanitizer
# report fails the run: UBSan is built with -fno-sanitize-recover (a report aborts the test), ASan
# aborts on its first error and LeakSanitizer fails the process at exit, and the log is grepped
# as well in case a report came from a process that still exited 0.
# Usage: tools/sanitize.sh [ctest label regex, default: unit]   e.g. tools/sanitize.sh 'unit|cli'
# The slow pure-arithmetic tests (albedo quadrature accuracy, the chi-square tests of the samplers
# with a million samples per case, the envelope audit on a dense lattice: 1-15 minutes each under
# ASan, seconds to minutes without) are left to the normal build unless SANITIZE_ALL=1: they run the
# code that the short tests of the same models run under the sanitizers, many more times. Keep this
# list in step with the suite: a name that no longer matches runs again (tools/sanitize.sh prints how
# many tests it excluded). They are most of its time.
set -euo pipefail
cd "$(dirname "$0")/.."
labels=${1:-unit}
build=build-asan
# -O1: a quarter of the -O3 compile time, and the sanitizers' reports keep their line numbers.
cmake -S . -B $build -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo -DCMAKE_CXX_FLAGS_RELWITHDEBINFO="-O1 -g1" \
  -DCMAKE_C_FLAGS_RELWITHDEBINFO="-O1 -g1" -DNUSSELT_SANITIZE=ON -DNUSSELT_TESTS=ON >/dev/null
targets=(unit_tests)
[[ $labels == *cli* ]] && targets+=(nusselt)
[[ $labels == *gpu* || $labels == *render* ]] && targets+=(nusselt render_tests)
cmake --build $build --target "${targets[@]}"

# GPU and render tests (optional, not in CI): lavapipe and the validation layer are loaded with
# dlopen and unloaded before LeakSanitizer runs, so their allocations at exit show up as leaks
# from "<unknown module>" that no suppression can name. With those labels leak checking is off
# (ASan and UBSan errors still abort).
leaks=1
[[ $labels == *gpu* || $labels == *render* ]] && leaks=0
export ASAN_OPTIONS=${ASAN_OPTIONS:-detect_leaks=$leaks:abort_on_error=1:strict_string_checks=1:detect_stack_use_after_return=1:check_initialization_order=1}
export UBSAN_OPTIONS=${UBSAN_OPTIONS:-print_stacktrace=1:halt_on_error=1}
log=$build/sanitize.log
set +e
exclude=()
slow='EnergyAndQuadratureAgreement|AnisotropicTreeTotalsOverIncidentAzimuth|ChiSquareCpu|TreeTotalsMatchDirectionalAlbedo'
slow+='|RimModelsIndependentQuadrature|AllStrategiesUnbiased|EnvelopesBoundFOnADenseLattice|ChiSquareBothDiscs'
slow+='|AnalyticChiSquare|ChiSquareAgainstItsOwnPdf|FresnelMomentsGiveTheTexelAlbedo|WeightsEstimateTheTexelAlbedo'
if [ "${SANITIZE_ALL:-0}" != 1 ]; then
  exclude=(-E "\\.($slow)\$")
  all=$(ctest --test-dir $build -L "$labels" -N | sed -n 's/^Total Tests: //p')
  kept=$(ctest --test-dir $build -L "$labels" "${exclude[@]}" -N | sed -n 's/^Total Tests: //p')
  echo "sanitize.sh: $kept of $all tests (labels: $labels); $((all - kept)) slow arithmetic ones left to the normal build (SANITIZE_ALL=1 runs them)"
fi
ctest --test-dir $build -L "$labels" "${exclude[@]}" --output-on-failure -j "$(nproc)" >"$log" 2>&1
rc=$?
set -e
tail -3 "$log"
if grep -qE 'ERROR: (Address|Leak)Sanitizer|runtime error:|SUMMARY: (Address|UndefinedBehavior|Leak)Sanitizer' "$log"; then
  echo "sanitize.sh: sanitizer reports (full log: $log):" >&2
  grep -E 'ERROR: |runtime error:|SUMMARY: ' "$log" | sort | uniq -c | head -20 >&2
  exit 1
fi
[ $rc -eq 0 ] || { echo "sanitize.sh: tests failed (log: $log)" >&2; exit $rc; }
echo "sanitize.sh: no sanitizer reports (labels: $labels)"
