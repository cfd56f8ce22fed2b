"""Pick-and-place joint trajectories for the two arms, and how a pair is sampled.

A task is a list of ``K = 4`` via configurations (start, pick, place, retreat)
and the ``K - 1`` segment durations. Between vias the joints move on the
straight joint-space segment with the quintic time law
``s(tau) = 10 tau^3 - 15 tau^4 + 6 tau^5`` (rest to rest; peak ``ds/dtau =
15/8``); a segment's duration is ``15/8 * max_j |dq_j| / v_max_j`` times a
slowness factor >= 1, rounded up to whole 20 ms samples, so the joint speed
limits ``V_MAX`` hold by construction and every via falls on a sample. The
trajectory is sampled at ``DT = 20 ms`` (the paper's controller sample time).
The compact form (vias and durations) is what the observation carries; the
samples are reproducible from it (:meth:`Trajectory.from_compact`).

Robot 2's path is also parametrised by travelled length (the paper's collision
map axis): the Cartesian arc length of its wrist centre (paper: "the travelled
length of robot 2's wrist"), ``L_T`` in total, split in ``N_l`` equal steps.

Sampling (``sample_pair``, from the reset generator only): each arm's vias are
drawn from joint boxes (``VIA_BOXES``, in its own base frame, so both arms
reach into the shared middle of the cell) and redrawn if the gripper would
dip under ``MIN_TOOL_Z``. Modes: ``"any"``; ``"colliding"``: the pair collides
when both start together, and running them one after the other is collision
free (robot 1's whole path clears robot 2's start, robot 2's whole path clears
robot 1's end), so a finite start delay always exists; ``"paper"``: the fixed
paper case (:func:`paper_case`), colliding undelayed over an interval like the
paper's 0.76-1.16 s. Every test is exact at every 20 ms sample; the geometry
of both arms' samples and the collision tests run in few NumPy operations
(:mod:`.capsule_paths`), since this runs on every reset. The draws are those of
drawing robot 1 until accepted, then robot 2 (:func:`_sample_arms`), so a
seed's tasks do not depend on how the geometry is computed.

With ``check="swept"`` (``DualArmCell-v1``, whose check covers the motion
between samples) a ``"colliding"`` pair must also run one after the other
collision free *in motion* (:func:`sequential_clear_in_motion`, the
certified bound of :mod:`.motion`): at the samples alone 5 of 300 sampled
pairs (seeds 50000-50299) passed while robot 1's path grazes robot 2's start
or robot 2's path robot 1's end between two samples, pairs that v1's check
makes unsolvable by any start delay.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping
from dataclasses import dataclass
from functools import partial
from typing import TYPE_CHECKING, Any, NamedTuple

import numpy as np
from gymnasium import spaces

from motiongym.envs.checks import Deprecated, check_choice
from motiongym.envs.core import Outcome, zero_terms
from motiongym.envs.dual_arm import capsule_paths, model, motion
from motiongym.envs.dual_arm.collision import CHECKS, SWEPT
from motiongym.envs.layout import ObservationLayout

if TYPE_CHECKING:
    from motiongym.envs.dual_arm.params import DualArmParams
    from motiongym.envs.dual_arm.world import DualArmWorld

DT = 0.02  # s, controller sample time (paper)
N_VIAS = 4
V_MAX = np.array([2.0, 2.0, 2.0, 4.0, 4.0, 4.0])  # rad/s, our nominal joint speed limits
PEAK = 15.0 / 8.0  # peak of ds/dtau for the quintic law
MIN_TOOL_Z = 0.05  # m, the gripper tip stays above the floor
PAIRS = ("colliding", "any", "paper")  # the values of the pairs keyword
TASK_MODES = PAIRS  # its former name

# Joint boxes (rad) per via, in the arm's own base frame: start, pick, place, retreat.
VIA_BOXES = np.array(
    [
        [[-0.9, 0.9], [0.9, 1.5], [-1.6, -0.8], [-1.0, 1.0], [-1.0, 1.0], [-1.0, 1.0]],
        [[-0.6, 0.6], [-0.3, 0.5], [-1.9, -0.9], [-1.0, 1.0], [-1.2, 1.2], [-1.0, 1.0]],
        [[-1.2, 1.2], [-0.2, 0.6], [-2.0, -1.0], [-1.0, 1.0], [-1.2, 1.2], [-1.0, 1.0]],
        [[-0.9, 0.9], [0.9, 1.5], [-1.6, -0.8], [-1.0, 1.0], [-1.0, 1.0], [-1.0, 1.0]],
    ]
)  # (4, 6, 2)
SLOWNESS = (1.0, 1.6)  # range of the factor on each segment's minimum duration


def quintic(tau: np.ndarray) -> np.ndarray:
    """Rest-to-rest time law ``s(tau)``, tau in [0, 1]."""
    tau = np.minimum(np.maximum(tau, 0.0), 1.0)  # np.clip, without its overhead
    return tau**3 * (10.0 - 15.0 * tau + 6.0 * tau * tau)


@dataclass(frozen=True)
class Trajectory:
    """One arm's joint trajectory from its compact form.

    Attributes:
        vias: (K, 6) via configurations, rad.
        durations: (K - 1,) segment durations, s (whole samples).
        robot: 0 or 1 (which base frame).
    """

    vias: np.ndarray
    durations: np.ndarray
    robot: int

    @staticmethod
    def from_compact(vias: np.ndarray, durations: np.ndarray, robot: int) -> Trajectory:
        vias = np.asarray(vias, float).reshape(N_VIAS, 6)
        steps = np.maximum(np.round(np.asarray(durations, float) / DT), 1.0)
        return Trajectory(vias, steps * DT, robot)

    @property
    def n_samples(self) -> int:
        """N: index of the last sample (the trajectory has N + 1 samples)."""
        return int(round(float(self.durations.sum()) / DT))

    @property
    def duration(self) -> float:
        return self.n_samples * DT

    def at_time(self, t: np.ndarray) -> np.ndarray:
        """Joint angles at times ``t`` (...,) s -> (..., 6); clamped to [0, T]."""
        t = np.asarray(t, float)
        bounds = np.zeros(N_VIAS)  # (K,)
        np.cumsum(self.durations, out=bounds[1:])
        seg = np.minimum(np.maximum(np.searchsorted(bounds, t, side="right") - 1, 0), N_VIAS - 2)
        tau = (t - bounds[seg]) / self.durations[seg]
        s = quintic(tau)[..., None]
        return self.vias[seg] + s * np.diff(self.vias, axis=0)[seg]

    def samples(self) -> np.ndarray:
        """(N + 1, 6) joint angles at ``k * DT``; computed once, read-only."""
        cached = self.__dict__.get("_samples")
        if cached is None:
            cached = self.at_time(np.arange(self.n_samples + 1) * DT)
            cached.flags.writeable = False
            object.__setattr__(self, "_samples", cached)
        return cached

    def wrist_length(self, oversample: int = 8) -> tuple[np.ndarray, np.ndarray]:
        """Wrist-centre arc length on a fine time grid: ``(times, lengths)``."""
        t = np.linspace(0.0, self.duration, self.n_samples * oversample + 1)
        w = model.wrist_centre(self.at_time(t), model.base_transform(self.robot))
        step = np.linalg.norm(np.diff(w, axis=0), axis=1)
        return t, np.concatenate([[0.0], np.cumsum(step)])

    def length_parametrised(self, n_levels: int) -> tuple[np.ndarray, np.ndarray, float]:
        """Configurations at travelled lengths ``l = s2 * L_T / N_l``.

        Returns:
            ``(q_levels (N_l + 1, 6), tlvst (N + 1,), L_T)``: the configuration at
            each length level, and TLVST: the level index ``floor(l(k dt) / dl)``
            the wrist has reached at each sample ``k`` (last sample = ``N_l``).
        """
        t, mono, total = self._monotone_length()
        t_of_level = self.level_times(n_levels)
        q_levels = self.at_time(t_of_level)
        k_times = np.arange(self.n_samples + 1) * DT
        l_k = np.interp(k_times, t, mono)
        tl = np.floor(l_k / (mono[-1] / n_levels) + 1e-9).astype(np.int64)
        tl = np.clip(tl, 0, n_levels)
        tl[-1] = n_levels
        return q_levels, tl, total

    def _monotone_length(self) -> tuple[np.ndarray, np.ndarray, float]:
        """``(times, lengths made strictly increasing, L_T)`` (the inverse is defined at rests)."""
        t, length = self.wrist_length()
        return t, length + 1e-12 * np.arange(len(length)), float(length[-1])

    def level_times(self, n_levels: int) -> np.ndarray:
        """(N_l + 1,) the time (s) at which the wrist has travelled ``s2 * L_T / N_l``."""
        t, mono, _ = self._monotone_length()
        return np.interp(np.linspace(0.0, mono[-1], n_levels + 1), mono, t)

    def compact(self) -> np.ndarray:
        """Flat compact form: vias (K * 6) then durations (K - 1)."""
        return np.concatenate([self.vias.ravel(), self.durations])


def tool_tip_z(frames: np.ndarray) -> np.ndarray:
    """Height of the gripper tip (...,) m from body frames (..., 6, 4, 4)."""
    fr = frames[..., 5, :, :]
    return fr[..., 2, 3] + fr[..., 2, 2] * model.LINKS[5][1][2]


def _draw_arm(rng: np.random.Generator, robot: int) -> Trajectory:
    """One draw of an arm's vias and segment durations (tip height not checked)."""
    lo, hi = VIA_BOXES[..., 0], VIA_BOXES[..., 1]
    vias = rng.uniform(lo, hi)  # (K, 6)
    dq = np.abs(np.diff(vias, axis=0))  # (K-1, 6)
    minimum = PEAK * np.max(dq / V_MAX, axis=1)
    dur = minimum * rng.uniform(*SLOWNESS, size=N_VIAS - 1)
    dur = np.ceil(np.maximum(dur, 0.2) / DT) * DT
    return Trajectory(vias, dur, robot)


