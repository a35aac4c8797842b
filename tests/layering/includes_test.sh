#!/bin/sh
# The parts' includes form a stack (docs/architecture.md, "The parts"): each folder may include
# only its own headers and those of the folders below it. Reads every header and source of every
# folder of code under ROOT (tests/ and build folders aside), prints each include that runs the
# wrong way with its file and line, and fails if there is one, or if a folder of code has no rule
# here (a new part must say where it stands). tests/layering/includes_self_test.sh plants wrong
# includes in a tree of its own and checks that this script fails on each.
#
# Usage: includes_test.sh ROOT
set -eu
root="$1"
cd "$root"

# shellcheck disable=SC2116 # echo joins the lines into one list of words
below_daemon=$(echo common capture vehicle processing processing/lens processing/stitch \
  processing/colour processing/calibration render render/outputs)
# One folder per output kind (daemon/outputs/<kind>), each a part of surroundd_output_kinds.
output_kinds=$(find daemon/outputs -mindepth 1 -type d 2>/dev/null | sort | tr '\n' ' ')
libraries="$below_daemon daemon/control daemon/config daemon/outputs $output_kinds daemon \
  daemon/stages"

# folder: the folders its headers and sources may include from (besides its own).
allowed() {
  case "$1" in
    common) echo "" ;;
    capture | vehicle | processing/lens) echo "common" ;;
    # The lens models are the shared geometry's own folder: one library with it.
    processing) echo "common processing/lens" ;;
    processing/stitch) echo "common processing processing/lens" ;;
    processing/colour | processing/calibration)
      echo "common processing processing/lens processing/stitch"
      ;;
    render) echo "common processing processing/lens processing/stitch" ;;
    render/outputs) echo "common render" ;;
    # The daemon: its control protocol stands alone; its config reads into every part's
    # settings; the output kinds are registered into the config's registry; the runtime (its
    # stages and the rest of it, one part) wires every part together. An output kind uses what
    # the kinds share, never another kind; their list names each.
    daemon/control) echo "common" ;;
    daemon/config) echo "$below_daemon" ;;
    daemon/outputs) echo "$below_daemon daemon/config $output_kinds" ;;
    daemon/outputs/*) echo "$below_daemon daemon/config daemon/outputs" ;;
    daemon | daemon/stages) echo "$libraries" ;;
    # The tools use the libraries, never one another, but the benchmark measures on the
    # generator's recordings; a tool's own folders (one per command) are one part.
    tools/bench) echo "$libraries tools/synth" ;;
    tools/*)
      # shellcheck disable=SC2046 # each folder a word
      echo "$libraries" $(find "tools/$(echo "$1" | cut -d/ -f2)" -type d)
      ;;
    *) return 1 ;;
  esac
}

report=$(mktemp)
trap 'rm -f "$report"' EXIT
# Every folder that holds C++ code, wherever it is, except the tests and build trees.
folders=$(find . -path ./tests -prune -o -path ./build -prune -o -path ./.git -prune -o \
  -path '*/node_modules' -prune -o -type f \( -name '*.hpp' -o -name '*.cpp' \) -print |
  sed 's|^\./||; s|/[^/]*$||' | sort -u)
if [ -z "$folders" ]; then
  echo "includes: no C++ code under $root" >&2
  exit 1
fi
files=0
for folder in $folders; do
  if ! permitted=$(allowed "$folder"); then
    echo "$folder: a folder of code with no rule in tests/layering/includes_test.sh" >>"$report"
    continue
  fi
  for file in "$folder"/*.hpp "$folder"/*.cpp; do
    [ -e "$file" ] || continue
    files=$((files + 1))
    # Each project include "a/b/c.hpp" belongs to folder "a/b". No include at all is no match:
    # grep's status is not the loop's.
    { grep -Hn '^#include "[A-Za-z0-9_/]*\.hpp"' "$file" || true; } |
      awk -v folder="$folder" -v permitted=" $permitted " '{
        split($0, at, ":"); header = $0; sub(/^[^"]*"/, "", header); sub(/".*$/, "", header)
        owner = header; sub(/\/[^\/]*$/, "", owner)
        if (owner != folder && index(permitted, " " owner " ") == 0)
          printf "%s:%s: includes %s: %s may include only from itself and:%s\n", at[1], at[2],
                 header, folder, permitted
      }' >>"$report"
  done
done
if [ -s "$report" ]; then
  cat "$report"
  exit 1
fi
echo "includes: all $files files of $(echo "$folders" | wc -l) folders include only from their" \
  "own part and the parts below it"
