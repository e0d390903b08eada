"""Numbers as writers print them: short, exact for what a person wrote, never ``-0``.

``fmt(x)`` prints at most 15 significant digits, which reproduces every decimal a person wrote
(at most 15 digits round-trip through a double) and removes the noise of arithmetic
(``1.0000000000000002`` → ``1``, ``6.123233995736766e-17`` stays as is: it is a real value).
Printing never rounds beyond the 15th digit, so a read-back differs from the model by at most
5e-15 relative (and is exact for anything written with 15 digits or fewer).
"""

from __future__ import annotations

import math
from collections.abc import Iterable

import numpy as np


def fmt(value: float) -> str:
    """One number: shortest of ``repr`` and 15 significant digits; integers without ``.0``."""
    x = float(value)
    if not math.isfinite(x):
        raise ValueError(f"cannot write a non-finite number ({x})")
    if x == 0.0:
        return "0"
    text = repr(x)
    short = f"{x:.15g}"
    if len(short) < len(text) and math.isfinite(float(short)):  # near DBL_MAX, rounding up overflows
        text = short
    if "e" in text:
        mantissa, exponent = text.split("e")
        if "." in mantissa:
            mantissa = mantissa.rstrip("0").rstrip(".")
        sign = "-" if exponent.startswith("-") else ""
        text = f"{mantissa}e{sign}{exponent.lstrip('+-').lstrip('0') or '0'}"
    elif "." in text:
        text = text.rstrip("0").rstrip(".")
    return "0" if text in ("-0", "") else text


def fmt_vec(values: Iterable[float] | np.ndarray) -> str:
    """Numbers separated by single spaces (XML attribute lists)."""
    return " ".join(fmt(v) for v in np.asarray(list(values) if not isinstance(values, np.ndarray) else values,
                                              dtype=float).ravel())


def clean(value: float, tol: float = 1e-15) -> float:
    """``value`` with arithmetic dust below ``tol`` (absolute) set to exactly 0 (rotation matrices)."""
    return 0.0 if abs(value) < tol else float(value)
