#!/bin/sh
# links_test.sh checked: on trees of its own, a clean one passes and each planted fault fails with
# its file and line named — a link to a missing file, to a heading that is not there, and a README
# past 250 lines.
#
# Usage: links_self_test.sh PATH/TO/links_test.sh
set -eu
check="$1"
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
failures=0

clean() {
  rm -rf "$work/tree"
  mkdir -p "$work/tree/docs"
  printf '# Tool\n\nSee [the guide](docs/guide.md#running-it) and [the web](https://example.org/x).\n' \
    >"$work/tree/README.md"
  printf '# Guide\n\n## Running it\n\nBack to [the README](../README.md) or [here](#guide).\n' \
    >"$work/tree/docs/guide.md"
}

expect() {  # expect pass|fail WHAT [MESSAGE]
  status=0
  output=$("$check" "$work/tree" 2>&1) || status=$?
  if [ "$1" = pass ] && [ "$status" -ne 0 ]; then
    echo "links_self_test: $2: failed, expected to pass: $output" >&2
    failures=$((failures + 1))
  elif [ "$1" = fail ] && { [ "$status" -eq 0 ] || ! echo "$output" | grep -q -- "$3"; }; then
    echo "links_self_test: $2: expected a failure saying '$3', got (exit $status): $output" >&2
    failures=$((failures + 1))
  fi
}

clean
expect pass "a clean tree"

clean
printf 'And [gone](docs/gone.md).\n' >>"$work/tree/README.md"
expect fail "a link to a missing file" "README.md:4: links to docs/gone.md, which is not there"

clean
printf 'Also [there](guide.md#stopping-it).\n' >>"$work/tree/docs/guide.md"
expect fail "a link to a missing heading" "docs/guide.md:6: links to guide.md#stopping-it"

clean
seq 1 260 >>"$work/tree/README.md"
expect fail "a README past 250 lines" "README.md: 263 lines"

if [ "$failures" -ne 0 ]; then
  echo "links_self_test: $failures case(s) wrong" >&2
  exit 1
fi
echo "links_self_test: the check passes a clean tree and names each planted fault"
