#!/usr/bin/env bash
# ctest install.prefix: `cmake --install` into a temporary prefix, then run the installed
# tools from another folder on the installed sample data (docs/install.md). Checks that no
# path of the source or build tree is compiled into the installed programs.
# Usage: check_install.sh BUILD_DIR SOURCE_DIR [PYTHON]
set -euo pipefail
build=$(cd "$1" && pwd)
src=$(cd "$2" && pwd)
python=${3:-}
tmp=$(mktemp -d "${TMPDIR:-/tmp}/sf-install-test.XXXXXX")
trap 'rm -rf "$tmp"' EXIT
prefix=$tmp/prefix
fail() { echo "FAIL: $*" >&2; exit 1; }

cmake --install "$build" --prefix "$prefix" >"$tmp/install.log" || { cat "$tmp/install.log"; fail "cmake --install"; }

for f in bin/gsa bin/simform share/man/man1/gsa.1 share/man/man1/simform.1 \
         share/bash-completion/completions/gsa share/bash-completion/completions/simform \
         share/sheetform/data/gsa/dome/grid.csv share/sheetform/data/forming/cantilever.yaml \
         share/doc/sheetform/README.md share/doc/sheetform/usage.md; do
  [ -e "$prefix/$f" ] || fail "$f not installed"
done
echo "installed files: ok ($(find "$prefix" -type f | wc -l) files)"

# No build-tree or source-tree path inside the installed programs (they would find nothing
# there once the build folder is gone).
for exe in "$prefix"/bin/gsa "$prefix"/bin/simform $(find "$prefix" -name '_core*.so'); do
  for tree in "$src" "$build"; do
    if grep -qaF "$tree" "$exe"; then
      fail "$exe holds the path $tree: $(grep -aoF "$tree[^[:cntrl:]]*" "$exe" | head -3 | tr '\n' ' ')"
    fi
  done
done
echo "no build-tree paths in the installed programs: ok"

# Run from another folder, on the installed sample, with the build tree out of PATH.
work=$tmp/elsewhere
mkdir -p "$work"
cd "$work"
env -i HOME="$tmp" PATH=/usr/bin:/bin "$prefix/bin/gsa" --quiet analyse \
  "$prefix/share/sheetform/data/gsa/dome/grid.csv" --out dome --no-plots
[ -s dome/strains.csv ] && [ -s dome/summary.json ] || fail "installed gsa wrote no results"
rows=$(grep -vc '^#' dome/strains.csv)
[ "$rows" -eq 442 ] || fail "dome/strains.csv has $rows lines, expected 442 (header + 441 marks)"
echo "installed gsa analyse on the installed sample from $work: ok"
env -i HOME="$tmp" PATH=/usr/bin:/bin "$prefix/bin/simform" --quiet check \
  "$prefix/share/sheetform/data/forming/cantilever.yaml" >/dev/null || fail "installed simform check"
echo "installed simform check: ok"

# The man page renders and names the subcommands; the completion completes them.
grep -q '^\.SS "gsa analyse"' "$prefix/share/man/man1/gsa.1" || fail "gsa.1 has no 'gsa analyse' section"
grep -q 'batch' "$prefix/share/man/man1/gsa.1" || fail "gsa.1 does not mention gsa batch"
if command -v man >/dev/null; then
  # Into a file first: with pipefail, grep -q quitting early would fail `man` with SIGPIPE.
  MANWIDTH=100 man -l "$prefix/share/man/man1/gsa.1" >"$tmp/man.txt" 2>"$tmp/man.err" || true
  grep -q -- '--out' "$tmp/man.txt" ||
    { cat "$tmp/man.err"; fail "man -l gsa.1 does not render the options"; }
  echo "man -l gsa.1 renders: ok"
fi
words=$(bash -c 'source "$1"; COMP_WORDS=(gsa an); COMP_CWORD=1; _sf_gsa; echo "${COMPREPLY[*]}"' _ \
        "$prefix/share/bash-completion/completions/gsa")
[ "$words" = "analyse" ] || fail "completion of 'gsa an' gave '$words', expected 'analyse'"
words=$(bash -c 'source "$1"; COMP_WORDS=(gsa analyse --smoothing-s); COMP_CWORD=2; _sf_gsa; echo "${COMPREPLY[*]}"' _ \
        "$prefix/share/bash-completion/completions/gsa")
[ "$words" = "--smoothing-scale" ] || fail "completion of 'gsa analyse --smoothing-s' gave '$words'"
echo "bash completion: ok"

# The Python module from the installed prefix.
if [ -n "$python" ]; then
  pydir=$(dirname "$(dirname "$(find "$prefix" -name '_core*.so' | head -1)")")
  [ -d "$pydir/sheetform" ] || fail "the Python module is not installed"
  env -i HOME="$tmp" PATH=/usr/bin:/bin PYTHONPATH="$pydir" "$python" -c "
import sheetform, numpy as np
r = sheetform.analyse('$prefix/share/sheetform/data/gsa/dome/grid.csv', as_frame=False)
ok = np.isfinite(r.points['E1']).sum()
assert ok == 441, ok
assert sheetform.__file__.startswith('$pydir'), sheetform.__file__
print('installed Python module: ok (%d marks, from %s)' % (ok, sheetform.__file__))
"
fi
echo "install.prefix: all checks passed"
