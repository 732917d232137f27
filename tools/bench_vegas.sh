#!/usr/bin/env bash
# VEGAS (--integrator vegas, docs/vegas.md) against the path tracer at equal time: the Cornell box,
# scenes/tests/punctual.gltf and scenes/tests/mis.gltf by default (the test scenes reach ~3000 spp
# in 10 s: give them REF_SPP=32768). tools/bench_integrator.sh does the work and documents the
# output and the environment (SIZE, TIME, REF_SPP, REPEATS, DEPTH, SCENES); VEGAS_ARGS are extra
# options of the vegas renders (e.g. "--vegas-bins 16").
#   tools/bench_vegas.sh [DIR] [NUSSELT]
cd "$(dirname "$0")/.."
SCENES=${SCENES:-"default scenes/tests/punctual.gltf scenes/tests/mis.gltf"} ARGS=${VEGAS_ARGS:-} \
  exec tools/bench_integrator.sh vegas "$@"
