# CMake arguments shared by the sanitizer and fuzz builds (sourced by scripts/sanitize.sh and
# scripts/fuzz.sh, so both configure build-asan the same way and neither forces a rebuild).
# Optimised like RelWithDebInfo, but with line tables only: a sanitizer report needs file:line
# in its stack, not variable locations, and full debug info of the Eigen/Ceres templates costs
# much of the compile time.
SANITIZER_BUILD_ARGS=(-DCMAKE_BUILD_TYPE=RelWithDebInfo
  "-DCMAKE_CXX_FLAGS_RELWITHDEBINFO=-O2 -gline-tables-only -DNDEBUG"
  "-DCMAKE_C_FLAGS_RELWITHDEBINFO=-O2 -gline-tables-only -DNDEBUG")
