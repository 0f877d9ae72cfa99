"""A context map for a real one-building site without a description (contexts.single_building_context_map,
what realbench calls per fold): msindoor site1/F2's radio map from a few of its walks, built by the
existing tools; every floor context gets at least one constellation member and the site file takes it."""

from __future__ import annotations

import warnings

import numpy as np
import pytest
from stridefix import fix_t, pose_t, site_t
from stridefix_analyzer.datasets import msindoor
from stridefix_analyzer.io import sitefile
from stridefix_analyzer.radiomap import contexts
from stridefix_analyzer.radiomap.build import build_site, load_recordings

from .conftest import MSINDOOR


@pytest.fixture(scope="module")
def real_site(tmp_path_factory):
    """GIVEN the radio map of six site1/F2 walks (skips without the shared data)."""
    folder = MSINDOOR / "site1" / "F2" / "path_data_files"
    traces = sorted(folder.glob("*.txt"))[:6] if folder.is_dir() else []
    if not traces:
        pytest.skip(f"real msindoor data not found at {folder} (needs ../shared/data beside the repository)")
    out = tmp_path_factory.mktemp("ctx")
    logs = []
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        for k, trace in enumerate(traces):
            logs.append(out / f"w{k}.lcmlog")
            msindoor.DATASET.import_walk(trace, logs[-1])
    site, _ = build_site(load_recordings([str(p) for p in logs]), name="site1-F2")
    return site, out


def test_every_floor_context_of_a_real_site_has_members(real_site):
    site, out = real_site
    contexts.single_building_context_map(site, scheme="ekf")
    lowest = site.lowest_floor
    assert list(site.context_floor) == [lowest + i for i in range(site.n_floors)]
    assert set(site.context_kind) == {site_t.CONTEXT_FLOOR}
    assert set(site.context_scheme) == {pose_t.SCHEME_EKF}
    assert set(site.context_method) <= {fix_t.METHOD_WIFI, fix_t.METHOD_BLE}
    members = np.bincount(np.asarray(site.cdd_context), minlength=site.n_contexts)
    floors_with_rps = {int(f) for f in site.rp_floor}
    for c in range(site.n_contexts):
        if site.context_floor[c] in floors_with_rps:
            assert members[c] >= 1, f"context {c} (floor {site.context_floor[c]}) has no member"
    # the outline holds every RP, and every member's threshold is one its own RPs reach
    b = np.asarray(site.outline_building)
    outline = [(site.outline_x_m[i], site.outline_y_m[i]) for i in np.flatnonzero(b == 0)]
    assert contexts.inside(np.asarray(site.rp_x_m), np.asarray(site.rp_y_m), outline).all()
    assert np.isfinite(site.cdd_min_dbm).all() and max(site.cdd_min_dbm) < 0.0
    path = out / "site.sfsite"
    sitefile.write_site(path, site)
    assert sitefile.read_site(path).n_contexts == site.n_floors
