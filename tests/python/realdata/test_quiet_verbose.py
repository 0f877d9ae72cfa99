"""`stridefix -q` and `-v` before a long-running command: -q leaves only warnings and
errors on stderr, and no verbosity changes a result.

GIVEN the handmade msindoor trace (four malformed lines), WHEN `stridefix [-q|-v] import msindoor` runs,
THEN the default prints the per-file and the total line, -q prints neither but still the four
malformed-line warnings, -v what the default prints, and stdout and the written log are the same at
every verbosity.
"""

from __future__ import annotations

import pytest

SAID = ("[1/1] ", "1/1 trace(s) imported into OUT")


def _import(cli, trace, out, *front):
    proc = cli(*front, "import", "msindoor", str(trace), "--out", str(out), timeout=120)
    assert proc.returncode == 0, proc.stderr
    log = (out / "handmade.lcmlog").read_bytes()
    return proc.stdout.replace(str(out), "OUT"), proc.stderr.replace(str(out), "OUT"), log


@pytest.mark.parametrize("flag", ["-q", "-v"])
def test_verbosity_changes_stderr_only(cli, handmade_trace, tmp_path, flag):
    out, err, log = _import(cli, handmade_trace, tmp_path / "default")
    out_f, err_f, log_f = _import(cli, handmade_trace, tmp_path / flag.lstrip("-"), flag)
    assert (out_f, log_f) == (out, log)
    assert err.count("warning:") == 4 and err_f.count("warning:") == 4
    assert all(s in err for s in SAID)
    if flag == "-q":
        assert not any(s in err_f for s in SAID)
    else:
        assert all(s in err_f for s in SAID)
