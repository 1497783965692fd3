#!/usr/bin/env bash
# README command (2): install dependencies, build, run the whole test suite through ctest; then
# (docs/reliability.md, "Tools") the suite under AddressSanitizer + UBSan, the pipeline tests
# under ThreadSanitizer and a short run of every fuzz target. CSLAM_CI_QUICK=1 stops after the
# normal suite.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/install_deps.sh
bash scripts/build.sh
(cd "${BUILD_DIR:-build}" && ctest --output-on-failure -j "$(nproc)" --timeout 600)
if [[ ${CSLAM_CI_QUICK:-0} != 1 ]]; then
  bash scripts/sanitize.sh all
  bash scripts/fuzz.sh
fi
