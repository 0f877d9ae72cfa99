"""The walker's body and the shape of one step: who walks, and how a step accelerates the body.

Person (seeded by its own random stream, so the same seed is the same person whatever the pace):
stride scale ~ N(1, 0.06) and cadence scale ~ N(1, 0.04) (clipped to ±12 % / ±8 %), Weinberg constant
K = 0.5 × stride scale × (1 ± 3 %) within 0.45..0.55 (K, like the stride, grows with leg length, so
people of one pace bounce alike). Pace (``walk.pace``): slow 1.5 Hz / 0.55 m, normal 1.8 Hz / 0.70 m, fast 2.1 Hz /
0.85 m, times the person's scales.

Gait shape: F(u) over one step (phase u in [0, 1), mid-stance to mid-stance), a fixed periodic shape
of unit peak-to-peak: a smooth stance/swing component (minimum at mid-stance, when the body is
highest) plus a sharp heel-strike peak just after contact (at u_peak ≈ 0.53); Z' and Z are its exact
integrals (Z ≤ 0, Z = Z' = 0 at mid-stance). ``walker.py`` scales them per step.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

G_MPS2 = 9.80665
PACES = {"slow": (1.5, 0.55), "normal": (1.8, 0.70), "fast": (2.1, 0.85)}  # cadence Hz, stride m
TURN_RATE_DPS = 90.0  # mean turn rate in place


def _gait_shape(n: int = 2048):
    """Tables of the unit gait shape over one step (u in [0, 1], n + 1 points): F (a_z), Z' (v_z), Z (z)."""
    u = np.arange(n) / n

    def bump(mu, sig):
        return sum(np.exp(-0.5 * ((u - mu + j) / sig) ** 2) for j in (-1, 0, 1))

    # stance/swing (minimum at mid-stance u = 0) + heel-strike transient + a small push-off shoulder
    f = -0.5 * np.cos(2 * math.pi * u) + 0.55 * bump(0.52, 0.035) + 0.08 * bump(0.40, 0.05)
    f -= f.mean()
    spec = np.fft.rfft(f)
    w = 2 * math.pi * np.arange(len(spec))
    zs = np.zeros_like(spec)
    zs[1:] = -spec[1:] / w[1:] ** 2
    z = np.fft.irfft(zs, n)
    dz = np.fft.irfft(1j * w * zs, n)
    i0 = int(np.argmax(z))  # start the step at mid-stance (highest point, v_z = 0)
    f, z, dz = (np.roll(a, -i0) for a in (f, z, dz))
    z = z - z[0]
    p2p = f.max() - f.min()
    f, z, dz = f / p2p, z / p2p, dz / p2p

    def close(a):
        return np.append(a, a[0])

    return (
        np.linspace(0.0, 1.0, n + 1),
        close(f),
        close(dz),
        close(z),
        float(np.argmax(f)) / n,
        float(z.mean()),
    )


GAIT_U, GAIT_F, GAIT_DZ, GAIT_Z, GAIT_U_PEAK, GAIT_Z_MEAN = _gait_shape()


@dataclass(frozen=True)
class Person:
    pace: str
    cadence_hz: float  # walking cadence at this pace
    stride_m: float  # walking step length at this pace
    weinberg_k: float
    stride_scale: float
    cadence_scale: float

    def as_dict(self) -> dict:
        return {k: (round(v, 6) if isinstance(v, float) else v) for k, v in self.__dict__.items()}


def make_person(sc: dict, rng: np.random.Generator) -> Person:
    """The walker's body: drawn from ``rng`` (always the same three draws), scenario values override."""
    p, w = sc["person"], sc["walk"]
    n_stride, n_cadence, n_k = rng.standard_normal(3)  # always three draws: same seed, same person
    stride_scale = p["stride_scale"] or float(np.clip(1.0 + 0.06 * n_stride, 0.88, 1.12))
    cadence_scale = p["cadence_scale"] or float(np.clip(1.0 + 0.04 * n_cadence, 0.92, 1.08))
    # Weinberg's K grows with leg length, as the stride does: 0.5 x stride scale, ±3 %, within 0.45..0.55
    k = p["weinberg_k"] or float(np.clip(0.5 * stride_scale * math.exp(0.03 * n_k), 0.45, 0.55))
    c0, l0 = PACES[w["pace"]]
    cadence = w["cadence_hz"] or c0 * cadence_scale
    stride = w["speed_mps"] / cadence if w["speed_mps"] > 0 else (w["stride_m"] or l0 * stride_scale)
    return Person(
        pace=w["pace"],
        cadence_hz=cadence,
        stride_m=stride,
        weinberg_k=k,
        stride_scale=stride_scale,
        cadence_scale=cadence_scale,
    )
