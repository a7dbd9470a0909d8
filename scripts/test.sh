#!/usr/bin/env bash
# Installs dependencies, builds, and runs the whole test suite (GoogleTest + VTK oracle tests).
# The shared test data is expected at ../shared/data (tests that need it are skipped otherwise).
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/install-deps.sh
bash scripts/build.sh
ctest --test-dir build --output-on-failure -j "$(nproc)"
