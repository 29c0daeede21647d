#!/usr/bin/env bash
# Runs every fuzz target for SECONDS each (./setup.sh fuzz): the committed corpus
# (tests/fuzz/corpus/TARGET) is read, new inputs go to BUILD/fuzz/corpus/TARGET, and a crash,
# hang (-timeout), leak or sanitizer report is kept in BUILD/fuzz/artifacts/TARGET and fails the run.
# Prints one line per target: executions, coverage (libFuzzer's "cov", edges) and the verdict;
# writes the same table to BUILD/fuzz/summary.txt.
# FUZZ_RUNS=N also stops a target after N executions (the issue's 10^6 benchmark: FUZZ_RUNS=1000000
# with a generous SECONDS). FUZZ_SEED=N fixes libFuzzer's random seed (CI: a failure there is
# replayed by the same command); without it every run explores from a fresh seed.
#   usage: tests/fuzz/run_fuzzers.sh BUILD_DIR SECONDS [TARGET...]
set -uo pipefail
build="$1"
seconds="$2"
shift 2
here="$(cd "$(dirname "$0")" && pwd)"
fuzzer="$build/tests/fuzz/gvio_fuzz"
[ -x "$fuzzer" ] || { echo "run_fuzzers: $fuzzer not built" >&2; exit 2; }
targets=("$@")
if [ ${#targets[@]} -eq 0 ]; then
  mapfile -t targets < <(find "$here/corpus" -mindepth 1 -maxdepth 1 -type d -printf '%f\n' | sort)
fi
summary="$build/fuzz/summary.txt"
mkdir -p "$build/fuzz"
printf '%-24s %12s %8s %8s  %s\n' target executions cov ft verdict | tee "$summary"
failed=0
for t in "${targets[@]}"; do
  work="$build/fuzz/corpus/$t"
  artifacts="$build/fuzz/artifacts/$t/"
  log="$build/fuzz/$t.log"
  mkdir -p "$work" "$artifacts"
  # Leaks are checked (ASan's LeakSanitizer); readers on 2 GB inputs are out of scope (-rss_limit).
  GVIO_FUZZ_TARGET="$t" "$fuzzer" -max_total_time="$seconds" -timeout=10 -rss_limit_mb=2048 \
    -max_len=65536 ${FUZZ_RUNS:+-runs="$FUZZ_RUNS"} ${FUZZ_SEED:+-seed="$FUZZ_SEED"} -print_final_stats=1 -artifact_prefix="$artifacts" "$work" "$here/corpus/$t" \
    >"$log" 2>&1
  rc=$?
  execs=$(sed -n 's/^stat::number_of_executed_units: *//p' "$log" | tail -1)
  cov=$(grep -oE 'cov: [0-9]+' "$log" | tail -1 | cut -d' ' -f2)
  ft=$(grep -oE 'ft: [0-9]+' "$log" | tail -1 | cut -d' ' -f2)
  verdict=ok
  if [ $rc -ne 0 ]; then
    verdict="FAILED (rc $rc, see $log and $artifacts)"
    failed=1
  fi
  printf '%-24s %12s %8s %8s  %s\n' "$t" "${execs:-?}" "${cov:-?}" "${ft:-?}" "$verdict" | tee -a "$summary"
done
exit $failed
