#!/usr/bin/env bash
# Makes `import basalt` work in any new shell: writes basalt.pth, one line naming the build's Python folder
# (<build>/python, which holds the package basalt), into the user site-packages folder of the Python the build
# was made for (Debian's /usr/bin/python3 unless configured otherwise). Python reads .pth files at start-up
# and puts the folder on sys.path, after PYTHONPATH. scripts/demo.sh and scripts/test.sh run it after building.
#
#   scripts/python-path.sh [BUILD_DIR]            write (default BUILD_DIR: $BASALT_BUILD_DIR or ./build)
#   scripts/python-path.sh --system [BUILD_DIR]   write into the system's site-packages instead (root: every user)
#   scripts/python-path.sh --remove [BUILD_DIR]   remove the basalt.pth files this script wrote (undo)
#
# Without it: PYTHONPATH=<build>/python /usr/bin/python3 ... (docs/python.md). The user site-packages folder
# is ~/.local/lib/python3.X/site-packages (PYTHONUSERBASE moves it); a python3 of another version, or one with
# other packages (pyenv), is named and left alone.
set -euo pipefail
here="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
mode=write
where=user
build=""
for arg in "$@"; do
  case "$arg" in
    --remove) mode=remove ;;
    --system) where=system ;;
    -h|--help) sed -n '2,15p' "$0" | sed 's/^# \{0,1\}//'; exit 0 ;;
    -*) echo "python-path: unknown option '$arg' (--remove, --system)" >&2; exit 2 ;;
    *) build="$arg" ;;
  esac
done
build="${build:-${BASALT_BUILD_DIR:-$here/build}}"
build="$(cd "$build" 2>/dev/null && pwd)" || { echo "python-path: no build folder '$build'" >&2; exit 1; }
cache="$build/CMakeCache.txt"
[ -f "$cache" ] || { echo "python-path: '$build' is not a configured build (no CMakeCache.txt)" >&2; exit 1; }

python="$(sed -n 's/^Python3_EXECUTABLE:[A-Z]*=//p' "$cache" | head -n 1)"
python="${python:-/usr/bin/python3}"
target="$build/python"
marker="# Written by Basalt's scripts/python-path.sh"

# The folder for basalt.pth of one interpreter: its user site-packages (created if missing), or with --system
# its first site-packages folder.
site_of() {
  if [ "$where" = system ]; then
    "$1" -c 'import site; print(site.getsitepackages()[0])'
  else
    "$1" -c 'import site, sys; sys.exit("user site-packages are off for this interpreter (PYTHONNOUSERSITE?); use --system as root, or PYTHONPATH") if not site.ENABLE_USER_SITE else print(site.getusersitepackages())'
  fi
}

if [ "$mode" = remove ]; then
  removed=0
  for py in "$python" "$(command -v python3 || true)"; do
    [ -n "$py" ] || continue
    for dir in "$("$py" -c 'import site; print(site.getusersitepackages())' 2>/dev/null || true)" \
               "$("$py" -c 'import site; print(site.getsitepackages()[0])' 2>/dev/null || true)"; do
      pth="$dir/basalt.pth"
      if [ -n "$dir" ] && [ -f "$pth" ] && grep -qF "$marker" "$pth"; then
        rm -f "$pth" && echo "python-path: removed $pth" && removed=1
      fi
    done
  done
  [ "$removed" = 1 ] || echo "python-path: no basalt.pth written by this script was found"
  exit 0
fi

if ! grep -q '^BASALT_HAS_PYTHON:INTERNAL=ON$' "$cache"; then
  echo "python-path: this build has no Python package (BASALT_WITH_PYTHON is OFF: pybind11-dev or python3-dev"
  echo "  missing when it was configured, or turned off); nothing written"
  exit 0
fi
[ -f "$target/basalt/__init__.py" ] || {
  echo "python-path: $target/basalt is not built yet (cmake --build $build --target basalt-python)" >&2; exit 1; }

dir="$(site_of "$python")" || exit 1
mkdir -p "$dir"
pth="$dir/basalt.pth"
text="$marker: \`import basalt\` finds the build $target. Undo: bash $here/scripts/python-path.sh --remove (or delete this file)
$target"
if [ -f "$pth" ] && [ "$(cat "$pth")" = "$text" ]; then
  echo "python-path: $pth already points at $target"
else
  if [ -f "$pth" ] && ! grep -qF "$marker" "$pth"; then
    echo "python-path: $pth exists and was not written by this script; left alone. Use PYTHONPATH=$target" >&2
    exit 1
  fi
  tmp="$pth.tmp.$$"
  printf '%s\n' "$text" > "$tmp" && mv -f "$tmp" "$pth"
  echo "python-path: wrote $pth -> $target"
fi
echo "  $python -c 'import basalt' now finds it in any shell; undo with: bash scripts/python-path.sh --remove"

# python3 on PATH may be another interpreter (pyenv): say whether it sees the package and can load it.
other="$(command -v python3 || true)"
if [ -n "$other" ] && [ "$("$other" -c 'import sys; print(sys.executable)' 2>/dev/null || true)" != "$("$python" -c 'import sys; print(sys.executable)')" ]; then
  want="$("$python" -c 'import sys; print("%d.%d" % sys.version_info[:2])')"
  have="$("$other" -c 'import sys; print("%d.%d" % sys.version_info[:2])' 2>/dev/null || echo "?")"
  if [ "$have" != "$want" ]; then
    echo "  note: python3 on PATH ($other) is Python $have; the package is built for $python (Python $want): use $python"
  elif [ "$(site_of "$other" 2>/dev/null || true)" != "$dir" ]; then
    echo "  note: python3 on PATH ($other) reads another site-packages folder; use $python, or PYTHONPATH=$target"
  elif ! "$other" -c 'import numpy' 2>/dev/null; then
    echo "  note: python3 on PATH ($other) finds basalt too, but has no numpy (Debian's packages are $python's): use $python for the readers and basalt.pack"
  fi
fi
