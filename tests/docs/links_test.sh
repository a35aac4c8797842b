#!/bin/sh
# The README is a map and the guide is in docs/ (issue 50): the README at most 250 lines, each
# docs/*.md page at most 400, and every relative link in them leads to a file of the repository
# (and, with #anchor into a Markdown page, to one of its headings). Links to the web and out of
# the repository (../shared) are not followed. Each fault is named FILE:LINE.
#
# Usage: links_test.sh REPOSITORY_ROOT
set -eu
root="$1"
cd "$root"
failures=0
fail() {
  echo "links_test: $1" >&2
  failures=$((failures + 1))
}

lines=$(wc -l <README.md)
[ "$lines" -le 250 ] || fail "README.md: $lines lines; a map is at most 250 (the rest goes to docs/)"
for page in docs/*.md; do
  lines=$(wc -l <"$page")
  [ "$lines" -le 400 ] || fail "$page: $lines lines; a page of the guide is at most 400"
done

# GitHub's anchor of a heading: lower case, spaces to hyphens, other punctuation dropped.
anchors() {
  sed -n 's/^#\{1,6\} \(.*\)$/\1/p' "$1" |
    tr '[:upper:]' '[:lower:]' | sed -e 's/[^a-z0-9 _-]//g' -e 's/ /-/g'
}

for file in README.md docs/*.md; do
  folder=$(dirname "$file")
  # Every ](target) on each line, with its line number.
  grep -n -o '\](\([^)]*\))' "$file" | sed 's/^\([0-9]*\):\](\(.*\))$/\1 \2/' |
    while read -r line target; do
      case "$target" in
        http://* | https://* | mailto:*) continue ;;
      esac
      path=${target%%#*}
      anchor=""
      [ "$path" = "$target" ] || anchor=${target#*#}
      [ -n "$path" ] || path=$(basename "$file")
      resolved="$folder/$path"
      # Out of the repository (the shared design and data): not this check's.
      case "$(realpath -m "$resolved")" in
        "$(realpath "$root")"/*) ;;
        *) continue ;;
      esac
      if [ ! -e "$resolved" ]; then
        echo "links_test: $file:$line: links to $target, which is not there" >&2
        echo x
        continue
      fi
      if [ -n "$anchor" ] && [ "${resolved%.md}" != "$resolved" ] &&
        ! anchors "$resolved" | grep -qx -- "$anchor"; then
        echo "links_test: $file:$line: links to $target, but $path has no heading #$anchor" >&2
        echo x
      fi
    done >"${TMPDIR:-/tmp}/links_test.$$"
  bad=$(wc -l <"${TMPDIR:-/tmp}/links_test.$$")
  rm -f "${TMPDIR:-/tmp}/links_test.$$"
  failures=$((failures + bad))
done

if [ "$failures" -ne 0 ]; then
  echo "links_test: $failures fault(s)" >&2
  exit 1
fi
echo "links_test: README.md and $(ls docs/*.md | wc -l) pages, every link leads somewhere"
