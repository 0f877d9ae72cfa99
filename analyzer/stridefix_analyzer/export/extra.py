"""The optional libraries of ``stridefix export`` (the ``export`` extra), imported when a format needs
them, with one message that says what to install."""

from __future__ import annotations

import importlib
from types import ModuleType

#: what to run when a library of the extra is missing
INSTALL_HINT = "pip install 'stridefix[export]' (in a checkout: make deps)"


class MissingExtraError(RuntimeError):
    """A library of the ``export`` extra is not installed; the message names it and how to get it."""


def need(module: str, what: str) -> ModuleType:
    """Import ``module`` (a library of the extra) for ``what`` (e.g. "--format gpx").

    Raises
    ------
    MissingExtraError
        It is not installed.
    """
    try:
        return importlib.import_module(module)
    except ImportError:
        raise MissingExtraError(
            f"{what} needs the Python package {module.split('.')[0]}: {INSTALL_HINT}"
        ) from None
