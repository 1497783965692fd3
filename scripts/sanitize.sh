#!/usr/bin/env bash
# Sanitizer runs (docs/reliability.md, "Tools"), both with clang from Debian:
#  asan: AddressSanitizer + UndefinedBehaviorSanitizer build into ${ASAN_DIR:-build-asan} (with the
#        libFuzzer targets, so scripts/fuzz.sh reuses it), then ctest over the suite minus
#        ${ASAN_EXCLUDE} (a ctest -E regex; ASAN_EXCLUDE= runs everything);
#  tsan: ThreadSanitizer build into ${TSAN_DIR:-build-tsan} of the tests that run the threaded
#        pipeline, then those tests.
# Usage: scripts/sanitize.sh [asan|tsan|all|asan-long]   (default all; asan-long: the ASan build,
# then only the tests CI leaves out of it). Any sanitizer report fails the run.
set -euo pipefail
cd "$(dirname "$0")/.."
what=${1:-all}
JOBS=${JOBS:-$(nproc)}
ASAN_DIR=${ASAN_DIR:-build-asan}
TSAN_DIR=${TSAN_DIR:-build-tsan}
# Left out of the ASan run to keep CI well under its limit: the tests in
# scripts/sanitizers/asan_skip.txt (why each is there is written beside it). asan-long runs
# exactly those; ASAN_EXCLUDE= runs everything.
SKIP_FILE=scripts/sanitizers/asan_skip.txt
skip_regex() {
  # One ctest name (or name* / Suite.*) per line, '#' comments; an anchored alternation.
  grep -v '^[[:space:]]*\(#\|$\)' "$SKIP_FILE" | sed -e 's/[.]/\\./g' -e 's/[*]/.*/g' -e 's/^/^/' -e 's/$/$/' |
    paste -sd'|'
}
ASAN_EXCLUDE=${ASAN_EXCLUDE-$(skip_regex)}
# The threaded pipeline: the in-process pipeline tests, the backend's worker pool and `cslam run`
# under signals.
TSAN_TESTS=${TSAN_TESTS:-'^Pipeline\.|^WorkerPool\.|CliSignal|^CliTrackingLoss'}
# The batch tests stay out: their only threads of ours are the worker pool's, which the
# WorkerPool tests and every online test above exercise, and the cold batch takes 6 min
# under TSan. The warm-started batch's 60-pose solves went to CHOLMOD, whose OpenMP threads
# (libgomp, built without TSan) TSan reports as racing on CHOLMOD's own workspace; both tests
# run in the gcc and ASan suites. The whole-sequence accuracy runs on generated outdoor drives
# (a far car once, two cars of one motion) stay out too: minutes under TSan, and their threads
# are the ones the tests above exercise.
TSAN_EXCLUDE=${TSAN_EXCLUDE-'^Pipeline\.(BatchModeGivesEveryFrameAPoseNearTheTruth|WarmStartedBatchClustersAsWellAsTheColdOne|WarmBatchReportsEachFarCarOfAnOutdoorDriveOnce|TwoCarsOfOneMotionInTwoPlacesAreTwoObjectsOnline|OnlineOutdoorRunsKeepAFarCarAlongTheLineOfSightAcrossWindows|TrueLabelsMethodKeepsTheGeneratorsLabelsAndBeatsFullBa)$'}
TEST_TIMEOUT=${TEST_TIMEOUT:-1500}
SUPP="$PWD/scripts/sanitizers"
source scripts/sanitizers/build_args.sh

export CC=clang CXX=clang++
export UBSAN_OPTIONS="print_stacktrace=1:halt_on_error=1:suppressions=$SUPP/ubsan.supp"
# Leak checking stays off: the Debian libraries we link (OSMesa, PCL, OpenCV) keep allocations
# alive to the exit on purpose, and LeakSanitizer cannot tell those from ours.
export ASAN_OPTIONS="detect_leaks=0:abort_on_error=1:strict_string_checks=1:detect_stack_use_after_return=1"
export TSAN_OPTIONS="halt_on_error=1:second_deadlock_stack=1:suppressions=$SUPP/tsan.supp"

if [[ $what == asan || $what == all || $what == asan-long ]]; then
  cmake -S . -B "$ASAN_DIR" -G Ninja "${SANITIZER_BUILD_ARGS[@]}" -DCSLAM_SANITIZE=address \
    -DCSLAM_BUILD_FUZZERS=ON
  cmake --build "$ASAN_DIR" -j "$JOBS"
  if [[ $what == asan-long ]]; then
    (cd "$ASAN_DIR" && ctest --output-on-failure -j "$JOBS" --timeout "$TEST_TIMEOUT" -R "$(skip_regex)")
  else
    (cd "$ASAN_DIR" && ctest --output-on-failure -j "$JOBS" --timeout "$TEST_TIMEOUT" ${ASAN_EXCLUDE:+-E "$ASAN_EXCLUDE"})
  fi
fi

if [[ $what == tsan || $what == all ]]; then
  cmake -S . -B "$TSAN_DIR" -G Ninja "${SANITIZER_BUILD_ARGS[@]}" -DCSLAM_SANITIZE=thread
  cmake --build "$TSAN_DIR" -j "$JOBS" --target cslam cslam_pipeline_tests cslam_cli_tests
  (cd "$TSAN_DIR" && ctest --output-on-failure -j "$JOBS" --timeout "$TEST_TIMEOUT" -R "$TSAN_TESTS" \
    ${TSAN_EXCLUDE:+-E "$TSAN_EXCLUDE"})
fi
