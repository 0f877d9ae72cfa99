"""Tuning as data: every choice ``realbench fusion`` makes per fold is one row — an :class:`Axis` of
(name, candidates, chooser) in :data:`AXES` — and :func:`choose` runs the rows in order.

Candidates are ``stridefixd --set KEY=VALUE`` lists (the first is the firmware default). A chooser
sees the prepared walks of one group and returns the candidate of every walk's fold, chosen from the
*other* walks only (DESIGN.md, evaluation protocol):

* ``heading`` (:class:`TruthAgreement`): gait-learned or fixed mounting offset (the wide magnetometer
  gate is no candidate since the attitude acquires its references from quiet samples); the one whose
  STEP headings agree best with the other walks' truth directions
  (:func:`stridefix_analyzer.radiomap.heading.choose_heading_variant`). A hand-held phone is not a body-worn board.
* ``matcher`` (:class:`InnerCV`, :mod:`.select`): scans averaged (1 or 2) × WkNN representation (dBm
  or "powed"), by cross-validation inside the training walks on the Wi-Fi fix error.
* ``adaptive`` (:class:`InnerCV`): the adaptive scheme's Wi-Fi accuracy-factor scale, the same way on
  the adaptive POSE error, with each block's matcher (settings chosen by earlier inner-CV rows carry
  over per block).
* ``fixmodel`` (:class:`Measured`): not a choice: the ``ekf`` scheme's fix-error model, measured on the
  other walks' Wi-Fi fixes against the truth (:mod:`.fixmodel`).
* ``lsd`` (:class:`SchemeByError`, :mod:`.lsd`): the multi-scheme controller's scheme for the floor's
  context (the site's localization scheme descriptor), the fusion scheme with the lowest POSE error
  on the training walks, every scheme scored from one replay.

A user's ``--set`` of any key an axis varies replaces that axis's candidates by ``{"given": []}``
(:func:`axes`). A new tuning idea is one more row, not a new stage in ``run_fusion``.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Callable, Mapping, Sequence
from pathlib import Path
from typing import Any, Protocol, TextIO

from stridefix_analyzer.console import Progress
from stridefix_analyzer.firmware import Firmware
from stridefix_analyzer.parallel import TaskRunner
from stridefix_analyzer.radiomap.heading import (
    HEADING_VARIANTS,
    RotationSums,
    choose_heading_variant,
    learn_heading,
)

from stridefix_lab.realbench import fixmodel, lsd
from stridefix_lab.realbench import select as rs

#: the matcher's candidates: scans averaged (1 or 2) × WkNN representation (dBm, or "powed" with beta
#: 2 or e — Torres-Sospedra 2015's choice)
_AVERAGE = {"1 scan": [], "2 scans": ["fingerprint.average_scans=2"]}
_REPRESENTATION = {
    "dBm": [],
    "powed 2": ["fingerprint.powed_beta=2"],
    "powed e": ["fingerprint.powed_beta=2.718281828"],
}
MATCHER_VARIANTS = {f"{a}, {r}": sa + sr for a, sa in _AVERAGE.items() for r, sr in _REPRESENTATION.items()}
#: the adaptive scheme's Wi-Fi accuracy factors (a table on the AP count, AADR 2015) times a scale: the
#: table says little when every scan hears ~100 APs
ADAPTIVE_VARIANTS = {
    "table x 1": [],
    "table x 0.5": ["fusion.acc_wifi_scale=0.5"],
    "table x 0.25": ["fusion.acc_wifi_scale=0.25"],
}

Candidates = Mapping[str, Sequence[str]]


@dataclasses.dataclass(frozen=True)
class Group:
    """What a chooser sees of one group: its prepared walks (phase 1) and how to replay them."""

    walks: list[dict[str, Any]]  # the same dict objects the sites callable sees (identity matters)
    rotation: Sequence[Mapping[str, RotationSums]]  # per walk, per heading candidate
    #: ``sites(removed, others, name, path)`` writes a selection site and returns its settings
    sites: Callable[[Any, list[dict[str, Any]], str, Path], list[str]]
    firmware: Firmware
    work_dir: Path
    base_sets: Sequence[str]
    tasks: TaskRunner  # where the replays run
    stream: TextIO
    #: the group's inner-CV replays, shared by every row that replays (:class:`.select.ReplayCache`)
    replays: rs.ReplayCache = dataclasses.field(default_factory=rs.ReplayCache)


@dataclasses.dataclass(frozen=True)
class Choice:
    """One axis's outcome in one group."""

    per_walk: list[str]  # the candidate of each walk's fold
    info: dict[str, Any]  # the group's record of how it was chosen (results.json)
    extra: list[dict[str, Any]]  # per walk, further fold fields (results.json)
    #: settings chosen per inner-CV block, for the inner-CV rows after this one
    block_sets: dict[int, list[str]] = dataclasses.field(default_factory=dict)
    #: per walk, site_t fields measured rather than chosen (``fixmodel``), None where not measured
    walk_site_fields: list[dict[str, Any] | None] | None = None


