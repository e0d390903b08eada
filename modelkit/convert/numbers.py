"""Numbers as writers print them: short, clean, exact to 1e-12, never ``-0``.

``fmt(x)`` prints the shortest decimal that is ``x`` up to arithmetic dust (within 1e-12 relative,
and 10⁴ below the decimal's last digit): a number a person wrote comes back as written, and the
dust goes (``0.0615250000000001`` → ``0.061525``, ``1.0000000000000002`` → ``1``); other values
get at most 15 significant digits. A read-back differs from the model by at most 1e-12 relative,
or 1e-12 of the quantity's scale where a writer gives one: a position's is the model's size
(:func:`fmt_length`, :func:`fmt_position`), a tensor entry's the tensor's largest entry
(:func:`fmt_inertia`, :func:`fmt_tensor`), so that a small value computed from larger ones loses
their dust too.

Near-zero values are a question of scale, which ``fmt`` cannot know (``6.123233995736766e-17``
is dust in a position, a real value in an inertia of a milligram part). Writers settle it where
they know the quantity: :func:`clean_rotation` for quaternion components, Euler angles and matrix
entries (dimensionless: below 1e-10 is 0, and within 1e-12 of ±1, ±0.5 or ±√½ is that value),
:func:`clean_angle` for angles (below 1e-10 is 0, within 1e-12 of another multiple of π/4 is that
multiple), :func:`fmt_direction` for axes (a component below 1e-10 of the length is 0),
:func:`clean_length` for positions (below 1e-10 of the model's length scale is 0; the scale is set
with :func:`length_scale` around a write, 1 m by default; :func:`fmt_position` writes a point so),
and :func:`clean_inertia` for inertia tensors (a tensor below 1e-12 of the link's mass × the length
scale² is 0, else its entries below 1e-10 of its largest). Zero is 1e-10 (:data:`ZERO`): a tenth of
a nanometre or of a nanoradian on a metre robot is no measurement, and a read-back still equals the
model to 1e-9.
"""

from __future__ import annotations

import contextvars
import math
from collections.abc import Iterable, Iterator
from contextlib import contextmanager

import numpy as np

SNAP = 1e-12  # relative: what a written number may differ from the model's
# relative: below this a length, angle or rotation value is written as 0. A tenth of a nanometre on
# a metre robot, a tenth of a nanoradian: below the precision of any CAD export or measurement
# (iCub's ``pos="0 2.28232e-12 ..."``), and ten of them in a chain still within the 1e-9 m a
# read-back and verify compare poses to.
ZERO = 1e-10
# kg·m²: the most a tensor of dust can hold, whatever its link's mass: a milligram a millimetre from
# its axis. A larger value is one someone wrote or measured (:func:`clean_inertia`).
INERTIA_DUST = 1e-12
_LENGTH_SCALE: contextvars.ContextVar[float] = contextvars.ContextVar("length_scale", default=1.0)
_EXACT_ROTATION_VALUES = (0.0, 1.0, 0.5, math.sqrt(0.5))


def fmt(value: float, dust: float = 0.0) -> str:
    """One number: the shortest decimal that is ``x`` up to dust (see :func:`_short`), else at most
    15 significant digits; integers without ``.0``. ``dust`` is an absolute size the caller knows to be
    no measurement for this quantity (1e-12 of the model's size for a position: :func:`fmt_position`;
    1e-12 of a tensor's largest entry for its entries: :func:`fmt_tensor`)."""
    x = float(value)
    if not math.isfinite(x):
        raise ValueError(f"cannot write a non-finite number ({x})")
    if x == 0.0:
        return "0"
    text = _short(x, dust) or repr(x)
    fifteen = f"{x:.15g}"
    if len(fifteen) < len(text) and math.isfinite(float(fifteen)):  # near DBL_MAX, rounding overflows
        text = fifteen
    return _tidy(text)