def _sample_arm(rng: np.random.Generator, robot: int) -> tuple[Trajectory, capsule_paths.Sweep]:
    """Draws until the gripper tip stays above ``MIN_TOOL_Z``."""
    while True:
        traj = _draw_arm(rng, robot)
        swept = capsule_paths.Sweep.of(traj.samples(), robot)
        if swept.tip_z.min() >= MIN_TOOL_Z:
            return traj, swept


def _sample_arms(rng: np.random.Generator) -> tuple[tuple, tuple]:
    """``(_sample_arm(rng, 0), _sample_arm(rng, 1))``: the same draws in the same
    order, with both arms' geometry computed in one batch. Robot 2 is drawn
    before robot 1's tip is checked; if robot 1 is redrawn (rare), the
    generator is put back to just after robot 1's draw, as if robot 2's draw
    had not happened."""
    traj1 = _draw_arm(rng, 0)
    after1 = rng.bit_generator.state
    traj2 = _draw_arm(rng, 1)
    swept1, swept2 = capsule_paths.Sweep.of_pair(traj1.samples(), traj2.samples())
    if swept1.tip_z.min() < MIN_TOOL_Z:
        rng.bit_generator.state = after1
        return _sample_arm(rng, 0), _sample_arm(rng, 1)
    if swept2.tip_z.min() < MIN_TOOL_Z:
        return (traj1, swept1), _sample_arm(rng, 1)
    return (traj1, swept1), (traj2, swept2)