class Chooser(Protocol):
    def __call__(self, axis: Axis, group: Group, block_sets: Mapping[int, Sequence[str]]) -> Choice: ...


@dataclasses.dataclass(frozen=True)
class TruthAgreement:
    """Per fold, the candidate whose STEP headings agree best with the truth directions of the other
    walks (every walk was replayed with every candidate in phase 1)."""

    def __call__(self, axis: Axis, group: Group, block_sets: Mapping[int, Sequence[str]]) -> Choice:
        variant, score, rotation = learn_heading(group.rotation)
        per_walk, extra = [], []
        for j in range(len(group.walks)):
            v, s = choose_heading_variant(group.rotation, exclude=j)
            per_walk.append(v)
            extra.append({f"{axis.name}_resultant": s})
        info = {
            f"{axis.name}_variant_all_walks": variant,
            f"{axis.name}_resultant_all_walks": score,
            "rotation_all_walks_deg": rotation,
        }
        return Choice(per_walk, info, extra)


@dataclasses.dataclass(frozen=True)
class InnerCV:
    """Cross-validation inside the training walks (:func:`.select.select`); ``stage`` says what is
    replayed and scored (:data:`.select.STAGES`)."""

    stage: str

    def __call__(self, axis: Axis, group: Group, block_sets: Mapping[int, Sequence[str]]) -> Choice:
        prog = Progress(
            f"choose {axis.name}", rs.n_tasks(len(group.walks), len(axis.candidates)), group.stream
        )
        per_walk, report = rs.select(
            group.walks,
            group.sites,
            stridefixd=group.firmware.path,
            work_dir=group.work_dir,
            base_sets=list(group.base_sets),
            candidates={k: list(v) for k, v in axis.candidates.items()},
            tasks=group.tasks,
            progress=prog.step,
            stage=self.stage,
            block_sets={a: list(s) for a, s in block_sets.items()},
            cache=group.replays,
        )
        chosen = report.get("choice_of_block", {})
        sets = {a: list(axis.candidates[n]) for a, n in chosen.items()}
        return Choice(per_walk, {f"{axis.name}_selection": report}, [{} for _ in per_walk], sets)


@dataclasses.dataclass(frozen=True)
class Measured:
    """Not a choice but a measurement (:func:`.fixmodel.measure`): the ``ekf`` scheme's fix-error
    model from the other walks' Wi-Fi fixes against the truth, with each block's matcher. The one
    candidate stands for "measured"; a user's ``--set`` of a model key keeps the given value."""

    def __call__(self, axis: Axis, group: Group, block_sets: Mapping[int, Sequence[str]]) -> Choice:
        n = len(group.walks)
        if "given" in axis.candidates or n < fixmodel.MIN_WALKS:
            why = "given by --set" if "given" in axis.candidates else f"fewer than {fixmodel.MIN_WALKS} walks"
            info = {f"{axis.name}_model": {"measured_by": f"firmware prior ({why})"}}
            return Choice([next(iter(axis.candidates))] * n, info, [{} for _ in range(n)])
        fields, sigma_c, report = fixmodel.measure(
            group.walks,
            group.sites,
            group.firmware,
            group.work_dir / axis.name,
            group.base_sets,
            block_sets,
            group.tasks,
            group.stream,
            cache=group.replays,
            site_dir=group.work_dir,
        )
        extra = [
            {f"{axis.name}_site_fields": f, f"{axis.name}_correlated_sigma_m": c}
            for f, c in zip(fields, sigma_c, strict=True)
        ]
        # later inner-CV rows (the controller's scheme) replay with each block's model as settings,
        # so the ekf is judged there with what its fold sites give it (block a: i % n_blocks, the
        # blocks of select.block_replays; the model of block a was measured without block a)
        n_blocks = min(rs.DEFAULT_BLOCKS, n)
        sets = {a: fixmodel.model_sets(f) for a in range(n_blocks) for f in fields[a::n_blocks][:1] if f}
        return Choice(
            ["measured"] * n, {f"{axis.name}_model": report}, extra, block_sets=sets, walk_site_fields=fields
        )


