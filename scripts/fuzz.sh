#!/usr/bin/env bash
# Long fuzzing campaigns on the readers (docs/RELIABILITY.md):
#   scripts/fuzz.sh [RUNS] [TARGET...]     default: 1000000 executions of every target
# Builds build-fuzz (make fuzz-build), runs each target RUNS times from its seeds and its corpus
# (build-fuzz/Testing/Fuzz/corpus/<TARGET>, kept between campaigns), and prints one line per
# target: executions, rate, wall time, result. A finding is saved as build-fuzz/Testing/Fuzz/
# crash-*, leak-*, timeout-* or oom-*: reproduce with build-fuzz/bin/Fuzz<TARGET> <file>, then
# make it a regression test.
set -euo pipefail
cd "$(dirname "$0")/.."
RUNS=${1:-1000000}
shift || true
TARGETS=("$@")
[ ${#TARGETS[@]} -gt 0 ] || TARGETS=(Nifti Nrrd SegNrrd Dicom PoseJson Mesh Scene)
make -s fuzz-build >/dev/null
DIR=build-fuzz/Testing/Fuzz
export ASAN_OPTIONS=fast_unwind_on_malloc=0
export LSAN_OPTIONS=suppressions=$PWD/Testing/Sanitizers/lsan.supp:print_suppressions=0
status=0
for t in "${TARGETS[@]}"; do
  log="$DIR/campaign-$t.log"
  start=$(date +%s)
  # teem leaks on almost every corrupt gzip input (lsan.supp); each leak makes libFuzzer run a
  # full leak scan, which held NRRD to 50-60 inputs a second. Its campaigns skip leak checks;
  # the smoke runs in make test and make test-asan still check leaks on these readers.
  leaks=1
  case $t in Nrrd | SegNrrd) leaks=0 ;; esac
  if build-fuzz/bin/Fuzz$t -runs="$RUNS" -timeout=10 -max_len=65536 -rss_limit_mb=2560 -malloc_limit_mb=2048 \
      -detect_leaks=$leaks -print_final_stats=1 -artifact_prefix="$DIR/" "$DIR/corpus/$t" "$DIR/seeds/$t" \
      >"$log" 2>&1; then
    result=clean
  else
    result="FINDING (see $log)"
    status=1
  fi
  execs=$(grep -o 'stat::number_of_executed_units: *[0-9]*' "$log" | grep -o '[0-9]*$' || echo "?")
  rate=$(grep -o 'stat::average_exec_per_sec: *[0-9]*' "$log" | grep -o '[0-9]*$' || echo "?")
  echo "Fuzz$t: $execs executions, $rate/s, $(( $(date +%s) - start )) s: $result"
done
exit $status
