#!/usr/bin/env bash
# The default SIL walk, end to end, timing each step:
#   1. survey: the simulator surveys the office (both floors) -> candump -> stridefixd -> LCM log
#      -> `stridefix radiomap build --building` -> out/demo/site.sfsite (floors, map rotation, radio map, and
#      the survey's building.toml: walls, stairs and elevator, geo-reference; the survey's world is the walk's)
#   2. walk: the default two-floor tour -> candump -> stridefixd --site -> LCM log with every fusion
#      scheme side by side (POSE per scheme, FIX audit records) -> analyzer -> metrics.json + report.html,
#      headlining the scheme stridefixd published on POSE (its primary pose)
#   3. true start: the same walk replayed once more with every scheme truth-initialised (the simulator's
#      init_truth.ini, init.use_config_pose=1) -> out/demo/true_start/ (metrics.json, report.html): the
#      row to read there is pdr_only, PDR alone from the true start (--scheme pdr_only headlines it)
# The survey is its own recording (seed 1000); the walk never trains its own map. In step 2 every scheme
# starts at its first Wi-Fi fix (pdr_only too): nothing there is truth-initialised.
set -euo pipefail
out=${1:-out/demo}; stridefixd=${2:-build/firmware/stridefixd}; venv=${3:-.venv}
mkdir -p "$out/survey"
step() { local name=$1; shift; local t0 t1; t0=$(date +%s%N); "$@"; t1=$(date +%s%N);
         local ms=$(( (t1 - t0) / 1000000 ))
         printf 'demo: %-12s %4d.%03d s\n' "$name" $((ms / 1000)) $((ms % 1000)) | tee -a "$out/timings.txt"; }
: > "$out/timings.txt"
step survey-sim "$venv/bin/stridefix" sim --scenario office_survey --seed 1000 --out "$out/survey"
step survey-fw  "$stridefixd" --input "$out/survey/board.candump" --log "$out/survey/stridefixd.lcmlog" -q
rotation=$("$venv/bin/python" -c 'import json,sys; print(json.load(open(sys.argv[1]))["map_rotation_deg"])' \
           "$out/survey/sim_summary.json")
step radiomap   "$venv/bin/stridefix" radiomap build "$out/survey/stridefixd.lcmlog" "$out/survey/truth.lcmlog" \
                --mode survey --name office --map-rotation-deg "$rotation" --building "$out/survey/building.toml" \
                --out "$out/site.sfsite"
step sim        "$venv/bin/stridefix" sim --out "$out"
ln -f "$out/board.candump" "$out/board.log"  # the same file: python-can's LogReader picks candump text by .log
step stridefixd "$stridefixd" --input "$out/board.candump" --log "$out/stridefixd.lcmlog" --site "$out/site.sfsite"
step analyze    "$venv/bin/stridefix" analyze "$out/stridefixd.lcmlog" "$out/truth.lcmlog" --out "$out" --site "$out/site.sfsite" \
                --label "default SIL walk, office radio map, every scheme from its first fix"
step report     "$venv/bin/stridefix" report "$out"
echo "demo: the same walk, every scheme TRUTH-INITIALISED (read pdr_only: PDR alone from the true start)"
mkdir -p "$out/true_start"
step true-start "$stridefixd" --input "$out/board.candump" --log "$out/true_start/stridefixd.lcmlog" \
                --site "$out/site.sfsite" --config "$out/init_truth.ini" --set init.use_config_pose=1 -q
step analyze-ts "$venv/bin/stridefix" analyze "$out/true_start/stridefixd.lcmlog" "$out/truth.lcmlog" \
                --out "$out/true_start" --site "$out/site.sfsite" --scheme pdr_only \
                --label "default SIL walk, office radio map, every scheme truth-initialised (init_truth.ini)"
step report-ts  "$venv/bin/stridefix" report "$out/true_start"
echo "demo: wrote $out/report.html and $out/metrics.json (from the first fix)," \
     "$out/true_start/report.html and metrics.json (truth-initialised)"
