#!/usr/bin/env bash
# fields_check.sh DIR STEPS: DIR/fields.csv has the header step,time,kinetic_energy and STEPS rows
# whose kinetic energy is positive by the last one.
set -eu
f=$1/fields.csv
[ "$(head -1 "$f")" = "step,time,kinetic_energy" ] || { echo "bad header in $f"; exit 1; }
rows=$(($(wc -l <"$f") - 1))
[ "$rows" -eq "$2" ] || { echo "$f: $rows rows, expected $2"; exit 1; }
awk -F, -v n="$2" 'END { if ($1 != n || !($3 > 0)) { print "last row " $0; exit 1 } }' "$f"
