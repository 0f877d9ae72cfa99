"""``stridefix-lab bench particle-cost``: the particle scheme's instructions per step under callgrind.

The cost target: at most 1 million instructions per PDR step at 1 000 particles on a floor plan
of 5 000 wall segments. The harness ``tests/perf/particle_cost.c`` (built as ``sf_particle_cost`` next
to ``stridefixd``'s build tree) builds such a floor, seeds the cloud and walks; callgrind counts the
instructions inside the scheme's step call (``--toggle-collect=sf_fusion_step_on_floor``) and, in a
second run, inside its fix call (``sf_fusion_fix_on_floor``). Writes ``particle_cost.json``.
"""

from __future__ import annotations

import argparse
import json
import subprocess
from pathlib import Path
from typing import Any

from stridefix_analyzer.firmware import Firmware

from stridefix_lab.bench import callgrind
from stridefix_lab.bench.registry import Bench
from stridefix_lab.stages import StageError

TARGET_PER_STEP = 1_000_000
STEPS = 400
FIXES = STEPS // 4


def harness_path(stridefixd: Path) -> Path:
    """``sf_particle_cost`` of the build tree that holds ``stridefixd`` (``build/firmware/stridefixd``)."""
    return stridefixd.resolve().parents[1] / "tests" / "perf" / "sf_particle_cost"


def _callgrind(harness: Path, function: str, out: Path) -> int:
    return callgrind.instructions([str(harness), str(STEPS)], [function], out, "particle-cost")


def run_particle_cost(stridefixd: Path, out: Path) -> dict[str, Any]:
    """Runs the harness twice under callgrind; returns (and writes) the document."""
    harness = harness_path(stridefixd)
    if not harness.is_file():
        raise StageError(f"particle-cost: {harness} not found (build it: make build)")
    out.mkdir(parents=True, exist_ok=True)
    plain = subprocess.run([str(harness), str(STEPS)], capture_output=True, text=True, check=True)
    walk = json.loads(plain.stdout)
    step_ir = _callgrind(harness, "sf_fusion_step_on_floor", out / "particle_cost.step.callgrind")
    fix_ir = _callgrind(harness, "sf_fusion_fix_on_floor", out / "particle_cost.fix.callgrind")
    per_step = step_ir / STEPS
    doc = {
        "harness": str(harness),
        "walk": walk,
        "instructions_per_step": per_step,
        "instructions_per_fix": fix_ir / FIXES,
        "target_per_step": TARGET_PER_STEP,
        "met": per_step <= TARGET_PER_STEP,
    }
    (out / "particle_cost.json").write_text(json.dumps(doc, indent=1))
    return doc


def format_table(doc: dict[str, Any]) -> str:
    w = doc["walk"]
    verdict = "MET" if doc["met"] else "MISSED"
    return (
        f"particle cost: {w['particles']} particles, {w['walls']} walls ({w['grid_bytes']} B index, "
        f"{w['cell_m']:.1f} m cells), {w['steps']} steps\n"
        f"  instructions per step {doc['instructions_per_step']:,.0f} (target <= {TARGET_PER_STEP:,}): {verdict}\n"
        f"  instructions per fix  {doc['instructions_per_fix']:,.0f}"
    )


def missed_targets(doc: dict[str, Any]) -> list[str]:
    if doc["met"]:
        return []
    return [f"particle-cost: {doc['instructions_per_step']:,.0f} instructions per step > {TARGET_PER_STEP:,}"]


def _run(args: argparse.Namespace, firmware: Firmware, seeds: list[int], out: Path) -> list[str]:
    del args, seeds  # one fixed walk of the harness
    doc = run_particle_cost(firmware.path, out)
    print(format_table(doc))
    print(f"wrote {out / 'particle_cost.json'}")
    return missed_targets(doc)


BENCH = Bench(
    "particle-cost",
    "the particle scheme's instructions per step under callgrind (1 000 particles, 5 000 walls; "
    "target <= 1 million)",
    _run,
    in_make_bench=True,
)
