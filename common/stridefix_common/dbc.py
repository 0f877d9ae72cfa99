"""The board's CAN frames, ``board.dbc``: the one contract between board, simulator and firmware.

The file lives at ``firmware/board.dbc`` (the firmware's build generates its C codec from it);
``stridefix_common/board.dbc`` is a link to it in a checkout and a copy of it in a wheel, so every
Python reader finds it as this package's data, installed or not.
"""

from __future__ import annotations

from importlib import resources
from pathlib import Path

#: the DBC as a file (packages are installed as folders, never zipped)
DBC_PATH = Path(str(resources.files(__package__ or "stridefix_common") / "board.dbc"))
