"""``stridefix spy``: LCM's live channel viewer, lcm-spy, with the StrideFix types on its classpath.

lcm-spy is Java: it decodes a channel only when the message's Java class is on its classpath, which
``lcm-gen --java`` + ``javac`` + ``jar`` build into ``build/lcmtypes/java/stridefix_lcmtypes.jar``
(lcmtypes/CMakeLists.txt, when a JDK and lcm.jar are found). Debian's ``lcm-spy`` script cannot be
used: it passes ``-Xincgc``, which no JDK since 9 accepts (the JVM exits before the viewer starts).
So this starts ``java -cp lcm.jar:stridefix_lcmtypes.jar[:jchart2d.jar] lcm.spy.Spy`` itself, with
``--lcm-url`` passed through (stridefixd's ``-u`` URL; LCM's default, ``$LCM_DEFAULT_URL`` or
udpm://239.255.76.67:7667, without it). jchart2d (Debian libjchart2d-java) draws lcm-spy's field
plots: its message view fails without it, so it is put on the classpath when installed.

Each pose channel is its own row (POSE_EKF, POSE_KALMAN, ...; POSE is the primary pose), so the
schemes can be watched apart. :func:`spy_command` builds the command (the tests check it and run the
jar's classes headless); ``--print`` shows it instead of starting the window.
"""

from __future__ import annotations

import argparse
import os
import shlex
import shutil
import subprocess
import sys
import zipfile
from collections.abc import Sequence
from pathlib import Path

from stridefix_common.exits import EXIT_FAILURE, EXIT_OK, EXIT_USAGE

REPO = Path(__file__).resolve().parents[2]
#: the build's Java types (lcmtypes/CMakeLists.txt); ``$STRIDEFIX_LCMTYPES_JAR`` overrides it
DEFAULT_TYPES_JAR = REPO / "build" / "lcmtypes" / "java" / "stridefix_lcmtypes.jar"
#: LCM's Java library (Debian liblcm-java); ``$LCM_JAR`` overrides it
DEFAULT_LCM_JAR = Path("/usr/share/java/lcm.jar")
#: lcm-spy's plotting library (Debian libjchart2d-java), optional
DEFAULT_JCHART2D_JAR = Path("/usr/share/java/jchart2d.jar")
#: lcm-spy's entry point in lcm.jar
SPY_CLASS = "lcm.spy.Spy"


class SpyError(RuntimeError):
    """What lcm-spy needs is missing (java, lcm.jar, the types jar); the message says how to get it.
    ``status``: the exit status (1: the machine lacks a tool; 2: the types jar cannot be read or is
    not a jar, as stridefixd treats a --site or --config that is not one)."""

    def __init__(self, message: str, status: int = EXIT_FAILURE) -> None:
        super().__init__(message)
        self.status = status


def types_jar() -> Path:
    """``$STRIDEFIX_LCMTYPES_JAR`` when set, else the jar of the build whose Python bindings are
    imported (``<build>/lcmtypes/java`` beside ``<build>/lcmtypes/python``), else build/'s."""
    env = os.environ.get("STRIDEFIX_LCMTYPES_JAR")
    if env:
        return Path(env)
    import stridefix  # the generated bindings: on PYTHONPATH or the venv's .pth (tools/deps.sh)

    beside = Path(stridefix.__file__).resolve().parents[2] / "java" / DEFAULT_TYPES_JAR.name
    return beside if beside.is_file() else DEFAULT_TYPES_JAR


def lcm_jar() -> Path:
    """``$LCM_JAR`` when set, else Debian's lcm.jar."""
    return Path(os.environ.get("LCM_JAR") or DEFAULT_LCM_JAR)


