#!/usr/bin/env bash
# Installs the Debian 12 packages clusterslam builds against (only what is missing).
set -euo pipefail
PKGS=(build-essential cmake ninja-build pkg-config
      libopencv-dev libpng-dev libdeflate-dev libeigen3-dev libceres-dev libsuitesparse-dev libpcl-dev libosmesa6-dev
      libspdlog-dev libcli11-dev libyaml-cpp-dev nlohmann-json3-dev libtinyxml2-dev
      libgtest-dev libgmock-dev libbenchmark-dev
      clang libclang-rt-dev llvm   # sanitizers, libFuzzer, llvm-symbolizer (scripts/sanitize.sh, fuzz.sh)
      slurm-wlm munge              # a single-node Slurm for the suite test (scripts/slurm-local.sh)
      libjs-three                  # three.js, inlined into each run's view.html (system/run/view_page.h)
      chromium)                    # headless browser of the view.html test (tests/apps/cli_view_test.cc)
missing=()
for p in "${PKGS[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if [ ${#missing[@]} -gt 0 ]; then
  SUDO=""; [ "$(id -u)" -ne 0 ] && SUDO="sudo"
  echo "installing: ${missing[*]}"
  $SUDO apt-get update -qq
  DEBIAN_FRONTEND=noninteractive $SUDO apt-get install -y -qq "${missing[@]}"
fi
