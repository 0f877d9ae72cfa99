"""StrideFix analyzer: reads LCM logs, scores POSE against TRUTH, writes metrics and reports.

``__version__`` has one source, the repository's file VERSION (CMake's project version, so stridefixd's
too): read from the checkout when this package runs from one (an editable install's metadata may be
older), else the installed distribution's metadata (which setuptools took from VERSION).
"""

from __future__ import annotations

from importlib import metadata
from pathlib import Path


def _version() -> str:
    checkout = Path(__file__).resolve().parents[2] / "VERSION"
    if checkout.is_file() and (checkout.parent / "pyproject.toml").is_file():
        return checkout.read_text(encoding="utf-8").strip()
    try:
        return metadata.version("stridefix")
    except metadata.PackageNotFoundError:
        return "unknown"


__version__ = _version()