def _short(x: float, dust: float = 0.0) -> str | None:
    """The shortest decimal of at most 14 digits that differs from ``x`` by dust: at most 1e-12
    relative (or ``dust``, when larger), and at least 10⁴ times less than its own last digit
    (``0.0615250000000001`` → ``0.061525``; ``1/3`` stays ``0.333333333333333``, which is not a decimal
    with a dusty tail). With ``dust`` a small value keeps no tail of the arithmetic on larger ones
    (iCub's ``1.38999999999695e-5`` m, a difference of two positions near 0.1 m: 3e-17 m off
    ``1.39e-5``, which is 2e-12 of the value but far below 1e-12 m)."""
    exponent = math.floor(math.log10(abs(x)))
    tolerance = max(SNAP * abs(x), dust)
    for digits in range(1, 15):
        short = f"{x:.{digits}g}"
        y = float(short)
        if not math.isfinite(y):
            continue
        error = abs(y - x)
        if error <= tolerance and error * 1e4 <= 10.0 ** (exponent - digits + 1):
            return f"{y:.15g}"  # the same decimal, laid out as before (1000000, not 1e+06)
    return None


def _tidy(text: str) -> str:
    """Trailing zeros, ``e+05`` and ``-0`` removed from a Python number text."""
    if "e" in text:
        mantissa, exponent = text.split("e")
        if "." in mantissa:
            mantissa = mantissa.rstrip("0").rstrip(".")
        sign = "-" if exponent.startswith("-") else ""
        text = f"{mantissa}e{sign}{exponent.lstrip('+-').lstrip('0') or '0'}"
    elif "." in text:
        text = text.rstrip("0").rstrip(".")
    return "0" if text in ("-0", "") else text


def fmt_text(text: str) -> str:
    """An attribute a source wrote, in the writers' form when it is a list of finite numbers
    (``".005"`` → ``"0.005"``, ``"0 0 -9.81000"`` → ``"0 0 -9.81"``); any other text as it is."""
    numbers: list[str] = []
    for token in text.split():
        try:
            x = float(token)
        except ValueError:
            return text
        if not math.isfinite(x) or "_" in token:
            return text
        numbers.append(fmt(x))
    return " ".join(numbers) if numbers else text


def fmt_vec(values: Iterable[float] | np.ndarray) -> str:
    """Numbers separated by single spaces (XML attribute lists)."""
    return " ".join(fmt(v) for v in np.asarray(list(values) if not isinstance(values, np.ndarray) else values,
                                              dtype=float).ravel())


def fmt_position(values: Iterable[float] | np.ndarray) -> str:
    """A point in metres (a centre of mass, a joint anchor, a light): each coordinate cleaned by
    :func:`clean_length`, so a CAD export's ``2.9948e-14`` on a half-metre arm is written as 0, and
    written by :func:`fmt_length`."""
    vector = np.asarray(list(values) if not isinstance(values, np.ndarray) else values, dtype=float).ravel()
    return " ".join(fmt_length(clean_length(float(v))) for v in vector)


def fmt_length(value: float) -> str:
    """A length in metres: :func:`fmt` with 1e-12 of the model's length scale as dust."""
    return fmt(value, SNAP * _LENGTH_SCALE.get())


def fmt_tensor(values: Iterable[float] | np.ndarray, tensor: np.ndarray) -> str:
    """Entries of an inertia tensor (moments, products): :func:`fmt` with 1e-12 of the tensor's largest
    entry as dust (iCub's product ``7.12496000000835e-8`` beside moments of 3e-4 kg·m² is
    ``7.12496e-8``), the scale :func:`clean_inertia` and ``verify`` judge a tensor by."""
    dust = _tensor_dust(tensor)
    return " ".join(fmt(v, dust) for v in np.asarray(
        list(values) if not isinstance(values, np.ndarray) else values, dtype=float).ravel())


def fmt_inertia(value: float, tensor: np.ndarray) -> str:
    """One entry of ``tensor``, as :func:`fmt_tensor` writes it."""
    return fmt(value, _tensor_dust(tensor))


def _tensor_dust(tensor: np.ndarray) -> float:
    """1e-12 (:data:`SNAP`) of the tensor's largest entry; 0 for an empty or non-finite tensor."""
    t = np.asarray(tensor, dtype=float)
    own = float(np.max(np.abs(t))) if t.size else 0.0
    return SNAP * own if math.isfinite(own) else 0.0


