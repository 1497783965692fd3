#!/usr/bin/env bash
# Runs each libFuzzer target (fuzz/) for ${FUZZ_SECONDS:-30} s from its committed seed corpus
# fuzz/corpus/<target>/ (a smoke run in CI; fuzz longer by hand with FUZZ_SECONDS). Needs the clang ASan build with CSLAM_BUILD_FUZZERS=ON in
# ${ASAN_DIR:-build-asan} (scripts/sanitize.sh asan makes it; built here when missing).
# New interesting inputs go to $ASAN_DIR/fuzz-corpus/<target>/ (not committed); a crash is
# saved as $ASAN_DIR/fuzz-findings/<target>/crash-* and fails the script: fix it, then commit
# the reproducer to fuzz/corpus/<target>/ so fuzz_corpus_<target> keeps it as a regression test.
set -euo pipefail
cd "$(dirname "$0")/.."
ASAN_DIR=${ASAN_DIR:-build-asan}
FUZZ_SECONDS=${FUZZ_SECONDS:-30}
TARGETS=${FUZZ_TARGETS:-calibration rig_calibration oxts tracklets options synthetic png}
JOBS=${JOBS:-$(nproc)}
export CC=clang CXX=clang++
export ASAN_OPTIONS="detect_leaks=0:abort_on_error=1"
export UBSAN_OPTIONS="print_stacktrace=1:halt_on_error=1"

need_build=0
for t in $TARGETS; do [[ -x $ASAN_DIR/fuzz/${t}_fuzzer ]] || need_build=1; done
if [[ $need_build == 1 ]]; then
  source scripts/sanitizers/build_args.sh
  cmake -S . -B "$ASAN_DIR" -G Ninja "${SANITIZER_BUILD_ARGS[@]}" -DCSLAM_SANITIZE=address \
    -DCSLAM_BUILD_FUZZERS=ON
  cmake --build "$ASAN_DIR" -j "$JOBS" --target $(for t in $TARGETS; do echo "${t}_fuzzer"; done)
fi

failed=()
for t in $TARGETS; do
  work="$ASAN_DIR/fuzz-corpus/$t" findings="$ASAN_DIR/fuzz-findings/$t"
  mkdir -p "$work" "$findings"
  echo "== fuzzing $t for ${FUZZ_SECONDS}s"
  if ! "$ASAN_DIR/fuzz/${t}_fuzzer" -max_total_time="$FUZZ_SECONDS" -timeout=20 -rss_limit_mb=2560 \
       -max_len=8192 -print_final_stats=1 -artifact_prefix="$findings/" "$work" "fuzz/corpus/$t" \
       > "$findings/log.txt" 2>&1; then
    failed+=("$t")
    tail -60 "$findings/log.txt"
  fi
  grep -E "^stat::number_of_executed_units|^stat::new_units_added" "$findings/log.txt" || true
done
if [[ ${#failed[@]} -gt 0 ]]; then
  echo "fuzz: findings in: ${failed[*]} (see $ASAN_DIR/fuzz-findings/)" >&2
  exit 1
fi
echo "fuzz: no findings"
