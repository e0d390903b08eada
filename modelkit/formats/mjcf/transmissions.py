"""Tendons and general actuators read from MuJoCo's compiled model, as MJCF attribute text.

The model holds neither tendons nor actuators that are not a motor, position or velocity law on one
hinge or slide (:mod:`.actuators`): activation dynamics, muscles, other gain and bias laws, tendon,
site, slider-crank and body transmissions. The MJCF reader keeps them as data
(``extras["mjcf_tendons"]``, ``extras["mjcf_actuators"]``) with what an MJCF writer needs to write
them back (:mod:`.write_transmissions`): the compiled values that differ from MuJoCo's defaults, as
the attribute text of ``<fixed>``/``<spatial>`` and of ``<general>`` (every actuator shortcut
compiles to a general actuator, so ``<general>`` with its compiled parameters is the same actuator).
Classes and defaults are resolved by the compilation; numbers are the shortest decimals that give the
compiled values back (colours: the shortest that give the float32 back).
"""

from __future__ import annotations

from typing import Any

from modelkit.formats.mjcf.bodies import non_default, plain, singles

SOLREF = (0.02, 1.0)
SOLIMP = (0.9, 0.95, 0.001, 0.5, 2.0)
TENDON_DEFAULTS: dict[str, tuple[str, str, tuple[float, ...]]] = {  # attribute → compiled field, default
    "width": ("tendon", "width", (0.003,)),
    "margin": ("tendon", "margin", (0.0,)),
    "frictionloss": ("tendon", "frictionloss", (0.0,)),
    "armature": ("tendon", "armature", (0.0,)),
    "springyield": ("tendon", "springyield", (0.0,)),
    "solreflimit": ("tendon", "solref_lim", SOLREF),
    "solimplimit": ("tendon", "solimp_lim", SOLIMP),
    "solreffriction": ("tendon", "solref_fri", SOLREF),
    "solimpfriction": ("tendon", "solimp_fri", SOLIMP),
}
TENDON_RGBA = (0.5, 0.5, 0.5, 1.0)
LOOK = frozenset({"width", "rgba"})  # a spatial tendon's only
# attribute → compiled field, MuJoCo's default (the values written: all of them)
ACTUATOR_PARAMETERS: dict[str, tuple[str, tuple[float, ...]]] = {
    "dynprm": ("dynprm", (1.0,)),
    "gainprm": ("gainprm", (1.0,)),
    "biasprm": ("biasprm", (0.0,)),
    "gear": ("gear", (1.0,)),
}
ACTUATOR_SCALARS = {  # attribute → compiled field; written when not 0 (fields older libraries lack: skipped)
    "cranklength": "cranklength",
    "armature": "armature",
    "damping": "damping",
}
LAWS = (("dyntype", "mjtDyn", "mjDYN_", "none"), ("gaintype", "mjtGain", "mjGAIN_", "fixed"),
        ("biastype", "mjtBias", "mjBIAS_", "none"))
RANGES = (("ctrlrange", "ctrl"), ("forcerange", "force"), ("actrange", "act"))


def _row(m: Any, field: str, index: int) -> tuple[float, ...] | None:
    try:
        raw = getattr(m, field)[index]
    except AttributeError:
        return None
    return tuple(float(x) for x in (raw if hasattr(raw, "__len__") else (raw,)))


def _trimmed(values: tuple[float, ...]) -> tuple[float, ...]:
    """Without trailing zeros, keeping the first value (MJCF fills the rest of a vector with zeros)."""
    end = len(values)
    while end > 1 and values[end - 1] == 0.0:
        end -= 1
    return values[:end]


def _differs(values: tuple[float, ...], default: tuple[float, ...]) -> bool:
    padded = default + (0.0,) * (len(values) - len(default))
    return any(abs(a - b) > 1e-12 * max(1.0, abs(b)) for a, b in zip(values, padded, strict=True))


