"""``stridefix spy`` (stridefix_analyzer/spy.py) and the Java types it puts on lcm-spy's classpath.

Headless: no window is opened and nothing goes on the network. The command is checked as built
(every classpath entry exists, the URL passed through, no ``-Xincgc``); the JVM is started with it
and ``--help`` (lcm-spy prints its usage: the options are accepted by this JDK and lcm.spy.Spy
loads); and a cross-language decode: Python's LCM bindings write messages into a log, a small Java
class (java/SpyDecode.java, compiled here) reads them back with lcm.logging.Log and decodes each
by its fingerprint through lcm-spy's own type database, as lcm-spy would, printing the fields.

The Java build is optional (lcmtypes/CMakeLists.txt: only with a JDK and lcm.jar), so without
javac or lcm.jar these tests are skipped; with both, a missing types jar is a failure.
"""

from __future__ import annotations

import os
import shlex
import shutil
import subprocess
import sys
from pathlib import Path

import lcm
import pytest
import stridefix_channels
from stridefix import fix_t, pose_t
from stridefix_analyzer import cli, spy

HERE = Path(__file__).resolve().parent
URL = "udpm://239.255.76.67:7667?ttl=0"


@pytest.fixture(scope="module")
def jars() -> tuple[Path, Path]:
    """(lcm.jar, stridefix_lcmtypes.jar); skips without a JDK or lcm.jar."""
    if not (shutil.which("java") and shutil.which("javac")):
        pytest.skip("no JDK (java, javac): the Java types are optional")
    if not spy.lcm_jar().is_file():
        pytest.skip(f"{spy.lcm_jar()}: no lcm.jar (liblcm-java): the Java types are optional")
    types = spy.types_jar()
    assert types.is_file(), f"{types}: a JDK and lcm.jar are here, so the build must have made the jar"
    return spy.lcm_jar(), types


def test_command_runs_spy_with_both_jars_and_the_url(jars):
    cmd = spy.spy_command(URL)
    cp = cmd[cmd.index("-cp") + 1].split(os.pathsep)
    assert cp[:2] == [str(j) for j in jars] and all(Path(p).is_file() for p in cp)
    assert cmd[-3:] == [spy.SPY_CLASS, "--lcm-url", URL]
    assert "-Xincgc" not in cmd  # Debian's lcm-spy script's option: no JDK since 9 starts with it
    assert spy.spy_command()[-1] == spy.SPY_CLASS  # no URL: LCM's default


def test_spy_starts_on_this_jdk(jars):
    """The JVM accepts the options and lcm.spy.Spy loads from the classpath: --help prints its usage
    and exits before any window or socket."""
    proc = subprocess.run([*spy.spy_command(URL), "--help"], capture_output=True, text=True, timeout=60)
    assert "usage: lcm-spy" in proc.stderr and "--lcm-url=URL" in proc.stderr, proc.stderr
    assert "Unrecognized VM option" not in proc.stderr and "Error" not in proc.stderr


def test_cli_prints_the_command(jars, capsys):
    assert cli.main(["spy", "--print", "--lcm-url", URL]) == 0
    assert shlex.split(capsys.readouterr().out) == spy.spy_command(URL)


def test_cli_names_a_missing_types_jar(tmp_path, monkeypatch, capsys):
    fake_lcm = tmp_path / "lcm.jar"
    fake_lcm.write_bytes(b"")
    monkeypatch.setenv("LCM_JAR", str(fake_lcm))
    monkeypatch.setenv("STRIDEFIX_LCMTYPES_JAR", str(tmp_path / "missing.jar"))
    assert cli.main(["spy", "--print"]) == 2  # an input that cannot be read
    err = capsys.readouterr().err
    assert "missing.jar" in err and "no StrideFix Java types" in err


def _pose(scheme: int, x_m: float) -> pose_t:
    m = pose_t()
    m.t_us, m.x_m, m.y_m, m.floor, m.heading_rad = 1_500_000, x_m, -2.25, 3, 0.5
    m.sigma_m, m.cov_xx_m2, m.cov_xy_m2, m.cov_yy_m2 = 1.5, 2.25, -0.125, 2.0
    m.heading_bias_rad, m.stride_scale, m.ess, m.step_count, m.scheme = 0.0625, 1.125, 0.0, 42, scheme
    return m


def _java_decode(log: Path, jars: tuple[Path, Path], tmp_path: Path) -> list[str]:
    classes = tmp_path / "classes"
    javac = [
        "javac",
        "-nowarn",
        "-cp",
        str(jars[0]),
        "-d",
        str(classes),
        str(HERE / "java" / "SpyDecode.java"),
    ]
    subprocess.run(javac, check=True, capture_output=True, timeout=120)
    # lcm-spy's own classpath (its type database scans it all: without jchart2d it reports lcm.jar's
    # plot classes as broken), plus the test class
    cp = os.pathsep.join([*(str(p) for p in spy.classpath()), str(classes)])
    out = subprocess.run(
        ["java", "-cp", cp, "SpyDecode", str(log)], check=True, capture_output=True, text=True, timeout=60
    ).stdout
    return out.splitlines()


