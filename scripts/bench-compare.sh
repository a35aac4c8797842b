#!/bin/sh
# Before/after: this checkout's pipeline benchmark against another revision's, both built as
# release from their own sources, run in turns on the same recordings in one run, so that the
# machine's drift weighs on both alike. Prints, per recording, each one's frames per second and
# milliseconds per stage (medians over the rounds) and after/before ratios.
#
# usage: scripts/bench-compare.sh REVISION [ROUNDS] [surround-bench pipeline options...]
#   REVISION  what to compare against (a commit, tag or branch of this repository)
#   ROUNDS    turns of each (default 5); each turn is one `surround-bench pipeline --repeats 1`
# e.g. scripts/bench-compare.sh 235da05^ 5 --input raw
set -eu
cd "$(dirname "$0")/.."
if [ $# -lt 1 ]; then
  echo "usage: scripts/bench-compare.sh REVISION [ROUNDS] [surround-bench pipeline options...]" >&2
  exit 2
fi
revision="$1"
shift
rounds=5
if [ $# -gt 0 ]; then
  rounds="$1"
  shift
fi
commit=$(git rev-parse --verify --quiet "$revision^{commit}") || {
  echo "bench-compare: '$revision' is not a commit of this repository" >&2
  exit 2
}

scripts/install-deps.sh
cmake --preset release
cmake --build --preset release --target surround-synth surround-bench
scripts/bench-recordings.sh build/release/tools/synth/surround-synth

# The other revision from its own sources, in build/compare/<commit>/ (kept for the next run).
base="build/compare/$commit"
if [ ! -x "$base/build/release/tools/bench/surround-bench" ]; then
  rm -rf "$base"
  mkdir -p "$base"
  git archive "$commit" | tar -x -C "$base"
  (cd "$base" && cmake --preset release && cmake --build --preset release --target surround-bench)
fi

results="build/compare/results-$(date +%Y%m%d-%H%M%S).jsonl"
inputs="recordings/bench/480p recordings/bench/720p recordings/bench/1080p"
round=1
while [ "$round" -le "$rounds" ]; do
  echo "bench-compare: round $round of $rounds" >&2
  for side in before after; do
    if [ "$side" = before ]; then
      bench="$base/build/release/tools/bench/surround-bench"
    else
      bench=build/release/tools/bench/surround-bench
    fi
    printf '{"side": "%s", "run": ' "$side" >>"$results"
    "$bench" pipeline --json --repeats 1 "$@" $inputs | tr -d '\n' >>"$results"
    printf '}\n' >>"$results"
  done
  round=$((round + 1))
done

python3 - "$results" "$revision" <<'PY'
import json, statistics, sys
path, revision = sys.argv[1], sys.argv[2]
runs = {"before": {}, "after": {}}
for line in open(path):
    record = json.loads(line)
    for figures in record["run"]["pipeline"]["inputs"]:
        per = runs[record["side"]].setdefault(figures["name"], {})
        per.setdefault("FPS", []).append(figures["fps"])
        for stage, ms in figures["ms"].items():
            per.setdefault(stage + " ms", []).append(ms)
print(f"\nbefore: {revision}; after: this checkout; medians of each one's runs, in turns")
print(f"{'recording':<10} {'figure':<18} {'before':>9} {'after':>9} {'after/before':>13}")
for name, after in runs["after"].items():
    before = runs["before"].get(name, {})
    for figure, values in after.items():
        if figure not in before:
            print(f"{name:<10} {figure:<18} {'-':>9} {statistics.median(values):>9.2f}")
            continue
        b, a = statistics.median(before[figure]), statistics.median(values)
        ratio = f"{a / b:.2f}" if b > 0 else "-"
        print(f"{name:<10} {figure:<18} {b:>9.2f} {a:>9.2f} {ratio:>13}")
print("\nFPS: higher is better; ms: lower is better. Raw runs:", path)
PY