def classpath(types: Path | None = None, lcm: Path | None = None) -> list[Path]:
    """lcm.jar, the StrideFix types and (when installed) jchart2d: every entry an existing file.

    Raises
    ------
    SpyError
        lcm.jar or the types jar is missing (the message says which and how to get it).
    """
    lcm = lcm or lcm_jar()
    types = types or types_jar()
    if not lcm.is_file():
        raise SpyError(
            f"{lcm}: no lcm.jar (Debian: apt-get install liblcm-java, or make deps; or set $LCM_JAR)"
        )
    if not types.is_file():
        raise SpyError(
            f"{types}: no StrideFix Java types (make build with a JDK and lcm.jar found; "
            "or set $STRIDEFIX_LCMTYPES_JAR)",
            EXIT_USAGE,
        )
    if not zipfile.is_zipfile(types):  # java would start and decode nothing: say so before it does
        raise SpyError(f"{types}: not a jar (zip) file of StrideFix Java types", EXIT_USAGE)
    extra = [DEFAULT_JCHART2D_JAR] if DEFAULT_JCHART2D_JAR.is_file() else []
    return [lcm, types, *extra]


def java() -> str:
    """The ``java`` launcher on PATH (``$JAVA_HOME/bin/java`` first when set)."""
    home = os.environ.get("JAVA_HOME")
    found = str(Path(home) / "bin" / "java") if home and (Path(home) / "bin" / "java").is_file() else None
    found = found or shutil.which("java")
    if not found:
        raise SpyError("no java on PATH (Debian: apt-get install openjdk-17-jre, or make deps for the JDK)")
    return found


def spy_command(lcm_url: str | None = None, types: Path | None = None, lcm: Path | None = None) -> list[str]:
    """The command that starts lcm-spy on ``lcm_url`` (LCM's default without one).

    IPv4 is preferred as in LCM's own script (its UDP multicast), and the heap kept small; the
    script's ``-Xincgc`` (removed in JDK 9) is left out."""
    cp = os.pathsep.join(str(p) for p in classpath(types, lcm))
    cmd = [java(), "-Djava.net.preferIPv4Stack=true", "-Xmx256m", "-cp", cp, SPY_CLASS]
    return cmd + (["--lcm-url", lcm_url] if lcm_url else [])


def add_parser(sub: argparse._SubParsersAction) -> argparse.ArgumentParser:
    p = sub.add_parser(
        "spy",
        help="start lcm-spy with the StrideFix types (live channels: POSE, POSE_<SCHEME>, FIX, ...)",
        description=__doc__.split("\n\n")[0] + " It runs java -cp lcm.jar:stridefix_lcmtypes.jar "
        "lcm.spy.Spy directly (Debian's lcm-spy script fails on JDK 17), so each StrideFix channel "
        "is decoded; watch stridefixd's live output (its -u URL) with the same --lcm-url.",
    )
    p.add_argument(
        "--lcm-url",
        metavar="URL",
        help="LCM URL to listen on, passed to lcm-spy (e.g. udpm://239.255.76.67:7667?ttl=0; "
        "default: LCM's, $LCM_DEFAULT_URL or udpm://239.255.76.67:7667)",
    )
    p.add_argument(
        "--types-jar",
        type=Path,
        help="the StrideFix Java types ($STRIDEFIX_LCMTYPES_JAR when set, else the jar of the build "
        "whose Python bindings are imported, <build>/lcmtypes/java/stridefix_lcmtypes.jar)",
    )
    p.add_argument("--print", action="store_true", help="print the command instead of starting lcm-spy")
    return p


def run(args: argparse.Namespace) -> int:
    try:
        cmd = spy_command(args.lcm_url, args.types_jar)
    except SpyError as exc:
        print(f"stridefix spy: error: {exc}", file=sys.stderr)
        return exc.status
    if args.print:
        print(shlex.join(cmd))
        return EXIT_OK
    return _start(cmd)


def _start(cmd: Sequence[str]) -> int:
    """Run lcm-spy until its window is closed; its exit status (1 when it could not start)."""
    proc = subprocess.run(list(cmd))
    return EXIT_OK if proc.returncode == 0 else EXIT_FAILURE
