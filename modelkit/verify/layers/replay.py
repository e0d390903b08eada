"""Layer 3b: the contact-free torque replay.

The same :class:`~modelkit.verify.engines.protocol.TorqueLaw` (a PD law tracking sinusoids) drives the
fixed-base model in MuJoCo (``integrator="Euler"``) and in PyBullet at the same time step (1 ms)
for 10 s, both from q = dq = 0. Both engines integrate semi-implicit Euler (v ← v + h·a(q, v),
q ← q + h·v), so for a contact-free tree they compute the same ODE step up to round-off: the
measured difference on the tutorial robot is ~1e-16 rad (≤ 1e-10 rad over 10 s on every
well-conditioned model measured), and anything above 1e-8 rad means the two files describe
different robots (inertia, COM, axis, frame, damping, armature, a motor left on), **unless the model
itself amplifies differences**: the tolerance is calibrated at run time (:func:`tolerances`), 1e-8
times the amplification of a 1e-12 rad start difference that MuJoCo measures on the same model
(:func:`envelope`), step by step, so a sensitive arm (example-robot-data's UR10: ×2e4 by 10 s) is
not failed for its own chaos while a model difference, visible from the first steps, still is.

A model with a ball joint is graded differently (:func:`ladder_layer`): the engines integrate a ball
in different coordinates, so their trajectories part by O(dt) even for the same robot, and the
difference is extrapolated to dt → 0 from runs at dt, dt/2, dt/4 and dt/8.

The law (:func:`default_law`) is chosen from the source model so that the replay is well
conditioned: every moving joint is excited, the motion stays inside the joint limits (PyBullet's 100
rad/s velocity clamp is lifted for the replay: a light wrist can be whipped past it), gravity cannot
drag a joint far from its target, and the closed loop is inside semi-implicit Euler's stability
limit at 1 ms: the gains come from each joint's effective inertia 1/(M⁻¹)ᵢᵢ (Pinocchio on the
source), and the growth factor of the linearised step (:func:`step_growth`) is checked below 1, the
bandwidth halved until it is.
"""

from __future__ import annotations

import dataclasses
import math
import time
from typing import Any

import numpy as np

from modelkit.model import BALL_KEYS, JointType, Robot
from modelkit.verify.engines.protocol import Array, Check, Simulator, Skip, TorqueLaw

TOLERANCE = 1e-8  # rad (m for prismatic joints): two engines, same ODE step, round-off apart
PERTURBATION = 1e-12  # rad (m): the start moved by this to measure the model's own amplification
GRAVITY = 9.81

# The law's design constants (see default_law).
BANDWIDTH = 2.0 * math.pi * 2.0  # rad/s: closed-loop natural frequency from the joint's effective inertia
MAX_BANDWIDTH = 100.0  # rad/s: ω·dt = 0.1 at 1 ms (semi-implicit Euler is stable below 2)
DAMPING_RATIO = 0.7
GRAVITY_MARGIN = 10.0  # kp ≥ 10 × the worst gravity load per unit of amplitude (sag ≤ 10 %)
REVOLUTE_AMPLITUDE = 1.0  # rad, unlimited joints; limited: half the distance from 0 to the nearer limit
BALL_AMPLITUDE = 0.5  # rad per component of a ball's target rotation vector (at most 0.87 rad in all,
#                       far from the chain's gimbal lock at b = ±π/2)
PRISMATIC_AMPLITUDE = 0.1  # m
MIN_INERTIA = 1e-12
MAX_GROWTH = 1.0 - 1e-6  # the linearised step must contract (step_growth); else the bandwidth is halved
MAX_HALVINGS = 60


