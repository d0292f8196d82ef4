#!/usr/bin/env bash
# ctest gsa.batch.*: `gsa batch` on a folder of parts with one broken part, a list file,
# --collect, and options gsa analyse rejects (docs/batch.md).
# Usage: check_batch.sh GSA SOURCE_DIR WORK_DIR
set -euo pipefail
gsa=$1
src=$(cd "$2" && pwd)
work=$3
fail() { echo "FAIL: $*" >&2; [ -f "$work/out/batch.csv" ] && cat "$work/out/batch.csv" >&2; exit 1; }
rm -rf "$work"
mkdir -p "$work/parts"
cd "$work"
cp "$src/data/gsa/dome/grid.csv" parts/dome.csv
cp "$src/data/gsa/cylinder/grid.csv" parts/cylinder.csv
cp "$src/data/gsa/dome_noisy/grid.csv" parts/dome_noisy.csv
# A broken part: a malformed number on line 6.
sed '6s/,[^,]*,/,1.2.3,/' "$src/data/gsa/dome/grid.csv" > parts/broken.csv

# 1. A folder, two at a time: the broken part fails, the others finish; exit code 1.
status=0
"$gsa" batch parts --out out -j 2 --options "--no-plots" 2>stderr.txt || status=$?
cat stderr.txt
[ "$status" -eq 1 ] || fail "exit code $status, expected 1 (one part failed)"
[ -f out/batch.csv ] || fail "no out/batch.csv"
head -2 out/batch.csv | grep -q '^part,status,input,points,points_analysed,max_major_true,min_thickness_change_pct,worst_flc_margin,run_time_s,results,error$' ||
  fail "batch.csv header"
for p in cylinder dome dome_noisy; do
  grep -q "^$p,ok,.*,441,[0-9]*," out/batch.csv || fail "part $p not ok with 441 points"
  [ -s "out/$p/strains.csv" ] || fail "out/$p/strains.csv missing"
done
grep -q '^broken,failed,' out/batch.csv || fail "the broken part is not listed as failed"
grep '^broken,' out/batch.csv | grep -q 'broken.csv:6' || fail "the broken part's error does not name broken.csv line 6"
[ ! -e out/broken ] || fail "the broken part left a results folder"
grep -q 'broken' stderr.txt || fail "stderr does not name the failed part"
# The dome's max major true strain: ln(1.1) = 0.0953 meridional stretch.
awk -F, '$1 == "dome" { if ($6 < 0.094 || $6 > 0.097) exit 1 }' out/batch.csv || fail "dome max_major_true not ln(1.1)"
echo "batch of a folder with a broken part: ok"

# 2. --collect rebuilds the same table from the folders (and the broken part's log).
cp out/batch.csv batch_run.csv
rm out/batch.csv
status=0
"$gsa" --quiet batch --collect out || status=$?
[ "$status" -eq 1 ] || fail "--collect exit code $status, expected 1"
diff <(cut -d, -f1-8 batch_run.csv) <(cut -d, -f1-8 out/batch.csv) || fail "--collect table differs from the run's"
echo "batch --collect: ok"

# 3. A list file (relative paths), data/gsa-style part folders with an options file.
mkdir -p trellis && cp "$src/data/gsa/trellis/grid.csv" trellis/ && cp "$src/data/gsa/trellis/options" trellis/
printf '# parts of the trial\nparts/dome.csv\n\ntrellis/grid.csv\n' > parts.txt
"$gsa" --quiet batch parts.txt --out out2 -j 1 --options "--no-plots --elements 6x6" || fail "list batch"
grep -q '^dome,ok,' out2/batch.csv && grep -q '^trellis,ok,' out2/batch.csv || fail "list batch rows"
mkdir -p folders && cp -r trellis folders/ && mkdir -p folders/dome && cp parts/dome.csv folders/dome/grid.csv
"$gsa" --quiet batch folders --out out3 --options "--no-plots" || fail "batch of part folders"
grep -q 'shear_angle_deg' out3/trellis/strains.csv || fail "the trellis part's options file (--fibres 0,90) was not used"
echo "batch of a list and of part folders with options files: ok"

# 4. Options that gsa analyse rejects: exit code 2, named, and not every part tried.
status=0
"$gsa" --quiet batch parts --out out4 -j 1 --options "--no-plots --smoothing-scale -1" 2>stderr4.txt || status=$?
cat stderr4.txt
[ "$status" -eq 2 ] || fail "bad --options: exit code $status, expected 2"
grep -q -- '--smoothing-scale' stderr4.txt || fail "bad --options: the message does not name --smoothing-scale"
echo "batch with options gsa analyse rejects: ok"
echo "gsa.batch: all checks passed"
