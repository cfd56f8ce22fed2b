"""The dual-arm cell's state: the only code that moves the arms or talks to MuJoCo.

State: each arm's progress ``p_r`` along its own fixed trajectory, in samples
(0 .. N_r, real valued). An advance ``a_r`` in [0, 1] per step moves it by
``a_r`` samples (1 = nominal speed, 0 = wait); the geometric path and time law
never change. Between samples the joints are interpolated linearly (as a
controller interpolates set-points). Distances come from the MuJoCo model
(``model.MujocoCell``: ``mj_kinematics`` + ``mj_collision`` over the 25 pairs);
whether a step collides, from :func:`.collision.step_collides` (the one rule,
shared with the planners).

The observation is the task's (:data:`.task.LAYOUT`); ``OBS`` and ``OBS_SIZE``
here are the deprecated names of ``LAYOUT.slices`` and ``LAYOUT.size``.
"""

from __future__ import annotations

from typing import Any

import mujoco
import numpy as np
from gymnasium import spaces

from motiongym.envs.checks import Deprecated, warn_deprecated
from motiongym.envs.dual_arm import collision, model
from motiongym.envs.dual_arm.task import (
    DT,
    LAYOUT,
    StepEvents,
    Trajectory,
    observation_bounds,
    tasks_from_observation,
)
from motiongym.envs.rendering import OwnsRenderer

__all__ = ["DualArmWorld", "observation_bounds", "tasks_from_observation"]

_DEPRECATED = {
    "OBS": (lambda: LAYOUT.slices, "use motiongym.envs.dual_arm.task.LAYOUT"),
    "OBS_SIZE": (lambda: LAYOUT.size, "use motiongym.envs.dual_arm.task.LAYOUT.size"),
}


def __getattr__(name: str) -> Any:
    if name in _DEPRECATED:
        value, note = _DEPRECATED[name]
        warn_deprecated(__name__, name, Deprecated(None, note=note))
        return value()
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")


