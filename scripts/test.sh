#!/bin/sh
# Installs what is missing, builds everything with warnings as errors, and runs the whole test suite.
#
# --sanitizers (CI passes it): then also the whole suite built with AddressSanitizer + UBSan (the
# `asan` preset; tests labelled asan_slow left out, each with its reason where it is labelled), and
# the threaded parts (capture, the pipeline, its outputs' queues and servers, the service) built
# with ThreadSanitizer (the `tsan` preset). Each phase's time is printed at the end.
set -eu
cd "$(dirname "$0")/.."
sanitizers=no
case "${1:-}" in
  --sanitizers) sanitizers=yes ;;
  "") ;;
  *) echo "usage: scripts/test.sh [--sanitizers]" >&2; exit 2 ;;
esac

timings=""
phase_start=0
begin() { phase_start=$(date +%s); echo "test: $1"; }
end() { timings="$timings
  $1: $(($(date +%s) - phase_start)) s"; }

begin "dependencies"
scripts/install-deps.sh
end "dependencies"
begin "ci build"
cmake --preset ci
cmake --build --preset ci
# The browser test's driver (playwright-core, from the npm registry; it drives Debian's chromium).
npm ci --prefix tests/browser --no-audit --no-fund --loglevel=error
end "ci build"
begin "ci suite"
ctest --preset ci -j2
end "ci suite"

if [ "$sanitizers" = yes ]; then
  here="$(pwd)"
  # LeakSanitizer and TSan suppressions for third-party libraries only; each says why.
  export LSAN_OPTIONS="suppressions=$here/tests/sanitizers/lsan.supp:print_suppressions=0"
  export UBSAN_OPTIONS="print_stacktrace=1:halt_on_error=1"
  export ASAN_OPTIONS="detect_leaks=1:strict_init_order=1:detect_stack_use_after_return=1"
  export TSAN_OPTIONS="suppressions=$here/tests/sanitizers/tsan.supp:halt_on_error=1:second_deadlock_stack=1"

  begin "asan build"
  cmake --preset asan
  cmake --build --preset asan
  end "asan build"
  begin "asan suite"
  # The browser test drives Chromium against the daemon; under ASan only its driver's timeouts
  # would be tested. Packaging builds a .deb of the sanitized binaries: no memory is checked there.
  ctest --preset asan -j2 -LE '^(asan_slow|browser|packaging)$'
  end "asan suite"

  # Threads: capture, the synchronizer and camera health, the pipeline (replays, faults, report),
  # the output queue and HTTP server, the control server and the whole service.
  tsan_tests="synchronizer_test file_source_test v4l2_source_test camera_health_test
    queued_sink_test http_stream_sink_test replay_test fault_replay_test pipeline_report_test
    control_server_test service_notifier_test service_test end_to_end_test"
  begin "tsan build"
  cmake --preset tsan
  # shellcheck disable=SC2086 # the list is meant to split into words
  cmake --build --preset tsan --target $tsan_tests surroundd surroundctl surround-synth
  end "tsan build"
  begin "tsan suite"
  # shellcheck disable=SC2086 # the list is meant to split into words
  labels=$(echo $tsan_tests | tr ' ' '|')
  ctest --preset tsan -j2 -L "^($labels)\$"
  end "tsan suite"
fi

echo "test: phase times:$timings"
