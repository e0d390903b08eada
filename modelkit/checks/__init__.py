"""Validation rules over the robot model: each rule is a small function with a stable code.

``run_rules(robot)`` applies every registered rule; rules never raise on odd models (duplicate
names, cycles, missing parents): that is exactly what they are for.
"""

from modelkit.checks.registry import RULES, Rule, run_rules

__all__ = ["RULES", "Rule", "run_rules"]
