#!/usr/bin/env bash
# The main job: set up, build, then open a sample mesh by a sphere and print a summary.
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/build.sh
mkdir -p out
build/apps/mesh-open samples/icosphere_1280.off --se sphere:r=0.25,level=2 -o out/opened.ply --label-facets --stats
echo "main: wrote $(pwd)/out/opened.ply (the opening of samples/icosphere_1280.off by sphere:r=0.25,level=2)"
