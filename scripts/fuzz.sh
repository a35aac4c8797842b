#!/bin/sh
# Runs every libFuzzer target (tests/fuzz) for SECONDS each, one after another, and prints each
# one's executions and findings: `scripts/fuzz.sh [SECONDS [RUNS]]` (default 60 s; with RUNS, a
# target also stops after that many executions: `scripts/fuzz.sh 7200 1000000` is the issue's 10^6
# each, within 2 hours each). FUZZ_TARGETS="config_fuzz rig_fuzz" runs only those; FUZZ_TIMEOUT
# (seconds, default 10) is when one input counts as a hang.
#
# Builds the `fuzz` preset first (clang with ASan + UBSan; `scripts/install-deps.sh --fuzz`
# installs clang), at most FUZZ_JOBS (default 2) compile jobs. Each target starts from its seeds in
# tests/fuzz/corpus/<target>/ and keeps what it finds in build/fuzz/corpus/<target>/ (the repo's
# seeds stay as they are). A crash, leak, UB, timeout or out-of-memory input is written to
# build/fuzz/findings/<target>-*; rerun one with `build/fuzz/tests/fuzz/<target> FILE`.
# Exits 1 when any target found something.
#
# `scripts/fuzz.sh seeds` runs each target once over its seeds only, and keeps nothing: what CI does
# (scripts/test.sh --fuzz-seeds), so that no target stops building and no seed breaks one.
set -eu
cd "$(dirname "$0")/.."
seedsOnly=no
if [ "${1:-}" = seeds ]; then
  seedsOnly=yes
  set -- 0 0
fi
seconds="${1:-60}"
runs="${2:--1}"
case "$seconds:${2:-0}" in
  :* | *[!0-9:]* | *:) echo "usage: scripts/fuzz.sh [SECONDS [RUNS]] | scripts/fuzz.sh seeds" >&2; exit 2 ;;
esac
if ! command -v clang++ >/dev/null 2>&1; then
  echo "fuzz: clang++ is missing: scripts/install-deps.sh --fuzz installs it" >&2
  exit 2
fi

cmake --preset fuzz >/dev/null
cmake --build --preset fuzz -j"${FUZZ_JOBS:-2}"

build=build/fuzz
targets="${FUZZ_TARGETS:-config_fuzz rig_fuzz control_fuzz http_host_fuzz http_server_fuzz lut_cache_fuzz jpeg_fuzz dbc_fuzz gltf_fuzz import_fuzz}"
mkdir -p "$build/findings"
# Leaks count as findings; UB stops the run with a stack like ASan's. ASan's freed-memory quarantine
# is 16 MB, not 256: an input's use after free is caught within its own run, and the default made
# the YAML targets fault in fresh pages on every input (config_fuzz: 520 MB resident, about half
# the speed).
export ASAN_OPTIONS="${ASAN_OPTIONS:-detect_leaks=1:quarantine_size_mb=16}"
export UBSAN_OPTIONS="${UBSAN_OPTIONS:-print_stacktrace=1:halt_on_error=1}"

failed=""
summary=""
for target in $targets; do
  seeds="tests/fuzz/corpus/${target%_fuzz}"
  corpus="$build/corpus/${target%_fuzz}"
  log="$build/findings/$target.log"
  mkdir -p "$corpus"
  if [ "$seedsOnly" = yes ]; then
    # -runs=0: each input of the corpus once, nothing new; the seeds alone, as they are in git.
    status=0
    "$build/tests/fuzz/$target" -runs=0 -timeout="${FUZZ_TIMEOUT:-60}" -rss_limit_mb=2048 \
      -artifact_prefix="$build/findings/$target-" "$seeds" >"$log" 2>&1 || status=$?
    count=$(find "$seeds" -type f | wc -l)
    if [ "$status" -eq 0 ]; then
      verdict="$count seeds, no finding"
    else
      verdict="FINDING (exit $status): see $log"
      failed="$failed $target"
    fi
    echo "fuzz: $target: $verdict"
    summary="$summary
$(printf '%-18s %s' "$target" "$verdict")"
    continue
  fi
  echo "fuzz: $target for ${seconds}s (seeds: $seeds)"
  # -timeout: an input that takes FUZZ_TIMEOUT s (default 10) is a hang; it is wall-clock time, so
  # at nice 19 beside a busy build give it more (an input of 92 ms once took 10 s, starved).
  # -rss_limit_mb: 2 GiB is an unbounded allocation.
  status=0
  "$build/tests/fuzz/$target" -max_total_time="$seconds" -runs="$runs" \
    -timeout="${FUZZ_TIMEOUT:-10}" -rss_limit_mb=2048 \
    -print_final_stats=1 -artifact_prefix="$build/findings/$target-" "$corpus" "$seeds" \
    >"$log" 2>&1 || status=$?
  executions=$(sed -n 's/^stat::number_of_executed_units: *//p' "$log" | tail -n 1)
  rate=$(sed -n 's/^stat::average_exec_per_sec: *//p' "$log" | tail -n 1)
  if [ "$status" -eq 0 ]; then
    verdict="no finding"
  else
    verdict="FINDING (exit $status): $(grep -m 1 -E '^(==[0-9]+==ERROR|SUMMARY|.*runtime error)' "$log" || echo "see $log")"
    failed="$failed $target"
  fi
  line=$(printf '%-18s %12s executions %8s/s  %s' "$target" "${executions:-?}" "${rate:-?}" "$verdict")
  echo "fuzz: $line"
  summary="$summary
$line"
done

if [ "$seedsOnly" = yes ]; then
  echo "fuzz: summary (each target over its seeds):$summary"
else
  echo "fuzz: summary (at most ${seconds}s each):$summary"
fi
if [ -n "$failed" ]; then
  echo "fuzz: findings in:$failed (inputs and logs under $build/findings/)" >&2
  exit 1
fi
