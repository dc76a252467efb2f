#!/usr/bin/env bash
# install_deps_check.sh: scripts/install-deps.sh beside Debian's ParaView, with a fake dpkg-query (the packages
# in $FAKE_INSTALLED are installed), a fake apt-get (records its arguments) and a fake id (root), so nothing is
# installed. With python3-paraview installed and libvtk9-dev missing, it must explain the conflict and the two
# choices, install everything else but libvtk9-dev, and exit 0; otherwise it installs libvtk9-dev as before.
set -u
here="$(cd "$(dirname "${BASH_SOURCE[0]}")/../.." && pwd)"
fake="$(mktemp -d)"
trap 'rm -rf "$fake"' EXIT
fail() { echo "FAIL: $*"; exit 1; }

cat >"$fake/dpkg-query" <<'SH'
#!/bin/sh
# dpkg-query -W -f='${Status}' PACKAGE
for p in $FAKE_INSTALLED; do [ "$p" = "$3" ] && { printf 'install ok installed'; exit 0; }; done
echo "dpkg-query: no packages found matching $4" >&2
exit 1
SH
cat >"$fake/apt-get" <<'SH'
#!/bin/sh
echo "$*" >>"$APT_LOG"
SH
printf '#!/bin/sh\necho 0\n' >"$fake/id"
chmod +x "$fake/dpkg-query" "$fake/apt-get" "$fake/id"

all=$(sed -n '/^PACKAGES=(/,/^)/p' "$here/scripts/install-deps.sh" | sed '1d;$d' | tr -s ' \n' ' ')
[ -n "$all" ] && [[ " $all " == *" libvtk9-dev "* ]] || fail "could not read the package list of install-deps.sh"

# deps INSTALLED...: runs install-deps.sh; its output in $fake/out, apt-get's calls in $fake/apt
deps() {
  rm -f "$fake/apt"
  FAKE_INSTALLED="$*" APT_LOG="$fake/apt" PATH="$fake:$PATH" bash "$here/scripts/install-deps.sh" >"$fake/out" 2>&1
}
installs() { grep -q "^install .* $1\( \|\$\)" "$fake/apt" 2>/dev/null; }

# 1. ParaView with its Python module, nothing else: explained, everything else installed, no libvtk9-dev.
deps paraview python3-paraview || { cat "$fake/out"; fail "exit status $? beside ParaView"; }
cat "$fake/out"
for w in 'python3-paraview' 'python3-vtk9' 'libvtk9-dev' 'pkgProblemResolver::Resolve generated breaks' \
         'BASALT_WITH_VTK=OFF' 'ckpt_series.xmf' 'apt-get remove python3-paraview' \
         'installing everything but libvtk9-dev; the build will have no VTK'; do
  grep -qF -- "$w" "$fake/out" || fail "beside ParaView: the explanation does not say \"$w\""
done
installs cmake && installs libhdf5-openmpi-dev && installs xvfb || fail "beside ParaView: the other packages were not installed"
! installs libvtk9-dev || fail "beside ParaView: libvtk9-dev was asked for (apt would refuse)"

# 2. Everything but libvtk9-dev present beside ParaView: nothing to install, says so, exit 0.
deps python3-paraview paraview ${all/libvtk9-dev/} || { cat "$fake/out"; fail "exit status $? with all else present"; }
[ ! -e "$fake/apt" ] || fail "apt-get called although only libvtk9-dev is missing beside ParaView"
grep -q "all packages present but libvtk9-dev" "$fake/out" || { cat "$fake/out"; fail "does not say libvtk9-dev is left out"; }

# 3. No ParaView, or ParaView without its Python module: libvtk9-dev installed as before, no explanation.
for others in "" "paraview"; do
  deps $others || fail "exit status $? (installed: '$others')"
  installs libvtk9-dev || { cat "$fake/out" "$fake/apt"; fail "libvtk9-dev not installed (installed: '$others')"; }
  ! grep -q "python3-paraview" "$fake/out" || fail "a ParaView explanation without python3-paraview installed"
done
# 4. Everything installed, ParaView's Python module too (VTK's development files are there): nothing said.
deps python3-paraview $all || fail "exit status $? with everything installed"
grep -q "^install-deps: all [0-9]* packages present$" "$fake/out" || { cat "$fake/out"; fail "expected 'all packages present'"; }
echo "install-deps.sh: beside ParaView explained and VTK left out; otherwise libvtk9-dev installed"
