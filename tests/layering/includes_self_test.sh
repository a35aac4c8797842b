#!/bin/sh
# includes_test.sh checked: in trees of its own, a clean one passes and each planted fault fails
# with the file and line named — a wrong include in a folder's first file, one behind a file with
# no project include (the check once stopped reading a folder there, and passed while reading 19
# of 205 files), one in daemon/ and in tools/, the config including an output kind, and a folder
# of code with no rule.
#
# Usage: includes_self_test.sh PATH/TO/includes_test.sh
set -eu
check="$1"
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
failures=0

# A small clean tree: each part includes only from below.
clean() {
  rm -rf "$work/tree"
  mkdir -p "$work/tree/common" "$work/tree/processing/stitch" "$work/tree/render" \
    "$work/tree/daemon" "$work/tree/tools/synth" "$work/tree/tests/render"
  cd "$work/tree"
  printf '#pragma once\n' >common/a.hpp
  printf '#include "common/a.hpp"\n' >processing/stitch/lut.hpp
  printf '#include <vector>\n' >render/first.cpp
  printf '#include "processing/stitch/lut.hpp"\n#include "render/first.hpp"\n' >render/view.cpp
  printf '#include "render/first.hpp"\n' >daemon/main.cpp
  printf '#include "daemon/x.hpp"\n' >tools/synth/main.cpp
  # Tests may include anything; they are not a part.
  printf '#include "tools/synth/y.hpp"\n' >tests/render/t.cpp
  cd - >/dev/null
}

expect() {
  name="$1"
  wanted="$2"
  status=0
  output=$("$check" "$work/tree" 2>&1) || status=$?
  if [ -z "$wanted" ]; then
    if [ "$status" -ne 0 ]; then
      echo "FAIL $name: the clean tree failed: $output"
      failures=$((failures + 1))
      return
    fi
  elif [ "$status" -eq 0 ] || ! printf '%s\n' "$output" | grep -qF "$wanted"; then
    echo "FAIL $name: expected a failure naming '$wanted', got status $status: $output"
    failures=$((failures + 1))
    return
  fi
  echo "ok   $name"
}

clean
expect "a clean tree passes" ""

clean
printf '#include "render/first.hpp"\n' >"$work/tree/common/a.hpp"
expect "an include up the stack" "common/a.hpp:1: includes render/first.hpp"

clean
# render/first.cpp, read first, has no project include; the wrong one is in the next file.
printf '#include "processing/stitch/lut.hpp"\n\n#include "daemon/x.hpp"\n' >"$work/tree/render/view.cpp"
expect "a wrong include behind a file with none" "render/view.cpp:3: includes daemon/x.hpp"

clean
printf '#include "tools/synth/y.hpp"\n' >"$work/tree/daemon/main.cpp"
expect "the daemon including a tool" "daemon/main.cpp:1: includes tools/synth/y.hpp"

clean
# The config library does not link the output kinds: they are registered into it.
mkdir -p "$work/tree/daemon/config" "$work/tree/daemon/outputs"
printf '#include "render/first.hpp"\n' >"$work/tree/daemon/outputs/video_output.cpp"
printf '#include "daemon/outputs/built_in_outputs.hpp"\n' >"$work/tree/daemon/config/loader.cpp"
expect "the config including an output kind" \
  "daemon/config/loader.cpp:1: includes daemon/outputs/built_in_outputs.hpp"

clean
# An output kind uses what the kinds share, never another kind.
mkdir -p "$work/tree/daemon/config" "$work/tree/daemon/outputs/video" "$work/tree/daemon/outputs/http"
printf '#pragma once\n' >"$work/tree/daemon/outputs/h264_settings.hpp"
printf '#include "daemon/outputs/h264_settings.hpp"\n' >"$work/tree/daemon/outputs/video/video_output.cpp"
printf '#include "daemon/outputs/video/video_output.hpp"\n' >"$work/tree/daemon/outputs/http/http_output.cpp"
expect "an output kind including another" \
  "daemon/outputs/http/http_output.cpp:1: includes daemon/outputs/video/video_output.hpp"

clean
mkdir -p "$work/tree/tools/calibrate"
printf '#include "tools/synth/y.hpp"\n' >"$work/tree/tools/calibrate/c.cpp"
expect "a tool including another" "tools/calibrate/c.cpp:1: includes tools/synth/y.hpp"

clean
mkdir -p "$work/tree/telemetry"
printf '#pragma once\n' >"$work/tree/telemetry/t.hpp"
expect "a folder with no rule" "telemetry: a folder of code with no rule"

if [ "$failures" -ne 0 ]; then
  echo "includes_self_test: $failures of the planted faults were not caught as they should be"
  exit 1
fi
echo "includes_self_test: every planted fault caught, the clean tree passed"