class DualArmWorld(OwnsRenderer):
    """Both arms on their trajectories, stepped by advances; no reward, no episode logic.

    Args:
        control: ``"both"`` (the action is both arms' advances, (2,)) or ``"robot_2"``
            (robot 2's, (1,); robot 1 on its nominal schedule).
        check: the collision check (:data:`.collision.CHECKS`).
        margin: the safety margin (m): a step collides within it.

    The joints live in the MuJoCo data (``qpos``: robot 1, then 2); progress
    is kept as Python floats (``p1``, ``p2`` of ``n1``, ``n2``).
    """

    def __init__(self, control: str = "both", check: str = "samples", margin: float = 0.0) -> None:
        self._renderer: mujoco.Renderer | None = None
        self._size: tuple[int, int] | None = None
        self.control, self.check, self.margin = control, check, float(margin)
        n = 2 if control == "both" else 1
        self.action_space: spaces.Space = spaces.Box(0.0, 1.0, (n,), np.float32)
        self.tasks: tuple[Trajectory, Trajectory] | None = None
        self._attach(model.MujocoCell())

    def _attach(self, cell: model.MujocoCell) -> None:
        self.cell = cell
        self.qpos = qpos = cell.data.qpos  # both arms' joints, (12,)
        self._qpos = (qpos[:6], qpos[6:])  # views into the MuJoCo data

    @property
    def scene(self) -> tuple[Trajectory, Trajectory] | None:
        """The episode's task pair (robot 1, robot 2)."""
        return self.tasks

    def reset(self, scene: tuple[Trajectory, Trajectory], rng: np.random.Generator) -> None:
        """Put the task pair ``scene`` in place, both arms at their start (no noise)."""
        self.load(*scene)

    def advance(self, action: list[float]) -> StepEvents:
        """One step under a checked action (finite floats, one per driven arm; clipped
        into [0, 1] here): both arms move, and the step is checked on ``check``."""
        values = [min(max(v, 0.0), 1.0) for v in action]
        a1, a2 = (values[0], values[1]) if self.control == "both" else (1.0, values[0])
        wait = (1.0 - a2) * DT if self.p2 < self.n2 else 0.0
        before = self.p1 / self.n1 + self.p2 / self.n2
        start, d_start = (self.p1, self.p2), self.distances
        self.move(a1, a2)
        collided = collision.step_collides(
            self.check, self.margin, d_start, self.distances, self.samples, self.slopes,
            start, (self.p1, self.p2), self.distance,
        )  # fmt: skip
        return StepEvents(collided, before, wait)

    def load(self, traj1: Trajectory, traj2: Trajectory) -> None:
        """Put the pair in place (what :meth:`reset` does): both arms at sample 0."""
        self.tasks = (traj1, traj2)
        self.samples = (traj1.samples(), traj2.samples())  # (N_r + 1, 6) each
        self._deltas = (np.diff(self.samples[0], axis=0), np.diff(self.samples[1], axis=0))
        self.slopes = (np.abs(self._deltas[0]), np.abs(self._deltas[1]))  # (N_r, 6) |dq|
        self.n1, self.n2 = float(traj1.n_samples), float(traj2.n_samples)
        self.p1 = self.p2 = 0.0
        self.steps = 0
        self._update()

    @property
    def n(self) -> np.ndarray:
        """Last sample index of each arm, (2,)."""
        return np.array([self.n1, self.n2])

    @property
    def progress(self) -> np.ndarray:
        """Progress of each arm in samples, (2,)."""
        return np.array([self.p1, self.p2])

    @property
    def q(self) -> tuple[np.ndarray, np.ndarray]:
        """Joint angles of robot 1 and robot 2, (6,) each (copies)."""
        return self._qpos[0].copy(), self._qpos[1].copy()

    def config(self, robot: int) -> np.ndarray:
        """Joint angles (6,) of ``robot`` at its progress (linear between samples)."""
        out = np.empty(6)
        self._config(robot, (self.p1, self.p2)[robot], out)
        return out

    def _config(self, robot: int, p: float, out: np.ndarray) -> None:
        q = self.samples[robot]
        k = int(p)
        if k >= len(q) - 1:
            out[:] = q[-1]
            return
        f = p - k
        if f == 0.0:
            out[:] = q[k]
        else:
            np.add(q[k], f * self._deltas[robot][k], out=out)

    def _update(self) -> None:
        self._config(0, self.p1, self._qpos[0])
        self._config(1, self.p2, self._qpos[1])
        self.distances = self.cell.current_distances()  # (5, 5)
        self.distance = float(self.distances.min())

    def move(self, a1: float, a2: float) -> None:
        """Advance robot 1 by ``a1`` and robot 2 by ``a2`` samples (each in [0, 1])."""
        self.p1 = min(self.p1 + a1, self.n1)
        self.p2 = min(self.p2 + a2, self.n2)
        self.steps += 1
        self._update()

    @property
    def finished(self) -> tuple[bool, bool]:
        return self.p1 >= self.n1, self.p2 >= self.n2

    @property
    def elapsed(self) -> float:
        return self.steps * DT

    def render(self, size: tuple[int, int] = (480, 640)) -> np.ndarray:
        """A frame of ``size`` = (rows, columns) from the overview camera."""
        rows, columns = size
        if self._renderer is None or self._size != (rows, columns):
            self.close()
            self._renderer = mujoco.Renderer(self.cell.model, rows, columns)
            self._size = (rows, columns)
        mujoco.mj_kinematics(self.cell.model, self.cell.data)
        mujoco.mj_camlight(self.cell.model, self.cell.data)  # cameras and lights
        self._renderer.update_scene(self.cell.data, camera="overview")
        return self._renderer.render().copy()

    def __getstate__(self) -> dict[str, Any]:
        state = super().__getstate__()
        state["_qpos"] = None
        state["qpos"] = None
        state["cell"] = None
        return state

    def __setstate__(self, state: dict[str, Any]) -> None:
        self.__dict__.update(state)
        self._attach(model.MujocoCell())
        if self.tasks is not None:
            self._update()