def _axis_inertia_and_gravity(robot: Robot, joint_name: str,
                              poses: dict[str, Any], children: dict[str, list[str]],
                              axis_override: Array | None = None) -> tuple[float, float]:
    """The subtree's inertia about (revolute) or mass along (prismatic) the joint axis at q = 0,
    and an upper bound of the gravity load on the joint, root welded at the identity. A joint outside
    the root's tree (in the subtree of a free body of an SDF model, MK201) has no pose there: (0, 0),
    so it gets no torque and no excitation (its free body falls as a whole, the joint at rest).
    ``axis_override``: the axis (child frame) of one of a ball joint's three rotations."""
    joint = next(j for j in robot.joints if j.name == joint_name)
    if joint.child not in poses:
        return 0.0, 0.0
    frame = poses[joint.child]
    axis = frame.rotation @ np.asarray(joint.axis if axis_override is None else axis_override, dtype=float)
    axis = axis / float(np.linalg.norm(axis))
    origin = frame.translation
    links = {link.name: link for link in robot.links}
    inertia = load = 0.0
    stack = [joint.child]
    while stack:
        name = stack.pop()
        stack.extend(children.get(name, []))
        link = links.get(name)
        if link is None or link.inertial is None or name not in poses:
            continue
        mass = float(link.inertial.mass)
        pose = poses[name]
        com = pose.rotation @ np.asarray(link.inertial.com, dtype=float) + pose.translation
        if joint.type is JointType.PRISMATIC and axis_override is None:
            inertia += mass
            load += mass * GRAVITY
            continue
        r = com - origin
        r_perp = r - float(r @ axis) * axis
        rot_inertia = pose.rotation @ np.asarray(link.inertial.inertia, dtype=float) @ pose.rotation.T
        inertia += float(axis @ rot_inertia @ axis) + mass * float(r_perp @ r_perp)
        load += mass * GRAVITY * float(np.linalg.norm(r_perp))
    return inertia, load


class UnstableLaw(ValueError):
    """No PD gains make the replay's linearised step contract (:func:`stable_scale`)."""


def step_growth(mass_matrix: Array, kp: Array, kd: Array, dt: float) -> float:
    """The per-step growth factor of semi-implicit Euler (v ← v + dt·a, q ← q + dt·v) on the PD loop
    u = kp·(q* − q) − kd·dq linearised with the mass matrix ``mass_matrix`` (joints in the order of
    ``kp``/``kd``; gravity and velocity products left out): the spectral radius of the step matrix

        [[I − dt²·A·K, dt·(I − dt·A·D)], [−dt·A·K, I − dt·A·D]],  A = M⁻¹, K = diag(kp), D = diag(kd).

    Below 1 the linearised closed loop contracts at every step; at or above 1 it grows."""
    inverse = np.linalg.inv(np.asarray(mass_matrix, dtype=float))
    return _growth(inverse, np.asarray(kp, dtype=float), np.asarray(kd, dtype=float), dt)


def _growth(inverse: Array, kp: Array, kd: Array, dt: float) -> float:
    n = len(kp)
    if n and not np.any(inverse - np.diag(np.diagonal(inverse))):
        # Decoupled joints (the fallback without Pinocchio): the step matrix is n independent 2 × 2
        # blocks, whose eigenvalues are those of the whole; linear in n instead of a (2n)³ solve.
        a = np.diagonal(inverse)
        ak, ad = a * kp, 1.0 - dt * a * kd
        blocks = np.empty((n, 2, 2))
        blocks[:, 0, 0], blocks[:, 0, 1] = 1.0 - dt * dt * ak, dt * ad
        blocks[:, 1, 0], blocks[:, 1, 1] = -dt * ak, ad
        return float(np.max(np.abs(np.linalg.eigvals(blocks))))
    eye = np.eye(n)
    ak = inverse @ np.diag(kp)
    ad = eye - dt * (inverse @ np.diag(kd))
    step = np.block([[eye - dt * dt * ak, dt * ad], [-dt * ak, ad]])
    return float(np.max(np.abs(np.linalg.eigvals(step)))) if n else 0.0


def stable_scale(inverse: Array, kp: Array, kd: Array, dt: float) -> float:
    """The bandwidth scale s (1, 1/2, 1/4, ...) that makes the gains (s²·kp, s·kd) stable at ``dt``
    (:func:`step_growth` below ``MAX_GROWTH``) for the inverse mass matrix ``inverse``; halving the
    bandwidth keeps the damping ratio.

    Halving lowers the growth of the fast modes only: in a long chain the slowest modes contract by
    less than 1e-6 per step whatever the gains (a 50-link chain: 1 − 3e-8 at s = 1), and halving makes
    them slower still; run anyway, such a law let MuJoCo blow up at 100 links. When a halving no longer
    lowers the growth, or none is left, :class:`UnstableLaw` says so (verify skips the replay)."""
    scale = 1.0
    best = math.inf
    for _ in range(MAX_HALVINGS):
        growth = _growth(inverse, kp * scale**2, kd * scale, dt)
        if growth < MAX_GROWTH:
            return scale
        if growth >= best:
            break
        best = growth
        scale *= 0.5
    raise UnstableLaw(f"no PD gains make the linearised loop contract at dt {dt:g} s (its step grows by "
                      f"{best:.9g} at best, {MAX_GROWTH:.9g} is needed: the slowest modes of a long chain)")


