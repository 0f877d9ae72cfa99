"""The progress of the long-running commands at each verbosity (stridefix -q / default / -v).

GIVEN a phase of 1,000 steps (realbench's folds of a floor printed a line each), WHEN it runs at a
verbosity on a stream, THEN -v prints 1,000 lines, the default prints one line off a terminal and one
updating bar (carriage returns, never a newline: the command's live line, cleared when the command
ends) on a terminal, and -q prints nothing.
"""

from __future__ import annotations

import io

import pytest
from stridefix_analyzer import console
from stridefix_analyzer.console import Progress

N = 1000


class Terminal(io.StringIO):
    def isatty(self) -> bool:
        return True


@pytest.fixture
def level():
    """Sets the verbosity for one test and restores the default after it."""
    yield console.set_level
    console.end_progress()
    console.set_level(console.NORMAL)


def _phase(stream: io.StringIO) -> str:
    prog = Progress("fold", N, stream)
    for i in range(N):
        prog.step(f"walk {i}: kalman mean 2.0 m")
    return stream.getvalue()


def test_verbose_prints_a_line_per_step(level):
    level(console.VERBOSE)
    lines = _phase(io.StringIO()).splitlines()
    assert len(lines) == N
    assert lines[0].startswith("realbench: fold [1/1000] walk 0: kalman mean 2.0 m  elapsed ")
    assert lines[-1].startswith("realbench: fold [1000/1000] ") and lines[-1].endswith("ETA 0 s")


def test_default_off_a_terminal_prints_one_line(level):
    level(console.NORMAL)
    lines = _phase(io.StringIO()).splitlines()
    assert len(lines) == 1 and lines[0].startswith("realbench: fold 1000/1000 done (")


def test_default_on_a_terminal_draws_one_bar(level):
    level(console.NORMAL)
    stream = Terminal()
    _phase(stream)
    drawn = stream.getvalue()
    console.end_progress()
    out = stream.getvalue()
    assert out.count("\n") == 0 and drawn.count("\r") >= 2
    assert "realbench: fold" in drawn and "1000/1000" in drawn.rsplit("\r", 1)[-1]
    assert out[len(drawn) :].strip() == ""  # the command's end clears the line


@pytest.mark.parametrize("stream", [io.StringIO(), Terminal()], ids=["file", "terminal"])
def test_quiet_prints_nothing(level, stream):
    level(console.QUIET)
    assert _phase(stream) == ""
    console.say("bench x: [1/2]", stream)
    assert stream.getvalue() == ""


def test_no_stream_prints_nothing(level):
    level(console.VERBOSE)
    prog = Progress("walk", 3, None)
    for _ in range(3):
        prog.step("x")  # no error, nothing to write to


def test_say_follows_the_level(level):
    out = io.StringIO()
    level(console.NORMAL)
    console.say("a", out)
    level(console.QUIET)
    console.say("b", out)
    level(console.VERBOSE)
    console.say("c", out)
    assert out.getvalue() == "a\nc\n"
    with pytest.raises(ValueError):
        console.set_level(5)
