"""Colours, intensities and transparency as the robot model holds them: fractions in 0..1.

Readers settle the range at the format boundary: a value outside it is clamped and said (MK513), since
libsdformat refuses such a colour and urdfdom drops it, whatever the source's own loader did with it.
"""

from __future__ import annotations

from collections.abc import Iterable


def clamped_fractions(values: Iterable[float]) -> tuple[tuple[float, ...], bool]:
    """``values`` clamped to 0..1, and whether any was below 0 or above 1 (a NaN is neither: it is the
    non-finite rules' finding, and stays as it is)."""
    numbers = tuple(float(x) for x in values)
    clamped = tuple(min(max(x, 0.0), 1.0) for x in numbers)
    return clamped, any(x < 0.0 or x > 1.0 for x in numbers)