def _effective_inverse(source: Robot, names: list[str]) -> Array | None:
    """(M⁻¹) restricted to ``names`` at q = 0, root welded, armature zeroed (the replay zeroes it),
    the other joints free; None when Pinocchio is not installed or cannot hold the model."""
    try:
        from modelkit.verify.engines.pinocchio import PinocchioModel
    except ImportError:
        return None
    try:
        model = PinocchioModel(source)
    except (ValueError, RuntimeError) as exc:
        if getattr(type(exc), "engine_limit", False):
            # Too many joints for Pinocchio: the diagonal fallback ignores the couplings, which decide
            # a long chain's stability (MuJoCo blew up at once on a 200-link chain with it).
            raise UnstableLaw(f"its stability cannot be checked: {exc}") from exc
        return None
    model.model.armature = np.zeros(model.model.nv)
    model.ball_armature = {}
    dofs, full = model.dof_names_with_balls(), model.mass_matrix_with_balls({})
    massive = [i for i in range(len(dofs)) if full[i, i] > MIN_INERTIA]
    sub = full[np.ix_(massive, massive)]
    if not massive or np.linalg.cond(sub) > 1e12:
        return None
    inverse = np.linalg.inv(sub)
    where = {dofs[i]: k for k, i in enumerate(massive)}
    index = [where.get(n, -1) for n in names]
    out = np.zeros((len(names), len(names)))
    for a, ia in enumerate(index):
        for b, ib in enumerate(index):
            if ia >= 0 and ib >= 0:
                out[a, b] = inverse[ia, ib]
    return out


