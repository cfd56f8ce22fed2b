"""The dual-arm cell's state, shared by the Gymnasium and PettingZoo environments.

State: each arm's progress ``p_r`` along its own fixed trajectory, in samples
(0 .. N_r, real valued). An advance ``a_r`` in [0, 1] per step moves it by
``a_r`` samples (1 = nominal speed, 0 = wait); the geometric path and time law
never change. Between samples the joints are interpolated linearly (as a
controller interpolates set-points). Distances come from the MuJoCo model
(``model.MujocoCell``: ``mj_kinematics`` + ``mj_collision`` over the 25 pairs).

Observation layout (float32, ``OBS_SIZE`` = 94), named by ``OBS``:

======  ==========================================  =====  =================
index   meaning                                      unit   frame
======  ==========================================  =====  =================
0-5     robot 1 joint angles q1..q6                  rad    robot 1 joints
6-11    robot 2 joint angles                         rad    robot 2 joints
12      robot 1 progress p_1 / N_1                   -      -
13      robot 2 progress p_2 / N_2                   -      -
14      elapsed time (steps x 20 ms)                 s      -
15-39   d_ij, i robot-1 body, j robot-2 body, row    m      -
        major, bodies upper arm, forearm, wrist
        roll, wrist bend, gripper (paper eq. 1)
40-63   robot 1 via configurations (4 x 6)           rad    robot 1 joints
64-66   robot 1 segment durations (3)                s      -
67-90   robot 2 via configurations (4 x 6)           rad    robot 2 joints
91-93   robot 2 segment durations (3)                s      -
======  ==========================================  =====  =================
"""

from __future__ import annotations

from typing import Any

import mujoco
import numpy as np

from motiongym.envs.dual_arm import model
from motiongym.envs.dual_arm.task import DT, N_VIAS, Trajectory
from motiongym.envs.rendering import OwnsRenderer

_TASK = N_VIAS * 6 + N_VIAS - 1
OBS: dict[str, slice] = {
    "q1": slice(0, 6),
    "q2": slice(6, 12),
    "progress": slice(12, 14),
    "elapsed": slice(14, 15),
    "distances": slice(15, 40),
    "task1": slice(40, 40 + _TASK),
    "task2": slice(40 + _TASK, 40 + 2 * _TASK),
}
OBS_SIZE = 40 + 2 * _TASK


def observation_bounds() -> tuple[np.ndarray, np.ndarray]:
    lo, hi = np.empty(OBS_SIZE, np.float32), np.empty(OBS_SIZE, np.float32)
    lim = model.JOINT_LIMITS
    for key in ("q1", "q2"):
        lo[OBS[key]], hi[OBS[key]] = lim[:, 0], lim[:, 1]
    lo[OBS["progress"]], hi[OBS["progress"]] = 0.0, 1.0
    lo[OBS["elapsed"]], hi[OBS["elapsed"]] = 0.0, 1.0e4
    lo[OBS["distances"]], hi[OBS["distances"]] = -1.0, 5.0
    for key in ("task1", "task2"):
        sl = OBS[key]
        vias = slice(sl.start, sl.start + N_VIAS * 6)
        lo[vias], hi[vias] = np.tile(lim[:, 0], N_VIAS), np.tile(lim[:, 1], N_VIAS)
        lo[vias.stop : sl.stop], hi[vias.stop : sl.stop] = 0.0, 60.0
    return lo, hi


def tasks_from_observation(obs: np.ndarray) -> tuple[Trajectory, Trajectory]:
    """Rebuild both arms' trajectories from an observation (what planners do)."""
    obs = np.asarray(obs, dtype=float)
    out = []
    for r, key in enumerate(("task1", "task2")):
        flat = obs[OBS[key]]
        out.append(Trajectory.from_compact(flat[: N_VIAS * 6], flat[N_VIAS * 6 :], r))
    return out[0], out[1]


class DualArmWorld(OwnsRenderer):
    """Both arms on their trajectories, stepped by advances; no reward, no episode logic.

    The joints live in the MuJoCo data (``cell.data.qpos``: robot 1, then 2);
    progress is kept as Python floats (``p1``, ``p2`` of ``n1``, ``n2``).
    """

    def __init__(self) -> None:
        self._renderer: mujoco.Renderer | None = None
        self.tasks: tuple[Trajectory, Trajectory] | None = None
        self._attach(model.MujocoCell())

    def _attach(self, cell: model.MujocoCell) -> None:
        self.cell = cell
        qpos = cell.data.qpos
        self._qpos = (qpos[:6], qpos[6:])  # views into the MuJoCo data

    def load(self, traj1: Trajectory, traj2: Trajectory) -> None:
        self.tasks = (traj1, traj2)
        self.samples = (traj1.samples(), traj2.samples())  # (N_r + 1, 6) each
        self._deltas = tuple(np.diff(q, axis=0) for q in self.samples)  # (N_r, 6) each
        self.slopes = tuple(np.abs(d) for d in self._deltas)  # (N_r, 6) |dq| per sample
        self.n1, self.n2 = float(traj1.n_samples), float(traj2.n_samples)
        self.p1 = self.p2 = 0.0
        self.steps = 0
        self._obs = np.empty(OBS_SIZE, dtype=np.float32)  # template: the tasks part is fixed
        self._obs[OBS["task1"].start :] = np.concatenate([traj1.compact(), traj2.compact()])
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

    def advance(self, a1: float, a2: float) -> None:
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

    def observation(self) -> np.ndarray:
        obs = self._obs.copy()
        obs[0:12] = self.cell.data.qpos
        obs[12] = self.p1 / self.n1
        obs[13] = self.p2 / self.n2
        obs[14] = self.steps * DT
        obs[15:40] = self.distances.ravel()  # within [-1, 5] m by the cell's size
        return obs

    def render(self, width: int = 640, height: int = 480) -> np.ndarray:
        if self._renderer is None:
            self._renderer = mujoco.Renderer(self.cell.model, height, width)
        mujoco.mj_kinematics(self.cell.model, self.cell.data)
        mujoco.mj_camlight(self.cell.model, self.cell.data)  # cameras and lights
        self._renderer.update_scene(self.cell.data, camera="overview")
        return self._renderer.render().copy()

    def __getstate__(self) -> dict[str, Any]:
        state = super().__getstate__()
        state["_qpos"] = None
        state["cell"] = None
        return state

    def __setstate__(self, state: dict[str, Any]) -> None:
        self.__dict__.update(state)
        self._attach(model.MujocoCell())
        if self.tasks is not None:
            self._update()
