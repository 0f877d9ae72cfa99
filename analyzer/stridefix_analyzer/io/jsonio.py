"""JSON output of the analyzer: numpy values become Python, non-finite floats become null.

Every JSON document the analyzer writes (metrics.json, results.json, bench files) goes through
:func:`json_ready`, so a NaN never reaches a file as the non-standard ``NaN`` token.
"""

from __future__ import annotations

import json
import math
import os
from pathlib import Path
from typing import Any

import numpy as np


def json_ready(value: Any) -> Any:
    """Recursively convert numpy scalars/arrays to Python, and non-finite floats to None."""
    if isinstance(value, dict):
        return {str(k): json_ready(v) for k, v in value.items()}
    if isinstance(value, (list, tuple)):
        return [json_ready(v) for v in value]
    if isinstance(value, np.ndarray):
        return json_ready(value.tolist())
    if isinstance(value, np.generic):
        value = value.item()
    if isinstance(value, float) and not math.isfinite(value):
        return None
    if isinstance(value, os.PathLike):
        return os.fspath(value)
    return value


def write_json(path: str | os.PathLike[str], doc: Any, indent: int = 2) -> Path:
    """Writes ``json_ready(doc)`` to ``path`` (parent folders created) and returns the path."""
    out = Path(path)
    out.parent.mkdir(parents=True, exist_ok=True)
    out.write_text(json.dumps(json_ready(doc), indent=indent, allow_nan=False) + "\n", encoding="utf-8")
    return out