def default_law(source: Robot, dt: float = 1e-3) -> TorqueLaw:
    """A well-conditioned PD law for the replay at time step ``dt``, from the source model (joint
    order = the source's moving joints, mimic joints included: the replay runs the open tree, so a
    mimic joint is held at q = 0 like any joint whose amplitude is 0).

    Per joint i, with I_i the **effective inertia** 1/(M⁻¹)_ii (M the joint-space mass matrix of
    the source at q = 0, root welded, armature zeroed as in the replay, computed with Pinocchio
    built from the source; the joints left out of the law are free) and G_i a bound of the gravity
    load on the joint (the subtree's weight times its COM's distance from the axis):

    * amplitude A_i: 1 rad (revolute) / 0.1 m (prismatic) when unlimited; otherwise half the
      distance from q = 0 to the nearer limit (capped at those values); 0 when q = 0 is not
      strictly inside the limits, and for a mimic joint (the joint is only held). Every joint is
      driven or held: with the limits and the mimic couplings off, a free joint is flung without
      bound (Panda's finger_joint2, left free, reached 100 m/s, PyBullet's velocity clamp, at 4.7 s
      and the engines parted by 7.4e-2 rad);
    * kp_i = max(I_i·ω², 10·G_i / A_ref) with ω = 2π·2 Hz and A_ref = 1 rad or 0.1 m (gravity sags
      a joint by at most ~10 % of that), capped so that √(kp/I) ≤ 100 rad/s (ω·dt = 0.1 at 1 ms);
    * kd_i = 2·0.7·√(kp_i·I_i) (damping ratio 0.7);
    * stability, checked: the per-step growth factor of semi-implicit Euler on the loop linearised
      with M at q = 0 (:func:`step_growth`: the spectral radius of the step matrix built from
      M⁻¹·K, M⁻¹·D and dt, the joints' couplings included) must be below 1 − 1e-6; while it is not,
      every joint's bandwidth is halved (kp/4, kd/2: the damping ratio is kept); when a halving no
      longer lowers it (a long chain's slowest modes) there is no law and the replay is skipped
      (:func:`stable_scale`);
    * frequency 0.3 + 0.17·i Hz and phase 0.9·i rad: distinct, so the joints move out of step and
      the coupling terms of the mass matrix are excited. Peak speeds stay near A·2πf ≤ ~10 rad/s.

    The subtree's inertia about the axis (its mass for a prismatic joint) was the old rule: it is
    the mass matrix's diagonal M_ii ≥ 1/(M⁻¹)_ii, which overstates what a joint drives when the
    joints above it can move (hopper's planar root: ~100×, and the loop was unstable at 1 ms). It
    stays the fallback when Pinocchio is not installed or cannot hold the model, with the same
    stability check on the diagonal M.

    A joint whose subtree has no mass (I_i ≈ 0) gets no torque at all.

    A ball joint takes three entries (``NAME#x``, ``#y``, ``#z``; ``TorqueLaw.balls``), one per
    rotation about its child's axes, with the law of :mod:`~modelkit.verify.engines.ball_law`: I_i is
    that of the Pinocchio reference's revolute piece about the axis (at q = 0 the pieces' rates are
    the child's angular velocity), G_i the same bound about that axis, the amplitude
    ``BALL_AMPLITUDE`` per component (half the cone limit over √3 when that is smaller) and the
    phase 0: the target starts at the rest orientation, so the replay does not start with a step,
    whose fast first motion would keep the step ladder (:func:`ladder_layer`) out of its asymptotic
    regime (measured on a two-ball chain: extrapolated difference 2e-7 rad with phases, 4e-11 without).
    """
    moving = [j for j in source.joints if j.type in (JointType.REVOLUTE, JointType.PRISMATIC)]
    balls = [j for j in source.joints if j.type is JointType.BALL]
    world = source.world_poses({})
    root = world.get(str(source.root)) if source.root is not None else None
    poses = {k: root.inverse() @ v for k, v in world.items()} if root is not None else world
    children: dict[str, list[str]] = {}
    for j in source.joints:
        children.setdefault(j.parent, []).append(j.child)
    # a ball joint: three entries, one per rotation of its child's frame (BALL_KEYS, ball_law)
    entries = [(j, None) for j in moving] + [(j, k) for j in balls for k in range(3)]
    names = [j.name if k is None else j.name + BALL_KEYS[k] for j, k in entries]
    inverse = _effective_inverse(source, names) if entries else None
    kp, kd, amp, freq, phase, inertias = [], [], [], [], [], []
    for i, (joint, key) in enumerate(entries):
        inertia, load = _axis_inertia_and_gravity(source, joint.name, poses, children,
                                                  None if key is None else np.eye(3)[key])
        if inverse is not None:
            inertia = 1.0 / inverse[i, i] if inverse[i, i] > 0.0 and inertia > MIN_INERTIA else 0.0
        revolute = joint.type is not JointType.PRISMATIC
        reference = REVOLUTE_AMPLITUDE if revolute else PRISMATIC_AMPLITUDE
        lo, hi = joint.limits.lower, joint.limits.upper
        if key is not None:  # a ball: its cone limit, when it has one, bounds the whole rotation
            cone = 0.5 * hi / math.sqrt(3.0) if 0.0 < hi < math.inf else math.inf
            amplitude = min(BALL_AMPLITUDE, cone)
        else:
            amplitude = min(reference, 0.5 * min(-lo, hi)) if lo < 0.0 < hi and joint.mimic is None else 0.0
        if inertia <= MIN_INERTIA:
            gains = (0.0, 0.0)
            amplitude = 0.0
        else:
            stiffness = max(inertia * BANDWIDTH**2, GRAVITY_MARGIN * load / reference)
            stiffness = min(stiffness, inertia * MAX_BANDWIDTH**2)
            gains = (stiffness, 2.0 * DAMPING_RATIO * math.sqrt(stiffness * inertia))
        kp.append(gains[0])
        kd.append(gains[1])
        amp.append(amplitude)
        freq.append(0.3 + 0.17 * i)
        phase.append(0.9 * i if key is None else 0.0)  # a ball starts at its target (no step)
        inertias.append(inertia)
    driven = [i for i, k in enumerate(kp) if k > 0.0]
    if driven:
        if inverse is None:  # fallback: the joints taken as decoupled, M = diag(I)
            inverse = np.diag([1.0 / inertias[i] if i in driven else 0.0 for i in range(len(kp))])
        scale = stable_scale(inverse[np.ix_(driven, driven)], np.array([kp[i] for i in driven]),
                             np.array([kd[i] for i in driven]), dt)
        for i in driven:
            kp[i] *= scale**2
            kd[i] *= scale
    return TorqueLaw(tuple(names), tuple(kp), tuple(kd), tuple(amp), tuple(freq), tuple(phase),
                     tuple(j.name for j in balls))


def soften(law: TorqueLaw) -> TorqueLaw:
    """``law`` at half the bandwidth: kp/4 and kd/2, so the damping ratio is kept."""
    return dataclasses.replace(law, kp=tuple(k * 0.25 for k in law.kp), kd=tuple(k * 0.5 for k in law.kd))


