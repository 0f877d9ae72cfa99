#!/usr/bin/env bash
# The default SIL walk, end to end, timing each step:
#   simulator -> candump log -> stridefixd -> LCM log -> analyzer -> metrics.json + report.html
set -euo pipefail
out=${1:-out/demo}; stridefixd=${2:-build/firmware/stridefixd}; venv=${3:-.venv}
mkdir -p "$out"
step() { local name=$1; shift; local t0 t1; t0=$(date +%s%N); "$@"; t1=$(date +%s%N);
         local ms=$(( (t1 - t0) / 1000000 ))
         printf 'demo: %-10s %4d.%03d s\n' "$name" $((ms / 1000)) $((ms % 1000)) | tee -a "$out/timings.txt"; }
: > "$out/timings.txt"
step sim       "$venv/bin/stridefix" sim --out "$out"
# The map's rotation from magnetic north is a fact of the site (the site file will carry it).
rotation=$("$venv/bin/python" -c 'import json,sys; print(json.load(open(sys.argv[1]))["map_rotation_deg"])' "$out/sim_summary.json")
step stridefixd "$stridefixd" --input "$out/board.candump" --log "$out/stridefixd.lcmlog" --config "$out/init_truth.ini" \
               --set "heading.map_rotation_deg=$rotation"
step analyze   "$venv/bin/stridefix" analyze "$out/stridefixd.lcmlog" "$out/truth.lcmlog" --out "$out" \
               --label "default SIL walk, PDR only, truth-initialised start (init_truth.ini)"
step report    "$venv/bin/stridefix" report "$out"
echo "demo: wrote $out/report.html and $out/metrics.json"
