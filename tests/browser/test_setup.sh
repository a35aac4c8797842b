# Sourced by each browser test once it has set `here` (this folder): refuses to run without the
# page's driver, makes the work folder $work and, on exit, stops the server whose process is $pid
# (once one is started) and removes the folder.
if [ ! -d "$here/node_modules/playwright-core" ]; then
  echo "$(basename "$0" .sh): run 'npm ci --prefix tests/browser' first (scripts/test.sh does)" >&2
  exit 1
fi
work=$(mktemp -d)
pid=""
trap '[ -n "$pid" ] && { kill $pid 2>/dev/null || true; wait $pid 2>/dev/null || true; }; rm -rf "$work"' EXIT