def _run(sim: Simulator, law: TorqueLaw, seconds: float, dt: float) -> tuple[Array | None, float, str]:
    start = time.perf_counter()
    try:
        q = np.asarray(sim.replay(law, seconds, dt), dtype=float)
    except Exception as exc:  # a crash or a refusal of the engine is reported, never hidden
        return None, time.perf_counter() - start, f"{type(exc).__name__}: {exc}"
    wall = time.perf_counter() - start
    steps = round(seconds / dt)
    if q.shape != (steps + 1, len(law.joints)):
        return None, wall, f"replay returned shape {q.shape}, expected {(steps + 1, len(law.joints))}"
    return q, wall, ""


def first_nonfinite(q: Array) -> int | None:
    """The first step whose state holds a NaN or an infinity, or None."""
    bad = ~np.all(np.isfinite(q), axis=1)
    return int(np.argmax(bad)) if bool(bad.any()) else None


def envelope(sim: Simulator, law: TorqueLaw, seconds: float, dt: float, reference: Array) -> Array | None:
    """The model's own sensitivity along the replay: per step, the running maximum over the joints
    and over the perturbed runs of |q_perturbed − q_reference|, the same engine replaying the same
    law from starts moved by ``PERTURBATION`` (every joint +1e-12, then alternating signs). None
    when the engine cannot start from a given q (no ``replay_from``) or a perturbed run fails. A
    perturbed run that turns non-finite makes the envelope infinite from that step on."""
    replay_from = getattr(sim, "replay_from", None)
    if replay_from is None:
        return None
    n = len(law.joints)
    worst = np.zeros(len(reference))
    for pattern in (np.ones(n), (-1.0) ** np.arange(n)):
        try:
            q = np.asarray(replay_from(law, seconds, dt, PERTURBATION * pattern), dtype=float)
        except Exception:  # the calibration is not available: the strict tolerance stays
            return None
        if q.shape != reference.shape:
            return None
        with np.errstate(invalid="ignore"):
            diff = np.abs(q - reference)
        diff[~np.isfinite(diff)] = math.inf
        worst = np.maximum(worst, diff.max(axis=1))
    return np.maximum.accumulate(worst)


def tolerances(env: Array | None, steps: int) -> Array:
    """Per step, the replay's tolerance: ``TOLERANCE`` (1e-8 rad, the difference two engines may
    accumulate from round-off) times the model's own amplification G(t) = envelope(t) / 1e-12 of a
    start difference by then (at least 1): max(1e-8, 1e4 × envelope(t)). Without an envelope, 1e-8."""
    if env is None:
        return np.full(steps, TOLERANCE)
    with np.errstate(invalid="ignore", over="ignore"):
        return TOLERANCE * np.maximum(1.0, env / PERTURBATION)


def _until(growth: Array, bound: float, dt: float) -> float:
    """The last time (s) at which the amplification is still at most ``bound``."""
    above = growth > bound
    return (int(np.argmax(above)) - 1) * dt if bool(above.any()) else (len(growth) - 1) * dt


def layer3b(source: Robot, sims: list[Simulator], law: TorqueLaw, seconds: float, dt: float
            ) -> tuple[list[Check], list[Skip]]:
    """:func:`replay_layer` without the calibration record (checks and skips only)."""
    checks, skips, _ = replay_layer(source, sims, law, seconds, dt)
    return checks, skips


