"""Deterministic unique names for writers: ``base``, then ``base_2``, ``base_3`` ..."""

from __future__ import annotations


def unique_name(base: str, used: set[str]) -> str:
    """The first of ``base``, ``base_2``, ``base_3``... not in ``used``; it is added to ``used``."""
    name, n = base, 2
    while name in used:
        name = f"{base}_{n}"
        n += 1
    used.add(name)
    return name
