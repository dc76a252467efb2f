#!/usr/bin/env bash
# Prepares Debian 12's ParaView (5.11) pvpython in a folder, without installing ParaView: the packages
# paraview and python3-paraview, and the libraries they need that are not installed, are fetched with
# `apt-get download` and unpacked with `dpkg -x` into DIR/root. (python3-paraview cannot be installed beside
# libvtk9-dev: it conflicts with python3-vtk9. Never `apt-get install` it here: that removes libvtk9-dev.)
#
# Usage: tests/paraview/fetch_pvpython.sh DIR
#   then: source DIR/env.sh && pvpython --force-offscreen-rendering script.py   (under xvfb-run to draw)
# Idempotent: when DIR/ready names the same version and pvpython starts, nothing is fetched again; two
# callers at once wait for each other (flock). Costs, once: ~73 MB downloaded, ~530 MB unpacked, ~20-40 s.
# Exit 0: ready (prints DIR/env.sh). Exit 77: it cannot be done here (no apt-get, not Debian, no network to
# the mirror, a library that cannot be found, BASALT_SKIP_PARAVIEW=1): the reason on stderr; the ParaView
# test reports SKIPPED on 77 (tests/paraview/CMakeLists.txt).
set -uo pipefail

cannot() {
  echo "fetch_pvpython: $*" >&2
  exit 77
}

[ $# -eq 1 ] || {
  echo "usage: $0 DIR" >&2
  exit 2
}
[ "${BASALT_SKIP_PARAVIEW:-0}" = 0 ] || cannot "BASALT_SKIP_PARAVIEW=${BASALT_SKIP_PARAVIEW} set: not fetching ParaView"
mkdir -p "$1" || cannot "cannot create $1"
dest="$(cd "$1" && pwd)"
root="$dest/root"
lib="$root/usr/lib/x86_64-linux-gnu"

if command -v flock >/dev/null; then
  exec 9>"$dest/.lock"
  flock 9
fi

write_env() {
  cat >"$dest/env.sh" <<ENV
# pvpython unpacked by tests/paraview/fetch_pvpython.sh (Debian's paraview $1, not installed)
export PATH="$root/usr/bin:\$PATH"
export LD_LIBRARY_PATH="$lib:$lib/paraview-5.11\${LD_LIBRARY_PATH:+:\$LD_LIBRARY_PATH}"
export PYTHONPATH="$root/usr/lib/python3/dist-packages\${PYTHONPATH:+:\$PYTHONPATH}"
ENV
}

# pvpython starts and imports paraview.simple: prints ParaView's version, or fails.
works() {
  (
    source "$dest/env.sh"
    echo 'from paraview.simple import GetParaViewVersion; print("ParaView", GetParaViewVersion())' >"$dest/probe.py"
    timeout 120 pvpython --force-offscreen-rendering "$dest/probe.py" 2>&1
  )
}

if [ -f "$dest/ready" ] && [ -f "$dest/env.sh" ] && works >/dev/null; then
  echo "pvpython ready: $(cat "$dest/ready") ($dest/env.sh)"
  exit 0
fi

command -v apt-get >/dev/null && command -v dpkg-deb >/dev/null && command -v dpkg-query >/dev/null ||
  cannot "needs apt-get and dpkg (Debian)"
[ "$(dpkg --print-architecture 2>/dev/null)" = amd64 ] || cannot "needs an amd64 Debian (this is $(dpkg --print-architecture 2>/dev/null))"
apt_opts=(-q -o Acquire::http::Timeout=30 -o Acquire::Retries=2)
[ "$(id -u)" -eq 0 ] && apt_opts+=(-o APT::Sandbox::User=root)  # root downloads into a folder _apt cannot write

if ! apt-cache show paraview python3-paraview >/dev/null 2>&1; then
  [ "$(id -u)" -eq 0 ] || cannot "apt knows no paraview package; run apt-get update as root"
  apt-get "${apt_opts[@]}" update -qq >&2 || cannot "apt-get update failed (no network to the mirror?)"
  apt-cache show paraview python3-paraview >/dev/null 2>&1 || cannot "the mirror has no paraview/python3-paraview"
fi

rm -rf "$dest/debs" "$root" "$root.partial" "$dest/ready"
mkdir -p "$dest/debs" "$root.partial"
cd "$dest/debs" || cannot "cannot enter $dest/debs"
apt-get "${apt_opts[@]}" download paraview python3-paraview >&2 || cannot "apt-get download paraview python3-paraview failed"
version="$(dpkg-deb -f paraview_*.deb Version)"

# The libraries they depend on that are not installed (the first of each alternative; python modules, tclsh and
# the GUI's helpers are not needed to read and draw files).
missing=()
for p in $(for d in ./*.deb; do dpkg-deb -f "$d" Depends; done | tr ',' '\n' | sed 's/|.*//; s/(.*)//; s/:any//; s/ //g' | sort -u); do
  case "$p" in lib*) ;; *) continue ;; esac
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if [ ${#missing[@]} -gt 0 ]; then
  echo "fetch_pvpython: also fetching ${missing[*]} (not installed)" >&2
  apt-get "${apt_opts[@]}" download "${missing[@]}" >&2 || cannot "apt-get download ${missing[*]} failed"
fi
for d in ./*.deb; do
  dpkg -x "$d" "$root.partial" || cannot "dpkg -x $d failed"
done
mv "$root.partial" "$root"
cd "$dest" && rm -rf "$dest/debs"  # the packages are not kept: only what pvpython needs

write_env "$version"
if ! out="$(works)"; then
  echo "$out" | tail -5 >&2
  source "$dest/env.sh"
  ldd "$root/usr/bin/pvpython" 2>/dev/null | grep 'not found' >&2
  cannot "the unpacked pvpython does not start (above)"
fi
echo "$version" >"$dest/ready"
echo "pvpython ready: $version, $out ($dest/env.sh)"
