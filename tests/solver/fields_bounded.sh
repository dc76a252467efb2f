#!/usr/bin/env bash
# fields_bounded.sh DIR LIMIT MAXROWS: DIR/fields.csv has at least one row, at most MAXROWS rows, and
# every value after step and time is a finite number with |value| <= LIMIT (no nan, inf or blow-up).
set -eu
f=$1/fields.csv
rows=$(($(wc -l <"$f") - 1))
[ "$rows" -ge 1 ] && [ "$rows" -le "$3" ] || { echo "$f: $rows rows, expected 1..$3"; exit 1; }
awk -F, -v lim="$2" 'NR > 1 { for (c = 3; c <= NF; ++c) { v = $c + 0;
  if ($c !~ /^-?[0-9.]+([eE][-+]?[0-9]+)?$/ || v > lim || -v > lim) { print "row " NR ": " $0; bad = 1 } } }
  END { exit bad }' "$f"
echo "$f: $rows rows, all finite and within $2"