def _check_pair(
    swept1: capsule_paths.Sweep, swept2: capsule_paths.Sweep, margin: float
) -> tuple[bool, bool]:
    """(collides when both start together, one after the other is collision free).

    One after the other: robot 1's whole path clears robot 2's start and robot
    2's whole path clears robot 1's end. Both from one exact test over the
    instants of both schedules (:func:`.capsule_paths.schedules_collide`).
    """
    n1, n2 = swept1.n_samples, swept2.n_samples
    together, sequential = capsule_paths.schedules_collide(
        swept1,
        swept2,
        [capsule_paths.together_rows(n1, n2), capsule_paths.sequential_rows(n1, n2)],
        margin,
    )
    return together, not sequential


def undelayed_distance(traj1: Trajectory, traj2: Trajectory) -> np.ndarray:
    """``d(R1, R2)`` over time when both start together, (max(N1, N2) + 1,)."""
    n = max(traj1.n_samples, traj2.n_samples)
    t = np.arange(n + 1) * DT
    return model.robot_distance(traj1.at_time(t), traj2.at_time(t))


def sequential_clear(traj1: Trajectory, traj2: Trajectory, margin: float = 0.0) -> bool:
    """Robot 1's path clears robot 2's start and robot 2's path clears robot 1's end."""
    s1, s2 = (capsule_paths.Sweep.of(t.samples(), t.robot) for t in (traj1, traj2))
    rows1, rows2 = capsule_paths.sequential_rows(traj1.n_samples, traj2.n_samples)
    return not capsule_paths.colliding_instants(s1, rows1, s2, rows2, margin).any()


