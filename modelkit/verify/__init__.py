"""Verification: prove a conversion is the same robot, layer by layer, in real engines.

Layer 1 static equivalence, layer 2 kinematics, layer 3 dynamics without contact (see
``docs/verify.md``). One module per engine (``engine_*.py``), the reference (``reference.py``: the
source model itself and Pinocchio built from it in memory), the layers (``layers.py``), fault
injection (``inject.py``) and the report (``report.py``). Engines are imported only here, never by
``validate``, ``tree`` or ``convert``.
"""
