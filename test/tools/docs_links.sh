#!/usr/bin/env bash
# Every relative link and image in README.md and docs/*.md names a file of the repository (anchors
# and web addresses aside; code blocks and code spans are not links), and the README stays a page a
# newcomer reads in five minutes.
set -u
root=${1:?usage: docs_links.sh SOURCE_DIR}
cd "$root" || exit 2
bad=0
for page in README.md docs/*.md; do
  [ -f "$page" ] || continue
  dir=$(dirname "$page")
  # ](target) and ](target "title"): the target up to a space or the closing parenthesis.
  while IFS= read -r target; do
    target=${target%%#*}
    [ -z "$target" ] && continue
    case $target in http://* | https://* | mailto:*) continue ;; esac
    if [ ! -e "$dir/$target" ]; then
      echo "$page: link to '$target', which does not exist"
      bad=1
    fi
  done < <(awk '/^```/ { fenced = !fenced; next } !fenced' "$page" | sed 's/`[^`]*`//g' | grep -o '](\([^) ]*\)' | sed 's/^](//')
done
lines=$(wc -l < README.md)
if [ "$lines" -gt 250 ]; then
  echo "README.md: $lines lines, more than 250"
  bad=1
fi
[ $bad -eq 0 ] && echo "every link of README.md and docs/*.md resolves; README.md $lines lines"
exit $bad