def sequential_clear_in_motion(traj1: Trajectory, traj2: Trajectory, margin: float = 0.0) -> bool:
    """:func:`sequential_clear` over the motion between samples: robot 1's whole path
    (spans of fractional samples, :func:`.motion.spans_collide`) clears robot 2 at its
    start, and robot 2's whole path clears robot 1 at its end (exact to 1 mm)."""
    s1, s2 = traj1.samples(), traj2.samples()
    n1, n2 = float(traj1.n_samples), float(traj2.n_samples)
    first = motion.spans_collide(s1, (0.0, n1), s2, (0.0, 0.0), margin)
    return not first and not motion.spans_collide(s1, (n1, n1), s2, (0.0, n2), margin)


def sample_pair(
    rng: np.random.Generator,
    mode: str = "colliding",
    margin: float = 0.0,
    max_tries: int = 1000,
    check: str = "samples",
) -> tuple[Trajectory, Trajectory]:
    """A pair of tasks (robot 1, robot 2) drawn from ``rng``; see the module doc.

    ``mode`` is one of :data:`PAIRS`; ``check`` the environment's collision check
    (:data:`.collision.CHECKS`): on ``"swept"`` a "colliding" pair also runs one after
    the other without contact in motion."""
    if mode not in PAIRS:
        raise ValueError(f"unknown pairs mode {mode!r}; choose one of {', '.join(PAIRS)}")
    in_motion = check_choice("check", check, CHECKS) == SWEPT
    if mode == "paper":
        return paper_case()
    for _ in range(max_tries):
        (t1, s1), (t2, s2) = _sample_arms(rng)
        if mode == "any":
            return t1, t2
        collides, sequential_ok = _check_pair(s1, s2, margin)
        if (
            collides
            and sequential_ok
            and (not in_motion or sequential_clear_in_motion(t1, t2, margin))
        ):
            return t1, t2
    raise RuntimeError(
        f"no pair that collides started together and clears by {margin} m one after the "
        f"other in {max_tries} tries; lower safety_margin or use pairs='any'"
    )