def replay_layer(source: Robot, sims: list[Simulator], law: TorqueLaw, seconds: float, dt: float
                 ) -> tuple[list[Check], list[Skip], dict[str, Any]]:
    """Replay ``law`` in every simulator; compare each one's joint trajectories with the first's
    (MuJoCo by convention), step by step against the calibrated tolerance (:func:`tolerances`,
    from the first engine's :func:`envelope`). One ``replay`` check per compared engine: the step
    where |Δq| / tolerance is largest (its error, tolerance and time, naming the joint, source name),
    with the worst |Δq| over the run, the envelope and the margin in the detail. An engine whose
    state turns non-finite gets a failed ``engine-error`` check with the time; the run before it is
    still compared. The third value is the calibration, per compared engine, for the report."""
    checks: list[Check] = []
    skips: list[Skip] = []
    calibration: dict[str, Any] = {}
    names = "+".join(s.engine for s in sims) or "replay"
    if len(sims) < 2:
        skips.append(Skip(3, names, "layer 3b (replay) needs two engines that can integrate the model"))
        return checks, skips, calibration
    if not law.joints:
        skips.append(Skip(3, names, "layer 3b (replay): the model has no moving joint"))
        return checks, skips, calibration
    if law.balls:
        return ladder_layer(sims, law, dt)
    runs = [(sim, *_run(sim, law, seconds, dt)) for sim in sims]
    ref_sim, ref_q, _ref_wall, ref_error = runs[0]
    setting = f"{seconds:g} s at dt {dt:g} s, from q = dq = 0"
    if ref_q is None:
        for sim, *_ in runs[1:]:
            checks.append(Check(3, sim.engine, "replay", "", math.inf, TOLERANCE,
                                f"{ref_sim.engine} replay failed ({setting}): {ref_error}"))
        return checks, skips, calibration
    ref_bad = first_nonfinite(ref_q)
    if ref_bad is not None:
        checks.append(_nonfinite(ref_sim.engine, ref_q, ref_bad, law, dt, setting))
    env = envelope(ref_sim, law, seconds, dt, ref_q)
    tol = tolerances(env, len(ref_q))
    growth = tol / TOLERANCE
    for sim, q, _wall, error in runs[1:]:
        if q is None:
            checks.append(_failed(sim.engine, setting, error))
            continue
        bad = first_nonfinite(q)
        if bad is not None:
            checks.append(_nonfinite(sim.engine, q, bad, law, dt, setting))
        compared = min(x for x in (bad, ref_bad, len(q)) if x is not None)
        if compared <= 1:  # nothing but the common start to compare
            continue
        check, record = _compare(ref_sim.engine, sim.engine, ref_q[:compared], q[:compared],
                                 tol[:compared], growth[:compared], env, law, dt, setting)
        checks.append(check)
        calibration[sim.engine] = record
    return checks, skips, calibration


# ---- a model with ball joints: the step ladder ------------------------------------------------

LADDER_SECONDS = 0.5  # s: the ladder's horizon (short: the differences stay in their asymptotic regime)
LADDER_LEVELS = 4  # dt, dt/2, dt/4, dt/8


def richardson(differences: list[Array]) -> tuple[Array, Array]:
    """The engines' difference extrapolated to dt → 0 from its values at dt, dt/2, dt/4, ... (first
    order in dt, Richardson's table: each column removes the next power of dt), and the last
    correction made, the extrapolation's own uncertainty. For two first-order integrators of the
    same ODE the extrapolated value is O(dt^L) (L levels) and the correction O(dt^(L−1)); a difference
    of the models themselves survives every column."""
    column = list(differences)
    previous_best = column[-1]
    for order in range(1, len(differences)):
        factor = 2.0**order
        previous_best = column[-1]
        column = [(factor * column[i + 1] - column[i]) / (factor - 1.0) for i in range(len(column) - 1)]
    return column[0], column[0] - previous_best


def ladder_layer(sims: list[Simulator], law: TorqueLaw, dt: float
                 ) -> tuple[list[Check], list[Skip], dict[str, Any]]:
    """Layer 3b for a model with ball joints. MuJoCo integrates a ball as a quaternion turned by
    its angular velocity, the URDF PyBullet reads as three angles (MK813): two first-order schemes in
    different coordinates, whose trajectories part by O(dt) even for the same robot (measured on a
    two-ball chain: 1.1e-5 rad at 30 ms at dt 1 ms, halving with dt). So the replay runs
    ``LADDER_SECONDS`` at dt, dt/2, dt/4 and dt/8 in every engine, and grades the difference
    extrapolated to dt → 0 (:func:`richardson`; a ball's columns are its rotation vector) against the
    extrapolation's own uncertainty, its last correction (at least 1e-8 rad): a model difference
    survives the extrapolation, a difference of the schemes does not."""
    checks: list[Check] = []
    calibration: dict[str, Any] = {}
    steps = [dt / 2.0**k for k in range(LADDER_LEVELS)]
    setting = (f"{LADDER_SECONDS:g} s at dt {', '.join(f'{h:g}' for h in steps)} s, from q = dq = 0 "
               "(ball joints: the step ladder)")
    runs: list[list[Array]] = []
    for sim in sims:
        levels = []
        for k, h in enumerate(steps):
            q, _wall, error = _run(sim, law, LADDER_SECONDS, h)
            if q is None:
                checks.append(_failed(sim.engine, setting, error))
                break
            bad = first_nonfinite(q)
            if bad is not None:
                checks.append(_nonfinite(sim.engine, q, bad, law, h, setting))
                break
            levels.append(q[:: 2**k])
        runs.append(levels)
    reference = runs[0]
    if len(reference) < LADDER_LEVELS:
        return checks, [], calibration
    for sim, levels in zip(sims[1:], runs[1:], strict=True):
        if len(levels) < LADDER_LEVELS:
            continue
        extrapolated, correction = richardson([q - r for q, r in zip(levels, reference, strict=True)])
        check, record = _compare_ladder(sims[0].engine, sim.engine, extrapolated, correction,
                                        np.abs(levels[0] - reference[0]), reference[-1], law, dt, setting)
        checks.append(check)
        calibration[sim.engine] = record
    return checks, [], calibration


