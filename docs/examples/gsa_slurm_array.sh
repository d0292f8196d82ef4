#!/bin/bash
#SBATCH --job-name=gsa-trial
#SBATCH --array=1-120%40          # 120 parts, at most 40 at once (set 120 to: wc -l < parts.txt)
#SBATCH --cpus-per-task=1
#SBATCH --mem=2G
#SBATCH --time=00:10:00
#SBATCH --output=/dev/null        # each task writes its own log below
set -u
list=parts.txt                    # one grid file per line (absolute, or relative to the submit folder)
out=results/trial                 # on a file system every node sees
grid=$(sed -n "${SLURM_ARRAY_TASK_ID}p" "$list")
part=$(basename "$grid" .csv)
mkdir -p "$out/logs"
log="$out/logs/$part.log"
echo "# gsa batch input: $grid" > "$log"
gsa --quiet analyse "$grid" --out "$out/$part" --no-plots >> "$log" 2>&1