def fmt_rpy(rotation: np.ndarray) -> str:
    """A rotation as URDF/SDF roll-pitch-yaw text (MJCF ``euler`` with ``eulerseq="XYZ"``), angles
    cleaned by :func:`clean_angle`. Every rotation has two triples, (r, p, y) and (r + π, π − p, y + π),
    each angle in (−π, π]: the shorter text that gives the matrix back to 1e-12 is written, the
    matrix's own on a tie. A source's ``rpy="0 1.5707963268 0"`` (a pitch 5e-12 past π/2; pybullet_data's
    Spirit40) comes back from the matrix as (−π, 1.57079632678979, −π): its own text is the other triple.

    An angle whose 2π-equivalent on the other side of ±π is a decimal a person wrote (``3.1416``; see
    :func:`_as_written`) is written as that equivalent (a whole turn more about one axis is the same
    matrix), if the triple's text still gives the matrix back. iCub's ``rpy="-1.5708 3.1416 -1.5708"``
    (a pitch 7.3e-6 past π) comes back as the other triple with a pitch of −3.14158530717959: its
    equivalent is the source's ``3.1416``."""
    from modelkit.spatial import rpy_from_matrix

    r = np.asarray(rotation, dtype=float)

    def text_of(angles: list[float]) -> str:
        plain = fmt_vec(angles)
        written = " ".join(_as_written(a) for a in angles)
        return written if written != plain and _exact(written, r) else plain

    roll, pitch, yaw = (float(a) for a in rpy_from_matrix(r))
    own = text_of([clean_angle(a) for a in (roll, pitch, yaw)])
    other = text_of([clean_angle(_wrap(a)) for a in (roll + math.pi, math.pi - pitch, yaw + math.pi)])
    if len(other) < len(own) and _exact(other, r):
        return other
    return own


WRITTEN_DIGITS = 12  # at most: a longer decimal near a double is chance (one in ten has 14 digits)


def _as_written(angle: float) -> str:
    """``fmt(angle)``, or ``fmt`` of its equivalent on the other side of ±π (``angle ∓ 2π``) when that
    one is a decimal a person wrote: found by :func:`_short` with at most :data:`WRITTEN_DIGITS`
    significant digits, and fewer than ``angle``'s own text."""
    text = fmt(angle)
    if angle:
        turned = angle - math.copysign(2.0 * math.pi, angle)
        short = _short(turned)
        if (short is not None and significant_digits(short) <= WRITTEN_DIGITS
                and significant_digits(fmt(turned)) < significant_digits(text)):
            return fmt(turned)
    return text


def significant_digits(number: str) -> int:
    """Significant digits of a number's text (``-0.05236`` → 4)."""
    return len(number.split("e")[0].replace("-", "").replace(".", "").lstrip("0"))


def _exact(text: str, rotation: np.ndarray) -> bool:
    """Whether the roll-pitch-yaw ``text`` gives ``rotation`` back to :data:`SNAP`."""
    from modelkit.spatial import matrix_from_rpy

    back = matrix_from_rpy(*(float(v) for v in text.split()))
    return float(np.max(np.abs(back - rotation))) <= SNAP


def _wrap(angle: float) -> float:
    """``angle`` in (−π, π]."""
    wrapped = math.remainder(angle, 2.0 * math.pi)
    return math.pi if wrapped == -math.pi else wrapped


def fmt_direction(values: Iterable[float] | np.ndarray) -> str:
    """A direction (a joint axis): each component within 1e-10 (:data:`ZERO`) of the vector's length
    written as 0, as a dimensionless rotation value would be (``0 -1 6.12323e-17`` → ``0 -1 0``: a
    cosine of π/2 that a source's generator left in); the rest as :func:`fmt_vec`. The direction moves
    by at most 1e-10 rad."""
    vector = np.asarray(list(values) if not isinstance(values, np.ndarray) else values, dtype=float).ravel()
    length = float(np.linalg.norm(vector))
    if length > 0.0 and math.isfinite(length):
        vector = np.where(np.abs(vector) <= ZERO * length, 0.0, vector)
    return fmt_vec(vector)


