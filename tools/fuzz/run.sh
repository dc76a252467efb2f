#!/usr/bin/env bash
# Fuzzes the readers of untrusted input, each for N minutes, one target at a time:
#   bash tools/fuzz/run.sh [MINUTES] [TARGET...]     (default: 10 minutes each, all five targets)
# Targets: fuzz_scene (scene parser), fuzz_geo (.geo reader), fuzz_mesh (mesh-wall reader), fuzz_h5geo (HDF5
# geometry reader, whole and sliced), fuzz_checkpoint (checkpoint reader); contracts in docs/reliability.md.
# Engine (BASALT_FUZZ_ENGINE): "libfuzzer" (default when clang++ exists: coverage-guided, every library
# built with -fsanitize=fuzzer-no-link,address,undefined; needs Debian's libclang-rt-<N>-dev for the
# installed clang, the package that ships libclang_rt.fuzzer) or "standalone" (g++, the stdlib-only random
# mutator of standalone_main.cpp, with address,undefined). Builds into build-fuzz-<engine>/ (configure log
# there), starts from the seed corpus tools/fuzz/corpus/<scene|geo|mesh|h5geo|checkpoint> (plus the
# repository's scenes for fuzz_scene, and for the HDF5 targets the structural mutants that
# make_h5_seeds.py writes into build-fuzz-<engine>/seeds/), keeps what libFuzzer learns in
# build-fuzz-<engine>/corpus/<target>, and writes each crashing, leaking, hanging or over-allocating input
# to build-fuzz-<engine>/findings/<target>/. libFuzzer runs in fork mode with one job (-fork=1: one
# process fuzzing at a time) and goes on after a finding, so a run lasts its minutes and collects every
# finding. Exit status non-zero when a target found something (reproduce: build-fuzz-libfuzzer/tools/fuzz/
# <target> FILE).
set -euo pipefail
here="$(cd "$(dirname "${BASH_SOURCE[0]}")/../.." && pwd)"
minutes=${1:-10}
shift || true
targets=("$@")
[ ${#targets[@]} -gt 0 ] || targets=(fuzz_scene fuzz_geo fuzz_mesh fuzz_h5geo fuzz_checkpoint)
engine=${BASALT_FUZZ_ENGINE:-$(command -v clang++ >/dev/null && echo libfuzzer || echo standalone)}
build="${BASALT_FUZZ_BUILD_DIR:-$here/build-fuzz-$engine}"
if [ "$engine" = libfuzzer ]; then
  compilers=(CC=clang CXX=clang++)
  rt="$(clang++ -print-resource-dir)/lib/linux/libclang_rt.fuzzer-x86_64.a"
  if [ ! -f "$rt" ]; then
    version=$(clang++ -dumpversion | cut -d. -f1)
    echo "run.sh: clang++ has no libFuzzer ($rt is missing): install Debian's libclang-rt-$version-dev" \
      "(apt-get install libclang-rt-$version-dev), or run with BASALT_FUZZ_ENGINE=standalone" >&2
    exit 2
  fi
else
  compilers=(CC=gcc CXX=g++)
fi
launcher=()
if command -v ccache >/dev/null; then
  launcher=(-DCMAKE_CXX_COMPILER_LAUNCHER=ccache -DCMAKE_C_COMPILER_LAUNCHER=ccache)
fi
mkdir -p "$build"
env "${compilers[@]}" cmake -S "$here" -B "$build" -DCMAKE_BUILD_TYPE=RelWithDebInfo -DBASALT_NATIVE=OFF \
  -DBASALT_BUILD_TESTS=OFF -DBASALT_FUZZ=ON -DBASALT_SANITIZE=address,undefined "${launcher[@]}" \
  >"$build/configure.log" 2>&1 || { cat "$build/configure.log"; exit 1; }
cmake --build "$build" -j "${BASALT_JOBS:-2}" --target "${targets[@]}"
export ASAN_OPTIONS="${ASAN_OPTIONS:-detect_leaks=0}"
export UBSAN_OPTIONS="${UBSAN_OPTIONS:-print_stacktrace=1:halt_on_error=1}"
status=0
for t in "${targets[@]}"; do
  corpus="$build/corpus/$t"
  findings="$build/findings/$t"
  mkdir -p "$corpus" "$findings"
  seeds=("$here/tools/fuzz/corpus/${t#fuzz_}")
  max_len=8192
  case "$t" in
    fuzz_scene) seeds+=("$here/scenes" "$here/tests/solver") ;;
    fuzz_h5geo | fuzz_checkpoint)
      max_len=131072  # the seeds are HDF5 files of 17-40 KB
      if /usr/bin/python3 -c "import h5py" 2>/dev/null; then
        /usr/bin/python3 "$here/tools/fuzz/make_h5_seeds.py" mutants "$build/seeds"
        seeds+=("$build/seeds/${t#fuzz_}")
      else
        echo "run.sh: no h5py for /usr/bin/python3 (Debian's python3-h5py): $t starts from the real files only" >&2
      fi
      ;;
  esac
  echo "== $t ($engine): $minutes min, seeds ${seeds[*]}"
  before=$(find "$findings" -type f | wc -l)
  if [ "$engine" = libfuzzer ]; then
    # -timeout: one input taking > 10 s is a finding (a hang); -rss_limit_mb / -malloc_limit_mb: one process
    # above 2 GB, or one allocation above 1 GB, too (an unbounded allocation).
    cmd=("$build/tools/fuzz/$t" "$corpus" "${seeds[@]}" -max_total_time=$((minutes * 60)) -max_len=$max_len
         -timeout=10 -rss_limit_mb=2048 -malloc_limit_mb=1024 -fork=1 -ignore_crashes=1 -ignore_ooms=1
         -ignore_timeouts=1 -artifact_prefix="$findings/" -print_final_stats=1)
  else
    cmd=("$build/tools/fuzz/$t" $((minutes * 60)) "$findings" "${seeds[@]}")
  fi
  if ! "${cmd[@]}" >"$build/$t.log" 2>&1; then status=1; fi
  # Each fuzzing process (one per fork-mode job) leaves its scratch folder for the inputs.
  rm -rf /dev/shm/basalt-"${t//_/-}"-* "${TMPDIR:-/tmp}"/basalt-"${t//_/-}"-*
  after=$(find "$findings" -type f | wc -l)
  if [ "$after" -gt "$before" ]; then
    status=1
    echo "$t: $((after - before)) FINDING(S) in $findings/ (log: $build/$t.log)"
  fi
  grep -E '^#[0-9]+: cov:|^#[0-9]+.*(DONE|pulse)|stat::|INFO: (fuzzed|exiting)|inputs run' "$build/$t.log" | tail -n 4 || true
done
exit $status