def _compare_ladder(ref_engine: str, engine: str, extrapolated: Array, correction: Array, coarse: Array,
                    travel_run: Array, law: TorqueLaw, dt: float, setting: str
                    ) -> tuple[Check, dict[str, Any]]:
    error = np.abs(extrapolated)
    per_step = error.max(axis=1)
    tol = np.maximum(TOLERANCE, np.maximum.accumulate(np.abs(correction).max(axis=1)))
    ratio = per_step / tol
    step = int(np.argmax(ratio))
    joint = int(np.argmax(error[step]))
    margin = float(1.0 / ratio[step]) if ratio[step] > 0.0 else math.inf
    worst_step = int(np.argmax(per_step))
    travel = np.ptp(travel_run, axis=0)
    detail = (f"|q_{engine} − q_{ref_engine}| extrapolated to dt → 0 over {setting}, against the "
              f"extrapolation's own uncertainty (its last correction, at least {TOLERANCE:g} rad): worst "
              f"ratio at t = {step * dt:.3f} s ({error[step, joint]:.2e} rad against {tol[step]:.2e}, margin "
              f"×{margin:.3g}); at dt {dt:g} s alone the engines part by {float(coarse.max()):.2e} rad (the "
              "two integration schemes); per joint: "
              + ", ".join(f"{j} {e:.1e}" for j, e in zip(law.joints, error.max(axis=0), strict=True))
              + "; travel in " + ref_engine + ": "
              + ", ".join(f"{j} {t:.3g}" for j, t in zip(law.joints, travel, strict=True)))
    record = {"reference": ref_engine, "method": "step ladder", "time_steps": [dt / 2.0**k for k in
                                                                              range(LADDER_LEVELS)],
              "compared_seconds": (len(per_step) - 1) * dt, "difference_at_dt": float(coarse.max()),
              "worst_ratio_time": step * dt, "worst_ratio_error": float(error[step, joint]),
              "worst_ratio_tolerance": float(tol[step]), "margin": margin if math.isfinite(margin) else None,
              "largest_error": float(per_step[worst_step]), "largest_error_time": worst_step * dt}
    return Check(3, engine, "replay", law.joints[joint], float(error[step, joint]), float(tol[step]),
                 detail), record


def _failed(engine: str, setting: str, error: str) -> Check:
    """The replay check of an engine whose replay raised or returned a wrong shape."""
    return Check(3, engine, "replay", "", math.inf, TOLERANCE, f"{engine} replay failed ({setting}): {error}")


def _nonfinite(engine: str, q: Array, step: int, law: TorqueLaw, dt: float, setting: str) -> Check:
    joints = [j for j, ok in zip(law.joints, np.isfinite(q[step]), strict=True) if not ok]
    return Check(3, engine, "engine-error", joints[0] if joints else "", math.inf, 0.0,
                 f"{engine}'s replay state turned non-finite (NaN or infinity) at t = {step * dt:.3f} s "
                 f"({setting}; joints {', '.join(joints[:6])}): the engine failed there; the replay is "
                 "compared up to that time only")


