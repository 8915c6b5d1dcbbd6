#!/usr/bin/env bash
# bench/import_survey.sh PATHEX DIR: imports every scene file under DIR (*.pbrt, *.xml whose first
# 300 bytes hold a <scene> or pbrt directives) with `PATHEX query --scene FILE LDDE` and prints how
# many import, then the refusals grouped by message (file and position cut off), most frequent first.
# A public collection to run it on: Mitsuba 3's own data (the `fetch` tool,
# github:mitsuba-renderer/mitsuba-data, exported with `git archive` or `git show` per file).
#   bash bench/import_survey.sh build/pathex /tmp/mdata
set -uo pipefail
pathex=${1:?usage: bench/import_survey.sh PATHEX DIR}
dir=${2:?usage: bench/import_survey.sh PATHEX DIR}
total=0
ok=0
reasons=$(mktemp)
while IFS= read -r -d '' f; do
  case "$f" in
    *.xml) head -c 300 "$f" | grep -q "<scene" || continue ;;
  esac
  total=$((total + 1))
  err=$(timeout 120 "$pathex" query --scene "$f" LDDE 2>&1 >/dev/null | grep "error" | head -1)
  if [ -z "$err" ]; then ok=$((ok + 1)); else echo "$err" | sed -E 's/^pathex: error: [^ ]*: //; s/\(.*//' >> "$reasons"; fi
done < <(find "$dir" \( -name '*.pbrt' -o -name '*.xml' \) -not -path '*ipynb*' -print0 | sort -z)
echo "imported $ok of $total scene files under $dir"
sort "$reasons" | uniq -c | sort -rn | head -25
rm -f "$reasons"
