#!/usr/bin/env bash
# Builds and runs tools/make_test_assets.cpp, which writes the generated test data of issue 18
# (PNG/JPEG test images, the compressed grid glTF files, scenes/tests/textured, fuzz seeds) from
# Debian's encoders (libpng, libjpeg-turbo, Draco, meshoptimizer: tools/bootstrap.sh installs
# them). Run once after changing the generator; its outputs are committed.
set -euo pipefail
cd "$(dirname "$0")/.."
mkdir -p build tests/data/images tests/fuzz/corpus/image scenes/tests/textured
c++ -std=c++17 -O1 -o build/make_test_assets tools/make_test_assets.cpp -lpng -lturbojpeg -ldraco -lmeshoptimizer
build/make_test_assets .
