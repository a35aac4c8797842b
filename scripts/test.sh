#!/bin/sh
# Installs what is missing, builds everything with warnings as errors, and runs the whole test suite.
#
# --sanitizers (CI passes it): then also the whole suite built with AddressSanitizer + UBSan (the
# `asan` preset; what is left out says why below), and the threaded parts (the work pool, capture,
# the pipeline, its outputs' queues and servers, the control server, the service) built with
# ThreadSanitizer (the `tsan` preset).
# --fuzz-seeds: then also builds every libFuzzer target (the `fuzz` preset: clang, ASan + UBSan)
# and runs each once over its seeds (scripts/fuzz.sh seeds). The suites already build every target
# with gcc and run its seeds (FuzzSeeds.*), so this checks only the libFuzzer build itself.
# --minimal: then also builds the `minimal` preset (every optional part left out: X11, DRM, HTTP,
# RTSP, libcamera) and runs the tests that apply to it and may differ there; those of left-out parts
# are not run (configure lists them).
# Each phase's time is printed at the end.
set -eu
cd "$(dirname "$0")/.."
sanitizers=no
minimal=no
fuzzSeeds=no
for argument in "$@"; do
  case "$argument" in
    --sanitizers) sanitizers=yes ;;
    --minimal) minimal=yes ;;
    --fuzz-seeds) fuzzSeeds=yes ;;
    *) echo "usage: scripts/test.sh [--sanitizers] [--minimal] [--fuzz-seeds]" >&2; exit 2 ;;
  esac
done

# The minimal build compiles most files exactly as the ci build does, only in another folder:
# ccache then leaves the folder out of its hash (it appears only as the debug info's compilation
# directory), so those files are cache hits.
export CCACHE_NOHASHDIR=true
# Paths under the checkout hashed as relative ones: CI builds a fresh clone in another folder,
# which then finds what a build of the same sources anywhere else on the machine left in the cache
# (with absolute paths every CI build missed: the asan build alone took 16 minutes).
CCACHE_BASEDIR="$(pwd)"
export CCACHE_BASEDIR

