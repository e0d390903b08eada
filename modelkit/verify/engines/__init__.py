"""The engines: one adapter module per engine behind one protocol (:mod:`.protocol`).

:mod:`.registry` names them (data only, for the CLI); :mod:`.reference` is the source model itself
(and yourdfpy, in a child process); :mod:`.mujoco`, :mod:`.pybullet` (with its child process
:mod:`.pybullet_worker`; both children use :mod:`.child`'s pipe),
:mod:`.pinocchio` and :mod:`.drake` load the written files. Nothing here is imported by
``validate``, ``tree`` or ``convert``.
"""
