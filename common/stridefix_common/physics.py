"""Physical constants the simulator models and the analyzer's synthetic data share.

An access point hangs at the ceiling of its floor; the simulator's radio (:mod:`stridefix_sim.radio`)
and the lab's synthetic crowd fleet place every AP at this height above its floor's walking surface.
"""

from __future__ import annotations

#: height of a Wi-Fi access point above its floor's walking surface (ceiling mount) [m]
AP_HEIGHT_M = 2.8
