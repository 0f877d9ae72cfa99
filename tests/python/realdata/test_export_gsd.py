"""`stridefix export` on a real IPIN 2023 walk: the exported latitude/longitude lands on the
competition's own ground truth (its POSI records), so the site's geo-reference, the projection and
the export agree with the world, not only with each other."""

from __future__ import annotations

import json
import subprocess

import numpy as np
from stridefix_common.geodesy import project


def _posi(path):
    """(AppTimestamp [s], lat [deg], lon [deg]) of a logfile's POSI records."""
    rows = [
        line.split(";") for line in path.read_text(encoding="utf-8").splitlines() if line.startswith("POSI;")
    ]
    return np.array([[float(r[1]), float(r[3]), float(r[4])] for r in rows])


def test_exported_track_lands_on_the_competitions_truth(real_gsd, tmp_path, cli, stridefixd):
    # GIVEN repetition 1 as the site (radio map about the first POSI, rotation 0) and repetition 2 as the walk
    walk_txt = real_gsd.with_name(real_gsd.name.replace("repetition01", "repetition02"))
    posi = _posi(walk_txt)
    origin = f"{float(posi[0, 1])!r},{float(posi[0, 2])!r}"
    proc = cli(
        "-q", "import", "gsd", str(real_gsd), str(walk_txt), "--out", str(tmp_path), "--origin", origin
    )
    assert proc.returncode == 0, proc.stderr
    survey, walk = (tmp_path / p.with_suffix(".lcmlog").name for p in (real_gsd, walk_txt))
    site = tmp_path / "site.sfsite"
    proc = cli("-q", "radiomap", "build", str(survey), "--out", str(site), "--origin-deg", origin)
    assert proc.returncode == 0, proc.stderr
    run = tmp_path / "run.lcmlog"
    fw = [str(stridefixd), "--input", f"lcmlog:{walk}", "--log", str(run), "--site", str(site), "-q"]
    assert subprocess.run(fw, capture_output=True).returncode == 0
    # WHEN the kalman track is exported as GeoJSON
    out = tmp_path / "walk.geojson"
    proc = cli("export", str(run), "--site", str(site), "--out", str(out), "--scheme", "kalman")
    assert proc.returncode == 0, proc.stderr
    # THEN at each POSI time the exported position is within the estimator's error of the POSI
    # latitude/longitude (a wrong axis, sign or origin would put it tens of metres off or more)
    doc = json.loads(out.read_text())
    t_s = np.concatenate([f["properties"]["t_s"] for f in doc["features"]])
    coords = np.concatenate([np.atleast_2d(f["geometry"]["coordinates"]) for f in doc["features"]])
    i = np.clip(np.searchsorted(t_s, posi[:, 0]), 0, len(t_s) - 1)
    e, n = project(coords[i, 1], coords[i, 0], posi[0, 1], posi[0, 2])
    te, tn = project(posi[:, 1], posi[:, 2], posi[0, 1], posi[0, 2])
    error_m = np.hypot(e - te, n - tn)
    assert len(error_m) == 14
    assert np.median(error_m) < 4.0 and error_m.max() < 15.0  # measured: median 1.9 m, max 7.6 m
