#!/usr/bin/env bash
# README command (1): install dependencies, build in Release, run the embedded demo.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/install_deps.sh
bash scripts/build.sh -DCSLAM_BUILD_TESTS=OFF
"${BUILD_DIR:-build}/apps/cslam" demo --out "${DEMO_OUT:-out/demo}" --frames 60 --overwrite
