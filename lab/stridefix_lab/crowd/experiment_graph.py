"""The graph rows of ``crowd experiment``: the crowd graph (:mod:`.graph`) next to the thesis's rows.

Same walks, same anchors and the same error points as the thesis rows of :mod:`.experiment`; each row
says which constraints it used and how many (anchors, step rows, heading rows, Wi-Fi rows), and what
the graph learned from the anchors (fleet stride scale and heading bias, σ_θ by anchor
cross-validation).
"""

from __future__ import annotations

import time
from typing import Any

from stridefix_analyzer.crowd.graph_run import solve_walks_graph
from stridefix_analyzer.crowd.solve import error_stats


def graph_rows(
    walks, anchors: str, solver: str, band: str, wifi_models=(), progress=print
) -> list[dict[str, Any]]:
    """One row for steps + anchors, then one per Wi-Fi pair model in ``wifi_models`` (name, model)."""
    out = []
    for key, label, model in [
        ("graph", "graph: PDR steps + anchors (scale, heading bias per walk)", None)
    ] + [(f"graph_wifi:{name}", f"graph: + Wi-Fi loop closures ({name})", m) for name, m in wifi_models]:
        t0 = time.perf_counter()
        run = solve_walks_graph(walks, anchors=anchors, wifi_model=model, wifi="on", band=band, solver=solver)
        e = error_stats(run.xy_m, run.points, run)
        r = run.info["rows"]
        out.append(
            {
                "key": key,
                "label": label,
                "thesis_mean_m": None,
                "thesis_std_m": None,
                **{k: e.get(k) for k in ("mean_m", "std_m", "median_m", "p90_m", "n", "mean_all_m")},
                "rows": {"anchors": r["anchors"], "pdr": r["steps"], "wifi": r["wifi"], "graph": r},
                "solver": run.info["solver"]["solver"],
                "run_s": time.perf_counter() - t0,
                "problem": {
                    "priors": run.info["priors"],
                    "heading_sigma_rad_per_sqrt_s": run.info["settings"]["heading_sigma_rad_per_sqrt_s"],
                    "heading_sigma_cv": run.info["heading_sigma_cv"],
                    "scale": run.info["scale"],
                },
            }
        )
        p = run.info["priors"]
        progress(
            f"  {label:<55} mean {e.get('mean_m', float('nan')):6.2f} m  ({out[-1]['run_s']:.1f} s; "
            f"{r['steps']} step, {r['wifi']} Wi-Fi rows; fleet scale {p['scale']:.2f}±{p['scale_sigma']:.2f}, "
            f"σ_θ {run.info['settings']['heading_sigma_rad_per_sqrt_s']:g} rad/√s)"
        )
    return out


def select_pair_model(fit_walks, anchors: str, solver: str, band: str, progress=print):
    """The pair model for the Wi-Fi rows, chosen on the fitting walks only (never the scored ones):
    every candidate of :mod:`.select_model` by held-out R², the top 3 then by the solved position
    error of the held-out fold's walks (graph with that fold's model, loop closures on)."""
    from stridefix_lab.crowd.select_model import format_table, select_model  # noqa: PLC0415

    def score(model, held_walks) -> float:
        run = solve_walks_graph(
            held_walks, anchors=anchors, wifi_model=model, wifi="on", band=band, solver=solver
        )
        return float(error_stats(run.xy_m, run.points, run).get("mean_m", float("nan")))

    usable = [w for w in fit_walks if len(w.step_t_us) and len(w.truth_t_us) >= 3 and w.n_scans]
    sel = select_model(usable, band=band, score_positions=score)
    progress(format_table(sel))
    return sel
