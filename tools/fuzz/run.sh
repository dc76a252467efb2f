#!/usr/bin/env bash
# Fuzzes the scene parser, the .geo reader and the mesh reader, each for N minutes:
#   bash tools/fuzz/run.sh [MINUTES] [TARGET...]     (default: 10 minutes each; fuzz_scene fuzz_geo fuzz_mesh)
# Engine (BASALT_FUZZ_ENGINE): "libfuzzer" (default when clang++ exists: coverage-guided, every library
# built with -fsanitize=fuzzer-no-link,address,undefined) or "standalone" (g++, the stdlib-only random
# mutator of standalone_main.cpp, with address,undefined). Builds into build-fuzz-<engine>/, starts from
# the seed corpus tools/fuzz/corpus/<scene|geo|mesh> (plus the repository's scenes for fuzz_scene), keeps what
# libFuzzer learns in build-fuzz-<engine>/corpus/<target>, and writes a crashing input to
# build-fuzz-<engine>/findings/<target>/. Exit status non-zero when a target found something
# (reproduce: build-fuzz-<engine>/tools/fuzz/<target> FILE with libFuzzer).
set -euo pipefail
here="$(cd "$(dirname "${BASH_SOURCE[0]}")/../.." && pwd)"
minutes=${1:-10}
shift || true
targets=("$@")
[ ${#targets[@]} -gt 0 ] || targets=(fuzz_scene fuzz_geo fuzz_mesh)
engine=${BASALT_FUZZ_ENGINE:-$(command -v clang++ >/dev/null && echo libfuzzer || echo standalone)}
build="${BASALT_FUZZ_BUILD_DIR:-$here/build-fuzz-$engine}"
if [ "$engine" = libfuzzer ]; then compilers=(CC=clang CXX=clang++); else compilers=(CC=gcc CXX=g++); fi
env "${compilers[@]}" cmake -S "$here" -B "$build" -DCMAKE_BUILD_TYPE=RelWithDebInfo -DBASALT_NATIVE=OFF \
  -DBASALT_BUILD_TESTS=OFF -DBASALT_FUZZ=ON -DBASALT_SANITIZE=address,undefined >"$build.configure.log" 2>&1 ||
  { cat "$build.configure.log"; exit 1; }
cmake --build "$build" -j "${BASALT_JOBS:-2}" --target "${targets[@]}"
export ASAN_OPTIONS="${ASAN_OPTIONS:-detect_leaks=0}"
export UBSAN_OPTIONS="${UBSAN_OPTIONS:-print_stacktrace=1:halt_on_error=1}"
status=0
for t in "${targets[@]}"; do
  corpus="$build/corpus/$t"
  findings="$build/findings/$t"
  mkdir -p "$corpus" "$findings"
  seeds=("$here/tools/fuzz/corpus/${t#fuzz_}")
  if [ "$t" = fuzz_scene ]; then seeds+=("$here/scenes" "$here/tests/solver"); fi
  echo "== $t ($engine): $minutes min, seeds ${seeds[*]}"
  if [ "$engine" = libfuzzer ]; then
    # -timeout: one input taking > 10 s is a finding (a hang); -rss_limit_mb: one above 2 GB too.
    cmd=("$build/tools/fuzz/$t" "$corpus" "${seeds[@]}" -max_total_time=$((minutes * 60)) -max_len=8192
         -timeout=10 -rss_limit_mb=2048 -artifact_prefix="$findings/" -print_final_stats=1)
  else
    cmd=("$build/tools/fuzz/$t" $((minutes * 60)) "$findings" "${seeds[@]}")
  fi
  if ! "${cmd[@]}" >"$build/$t.log" 2>&1; then
    status=1
    echo "$t: FINDING (see $build/$t.log and $findings/)"
  fi
  tail -n 12 "$build/$t.log"
done
exit $status