timings=""
phase_start=0
begin() { phase_start=$(date +%s); echo "test: $1"; }
end() { timings="$timings
  $1: $(($(date +%s) - phase_start)) s"; }

begin "dependencies"
# With what runs the tests that need a KMS screen, V4L2 cameras or a CAN bus on a virtual
# machine that has them, and Debian's kernel for it.
if [ "$fuzzSeeds" = yes ]; then
  scripts/install-deps.sh --tests --device-vm --fuzz
else
  scripts/install-deps.sh --tests --device-vm
fi
scripts/device-vm.sh fetch || echo "test: no kernel for the device machine: its tests will say so"
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
  # OpenCV's parallel loops run on TBB's threads, which hand results back through TBB's own
  # (uninstrumented) atomics: TSan would report any picture they wrote as raced when our threads
  # read it. One OpenCV thread runs those loops inline; TSan still sees every thread of ours.
  export OPENCV_FOR_THREADS_NUM=1

  begin "asan build"
  # The test recordings come from the ci build's generator, as its own run made them: the
  # generator itself runs under ASan in synth_cli_test, and making all eight recordings again at
  # -O1 with ASan would add minutes and check nothing more.
  cmake --preset asan -DSURROUNDD_FIXTURE_SYNTH="$here/build/ci/tools/synth/surround-synth"
  cmake --build --preset asan
  end "asan build"
  begin "asan suite"
  # Mesa's llvmpipe driver keeps some allocations in its own static data, and eglTerminate()
  # unloads it: LeakSanitizer then no longer sees those references and reports the blocks as
  # leaked from an "<unknown module>", which no suppression can name. Loaded with every process,
  # the driver stays mapped to the end and what it holds stays reachable; ASan is told that a
  # library loaded before its runtime is meant.
  dri="/usr/lib/$(gcc -print-multiarch)/dri/swrast_dri.so"
  [ -e "$dri" ] || dri=""
  # Left out: the browser tests (Chromium and its node driver are not instrumented; the server
  # side of the page runs under ASan in http_stream_sink_test and end_to_end_test), lintian's
  # verdict on the .deb (it judges a release package; the ci suite runs it) and the runs on the
  # device machine (scripts/device-vm.sh: 5.6 min under ASan on its emulated CPU, against 2.6 in
  # the ci suite, which runs them; their programs' other tests run here; there LeakSanitizer also
  # reports blocks that Mesa's GBM and DRI driver keep after gbm_device_destroy(), in stacks that
  # end inside Mesa and that a suppression by module cannot reliably name).
  LD_PRELOAD="$dri" ASAN_OPTIONS="$ASAN_OPTIONS:verify_asan_link_order=0" \
    ctest --preset asan -j2 -LE '^(browser|device_vm)$' -E '^Packaging\.TheDebPassesLintian$'
  end "asan suite"

  # Threads: the work pool, capture (camera streams, the synchronizer, camera health), every test
  # that runs the pipeline (replays, faults, recordings, output files and retries, its report, an
  # egl window), the output queue and HTTP server, the control server and the whole service.
  # Left out: the libcamera test (no camera here: it only checks a message, and libcamera's own
  # threads are not instrumented), the v4l2loopback test (skipped without the kernel module) and
  # the RTSP tests:
  # GLib and GStreamer hand work between their threads and ours through their own futex-based
  # locks, which TSan cannot see, so every hand-over (a source given to the server's main loop, a
  # buffer to its pipeline) is reported as a race inside GLib; what the RTSP sink itself shares
  # is under one mutex or atomic (rtsp_stream_sink.cpp).
  tsan_tests="work_pool_test synchronizer_test replay_clock_test file_source_test
    preloaded_source_test v4l2_source_test camera_health_test queued_sink_test
    http_stream_sink_test replay_test preload_replay_test
    processing_backend_test fault_replay_test fault_isolation_test output_retry_test
    output_files_test recording_test still_rig_test pipeline_report_test control_server_test
    service_notifier_test service_test end_to_end_test window_output_test
    calibration_watch_stage_test"
  begin "tsan build"
  # Only these tests and the programs they run are built; their recordings are made by the ci
  # build's generator too, so it need not be built a third time.
  cmake --preset tsan -DSURROUNDD_FIXTURE_SYNTH="$here/build/ci/tools/synth/surround-synth"
  # shellcheck disable=SC2086 # the list is meant to split into words
  cmake --build --preset tsan --target $tsan_tests surroundd surroundctl
  end "tsan build"
  begin "tsan suite"
  # shellcheck disable=SC2086 # the list is meant to split into words
  labels=$(echo $tsan_tests | tr ' ' '|')
  # Left out: every view of the GPU stitch against the CPU path's picture (192 s of the suite's
  # 581 in CI, the longest, most of it llvmpipe drawing); the GPU path's threads are the same in
  # the other processing_backend tests, which run.
  ctest --preset tsan -j2 -L "^($labels)\$" \
    -E '^ProcessingBackendTest\.EveryViewFromTheGpuStitchIsTheCpuPathsPicture$'
  end "tsan suite"
fi

if [ "$minimal" = yes ]; then
  begin "minimal build"
  # Its recordings come from the ci build's generator: the same program as this build's.
  cmake --preset minimal -DSURROUNDD_FIXTURE_SYNTH="$(pwd)/build/ci/tools/synth/surround-synth"
  cmake --build --preset minimal
  end "minimal build"
  begin "minimal suite"
  # The .deb's lintian verdict is the full build's concern (tested above), and so are the tests
  # whose code and programs are the same with or without the optional parts (the preset does not
  # run them: processing, rendering, the generator, the calibration library). What it installs is
  # checked here too: its config must pass --check-config in a build without the HTTP page.
  ctest --preset minimal -j2 -E '^Packaging\.TheDebPassesLintian$'
  end "minimal suite"
fi

if [ "$fuzzSeeds" = yes ]; then
  begin "fuzz build and seeds"
  scripts/fuzz.sh seeds
  end "fuzz build and seeds"
fi

echo "test: phase times:$timings"
