#!/usr/bin/env bash
# Long fuzzing campaigns on the readers (docs/RELIABILITY.md), leak detection on for every target:
#   scripts/fuzz.sh [RUNS|SECONDSs] [TARGET...]   default: 1000000 executions of every target;
#                                                 "600s": ten minutes of each target
# Builds build-fuzz (make fuzz-build), runs each target from its seeds and its corpus
# (build-fuzz/Testing/Fuzz/corpus/<TARGET>, kept between campaigns), and prints one line per
# target: executions, rate, wall time, result. A finding is saved as build-fuzz/Testing/Fuzz/
# crash-*, leak-*, timeout-* or oom-*: reproduce with build-fuzz/bin/Fuzz<TARGET> <file>, then
# make it a regression test. A target that dies without a crash-* file (a smashed stack) leaves
# the input it died on in its /tmp/repose-fuzz-* folder. Campaigns can run side by side.
set -euo pipefail
cd "$(dirname "$0")/.."
RUNS=${1:-1000000}
shift || true
# A duration ("600s") bounds each target by time instead of by executions.
LIMIT=(-runs="$RUNS")
case $RUNS in *s) LIMIT=(-max_total_time="${RUNS%s}") ;; esac
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
  asan=$ASAN_OPTIONS
  # FuzzDicom forks once per input (the GDCM sandbox): a smaller ASan quarantine and shorter
  # allocation stacks make the fuzzer's footprint, and so each fork, smaller. Measured over 60 s
  # on the same corpus: 52 inputs a second by default, 126 with these (a freed block is then
  # caught reused only within the last 16 MB freed).
  case $t in Dicom) asan=$asan:quarantine_size_mb=16:malloc_context_size=5 ;; esac
  # The campaign runs a private copy of the target and its library, so that it tests the build
  # it started with, whatever is rebuilt meanwhile (another campaign's make fuzz-build).
  snap="$DIR/campaign-bin/$t"
  rm -rf "$snap" && mkdir -p "$snap" && cp build-fuzz/bin/Fuzz$t build-fuzz/lib/*.so "$snap/"
  : >"$log"
  result=clean
  if ! ASAN_OPTIONS=$asan LD_LIBRARY_PATH="$PWD/$snap" "$snap/Fuzz$t" "${LIMIT[@]}" -timeout=10 -max_len=65536 \
      -rss_limit_mb=2560 -malloc_limit_mb=2048 -detect_leaks=1 -print_final_stats=1 \
      -artifact_prefix="$DIR/" "$DIR/corpus/$t" "$DIR/seeds/$t" >>"$log" 2>&1; then
    result="FINDING (see $log)"
    status=1
  fi
  execs=$(grep -o 'stat::number_of_executed_units: *[0-9]*' "$log" | grep -o '[0-9]*$' |
    awk '{ s += $1 } END { print s + 0 }')
  seconds=$(($(date +%s) - start))
  echo "Fuzz$t: $execs executions, $((execs / (seconds > 0 ? seconds : 1)))/s, $seconds s: $result"
done
exit $status
