#!/usr/bin/env bash
# Metropolis (--integrator mlt, docs/mlt.md) against the path tracer at equal time: the Cornell box
# and its glass variant by default, the latter also in the region of its caustic under the sphere
# (x 0.40-0.60, y 0.80-0.90 of the image). tools/bench_integrator.sh does the work and documents
# the output and the environment (SIZE, TIME, REF_SPP, REPEATS, DEPTH, SCENES); MLT_ARGS are extra
# options of the mlt renders (e.g. "--mlt-chains 32768"); ARGS2 and ARGS3 other variants (bench_integrator.sh).
#   tools/bench_mlt.sh [DIR] [NUSSELT]
cd "$(dirname "$0")/.."
SCENES=${SCENES:-"default scenes/cornell/cornell-glass.glb@0.40,0.80,0.60,0.90"} ARGS=${MLT_ARGS:-} exec tools/bench_integrator.sh mlt "$@"
