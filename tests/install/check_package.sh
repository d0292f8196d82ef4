#!/usr/bin/env bash
# ctest package.deb and package.dpkg_install (docs/install.md).
#   check_package.sh control BUILD_DIR   cpack -G DEB into BUILD_DIR/package-test/; the
#                                         control file's Depends lists runtime packages only
#   check_package.sh dpkg BUILD_DIR      dpkg -i that package, run the installed gsa on
#                                         an installed sample from another folder, and
#                                         remove the package again. Root only, and only when
#                                         CI is set or SF_TEST_DPKG=1 (it changes the
#                                         system); skipped (exit 77) otherwise.
set -euo pipefail
mode=$1
build=$(cd "$2" && pwd)
fail() { echo "FAIL: $*" >&2; exit 1; }

if [ "$mode" = dpkg ]; then
  if [ "$(id -u)" -ne 0 ]; then echo "SKIP: dpkg -i needs root (runs in CI)"; exit 77; fi
  if [ -z "${CI:-}" ] && [ "${SF_TEST_DPKG:-0}" != 1 ]; then
    echo "SKIP: installs the package into this system; runs when CI is set or SF_TEST_DPKG=1"; exit 77
  fi
  if dpkg-query -W -f='${Status}' sheetform 2>/dev/null | grep -q "install ok installed"; then
    echo "SKIP: a sheetform package is already installed here; not touching it"; exit 77
  fi
fi
for tool in cpack dpkg-deb dpkg-shlibdeps file; do
  command -v "$tool" >/dev/null || fail "$tool not found (scripts/install_deps.sh installs dpkg-dev and file)"
done

tmp=$(mktemp -d "${TMPDIR:-/tmp}/sf-package-test.XXXXXX")
trap 'rm -rf "$tmp"' EXIT
pkgdir=$build/package-test
if [ "$mode" = control ]; then
  rm -rf "$pkgdir"
  mkdir -p "$pkgdir"
  (cd "$pkgdir" && cpack -G DEB --config "$build/CPackConfig.cmake" -B "$pkgdir" >"$pkgdir/cpack.log" 2>&1) ||
    { cat "$pkgdir/cpack.log"; fail "cpack -G DEB"; }
  rm -rf "$pkgdir/_CPack_Packages"
fi
deb=$(ls "$pkgdir"/sheetform_*.deb 2>/dev/null | head -1)
[ -n "$deb" ] || fail "no sheetform_*.deb in $pkgdir (package.deb makes it)"
echo "package: $(basename "$deb") ($(du -h "$deb" | cut -f1))"

depends=$(dpkg-deb -f "$deb" Depends)
echo "Depends: $depends"
[ -n "$depends" ] || fail "the package lists no dependencies"
# Runtime packages only: no -dev package, no compiler, no build tool.
# Here-strings, not `echo | grep -q`: with pipefail, grep -q quitting at its first match can
# kill echo with SIGPIPE on a long listing and fail the check at random.
if grep -Eq -- '-dev( |$|\()|(^| )(g\+\+|cmake|ninja-build)( |$)' <<<"${depends//,/$'\n'}"; then
  fail "build-time packages in Depends: $depends"
fi
for want in libc6 libstdc++6; do
  grep -q "$want" <<<"$depends" || fail "Depends lacks $want"
done
grep -Eq 'libvtk9' <<<"$depends" || fail "Depends lacks the VTK runtime library package"
grep -Eq 'libcholmod|libsuitesparse' <<<"$depends" || fail "Depends lacks the CHOLMOD runtime library package"
contents=$(dpkg-deb -c "$deb")
for f in ./usr/bin/gsa ./usr/bin/simform ./usr/share/man/man1/gsa.1 ./usr/share/bash-completion/completions/gsa \
         ./usr/share/sheetform/data/gsa/dome/grid.csv; do
  grep -q " $f\$" <<<"$contents" || grep -q " $f " <<<"$contents" || fail "$f is not in the package"
done
echo "package.deb: control file and contents ok"
[ "$mode" = dpkg ] || exit 0

dpkg -i "$deb" || fail "dpkg -i $deb"
trap 'dpkg -r sheetform >/dev/null 2>&1 || true; rm -rf "$tmp"' EXIT
work=$tmp/elsewhere
mkdir -p "$work"
cd "$work"
[ "$(command -v gsa)" = /usr/bin/gsa ] || fail "gsa on PATH is $(command -v gsa), not /usr/bin/gsa"
gsa --quiet analyse /usr/share/sheetform/data/gsa/dome/grid.csv --out dome --no-plots
[ -s dome/strains.csv ] || fail "the installed gsa wrote no strains.csv"
echo "dpkg -i, then gsa analyse on /usr/share/sheetform/data/gsa/dome from $work: ok"
if [ -n "$(dpkg-deb -c "$deb" | grep '_core.*\.so')" ]; then
  /usr/bin/python3 -c "import sheetform; r = sheetform.analyse('/usr/share/sheetform/data/gsa/dome/grid.csv', as_frame=False); print('import sheetform from the package: ok,', int((r.points['status'] == 'ok').sum()), 'marks')"
fi
dpkg -r sheetform >/dev/null
echo "package.dpkg_install: ok (package removed again)"
