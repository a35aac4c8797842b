#!/bin/sh
# Soak test: surroundd replays the demo recording in a loop for MINUTES minutes, writing the
# surround view to a video file and serving it over HTTP to a client that keeps polling, and is
# reloaded (SIGHUP) every SOAK_RELOAD_S seconds. Every SOAK_SAMPLE_S seconds its resident memory,
# open files (/proc/PID/fd) and threads go into out/soak/samples.csv; at the end a summary
# compares the memory after warm-up (the first sample after the first reload) with the end, per
# reload; with gnuplot (scripts/install-deps.sh --soak) it also draws them in out/soak/soak.png.
# Exits 1 if surroundd died, a reload was not taken, or memory grows by more than
# SOAK_MAX_MB_PER_RELOAD (1 MB) per reload after warm-up (judged from 10 reloads on).
#
#   scripts/soak.sh MINUTES
#
# Environment: SOAK_RELOAD_S (60), SOAK_SAMPLE_S (10), SOAK_OUT (out/soak), SOAK_PORT (8797),
# SOAK_RECORDING (recordings/demo, made by surround-synth as scripts/demo.sh makes it when absent;
# any folder with a rig.yaml whose cameras are files), SURROUNDD_BUILD (build/release, else
# build/ci: where surroundd and surround-synth are built), SURROUNDD (the binary itself).
# Extra memory settings go through the environment too, e.g. MALLOC_ARENA_MAX=2 scripts/soak.sh 5.
set -eu
cd "$(dirname "$0")/.."
if [ $# -ne 1 ] || ! [ "$1" -gt 0 ] 2>/dev/null; then
  echo "usage: scripts/soak.sh MINUTES" >&2
  exit 2
fi
minutes=$1
reload_s=${SOAK_RELOAD_S:-60}
sample_s=${SOAK_SAMPLE_S:-10}
out=${SOAK_OUT:-out/soak}
port=${SOAK_PORT:-8797}
build=${SURROUNDD_BUILD:-}
if [ -z "$build" ]; then
  build=build/release
  [ -x "$build/daemon/surroundd" ] || build=build/ci
fi
surroundd=${SURROUNDD:-$build/daemon/surroundd}
recording=${SOAK_RECORDING:-recordings/demo}
synth=$build/tools/synth/surround-synth
[ -x "$surroundd" ] || { echo "soak: no $surroundd (build it first)" >&2; exit 2; }

# The demo recording (as scripts/demo.sh makes it), once.
if [ ! -f "$recording/rig.yaml" ]; then
  [ "$recording" = recordings/demo ] || { echo "soak: no $recording/rig.yaml" >&2; exit 2; }
  [ -x "$synth" ] || { echo "soak: no recordings/demo and no $synth to make it" >&2; exit 2; }
  "$synth" --rig config/rigs/paper.yaml --out recordings/demo
fi

rm -rf "$out"
mkdir -p "$out"
out=$(cd "$out" && pwd)
recording=$(cd "$recording" && pwd)
# The recording's rig with every camera looping.
sed -e 's|source: {file: \([^,}]*\)}|source: {file: '"$recording"'/\1, loop: true}|' \
  "$recording/rig.yaml" > "$out/rig.yaml"
grep -q "loop: true" "$out/rig.yaml" || { echo "soak: cannot make the rig loop" >&2; exit 2; }
cat > "$out/soak.yaml" <<EOF
logging:
  level: info
rig:
  file: rig.yaml
capture:
  pacing: realtime
panorama:
  width_px: 2048
  height_px: 1024
render:
  view: orbit
  width_px: 640
  height_px: 360
control:
  socket: $out/control.sock
outputs:
  - {type: video, stream: surround, path: $out/surround.mkv, crf: 30, preset: ultrafast}
  - {type: http, stream: surround, view: top, listen: "127.0.0.1:$port", quality: 60}
EOF
"$surroundd" --check-config --config "$out/soak.yaml" > /dev/null

"$surroundd" --config "$out/soak.yaml" > "$out/surroundd.log" 2>&1 &
pid=$!
# The HTTP client: a snapshot every second, and two seconds of the MJPEG stream every ten.
(
  k=0
  while kill -0 "$pid" 2>/dev/null; do
    curl -s -o /dev/null --max-time 5 "http://127.0.0.1:$port/snapshot.jpg" || true
    if [ $((k % 10)) -eq 0 ]; then
      curl -s -o /dev/null --max-time 2 "http://127.0.0.1:$port/stream.mjpg" || true
    fi
    k=$((k + 1))
    sleep 1
  done
) &
client=$!
cleanup() {
  kill "$client" 2>/dev/null || true
  kill -INT "$pid" 2>/dev/null || true
  wait "$pid" 2>/dev/null || true
}
trap cleanup EXIT INT TERM

# Reloads start once the first pipeline runs: a SIGHUP before surroundd has installed its handlers
# would end it (the default action), which is no reload.
waited=0
until grep -q "HTTP stream:" "$out/surroundd.log"; do
  kill -0 "$pid" 2>/dev/null || { echo "soak: surroundd did not start" >&2; cat "$out/surroundd.log" >&2; exit 1; }
  [ "$waited" -lt 600 ] || { echo "soak: surroundd did not start within 600 s" >&2; exit 1; }
  sleep 1
  waited=$((waited + 1))
done

echo "t_s,reloads,rss_kb,fds,threads" > "$out/samples.csv"
start=$(date +%s)
end=$((start + minutes * 60))
next_reload=$((start + reload_s))
next_sample=$start
sent=0
died=0
while [ "$(date +%s)" -lt "$end" ]; do
  now=$(date +%s)
  if ! kill -0 "$pid" 2>/dev/null; then died=1; break; fi
  if [ "$now" -ge "$next_reload" ]; then
    # One reload at a time: a SIGHUP while the last one is still starting would be merged into it.
    if [ "$(grep -c "reload: starting the pipeline for the new config" "$out/surroundd.log")" -ge "$sent" ]; then
      kill -HUP "$pid"
      sent=$((sent + 1))
    fi
    next_reload=$((next_reload + reload_s))
  fi
  if [ "$now" -ge "$next_sample" ]; then
    status=$(cat "/proc/$pid/status" 2>/dev/null) || { died=1; break; }
    rss=$(echo "$status" | awk '/^VmRSS:/ {print $2}')
    threads=$(echo "$status" | awk '/^Threads:/ {print $2}')
    fds=$(find "/proc/$pid/fd" -mindepth 1 -maxdepth 1 2>/dev/null | wc -l)
    reloads=$(grep -c "reload: starting the pipeline for the new config" "$out/surroundd.log" || true)
    echo "$((now - start)),$reloads,$rss,$fds,$threads" >> "$out/samples.csv"
    next_sample=$((next_sample + sample_s))
  fi
  sleep 1
done
taken=$(grep -c "reload: starting the pipeline for the new config" "$out/surroundd.log" || true)
cleanup
trap - EXIT INT TERM

# Memory is compared at the same point of each run: the last sample before the next reload (a
# run's steady state; samples taken while a pipeline starts are lower). Warm-up: the first run
# after the first reload.
# The verdict on memory: the least-squares slope of those steady values over the runs after warm-up
# (endpoints alone swing by the ~10 MB a run's buffers vary), judged from 10 reloads on.
max_growth=${SOAK_MAX_MB_PER_RELOAD:-1}
memory=0
awk -F, -v sent="$sent" -v taken="$taken" -v died="$died" -v max_growth="$max_growth" '
  NR == 1 { next }
  {
    n++; t[n] = $1; rss[n] = $3; fds[n] = $4; th[n] = $5
    steady[$2] = $3; if ($2 > last) last = $2
    if (!($2 in low) || $3 < low[$2]) low[$2] = $3
    if ($4 > maxfd) maxfd = $4; if ($5 > maxth) maxth = $5; if ($3 > maxrss) maxrss = $3
  }
  END {
    if (n == 0) { print "soak: no samples"; exit 1 }
    printf "soak: %d samples over %d s; %d reloads sent, %d taken%s\n", n, t[n], sent, taken,
           died ? "; SURROUNDD DIED" : ""
    printf "RSS: first sample %.1f MB, max %.1f MB, last %.1f MB\n", rss[1] / 1024,
           maxrss / 1024, rss[n] / 1024
    line = "RSS of each run before the next reload (MB):"
    for (r = 0; r < last; r++) if (r in steady) line = line sprintf(" %.1f", steady[r] / 1024)
    print line
    # The lowest sample of a run comes as it starts: what the runs before it left behind.
    line = "lowest RSS of each run (MB):"
    for (r = 0; r <= last; r++) if (r in low) line = line sprintf(" %.1f", low[r] / 1024)
    print line
    grows = 0
    if (last >= 3) {
      for (r = 1; r < last; r++) if (r in steady) {
        m++; x += r; y += steady[r] / 1024; xx += r * r; xy += r * steady[r] / 1024
      }
      slope = (m * xx - x * x) > 0 ? (m * xy - x * y) / (m * xx - x * x) : 0
      printf "after warm-up (run 1): %.1f MB; run %d: %.1f MB; slope %+.2f MB per reload\n",
             steady[1] / 1024, last - 1, steady[last - 1] / 1024, slope
      if (last < 11) {
        print "memory: too few reloads to judge growth (10 or more: run longer)"
      } else if (slope > max_growth) {
        printf "memory: GROWS %.2f MB per reload (more than %s)\n", slope, max_growth
        grows = 1
      } else {
        printf "memory: flat (%+.2f MB per reload, limit %s)\n", slope, max_growth
      }
    } else {
      print "growth per reload: too few reloads to compare (run longer)"
    }
    printf "open files: first %d, max %d, last %d; threads: first %d, max %d, last %d\n",
           fds[1], maxfd, fds[n], th[1], maxth, th[n]
    exit grows
  }' "$out/samples.csv" || memory=1
# The curves: memory on the left axis, open files and threads on the right, a mark at each reload.
if command -v gnuplot >/dev/null 2>&1; then
  gnuplot <<EOF
set terminal pngcairo size 1200,600
set output "$out/soak.png"
set datafile separator ","
set title "surroundd soak: ${minutes} min, a reload every ${reload_s} s"
set xlabel "time (s)"
set ylabel "resident memory (MB)"
set y2label "open files, threads"
set y2tics
set ytics nomirror
set yrange [0:*]
set y2range [0:*]
set key below horizontal
prev = 0
plot "$out/samples.csv" every ::1 using 1:(\$3/1024) with linespoints pt 7 ps 0.4 title "RSS (MB)", \
     "" every ::1 using 1:4 axes x1y2 with steps title "open files", \
     "" every ::1 using 1:5 axes x1y2 with steps title "threads", \
     "" every ::1 using 1:(\$2 != prev ? (prev = \$2, 0) : 1/0) with points pt 9 lc "grey" title "reload"
EOF
  echo "plot: $out/soak.png"
else
  echo "soak: no plot (scripts/install-deps.sh --soak installs gnuplot)"
fi
echo "samples: $out/samples.csv; log: $out/surroundd.log"
[ "$died" -eq 0 ] && [ "$taken" -ge $((sent - 1)) ] && [ "$memory" -eq 0 ]
