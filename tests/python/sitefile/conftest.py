"""Fixtures for the site-file and radio-map tests: the C tests' vector site, and synthetic WIFI/TRUTH
logs written with the real generated LCM types."""

from __future__ import annotations

import argparse
import importlib
import importlib.util
import pathlib
import types

import lcm
import pytest
from stridefix import truth_t, wifi_scan_t
from stridefix_analyzer import cli

_VECTORS = pathlib.Path(__file__).resolve().parents[2] / "vectors" / "gen_site_vectors.py"


def _load_vectors():
    spec = importlib.util.spec_from_file_location("gen_site_vectors", _VECTORS)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


@pytest.fixture(scope="session")
def vectors():
    """tests/vectors/gen_site_vectors.py as a module: ``vector_site()``, ``variants()``,
    ``frame(payload, ...)`` (the same files tests/c/test_site.c checks)."""
    return _load_vectors()


@pytest.fixture
def vector_site(vectors):
    """The small known site of the C round-trip test (6 RPs, 4 APs, 7 entries, 3 floors)."""
    return vectors.vector_site()


def make_truth(t_us, x_m, y_m, floor=0):
    m = truth_t()
    m.t_us, m.x_m, m.y_m, m.floor = int(t_us), float(x_m), float(y_m), int(floor)
    m.heading_rad, m.step_count, m.source = float("nan"), -1, truth_t.SOURCE_WAYPOINT
    return m


def make_scan(t_us, aps, scan_id=0, complete=True):
    """``aps``: list of (bssid, rssi_dbm)."""
    m = wifi_scan_t()
    m.t_us, m.scan_id, m.complete = int(t_us), int(scan_id), bool(complete)
    m.n_ap = len(aps)
    m.bssid = [int(b) for b, _ in aps]
    m.rssi_dbm = [float(r) for _, r in aps]
    m.freq_mhz = [2412] * len(aps)
    return m


@pytest.fixture
def msg():
    """``msg.truth(t_us, x_m, y_m, floor=0)``, ``msg.scan(t_us, [(bssid, rssi), ...], ...)``."""
    return types.SimpleNamespace(truth=make_truth, scan=make_scan)


@pytest.fixture
def write_log(tmp_path):
    """``write_log(name, [(channel, msg), ...]) -> path``: an LCM event log in tmp_path."""

    def _write(name, events):
        path = tmp_path / name
        log = lcm.EventLog(str(path), "w", overwrite=True)
        for channel, m in events:
            log.write_event(int(m.t_us), channel, m.encode())
        log.close()
        return path

    return _write


@pytest.fixture
def stridefix_main():
    """``stridefix_main([...]) -> exit status``: ``stridefix`` with only the radiomap sub-command
    (so these tests do not depend on the other sub-commands' modules importing)."""

    def _main(argv):
        parser = argparse.ArgumentParser(prog="stridefix")
        sub = parser.add_subparsers(dest="command", required=True)
        module = importlib.import_module(cli.SUBCOMMANDS["radiomap"])
        module.add_parser(sub).set_defaults(_run=module.run)
        args = parser.parse_args([str(a) for a in argv])
        return int(args._run(args) or 0)

    return _main