# The paper's Fig. 6 trajectories are not in the text: our own pick-and-place pair
# in which both arms reach into the middle of the cell around t = 1 s.
_PAPER_VIAS = (
    np.array(
        [
            [0.0, 1.0, -0.8, 0.0, 0.5, 0.0],
            [0.2, 0.05, -1.35, 0.0, 0.6, 0.0],
            [0.9, 0.3, -1.5, 0.3, 0.4, 0.0],
            [1.4, 1.0, -0.7, 0.0, 0.5, 0.0],
        ]
    ),
    np.array(
        [
            [-0.6, 1.0, -0.8, 0.0, 0.5, 0.0],
            [0.05, 0.1, -1.3, 0.0, 0.5, 0.0],
            [0.6, 0.2, -1.4, 0.2, 0.5, 0.0],
            [0.5, 1.0, -0.8, 0.0, 0.5, 0.0],
        ]
    ),
)
# Minimum durations of the quintic law under V_MAX, rounded up to whole samples.
_PAPER_DURATIONS = (np.array([0.9, 0.66, 0.76]), np.array([0.86, 0.52, 0.76]))


def paper_case() -> tuple[Trajectory, Trajectory]:
    """The fixed "paper case" pair (robot 1, robot 2)."""
    return tuple(Trajectory.from_compact(_PAPER_VIAS[r], _PAPER_DURATIONS[r], r) for r in range(2))  # type: ignore[return-value]


def speeds_ok(traj: Trajectory) -> bool:
    """True if no joint exceeds ``V_MAX`` (finite differences on a fine grid)."""
    t = np.linspace(0.0, traj.duration, traj.n_samples * 10 + 1)
    q = traj.at_time(t)
    v = np.abs(np.diff(q, axis=0)) / np.diff(t)[:, None]
    return bool(np.all(v <= V_MAX * (1 + 1e-6)))


# ---------------------------------------------------------------- the episode's task

_TASK = N_VIAS * 6 + N_VIAS - 1  # one arm's compact task: vias, then segment durations
LAYOUT = ObservationLayout(
    [
        ("q1", 6, "rad", "robot 1 joint angles q1..q6 (robot 1 joints)"),
        ("q2", 6, "rad", "robot 2 joint angles q1..q6 (robot 2 joints)"),
        ("progress", 2, "-", "progress p_r / N_r of robot 1, robot 2"),
        ("elapsed", 1, "s", "elapsed time (steps x 0.02 s)"),
        (
            "distances",
            (5, 5),
            "m",
            "d_ij (paper eq. 1), robot-1 body i, robot-2 body j, row major",
        ),
        ("task1", _TASK, "rad, s", "robot 1 via configurations (4 x 6), segment durations (3)"),
        ("task2", _TASK, "rad, s", "robot 2 via configurations (4 x 6), segment durations (3)"),
    ]
)
_Q = slice(LAYOUT["q1"].start, LAYOUT["q2"].stop)
_P1, _P2 = LAYOUT["progress"].start, LAYOUT["progress"].start + 1
_ELAPSED = LAYOUT["elapsed"].start
_D = LAYOUT["distances"]
_TASKS = slice(LAYOUT["task1"].start, LAYOUT["task2"].stop)


def observation_bounds() -> tuple[np.ndarray, np.ndarray]:
    """``(low, high)`` of the observation (:data:`LAYOUT`)."""
    lim = model.JOINT_LIMITS
    task_low = np.concatenate([np.tile(lim[:, 0], N_VIAS), np.zeros(N_VIAS - 1)])
    task_high = np.concatenate([np.tile(lim[:, 1], N_VIAS), np.full(N_VIAS - 1, 60.0)])
    return LAYOUT.bounds(
        {
            "q1": (lim[:, 0], lim[:, 1]),
            "q2": (lim[:, 0], lim[:, 1]),
            "progress": (0.0, 1.0),
            "elapsed": (0.0, 1.0e4),
            "distances": (-1.0, 5.0),  # m, by the cell's size
            "task1": (task_low, task_high),
            "task2": (task_low, task_high),
        }
    )


def tasks_from_observation(obs: np.ndarray) -> tuple[Trajectory, Trajectory]:
    """Rebuild both arms' trajectories from an observation (what planners do)."""
    obs = np.asarray(obs, dtype=float)
    out = []
    for r, key in enumerate(("task1", "task2")):
        flat = obs[LAYOUT[key]]
        out.append(Trajectory.from_compact(flat[: N_VIAS * 6], flat[N_VIAS * 6 :], r))
    return out[0], out[1]


