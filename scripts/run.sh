#!/usr/bin/env bash
# The main job on a built-in input: installs dependencies, builds, meshes a CSG phantom (a ball
# and a torus fused, with a spherical cavity) by dual contouring with surface smoothing, checks
# the mesh and writes its quality report and histogram to out/. No data files are needed.
# (The pillowing and optimisation stages that remove the bad elements come with later issues.)
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/install-deps.sh
bash scripts/build.sh
mkdir -p out
phantom="difference(union(sphere(0,0,0,1), torus(0,0,0, 1.2,0.35)), sphere(0,0,0,0.55))"
./build/bin/isohex mesh --shape "$phantom" --resolution 40 -o out/phantom.vtu --json out/mesh.json
./build/bin/isohex check out/phantom.vtu
./build/bin/isohex quality out/phantom.vtu --metric scaled_jacobian --metric edge_ratio \
  --json out/quality.json --histogram out/quality.svg --per-element out/quality.csv
echo "mesh: out/phantom.vtu; reports: out/mesh.json out/quality.json;" \
     "figures: out/quality-scaled_jacobian.svg out/quality-edge_ratio.svg"