def _compare(ref_engine: str, engine: str, ref_q: Array, q: Array, tol: Array, growth: Array,
             env: Array | None, law: TorqueLaw, dt: float, setting: str) -> tuple[Check, dict[str, Any]]:
    diff = np.abs(q - ref_q)
    per_step = diff.max(axis=1)
    with np.errstate(invalid="ignore", divide="ignore"):
        ratio = np.where(per_step > 0.0, per_step / tol, 0.0)
    step = int(np.argmax(ratio))
    joint = int(np.argmax(diff[step]))
    per_joint = diff.max(axis=0)
    worst_step = int(np.argmax(per_step))
    travel = np.ptp(ref_q, axis=0)
    margin = float(1.0 / ratio[step]) if ratio[step] > 0.0 else math.inf
    end = len(ref_q) - 1
    if env is None:
        how = (f"tolerance {TOLERANCE:g} rad throughout ({ref_engine} cannot replay from a perturbed "
               "start: no calibration)")
    else:
        how = (f"tolerance 1e-8 rad × the model's own amplification: {ref_engine} replayed from starts "
               f"moved by {PERTURBATION:g} rad parts by {float(env[end]):.2e} rad by t = {end * dt:.3f} s "
               f"(×{float(growth[end]):.3g}); strict (amplification ≤ 10) up to t = "
               f"{_until(growth, 10.0, dt):.3f} s")
    detail = (f"|q_{engine} − q_{ref_engine}| over {setting} against the calibrated tolerance: worst "
              f"ratio at t = {step * dt:.3f} s ({diff[step, joint]:.2e} rad against {tol[step]:.2e}, "
              f"margin ×{margin:.3g}); {how}; largest difference {per_step[worst_step]:.2e} at "
              f"t = {worst_step * dt:.3f} s; per joint: "
              + ", ".join(f"{j} {e:.1e}" for j, e in zip(law.joints, per_joint, strict=True))
              + "; travel in " + ref_engine + ": "
              + ", ".join(f"{j} {t:.3g}" for j, t in zip(law.joints, travel, strict=True)))
    record = {"reference": ref_engine, "perturbation": PERTURBATION, "scale": TOLERANCE / PERTURBATION,
              "compared_seconds": end * dt,
              "envelope_end": float(env[end]) if env is not None else None,
              "amplification_end": float(growth[end]), "strict_until": _until(growth, 10.0, dt),
              "worst_ratio_time": step * dt, "worst_ratio_error": float(diff[step, joint]),
              "worst_ratio_tolerance": float(tol[step]),
              "margin": margin if math.isfinite(margin) else None,
              "largest_error": float(per_step[worst_step]), "largest_error_time": worst_step * dt}
    # (speed is a wall time: printed with the timings, never in a check, so report.json stays
    # the same from run to run)
    check = Check(3, engine, "replay", law.joints[joint], float(diff[step, joint]), float(tol[step]), detail)
    return check, record


# ---- harness overhead (bench, docs; never asserted in tests) ---------------------------------------


def _mujoco_bare(sim: Any, seconds: float, dt: float) -> float:
    """Wall seconds of a bare ``mj_step`` loop on the simulator's own compiled model."""
    import mujoco

    inner = getattr(sim, "inner", None)
    model = getattr(inner, "model", None) if inner is not None else getattr(sim, "model", None)
    if model is None:
        raise TypeError(f"cannot reach the MjModel of {sim!r}")
    data = mujoco.MjData(model)
    model.opt.timestep = dt
    step = mujoco.mj_step
    start = time.perf_counter()
    for _ in range(round(seconds / dt)):
        step(model, data)
    return time.perf_counter() - start


def overhead(sims: list[Simulator], law: TorqueLaw, seconds: float = 10.0, dt: float = 1e-3,
             repeats: int = 5) -> dict[str, dict[str, float]]:
    """Simulated seconds per wall second of each engine's replay against a bare stepping loop of
    the same engine on the same model (best of ``repeats``). PyBullet's figures are taken inside
    its child process (``replay_loop``: the stepping loop alone, without the pipe) and for the
    whole ``replay`` call as the layer sees it (``replay_call``)."""
    out: dict[str, dict[str, float]] = {}
    for sim in sims:
        replay_call, replay_loop, bare, closed = math.inf, math.inf, math.inf, math.nan
        for _ in range(repeats):
            start = time.perf_counter()
            sim.replay(law, seconds, dt)
            replay_call = min(replay_call, time.perf_counter() - start)
            inner_wall = float(getattr(sim, "last_replay_wall", math.nan))
            if math.isfinite(inner_wall):
                replay_loop = min(replay_loop, inner_wall)
            bench = getattr(sim, "bench", None)
            if bench is not None:
                figures = bench(seconds, dt)
                bare = min(bare, figures["bare"])
                closed = figures["closed_loop"] if math.isnan(closed) else min(closed, figures["closed_loop"])
            else:
                bare = min(bare, _mujoco_bare(sim, seconds, dt))
        if not math.isfinite(replay_loop):
            replay_loop = replay_call
        row = {"replay_call_rate": seconds / replay_call, "replay_loop_rate": seconds / replay_loop,
               "bare_rate": seconds / bare, "ratio_call": bare / replay_call,
               "ratio_loop": bare / replay_loop}
        if math.isfinite(closed):
            row["minimal_closed_loop_rate"] = seconds / closed
            row["ratio_loop_vs_minimal_closed_loop"] = closed / replay_loop
        out[sim.engine] = row
    return out