def tendon_attributes(m: Any, t: int, spatial: bool) -> dict[str, str]:
    """Tendon ``t``'s attributes that differ from MuJoCo's defaults, as MJCF text (its look only for a
    spatial tendon: a fixed one has no path to draw, and MJCF refuses ``width`` and ``rgba`` on it)."""
    out: dict[str, str] = {}
    if int(m.tendon_limited[t]):
        out["range"] = plain(_row(m, "tendon_range", t) or ())
    limited = _row(m, "tendon_actfrclimited", t)
    if limited and limited[0]:
        out["actuatorfrcrange"] = plain(_row(m, "tendon_actfrcrange", t) or ())
    for attribute, field in (("stiffness", "stiffness"), ("damping", "damping")):
        values = (float(getattr(m, f"tendon_{field}")[t]), *(_row(m, f"tendon_{field}poly", t) or ()))
        if any(values):
            out[attribute] = plain(_trimmed(values))
    spring = _row(m, "tendon_lengthspring", t)
    length0 = float(m.tendon_length0[t])
    # The rest length defaults to the length at qpos0, which a written joint's reference (baked into
    # its body's pose) moves: written as a length whenever a spring uses it
    if spring is not None and ("stiffness" in out or _differs(spring, (length0, length0))):
        out["springlength"] = plain(spring if spring[0] != spring[1] else spring[:1])
    out.update((k, v) for k, v in non_default(m, TENDON_DEFAULTS, {"tendon": t}).items()
               if spatial or k not in LOOK)
    rgba = tuple(singles(m.tendon_rgba[t]))
    if rgba != TENDON_RGBA and spatial:
        out["rgba"] = plain(rgba)
    group = int(m.tendon_group[t])
    if group:
        out["group"] = str(group)
    return out


def general_attributes(mj: Any, m: Any, a: int) -> tuple[dict[str, str], str | None]:
    """Actuator ``a`` as the attributes of a ``<general>`` that compiles to it (its transmission
    apart), and why it cannot be written back (None: it can)."""
    out: dict[str, str] = {}
    for attribute, enum, prefix, default_word in LAWS:
        value = getattr(mj, enum)(int(getattr(m, f"actuator_{attribute}")[a]))
        name = str(getattr(value, "name", value))
        word = name[len(prefix):].lower() if name.startswith(prefix) else name.lower()
        if word != default_word:
            out[attribute] = word
    for attribute, (field, default) in ACTUATOR_PARAMETERS.items():
        values = _row(m, f"actuator_{field}", a) or ()
        if _differs(values, default):
            out[attribute] = plain(_trimmed(values))
    for attribute, kind in RANGES:
        if bool(getattr(m, f"actuator_{kind}limited")[a]):
            out[attribute] = plain(_row(m, f"actuator_{kind}range", a) or ())
    lengthrange = _row(m, "actuator_lengthrange", a)
    if lengthrange and any(lengthrange):
        out["lengthrange"] = plain(lengthrange)
    for attribute, field in ACTUATOR_SCALARS.items():
        value = _row(m, f"actuator_{field}", a)
        if value and value[0]:
            out[attribute] = plain(value)
    if bool(m.actuator_actearly[a]):
        out["actearly"] = "true"
    group = int(m.actuator_group[a])
    if group:
        out["group"] = str(group)
    stateful = out.get("dyntype", "none") != "none"
    if int(m.actuator_actnum[a]) != (1 if stateful else 0):
        out["actdim"] = str(int(m.actuator_actnum[a]))
    why = None
    plugin = _row(m, "actuator_plugin", a)
    history = _row(m, "actuator_history", a)
    delay = _row(m, "actuator_delay", a)
    if plugin and plugin[0] >= 0:
        why = "a plugin actuator"
    elif (history and any(history)) or (delay and delay[0]):
        why = "a delayed actuator (history buffer)"
    return out, why


def transmission_sites(actuators: list[dict[str, Any]], tendons: list[dict[str, Any]]) -> set[str]:
    """Names of the sites actuator transmissions (site, reference, crank and slider sites) and tendons
    (the sites they pass, the side sites of their wrapping geoms) name."""
    used: set[str] = set()
    for actuator in actuators:
        if actuator.get("transmission") in ("site", "slidercrank") and actuator.get("target"):
            used.add(str(actuator["target"]))
        used.update(str(actuator[key]) for key in ("refsite", "slidersite") if actuator.get(key))
    for tendon in tendons:
        for wrap in tendon.get("wraps", []):
            if wrap.get("type") == "site" and wrap.get("object"):
                used.add(str(wrap["object"]))
            if wrap.get("sidesite"):
                used.add(str(wrap["sidesite"]))
    return used
