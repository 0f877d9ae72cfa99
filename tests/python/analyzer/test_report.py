"""report sub-command: a self-contained HTML page with embedded PNG figures."""

import base64
import re


def test_report_embeds_png_images(walk_logs, tmp_path, cli_main):
    fw, sim = walk_logs
    out = tmp_path / "an"
    assert cli_main(["analyze", str(fw), str(sim), "--out", str(out)]) == 0
    assert cli_main(["report", str(out)]) == 0
    page = (out / "report.html").read_text()
    images = re.findall(r"data:image/png;base64,([A-Za-z0-9+/=]+)", page)
    # the error figures: trajectory per floor, floor over time, error over time, error CDF; then the
    # walk's that the log has data for: floor and barometric height, claimed σ, HEALTH (no STEP, no FIX)
    alts = re.findall(r"<img alt='([^']*)'", page)
    assert alts[:4] == [
        "trajectory, one panel per floor",
        "estimated vs true floor over time",
        "error over time, one panel per scheme",
        "error CDF",
    ]
    assert alts[4:] == ["floor and barometric height over time", "claimed sigma over time"]
    assert len(images) == len(alts) == 6
    for img in images:
        assert base64.b64decode(img).startswith(b"\x89PNG\r\n\x1a\n")
    for text in ("adaptive", "pdr_only", "frames_total", "fusion.mode", "<style>"):
        assert text in page
    assert "http://" not in page and "https://" not in page  # nothing fetched from outside


def test_report_out_option(walk_logs, tmp_path, cli_main):
    fw, sim = walk_logs
    out = tmp_path / "an"
    assert cli_main(["analyze", str(fw), str(sim), "--out", str(out)]) == 0
    target = tmp_path / "elsewhere" / "r.html"
    assert cli_main(["report", str(out), "--out", str(target)]) == 0
    assert target.read_text().startswith("<!DOCTYPE html>")


def test_report_missing_dir_exits_2(tmp_path, cli_main, capsys):
    assert cli_main(["report", str(tmp_path / "none")]) == 2
    assert "none" in capsys.readouterr().err


def test_report_missing_npz_exits_2(tmp_path, cli_main, capsys):
    (tmp_path / "metrics.json").write_text("{}")
    assert cli_main(["report", str(tmp_path)]) == 2
    assert "analysis.npz" in capsys.readouterr().err
