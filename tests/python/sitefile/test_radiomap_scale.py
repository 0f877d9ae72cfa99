"""radiomap build on a fleet of walks: the logs read as tasks on every scheduler (serial, local
processes, a Dask LocalCluster of 2 workers, a scheduler address) give a byte-identical site file."""

from __future__ import annotations

import numpy as np
import pytest
from stridefix_analyzer.io import sitefile
from stridefix_analyzer.parallel import dask_client

S = 1_000_000  # µs per s
N_WALKS = 8


def walk_events(msg, seed: int, channels=("TRUTH", "WIFI")):
    """A 60 s walk along x at 1 m/s from (seed, seed): waypoints every 10 s, a scan every 2 s hearing
    4 of 6 APs (seeded RSSI, whole dBm)."""
    rng = np.random.default_rng(seed)
    events = []
    if "TRUTH" in channels:
        events += [("TRUTH", msg.truth(k * 10 * S, seed + 10.0 * k, float(seed), 0)) for k in range(7)]
    if "WIFI" in channels:
        for j in range(30):
            aps = sorted(rng.choice(6, size=4, replace=False))
            heard = [(0xA0 + int(a), float(np.round(-40 - 5 * a - rng.uniform(0, 20)))) for a in aps]
            events.append(("WIFI", msg.scan((2 * j + 1) * S, heard, scan_id=j)))
    return sorted(events, key=lambda e: e[1].t_us)


@pytest.fixture
def fleet_logs(write_log, msg):
    """GIVEN N_WALKS walk logs with WIFI and TRUTH, a recording given as 'a,b' (scans and truth in
    two files) and a plain firmware + truth pair (merged into one recording)."""
    logs = [str(write_log(f"walk{i}.lcmlog", walk_events(msg, i))) for i in range(N_WALKS)]
    a = write_log("pair_wifi.lcmlog", walk_events(msg, 20, ("WIFI",)))
    b = write_log("pair_truth.lcmlog", walk_events(msg, 20, ("TRUTH",)))
    fw = write_log("fw.lcmlog", walk_events(msg, 30, ("WIFI",)))
    truth = write_log("truth.lcmlog", walk_events(msg, 30, ("TRUTH",)))
    return [*logs, f"{a},{b}", str(fw), str(truth)]


@pytest.fixture(scope="module")
def client():
    with dask_client("local", 2) as c:
        yield c


def test_every_scheduler_builds_the_same_site_bytes(fleet_logs, tmp_path, stridefix_main, client, capsys):
    def build(name: str, *opts: str) -> bytes:
        out = tmp_path / name / "fleet.sfsite"  # one site name (the file stem) for all
        assert (
            stridefix_main(
                ["radiomap", "build", *fleet_logs, "--mode", "walk", "--min-count", "1", "--out", out, *opts]
            )
            == 0
        )
        return out.read_bytes()

    serial = build("serial")
    site = sitefile.read_site(tmp_path / "serial" / "fleet.sfsite")
    assert int(np.sum(site.rp_scans)) == 30 * (N_WALKS + 2)  # every walk's scans placed, two merged pairs
    assert "10 recording(s)" in site.source
    assert build("processes", "--scheduler", "processes", "--workers", "2") == serial
    assert build("local", "--scheduler", "local", "--workers", "2") == serial
    assert build("address", "--scheduler", client.scheduler.address) == serial
    capsys.readouterr()


def test_a_worker_without_the_logs_is_told_what_to_share(
    fleet_logs, tmp_path, stridefix_main, client, capsys
):
    missing = str(tmp_path / "elsewhere" / "walk9.lcmlog")
    status = stridefix_main(
        [
            "radiomap",
            "build",
            *fleet_logs,
            missing,
            "--scheduler",
            client.scheduler.address,
            "--out",
            tmp_path / "x",
        ]
    )
    err = capsys.readouterr().err
    assert status == 2
    assert f"missing {missing}" in err and "same paths" in err