def clean(value: float, tol: float = 1e-15) -> float:
    """``value`` with arithmetic dust below ``tol`` (absolute) set to exactly 0 (rotation matrices)."""
    return 0.0 if abs(value) < tol else float(value)


def clean_rotation(value: float) -> float:
    """A dimensionless rotation number (quaternion component, angle, matrix entry) with dust removed:
    within 1e-10 of 0 (:data:`ZERO`) it is 0, within 1e-12 of ±1, ±0.5 or ±√½ it is that value exactly."""
    x = float(value)
    if abs(x) <= ZERO:
        return 0.0
    for exact in _EXACT_ROTATION_VALUES[1:]:
        if abs(abs(x) - exact) <= SNAP:
            return math.copysign(exact, x) if exact else 0.0
    return x


def clean_angle(value: float) -> float:
    """An angle in radians with dust removed: within 1e-10 of 0 (:data:`ZERO`) it is 0 (iCub's
    ``1.53106e-11``), within 1e-12 of another multiple of π/4 it is that multiple
    (``-3.14159265358959`` → -π)."""
    x = float(value)
    if abs(x) <= ZERO:
        return 0.0
    quarter = round(x / (math.pi / 4.0))
    exact = quarter * (math.pi / 4.0)
    return exact + 0.0 if abs(x - exact) <= SNAP else x


def clean_length(value: float) -> float:
    """A position coordinate with dust below 1e-10 of the model's length scale (:data:`ZERO`) set to 0."""
    x = float(value)
    return 0.0 if abs(x) <= ZERO * _LENGTH_SCALE.get() else x


def clean_inertia(tensor: np.ndarray, mass: float) -> np.ndarray:
    """An inertia tensor (kg·m²) with dust set to 0. A tensor whose every entry is below 1e-12
    (:data:`SNAP`) of ``mass`` × the model's length scale² is float dust of a zero tensor, and is 0:
    iCub's ``ixz="1.35525e-20"`` on a link whose other five entries are 0 (written as it is, MuJoCo
    refuses it: a negative eigenvalue), Drake's cart-pole's 1e-20 on each axis. In any other tensor,
    the entries below 1e-10 (:data:`ZERO`) of its own largest are 0, as lengths and rotations below 1e-10
    are: gym-ignition's cart-pole turns its pole's tensor by ``rpy="1.57079632679 0 0"`` (π/2 to 11
    decimals, 4.9e-12 rad short), which leaves a product of 5.1e-11 beside moments of 10.4 kg·m².

    Relative to the tensor itself, not to mass × size²: verify compares each tensor with the source's
    to 1e-9 of its own largest entry, and a small link's tensor is far below its mass × the robot's
    size² (dm_control's dog: a tail vertebra's products of 3e-15 beside moments of 7e-7 kg·m², zeroed
    at 1e-12 of m·L², were 4e-9 of the tensor).

    Never a tensor above :data:`INERTIA_DUST`: a semantic-fuzz mutant gave the tutorial's wheel a mass of
    3.5e38 kg beside its written 0.0023 kg·m², which 1e-12 of m·L² zeroed, and MuJoCo refused the MJCF
    ("mass and inertia of moving bodies must be larger than mjMINVAL")."""
    t = np.asarray(tensor, dtype=float)
    scale = SNAP * abs(float(mass)) * _LENGTH_SCALE.get() ** 2
    own = float(np.max(np.abs(t))) if t.size else 0.0
    if not (math.isfinite(scale) and math.isfinite(own)) or scale <= 0.0:
        return t
    if own <= min(scale, INERTIA_DUST):
        return np.zeros_like(t)
    cleaned: np.ndarray = np.where(np.abs(t) <= ZERO * own, 0.0, t)
    return cleaned


@contextmanager
def length_scale(scale: float) -> Iterator[None]:
    """Positions written inside the block take ``scale`` (metres) as the model's size."""
    token = _LENGTH_SCALE.set(scale if math.isfinite(scale) and scale > 0.0 else 1.0)
    try:
        yield
    finally:
        _LENGTH_SCALE.reset(token)