def _pairs_option_from_task(value: Any, current: Any) -> str:
    """The ``pairs`` option from its deprecated name ``task`` (a bad value named as given)."""
    return check_choice("options['task']", value, PAIRS)


class StepEvents(NamedTuple):
    """What one step of the world did (:meth:`.world.DualArmWorld.advance`)."""

    collided: bool  # the step collides on the world's check (:mod:`.collision`)
    progress_before: float  # p_1 / N_1 + p_2 / N_2 before the step
    robot_2_wait: float  # s robot 2 spent not advancing in the step (0 once it is done)


class DualArmTask:
    """Sample a task pair, score the step, observe (the environment's docstring).

    Reward terms (weights from :class:`.params.DualArmParams`): ``time``,
    ``collision``, ``clearance`` (costs) and ``advance`` (paid). Reset option:
    ``pairs`` (:data:`PAIRS`; ``task`` its deprecated name).
    """

    reward_terms: tuple[str, ...] = ("time", "collision", "clearance", "advance")
    layout = LAYOUT

    def __init__(self, params: DualArmParams) -> None:
        self.params = params
        self.weights = params.weights
        lo, hi = observation_bounds()
        self.observation_space: spaces.Space = spaces.Box(lo, hi, dtype=np.float32)
        self.options: Mapping[str, Callable[[str, Any], Any]] = {
            "pairs": partial(check_choice, choices=PAIRS)
        }
        self.deprecated_options = {"task": Deprecated("pairs", _pairs_option_from_task)}
        self._wait2 = 0.0
        self._template = np.empty(LAYOUT.size, dtype=np.float32)

    def sample(self, rng: np.random.Generator, options: Mapping[str, Any]) -> tuple:
        p = self.params
        mode = options.get("pairs", p.pairs)
        return sample_pair(rng, mode, p.safety_margin, check=p.collision_check)

    def begin(self, world: DualArmWorld) -> Outcome:
        self._wait2 = 0.0
        assert world.tasks is not None  # the world was reset
        traj1, traj2 = world.tasks
        self._template = np.empty(LAYOUT.size, dtype=np.float32)  # the tasks part is fixed
        self._template[_TASKS] = np.concatenate([traj1.compact(), traj2.compact()])
        return self._outcome(world, False, zero_terms(self.reward_terms))

    def evaluate(self, world: DualArmWorld, events: StepEvents) -> Outcome:
        self._wait2 += events.robot_2_wait
        w, d, collided = self.weights, world.distance, events.collided
        terms = {
            "time": -w["time"] * DT,
            "collision": -w["collision"] if collided else 0.0,
            "clearance": -w["clearance"] * max(0.0, 1.0 - d / self.params.clearance_distance),
            "advance": w["advance"] * (world.p1 / world.n1 + world.p2 / world.n2
                                       - events.progress_before),
        }  # fmt: skip
        return self._outcome(world, collided, terms)

    def _outcome(self, world: DualArmWorld, collided: bool, terms: dict[str, float]) -> Outcome:
        done = world.p1 >= world.n1 and world.p2 >= world.n2
        measures = {
            "collision": collided,
            "distance": world.distance,
            "makespan": world.steps * DT,
            "progress_1": world.p1,
            "progress_2": world.p2,
            "robot_2_wait": self._wait2,
        }
        return Outcome(terms, not collided and done, 1.0 if collided else 0.0, measures,
                       collided or done)  # fmt: skip

    def observe(self, world: DualArmWorld) -> np.ndarray:
        obs = self._template.copy()
        obs[_Q] = world.qpos
        obs[_P1] = world.p1 / world.n1
        obs[_P2] = world.p2 / world.n2
        obs[_ELAPSED] = world.steps * DT
        obs[_D] = world.distances.ravel()
        return obs
