"""Verification: prove a conversion is the same robot, layer by layer, in real engines.

Layer 1 static equivalence, layer 2 kinematics, layer 3 dynamics without contact, layer 4 the driven
robot (see ``docs/verify.md``). Subpackages, in the order the data flows: :mod:`.engines` (one
adapter per engine behind :mod:`.engines.protocol`), :mod:`.drive` (scenarios, controllers, the
references), :mod:`.layers` (one module per layer) and :mod:`.report` (JSON, HTML, plots,
pictures); the entry points :mod:`.api`, :mod:`.many` and :mod:`.cluster` on top. No import cycle
(``tests/test_verify_import_graph.py``). Engines are imported only here, never by ``validate``,
``tree`` or ``convert``.
"""
