#!/usr/bin/env bash
# Sorts the findings of a fuzz run by where they happen: one line per input in
# build-fuzz-libfuzzer/findings/<target>/ (kind, sanitizer report, first frame outside the sanitizer
# runtime, libFuzzer and the C/C++ runtimes), then a count per place. A first frame in libhdf5 is a bug
# of the HDF5 library on a damaged file (docs/reliability.md, "Fuzzing"); one in basalt:: is ours.
#   bash tools/fuzz/triage.sh TARGET [BUILD_DIR]
set -uo pipefail
here="$(cd "$(dirname "${BASH_SOURCE[0]}")/../.." && pwd)"
t=${1:?usage: triage.sh TARGET [BUILD_DIR]}
build=${2:-$here/build-fuzz-libfuzzer}
export ASAN_OPTIONS=detect_leaks=0 UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1
places=()
for f in "$build/findings/$t"/*; do
  [ -f "$f" ] || continue
  out=$(timeout 120 "$build/tools/fuzz/$t" -malloc_limit_mb=1024 -rss_limit_mb=2048 -timeout=10 "$f" 2>&1)
  report=$(echo "$out" | grep -m1 -E 'ERROR: (AddressSanitizer|libFuzzer)|runtime error:' |
    sed -E 's/.*(ERROR: |runtime error: )//; s/ (on|at|for) .*//; s/ \(.*//' | cut -c1-60)
  frame=$(echo "$out" | grep -E '^ +#[0-9]+ ' |
    grep -vE 'libclang_rt|sanitizer|__asan|__interceptor|libc\.so|libstdc|fuzzer::|LLVMFuzzer|malloc|/usr/include|string/\.\./sysdeps' |
    head -1 | sed -E 's/^ +#[0-9]+ 0x[0-9a-f]+ (in )?//; s/ \(BuildId.*//; s/\(.*\/(lib[a-z0-9_]+)\.so[^)]*\)/\1/' | cut -c1-110)
  [ -n "$report" ] || report="(no report: fixed?)"
  echo "$(basename "$f") | $report | ${frame:-?}"
  case "$frame" in *basalt::*) places+=("basalt") ;; *libhdf5* | H5*) places+=("libhdf5") ;; *) places+=("other") ;; esac
done
printf '%s\n' "${places[@]}" | sort | uniq -c | while read -r n where; do echo "$t: $n finding(s) with their first frame in $where"; done
