#!/usr/bin/env bash
# The main job on a built-in input: installs dependencies, builds, generates a hex mesh of a
# ball (a cube grid mapped onto a sphere), checks it and writes its quality report to out/.
# (Until the volume mesher lands, the built-in input is this generated mesh.)
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/install-deps.sh
bash scripts/build.sh
mkdir -p out
./build/bin/isohex generate ball --resolution 24 -o out/ball.vtu
./build/bin/isohex check out/ball.vtu
./build/bin/isohex quality out/ball.vtu --metric scaled_jacobian --metric edge_ratio \
  --json out/quality.json --histogram out/quality.svg --per-element out/quality.csv
echo "report: out/quality.json, figures: out/quality-scaled_jacobian.svg out/quality-edge_ratio.svg"
