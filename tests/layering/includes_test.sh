#!/bin/sh
# The parts' includes form a stack (docs/architecture.md, "The parts"): each folder may include
# only its own headers and those of the folders below it. Prints every include that runs the
# wrong way, with its file and line, and fails if there is one.
set -eu
root="$1"
cd "$root"

# folder: the folders its headers and sources may include from (besides its own).
allowed() {
  case "$1" in
    common) echo "common" ;;
    capture) echo "common capture" ;;
    vehicle) echo "common vehicle" ;;
    processing) echo "common processing" ;;
    processing/stitch) echo "common processing processing/stitch" ;;
    processing/colour) echo "common processing processing/stitch processing/colour" ;;
    processing/calibration) echo "common processing processing/stitch processing/calibration" ;;
    render) echo "common processing render" ;;
    render/outputs) echo "common render render/outputs" ;;
    *) return 1 ;;
  esac
}

report=$(mktemp)
trap 'rm -f "$report"' EXIT
for folder in common capture vehicle processing processing/stitch processing/colour \
              processing/calibration render render/outputs; do
  permitted=$(allowed "$folder")
  # Each project include "a/b/c.hpp" belongs to folder "a/b".
  for file in "$folder"/*.hpp "$folder"/*.cpp; do
    [ -e "$file" ] && grep -Hn '^#include "[a-z_/]*\.hpp"' "$file"
  done | awk -v folder="$folder" -v permitted=" $permitted " '{
    split($0, at, ":"); header = $0; sub(/^[^"]*"/, "", header); sub(/".*$/, "", header)
    owner = header; sub(/\/[^\/]*$/, "", owner)
    if (index(permitted, " " owner " ") == 0)
      printf "%s:%s: includes %s: %s may include only from:%s\n", at[1], at[2], header, folder, permitted
  }'
done > "$report"
if [ -s "$report" ]; then
  cat "$report"
  exit 1
fi
echo "includes: every part includes only from itself and the parts below it"
