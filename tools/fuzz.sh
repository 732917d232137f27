#!/usr/bin/env bash
# Builds the libFuzzer targets (tests/fuzz) with clang into build-fuzz/ and runs each one for
# SECONDS (default 60) on a copy of its committed seed corpus, so CI never grows the corpus.
# Exits non-zero on a finding (crash, sanitizer report, leak, timeout, out-of-memory); the
# reproducer is left in build-fuzz/findings/. Installs nothing: needs clang and
# libclang-rt-14-dev (tools/bootstrap.sh).
# Usage: tools/fuzz.sh [SECONDS] [fuzzer...]      fuzzers: fuzz_gltf fuzz_brdf_params fuzz_image fuzz_hdr fuzz_merl
# Extra libFuzzer flags: FUZZ_FLAGS="-jobs=2 -workers=2" tools/fuzz.sh 1800 fuzz_gltf
# FUZZ_SEED (default 1) fixes libFuzzer's mutation sequence, so a CI run explores the same inputs
# each time (up to where its time runs out) and a finding reproduces; FUZZ_SEED=0 lets libFuzzer
# pick a new seed per run, for exploratory runs.
set -euo pipefail
cd "$(dirname "$0")/.."
seconds=${1:-60}
shift || true
fuzzers=("$@")
[ ${#fuzzers[@]} -gt 0 ] || fuzzers=(fuzz_gltf fuzz_brdf_params fuzz_image fuzz_hdr fuzz_merl)

for tool in clang clang++; do
  command -v $tool >/dev/null || { echo "fuzz.sh: $tool not found (apt-get install clang libclang-rt-14-dev)" >&2; exit 2; }
done
build=build-fuzz
CC=clang CXX=clang++ cmake -S . -B $build -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo -DNUSSELT_FUZZ=ON \
  -DNUSSELT_TESTS=OFF >/dev/null
cmake --build $build --target "${fuzzers[@]}"

declare -A corpus=([fuzz_gltf]=gltf [fuzz_brdf_params]=params [fuzz_image]=image [fuzz_hdr]=hdr [fuzz_merl]=merl)
declare -A dict=([fuzz_gltf]=gltf.dict [fuzz_brdf_params]=params.dict [fuzz_image]=image.dict [fuzz_hdr]=hdr.dict
                 [fuzz_merl]=merl.dict)
status=0
mkdir -p $build/findings
for f in "${fuzzers[@]}"; do
  c=${corpus[$f]:?unknown fuzzer $f}
  work=$build/corpus-run/$c
  rm -rf "$work" && mkdir -p "$work"
  cp tests/fuzz/corpus/$c/* "$work/"
  log=$build/$f.log
  echo "== $f: ${seconds}s on a copy of tests/fuzz/corpus/$c ($(ls "$work" | wc -l) seeds)"
  set +e
  # -timeout: one input may take at most 10 s; -rss_limit_mb: the loader's own caps keep a
  # hostile file well below this; -max_len: large enough for the cornell-box seed and mutations.
  $build/tests/fuzz/$f -seed="${FUZZ_SEED:-1}" -max_total_time="$seconds" -timeout=10 -rss_limit_mb=2560 -max_len=65536 \
    -dict=tests/fuzz/${dict[$f]} -artifact_prefix=$build/findings/$f- -print_final_stats=1 \
    ${FUZZ_FLAGS:-} "$work" >"$log" 2>&1
  rc=$?
  set -e
  execs=$(grep -h 'stat::number_of_executed_units' "$log" | awk '{s += $2} END {print s + 0}')
  if [ $rc -ne 0 ]; then
    echo "!! $f: FINDING (exit $rc) after $execs executions; log: $log" >&2
    grep -E 'ERROR|runtime error|SUMMARY|fuzz_gltf:|fuzz_brdf_params:|fuzz_image:|fuzz_hdr:|fuzz_merl:|Test unit written' "$log" | head -20 >&2 || true
    status=1
  else
    echo "   $f: ok, $execs executions in ${seconds}s, $(grep -h 'cov:' "$log" | tail -1 | grep -o 'cov: [0-9]*')"
  fi
done
exit $status