def test_java_decodes_what_python_wrote(jars, tmp_path):
    """Python writes an ekf pose on POSE_EKF, the controller's on POSE, a FIX and a message of no
    StrideFix type; Java decodes the three by fingerprint, field for field, and knows the fourth not."""
    ekf_channel = stridefix_channels.POSE_SCHEME_CHANNELS[pose_t.SCHEME_EKF]
    fix = fix_t()
    fix.t_us, fix.method, fix.scheme, fix.x_m, fix.accuracy_m = 1_400_000, 1, pose_t.SCHEME_EKF, 7.5, 3.25
    fix.innovation_m, fix.accepted, fix.reason, fix.reason_text = [0.5, -0.75], True, 0, "accepted"
    events = [
        (ekf_channel, _pose(pose_t.SCHEME_EKF, 12.5)),
        ("POSE", _pose(pose_t.SCHEME_CONTROLLER, 12.5)),
        ("FIX", fix),
    ]
    path = tmp_path / "cross.lcmlog"
    log = lcm.EventLog(str(path), "w", overwrite=True)
    for k, (channel, msg) in enumerate(events):
        log.write_event(1_000 + k, channel, msg.encode())
    log.write_event(2_000, "OTHER", b"\x01" * 16)  # no type of ours has this fingerprint
    log.close()

    found, *rows = _java_decode(path, jars, tmp_path)
    # lcm-spy's type database finds every type of lcmtypes/stridefix on the classpath
    n_types = len(list((HERE.parents[2] / "lcmtypes" / "stridefix").glob("*.lcm")))
    assert found == f"Found {n_types} LCM types"
    lines = [row.split("\t") for row in rows]
    assert [ln[:2] for ln in lines] == [
        [ekf_channel, "stridefix.pose_t"],
        ["POSE", "stridefix.pose_t"],
        ["FIX", "stridefix.fix_t"],
        ["OTHER", "-"],
    ]
    for (_channel, msg), line in zip(events, lines):
        fields = dict(item.split("=", 1) for item in line[2:])
        assert sorted(fields) == sorted(msg.__slots__)
        for name in msg.__slots__:
            want = getattr(msg, name)
            got = fields[name]
            if isinstance(want, bool):
                assert got == str(want).lower(), name
            elif isinstance(want, list):
                assert [float(v) for v in got.strip("[]").split(", ")] == want, name
            elif isinstance(want, float):
                assert float(got) == want, name  # values exact in float32: no rounding either way
            elif isinstance(want, int):
                assert int(got) == want, name
            else:
                assert got == want, name
    assert lines[0][2:] != lines[1][2:]  # the scheme field tells the copies apart too


@pytest.mark.skipif(
    shutil.which("xvfb-run") is None or shutil.which("xwininfo") is None,
    reason="needs xvfb-run and xwininfo (tools/deps.sh)",
)
def test_spy_window_opens_on_a_virtual_display(jars, tmp_path):
    """GIVEN a file:// replay of a log and a virtual X display (Xvfb: no screen, no network), WHEN
    `stridefix spy` starts, THEN lcm-spy's window "LCM Spy" opens and lcm-spy finds every StrideFix
    type on its classpath (one per .lcm file), with no Java exception."""
    log = tmp_path / "w.lcmlog"
    ev = lcm.EventLog(str(log), "w", overwrite=True)
    m = pose_t()
    for k in range(50):
        m.t_us, m.x_m, m.scheme = 100_000 * k, 0.1 * k, pose_t.SCHEME_ADAPTIVE
        ev.write_event(m.t_us, "POSE_ADAPTIVE", m.encode())
    ev.close()
    script = (
        f"{shlex.quote(sys.executable)} -m stridefix_analyzer.cli spy --lcm-url "
        f"{shlex.quote(f'file://{log}?speed=1')} > {shlex.quote(str(tmp_path / 'spy.out'))} 2>&1 & P=$!; "
        "for i in $(seq 1 40); do xwininfo -root -tree | grep -q '\"LCM Spy\"' && break; sleep 0.5; done; "
        "xwininfo -root -tree | grep '\"LCM Spy\"'; kill $P; wait $P 2>/dev/null; true"
    )
    proc = subprocess.run(["xvfb-run", "-a", "sh", "-c", script], capture_output=True, text=True, timeout=120)
    out = (tmp_path / "spy.out").read_text()
    assert '"LCM Spy"' in proc.stdout, proc.stdout + proc.stderr + out
    n_types = len(list((HERE.parents[2] / "lcmtypes" / "stridefix").glob("*.lcm")))
    assert f"Found {n_types} LCM types" in out, out
    assert "Exception" not in out, out