@dataclasses.dataclass(frozen=True)
class SchemeByError:
    """The controller's scheme of every fold (:func:`.lsd.choose_lsd`): it goes into the fold's site
    (its context map), not into the --set list, so each candidate's settings are empty."""

    def __call__(self, axis: Axis, group: Group, block_sets: Mapping[int, Sequence[str]]) -> Choice:
        per_walk, report = lsd.choose_lsd(
            group.walks,
            group.sites,
            firmware=group.firmware,
            work_dir=group.work_dir / axis.name,
            base_sets=group.base_sets,
            block_sets=block_sets,
            tasks=group.tasks,
            stream=group.stream,
            cache=group.replays,
            site_dir=group.work_dir,
        )
        fields: list[dict[str, Any] | None] = [{lsd.SITE_KEY: s} for s in per_walk]
        extra = [{f"{axis.name}_scheme": s} for s in per_walk]
        return Choice(per_walk, {f"{axis.name}_selection": report}, extra, walk_site_fields=fields)


@dataclasses.dataclass(frozen=True)
class Axis:
    """One tuning row: ``name`` (fold field ``<name>_variant``), ``label`` (console), the candidates
    (name → --set list) and the chooser."""

    name: str
    label: str
    candidates: Candidates
    chooser: Chooser


AXES: tuple[Axis, ...] = (
    Axis("heading", "heading variant", HEADING_VARIANTS, TruthAgreement()),
    Axis("matcher", "matcher", MATCHER_VARIANTS, InnerCV("matcher")),
    Axis("adaptive", "adaptive", ADAPTIVE_VARIANTS, InnerCV("adaptive")),
    Axis("fixmodel", "ekf fix model", {"measured": [f"{k}=" for k in fixmodel.KEYS]}, Measured()),
    Axis("lsd", "controller scheme", {name: [] for name in lsd.CANDIDATES}, SchemeByError()),
)


def variants_unless_given(param_sets: Sequence[str] | None, table: Candidates) -> dict[str, list[str]]:
    """The candidates of ``table`` ({name: ["key=value", ...]}), or only ``{"given": []}`` when the
    user's ``--set`` list already sets one of the keys they vary (the user's choice wins)."""
    keys = {kv.split("=", 1)[0] for sets in table.values() for kv in sets}
    if any(kv.split("=", 1)[0].strip() in keys for kv in param_sets or []):
        return {"given": []}
    return {k: list(v) for k, v in table.items()}


def axes(param_sets: Sequence[str] | None, rows: Sequence[Axis] = AXES) -> tuple[Axis, ...]:
    """The rows with the user's ``--set`` applied (see :func:`variants_unless_given`)."""
    return tuple(
        dataclasses.replace(a, candidates=variants_unless_given(param_sets, a.candidates)) for a in rows
    )


def candidates(name: str, param_sets: Sequence[str] | None = None) -> dict[str, list[str]]:
    """The candidates of axis ``name`` given the user's ``--set`` list."""
    (axis,) = [a for a in axes(param_sets) if a.name == name]
    return {k: list(v) for k, v in axis.candidates.items()}


def choose(rows: Sequence[Axis], group: Group) -> dict[str, Choice]:
    """Run every row's chooser in order on one group; returns axis name → choice."""
    choices: dict[str, Choice] = {}
    block_sets: dict[int, list[str]] = {}
    for axis in rows:
        choices[axis.name] = c = axis.chooser(axis, group, block_sets)
        for a, sets in c.block_sets.items():
            block_sets[a] = block_sets.get(a, []) + sets
    return choices


def settings(rows: Sequence[Axis], variants: Mapping[str, str]) -> list[str]:
    """The --set list of the chosen candidate of every row, in row order (a measured row's one
    candidate only names its keys: its values go into the fold's site, ``walk_site_fields``)."""
    return [kv for a in rows if not isinstance(a.chooser, Measured) for kv in a.candidates[variants[a.name]]]


def walk_site_fields(choices: Mapping[str, Choice], j: int) -> dict[str, Any]:
    """The measured site_t fields of walk ``j``'s fold, from every row that measures."""
    return {
        k: v for c in choices.values() if c.walk_site_fields for k, v in (c.walk_site_fields[j] or {}).items()
    }
