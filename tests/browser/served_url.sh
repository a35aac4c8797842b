# Sourced by the browser tests' scripts: served_url LOG PID SED_EXPRESSION prints the URL a
# program started in the background (PID) writes to LOG once it listens (it picks a free port),
# found by SED_EXPRESSION; nothing when it exits first or does not say within 10 s.
served_url() {
  for _ in $(seq 1 100); do
    found=$(sed -n "$3" "$1" | head -n 1)
    [ -n "$found" ] && { printf '%s\n' "$found"; return 0; }
    kill -0 "$2" 2>/dev/null || return 0
    sleep 0.1
  done
}
