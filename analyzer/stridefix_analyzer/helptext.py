"""``--help`` as a user reads it: the docstring markup the sub-commands' descriptions reuse is removed
(````code````, ``:func:`x```, ``:mod:`.y```), and "(default: ...)" is shown only where a default says
something (not on a required option, a flag, an empty list or a None that means "see the help").

:func:`plain_parser` gives one parser and its sub-parsers a formatter class derived from each parser's
own (raw descriptions stay raw); ``stridefix_analyzer.cli`` applies it to every sub-command.
"""

from __future__ import annotations

import argparse
import re

# :role:`target` (Sphinx), with an optional ~ (show the last part) or leading . (relative target)
_ROLE = re.compile(r":(?:py:)?(?:func|mod|class|meth|data|attr|exc|obj|ref|term):`(~?)(\.?)([^`]+)`")
_LITERAL = re.compile(r"``([^`]*)``")


def plain(text: str) -> str:
    """``text`` without reStructuredText roles and literals: ``:func:`a.b``` -> ``a.b``, ``:mod:`.c```
    and ``:class:`~a.C``` -> the last part, ````x```` -> ``x``."""

    def role(m: re.Match[str]) -> str:
        target = m.group(3)
        return target.rsplit(".", 1)[-1] if (m.group(1) or m.group(2)) else target

    return _LITERAL.sub(r"\1", _ROLE.sub(role, text))


def _says_nothing(action: argparse.Action) -> bool:
    """A default not worth printing: a required option, a flag, None, an empty list."""
    d = action.default
    return action.required or action.nargs == 0 or d is None or d == [] or d is argparse.SUPPRESS


def plain_formatter(base: type[argparse.HelpFormatter]) -> type[argparse.HelpFormatter]:
    """``base`` (the parser's formatter class) that writes :func:`plain` text and no empty defaults."""

    class Plain(base):  # type: ignore[valid-type, misc]
        def _format_text(self, text: str) -> str:
            return str(super()._format_text(plain(text)))

        def _get_help_string(self, action: argparse.Action) -> str | None:
            own = action.help or ""
            text = super()._get_help_string(action)
            if text is None or "%(default)" in own:
                return text
            if "default" in own or _says_nothing(action):  # the help states it, or there is none to state
                return own
            return text

        def _expand_help(self, action: argparse.Action) -> str:
            return plain(str(super()._expand_help(action)))

    Plain.__name__ = f"Plain{base.__name__}"
    return Plain


def plain_parser(parser: argparse.ArgumentParser) -> None:
    """Give ``parser`` and every sub-parser below it :func:`plain_formatter` of its own formatter."""
    if not getattr(parser.formatter_class, "_stridefix_plain", False):
        cls = plain_formatter(parser.formatter_class)  # type: ignore[arg-type]
        cls._stridefix_plain = True  # type: ignore[attr-defined]
        parser.formatter_class = cls
    for action in parser._actions:
        if isinstance(action, argparse._SubParsersAction):
            for child in set(action.choices.values()):
                plain_parser(child)
