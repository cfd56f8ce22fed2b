"""The paper's sweeping algorithm as a scripted policy: PSA + point-to-point + CWA (Fig. 2).

Flow (paper Fig. 2): sweep with PSA (:mod:`.psa`), moving between runs with
the quadtree point-to-point transfer (:mod:`.quadtree`) until the stack is
empty; then sweep the leftovers along walls and obstacles with CWA
(:mod:`.cwa`). The policy acts from the observation alone: it writes each
``sensed``/``swept`` window into its own maps (:mod:`.belief`) at the
believed ``pose`` and plans on those maps, treating unknown cells as free
until sensed. Under odometry noise a bump marks the cells ahead as obstacle
and the current plan is dropped; the felt cells stay obstacles (whatever the
drifted window says) until the robot has moved on.

Under odometry noise (the robot's spec, ``heading_noise`` / ``slip_noise``
of its keywords) the believed pose is the localiser's (:mod:`.localise`,
Monte Carlo localisation on the policy's own map) instead of the dead-
reckoned ``pose``, the map is kept by occupancy votes
(:class:`.belief.RobotMap` ``evidence``), and "done" is declared only when
the map holds no reachable floor unswept or unknown: a bump is not taken as
proof of a wall at that point (the felt marks are dropped and the map looked
at again), and a scan that finds the same leftovers as the last one sends
the robot to the nearest of them, up to :data:`MAX_STALLS` times in a row.
A bump where the map holds the footprint ahead free (the continuous pose,
drifted by the heading error, rounds into the wall beside the path) sends
the robot one cell sideways, against the estimated drift, and its bump
marks become unknown, not walls, once it has moved on. Three mechanisms act
under noise, each with its ablation here: a map per particle
(:mod:`.fastslam`, grid FastSLAM; :class:`PsaCwaOneMapPolicy` files every
window into one map at the estimate), steering by the estimated heading
error (:mod:`.drift`, :mod:`.steer`; ``steering``) and heading-error
diffusion of the particles on forward moves (``diffuse``); measured in
``docs/experiments/Sweeper-v1.md`` (fourth pass) and
``tests/baselines/test_sweeper_localise.py``.
:class:`PsaCwaDeadReckoningPolicy` is the ablation that trusts the
dead-reckoned pose; :class:`PsaCwaBfsTransferPolicy` the one that moves
between runs along the shortest path over all known free configurations
instead of the quadtree's chain of squares; :class:`PsaNoCornerWorkPolicy`
the one without CWA (``tests/baselines/test_sweeper_corner_work.py``).
``diagnostics()["done"]`` says when the policy has declared itself done.
"""

from __future__ import annotations

from collections import deque
from dataclasses import dataclass, field
from typing import Any

import numpy as np
from gymnasium import spaces

from motiongym.baselines.policy import ScriptedPolicy
from motiongym.baselines.sweeper import cwa, psa, quadtree
from motiongym.baselines.sweeper.belief import FREE, OBSTACLE, RobotMap
from motiongym.baselines.sweeper.drift import DriftActing
from motiongym.baselines.sweeper.fastslam import ParticleMaps
from motiongym.baselines.sweeper.localise import Localiser
from motiongym.baselines.sweeper.steer import DIRECTION, turn_towards
from motiongym.envs.sweeper import occupancy
from motiongym.envs.sweeper.occupancy import DC, DR
from motiongym.envs.sweeper.params import SweeperParams
from motiongym.envs.sweeper.world import FORWARD, LEFT

EVIDENCE = 4  # votes a map cell holds at most when localising (belief.RobotMap)
MAX_STALLS = 20  # scans without progress a localising policy makes before it declares done
MAX_ROUNDS = 50  # mode changes per step, then move on (docs/experiments/Sweeper-v1.md)
PARTICLE_VOTES = EVIDENCE  # per particle's map (fastslam.py; other values: the same file)


def robot_geometry(observation_space: spaces.Space, env_kwargs: dict[str, Any]) -> tuple[int, int]:
    """``(w, R)``: the robot width (from the env's keywords) and sensing range (window size)."""
    w = SweeperParams.from_kwargs(env_kwargs).robot_width
    sensed = observation_space["sensed"] if isinstance(observation_space, spaces.Dict) else None
    if not isinstance(sensed, spaces.Box):
        raise ValueError(f"observation_space must be the sweeper's, got {observation_space}")
    s = int(round(np.sqrt(sensed.shape[0])))
    return w, (s - w) // 2


@dataclass
class Memory:
    """One episode's state of the sweeping algorithm."""

    map: RobotMap
    loc: Localiser | None = None  # pose correction under odometry error (None: trust the pose)
    mode: str = "lane"  # lane | shift | pop | transfer | cwa_scan | cwa_pop | cwa_follow | done
    path: deque = field(default_factory=deque)  # configurations still to visit
    goal: tuple[int, int] | None = None
    run_heading: int | None = None
    run_side: int | None = None
    lane_start: tuple[int, int] | None = None
    lane_length: int = 0  # configurations along the lane last ended
    first_lane: bool = True  # no shift yet in this run (its side may still flip)
    run: int = 0  # number of the current PSA run (stack entries carry the run that pushed them)
    retry: bool = False  # a transfer was aborted: take the stack's top entry next
    stack: psa.PsaStack = field(default_factory=psa.PsaStack)
    cwa_stack: list = field(default_factory=list)
    cwa_cells: np.ndarray | None = None
    cwa_last: tuple[int, int] | None = None  # (swept cells, leftovers) at the last scan
    steps: int = 0  # observations acted on
    stalled_at: int = -1  # the step of the last stall
    stalls: int = 0  # scans in a row that found the same leftovers (each sends it to the nearest)
    started: bool = False
    last_pose: tuple[int, int] | None = None
    heading: int = 0  # the commanded heading of the last observation
    blocked: set = field(default_factory=set)  # commanded headings that bumped from this cell
    log: list = field(default_factory=list)  # (mode, pose) at each decision, for figures


class PsaCwaPolicy(DriftActing, ScriptedPolicy):
    """PSA with a LIFO stack, quadtree transfers, then CWA (paper section 3)."""

    pop_order = "lifo"  # "lifo": LIFO by runs; "stack": the top entry; "nearest": any entry
    restart_wide = True  # a wide leftover restarts PSA instead of corner work
    slide_back = False  # shift further back along the lane when blocked at its end
    repush = True  # a popped segment goes back under the run it starts
    cwa_order = "scan"  # "scan": the paper's scan-order stack; "nearest": nearest group first
    restart_axis = True  # a popped run may turn its lanes across (psa.restart_heading)
    push_behind = True  # push the segment in line behind a lane that starts after a shift
    transfer = "quadtree"  # "quadtree": the chain of free squares plans it; "bfs": the ablation
    corner_work = True  # False: the ablation that stops where CWA would start (wide restarts kept)

    localise = True  # correct the pose by scan matching when the odometry is noisy
    max_stalls = 0  # scans without progress before done (localising: MAX_STALLS)
    evidence = EVIDENCE  # map votes when localising (0: the latest window wins)
    sidestep = True  # localising: step aside after a bump the map does not explain
    steering = True  # localising: steer by the estimated heading error (drift.py)
    particle_maps = True  # localising: a map per particle (fastslam.py); False: one map
    map_votes = PARTICLE_VOTES  # with particle_maps: votes a cell holds at most
    diffuse = True  # localising: heading-error diffusion on moves (localise.py)
    skip_ahead = True  # a move onto a later cell of the plan skips to it, not replans

    def __init__(self, observation_space, action_space, env_kwargs=None) -> None:
        super().__init__(observation_space, action_space, env_kwargs)
        self.w, self.R = robot_geometry(observation_space, self.env_kwargs)
        self.params = SweeperParams.from_kwargs(self.env_kwargs)
        if self.localise and self.params.noisy:
            self.max_stalls = MAX_STALLS

    def new_memory(self) -> Memory:
        p = self.params
        if not (self.localise and p.noisy):
            return Memory(RobotMap(self.w, self.R))
        spec = (self.w, self.R, p.heading_noise, p.slip_noise)
        diffusion = p.heading_noise if self.diffuse else 0.0
        loc: Localiser
        if self.particle_maps:
            votes = self.map_votes if self.evidence else 1  # 1: the latest window wins
            loc = ParticleMaps(*spec, diffusion=diffusion, evidence=votes)
        else:
            loc = Localiser(*spec, diffusion=diffusion)
        return Memory(RobotMap(self.w, self.R, self.evidence), loc)

    def describe(self, memory: Memory) -> dict[str, Any]:
        """``mode`` (the algorithm's step), ``done`` (True once it has declared the
        area swept: its map holds no reachable floor unswept or unknown), ``pose``
        (the cell it believes its footprint at), ``spread`` (the localiser's
        position spread in cells, 0.0 without one) and ``log`` (its transfers,
        restarts and corner moves so far: ``(kind, from cell, to cell)``)."""
        m = memory
        return {
            "mode": m.mode,
            "done": m.mode == "done",
            "pose": m.last_pose,
            "spread": m.loc.spread if m.loc is not None else 0.0,
            "log": list(m.log),
        }

    # ----------------------------------------------------------------- acting
    def act(self, observation: Any, memory: Memory) -> int:
        m = memory
        m.steps += 1
        if m.loc is not None:
            r, c, h, bump = m.loc.observe(m.map, observation)
        else:
            r, c, h, bump = m.map.integrate(observation)
        if not m.started:
            m.started = True
            m.run_heading, m.run_side = h, psa.right_of(h)
            m.lane_start = (r, c)
        self._bumped(m, r, c, h, bump)
        for _ in range(MAX_ROUNDS):
            a = self._follow(m, r, c, h)
            if a is not None:
                return a
            a = getattr(self, "_" + m.mode)(m, r, c, h)
            if a is not None:
                return a
        # Not settled: every way on bumped from here and the map replans the same. Move on
        # in a heading that has not bumped here, else turn; bumps in all four headings were
        # felt at other true positions (slips the estimate missed) and are forgotten.
        m.path.clear()
        if len(m.blocked) == 4:
            m.blocked.clear()
        return FORWARD if h not in m.blocked else LEFT

    def _follow(self, m: Memory, r: int, c: int, h: int) -> int | None:
        """Execute the planned path of configurations (turn towards, then forward)."""
        if self.skip_ahead and (r, c) in list(m.path)[1:3]:  # a diagonal move skipped one
            while m.path[0] != (r, c):
                m.path.popleft()
        while m.path and m.path[0] == (r, c):
            m.path.popleft()
        if not m.path:
            return None
        nr, nc = m.path[0]
        occ, _ = m.map.footprint(nr, nc)
        if abs(nr - r) + abs(nc - c) != 1 or (occ == OBSTACLE).any():
            m.path.clear()  # blocked or off the path: the mode replans
            return None
        if m.loc is not None and self.steering:
            a = self._steered(m, r, c, list(m.path))
            if a is None:  # every way towards it bumped here: the mode replans
                m.path.clear()
            return a
        d = DIRECTION[(nr - r, nc - c)]
        return FORWARD if d == h else turn_towards(h, d)

    def _known(self, m: Memory, r: int, c: int):
        """Known-map arrays on the explored box: origin, occupancy, swept, free configs, start."""
        r0, c0, occ, swept = m.map.window()
        cfree = occupancy.config_free(occ == OBSTACLE, self.w)
        cur = (r - r0, c - c0)
        cfree[cur] = True  # the robot stands there, whatever the map says
        return (r0, c0), occ, swept, cfree, cur

    def _plan(self, occ, swept, cfree, cur, goal) -> list[tuple[int, int]] | None:
        """Quadtree transfer (:mod:`.quadtree`) sweeping the most unswept cells on its way
        (``transfer == "bfs"``: the shortest path over all known free configurations)."""
        gains = psa.entering_gains((~swept) & (occ != OBSTACLE), self.w)
        planner = quadtree.bfs_plan if self.transfer == "bfs" else quadtree.plan
        return planner(cfree, cur, goal, gains)

    # -------------------------------------------------------------- PSA modes
    def _lane(self, m: Memory, r: int, c: int, h: int) -> int | None:
        assert m.run_heading is not None and m.run_side is not None, "set before a lane"
        steering = m.loc is not None and self.steering
        if steering:  # the lane's heading in the map; steer picks the command
            h = m.run_heading
        elif h != m.run_heading:
            return turn_towards(h, m.run_heading)
        nr, nc = r + int(DR[h]), c + int(DC[h])
        occ, sw = m.map.footprint(nr, nc)
        edge = occupancy.entering_mask(int(DR[h]), int(DC[h]), self.w)
        if psa.lane_open(occ, sw[edge]):
            if not steering:
                return FORWARD  # step 1: straight on, sweeping
            a = self._steered(m, r, c, [(nr, nc)])
            if a is not None:
                return a  # else the lane ends here: every way on bumped
        assert m.lane_start is not None, "set before a lane"
        for seg in psa.side_segments(m.lane_start, (r, c), h, self.w):  # steps 2-3
            if self._strip_unswept(m, seg):
                m.stack.push(seg, m.run)
        m.lane_length = abs(r - m.lane_start[0]) + abs(c - m.lane_start[1]) + 1
        # step 4: shift one width to the run's side, at the blocking point or,
        # where the side is blocked there, at the nearest point back along the lane;
        # a run's first shift may take the other side when the run's side is closed
        back = (h + 2) % 4
        sides = (m.run_side, (m.run_side + 2) % 4) if m.first_lane else (m.run_side,)
        for s in sides:
            plan = self._plan_shift(m, r, c, h, s)
            if plan is not None:
                break
        if plan is None:
            m.mode = "pop"
            return None
        j, base, k = plan
        path = [(r + i * int(DR[back]), c + i * int(DC[back])) for i in range(1, j + 1)]
        path += [(base[0] + i * int(DR[s]), base[1] + i * int(DC[s])) for i in range(1, k + 1)]
        m.path = deque(path)
        m.goal, m.run_heading, m.run_side, m.mode = path[-1], back, s, "shift"
        m.first_lane = False
        return None

    def _plan_shift(
        self, m: Memory, r: int, c: int, h: int, s: int
    ) -> tuple[int, tuple[int, int], int] | None:
        """Step 4 towards side ``s``: ``(j, base, k)``, a shift of ``k`` cells from ``j``
        cells back along the lane, or None when no shift leads to a lane with work."""
        back = (h + 2) % 4
        assert m.lane_start is not None, "set before a lane"
        lane_len = abs(r - m.lane_start[0]) + abs(c - m.lane_start[1])
        plan = None
        for j in range(0, lane_len + 1 if self.slide_back else 1):  # pragma: no branch
            base = (r + j * int(DR[back]), c + j * int(DC[back]))
            k = self._shift_length(m, base, s)
            target = (base[0] + k * int(DR[s]), base[1] + k * int(DC[s]))
            if k == 0 or not self._lane_has_work(m, target, back):
                continue
            if k == self.w or j == 0:
                plan = (j, base, k)
            if k == self.w:
                break
        return plan

    def _shift_length(self, m: Memory, base: tuple[int, int], side: int) -> int:
        """How many cells (up to ``w``) the robot can shift sideways from ``base``."""
        k = 0
        while k < self.w:
            occ, _ = m.map.footprint(
                base[0] + (k + 1) * int(DR[side]), base[1] + (k + 1) * int(DC[side])
            )
            if (occ == OBSTACLE).any():
                break
            k += 1
        return k

    def _strip_unswept(self, m: Memory, seg: psa.Segment) -> bool:
        rr, cc = psa.segment_configs(seg)
        o, w = m.map.off, self.w
        r0, r1 = int(rr.min()) + o, int(rr.max()) + o + w
        c0, c1 = int(cc.min()) + o, int(cc.max()) + o + w
        if r0 < 0 or c0 < 0:
            return False
        occ, swept = m.map.occ[r0:r1, c0:c1], m.map.swept[r0:r1, c0:c1]
        return bool(((~swept) & (occ != OBSTACLE)).any())

    def _lane_has_work(self, m: Memory, cfg: tuple[int, int], heading: int) -> bool:
        occ, sw = m.map.footprint(*cfg)
        if ((~sw) & (occ != OBSTACLE)).any():
            return True
        nocc, nsw = m.map.footprint(cfg[0] + int(DR[heading]), cfg[1] + int(DC[heading]))
        edge = occupancy.entering_mask(int(DR[heading]), int(DC[heading]), self.w)
        return psa.lane_open(nocc, nsw[edge])

    def _shift(self, m: Memory, r: int, c: int, h: int) -> int | None:
        if self.push_behind:
            self._push_behind(m, r, c)
        m.mode, m.lane_start = "lane", (r, c)
        return None

    def _push_behind(self, m: Memory, r: int, c: int) -> None:
        """Push the segment in line behind a lane about to start at ``(r, c)``.

        It runs back from the lane's start, as long as the lane last ended,
        over configurations known to be free, and is pushed when it holds
        unswept cells (steps 2-3 for the cells no side segment covers).
        """
        assert m.run_heading is not None and m.run_side is not None, "set with the run"
        seg = psa.behind_segment((r, c), m.run_heading, m.lane_length, m.run_side)
        rr, cc = psa.segment_configs(seg)
        known = 0
        for cr, cc_ in zip(rr.tolist(), cc.tolist(), strict=True):
            occ, _ = m.map.footprint(cr, cc_)
            if (occ != FREE).any():
                break
            known += 1
        if known:
            seg = psa.Segment(seg.start, seg.heading, known, seg.side)
            if self._strip_unswept(m, seg):
                m.stack.push(seg, m.run)

    def _pop(self, m: Memory, r: int, c: int, h: int) -> int | None:
        """Take the next stack entry that still holds work and transfer there.

        LIFO by runs: the candidates are the entries the latest run on the
        stack pushed, and of those the one whose restart point is nearest
        (:mod:`.psa`'s docstring); a group with no work left is dropped (the
        paper's skip). After an aborted transfer (its goal found blocked, as
        under odometry error) only the top entry, the one re-pushed, is a
        candidate: choosing the nearest again could swing between two
        entries for ever. The ``nearest`` ablation considers every entry.
        """
        origin, occ, swept, cfree, cur = self._known(m, r, c)
        dist = occupancy.bfs_distance(cfree, cur)
        todo = psa.covers_unswept(occ, swept, self.w)

        def restart(seg: psa.Segment) -> tuple[tuple[int, int], int] | None:
            for j in range(self.w):  # one width away, else closer to the lane
                found = psa.first_target(psa.toward_lane(seg, j), origin, dist >= 0, todo, dist)
                if found is not None:
                    return found
            return None

        retry, m.retry = m.retry, False
        group: list[int] | range
        while len(m.stack):
            if retry:  # the entry of an aborted transfer, re-pushed on top
                group, retry = [len(m.stack) - 1], False
            elif self.pop_order == "nearest":
                group = range(len(m.stack))
            elif self.pop_order == "stack":  # the plain stack: its top entry only
                group = [len(m.stack) - 1]
            else:
                group = m.stack.top_run()
            found = {k: t for k in group if (t := restart(m.stack.items[k])) is not None}
            if not found:
                for k in reversed(group):
                    m.stack.pop(k)
                continue
            k = min(
                found,
                key=lambda k: (dist[found[k][0][0] - origin[0], found[k][0][1] - origin[1]], -k),
            )
            seg, run = m.stack.pop(k)
            target, heading = found[k]
            goal = (target[0] - origin[0], target[1] - origin[1])
            path = self._plan(occ, swept, cfree, cur, goal)
            if path is None:  # pragma: no cover - BFS reached it, the quadtree must too
                continue
            if self.repush:
                m.stack.push(seg, run)  # what the new run leaves of it is found on a later pop
            m.run += 1
            m.path = deque((p[0] + origin[0], p[1] + origin[1]) for p in path)
            m.goal, m.run_heading, m.run_side = target, heading, seg.side
            m.mode = "transfer"
            m.log.append(("transfer", (r, c), target))
            return None
        m.mode = "cwa_scan"
        return None

    def _transfer(self, m: Memory, r: int, c: int, h: int) -> int | None:
        assert m.goal is not None, "set with the transfer"
        if (r, c) != m.goal:  # the path was blocked: plan again
            origin, occ, swept, cfree, cur = self._known(m, r, c)
            goal = (m.goal[0] - origin[0], m.goal[1] - origin[1])
            ok = 0 <= goal[0] < cfree.shape[0] and 0 <= goal[1] < cfree.shape[1]
            path = self._plan(occ, swept, cfree, cur, goal) if ok and cfree[goal] else None
            if path is None:  # the goal turned out blocked: its entry is retried first
                m.mode, m.retry = "pop", True
                return None
            m.path = deque((p[0] + origin[0], p[1] + origin[1]) for p in path)
            return None
        if self.restart_axis:
            assert m.run_heading is not None and m.run_side is not None, "set with the transfer"
            m.run_heading, m.run_side = psa.restart_heading(
                self._stretches(m, r, c), m.run_heading, m.run_side, self.w
            )
        m.mode, m.lane_start, m.first_lane = "lane", (r, c), True
        return None

    def _stretches(self, m: Memory, r: int, c: int) -> tuple[int, ...]:  # 4 values
        """Per heading: known-map configurations covering unswept cells in a row from ``(r, c)``."""
        _, occ, swept, cfree, cur = self._known(m, r, c)
        return psa.stretches(psa.covers_unswept(occ, swept, self.w) & cfree, cur)

    # -------------------------------------------------------------- CWA modes
    def _cwa_scan(self, m: Memory, r: int, c: int, h: int) -> int | None:
        origin, occ, swept, cfree, cur = self._known(m, r, c)
        reach = occupancy.reachable_configs(cfree, cur)
        targets = cwa.leftovers(occ, swept, reach, self.w)
        if self.max_stalls and not targets.any() and m.map.felt.any():  # a bump: look again
            m.map.forget_felt(unmark=True)
            return None
        state = (int(m.map.swept.sum()), int(targets.sum()))
        if state == m.cwa_last and targets.any() and m.stalls < self.max_stalls:
            if m.stalled_at == m.steps:  # stalled twice without acting: step off the spot
                occ_ahead, _ = m.map.footprint(r + int(DR[h]), c + int(DC[h]))
                return LEFT if (occ_ahead == OBSTACLE).any() else FORWARD
            m.stalls, m.stalled_at = m.stalls + 1, m.steps  # head for the nearest leftover
            m.cwa_cells = np.argwhere(targets) + np.array(origin)
            m.mode = "cwa_follow"
            return None
        if not targets.any() or state == m.cwa_last:
            m.mode = "done"
            return None
        m.cwa_last, m.stalls = state, 0
        wide = (occupancy.box_sum(targets.astype(np.int64), self.w) == self.w * self.w) & reach
        if self.restart_wide and wide.any():  # a region PSA missed, not a corner: restart PSA there
            self._restart_psa(m, r, c, origin, occ, swept, cfree, cur, wide, targets)
            return None
        if not self.corner_work:
            m.mode = "done"
            return None
        m.cwa_stack = [
            ((s[0] + origin[0], s[1] + origin[1]), cells + np.array(origin))
            for s, cells in cwa.scan_groups(targets, occ == OBSTACLE, self.w)
        ]
        m.mode = "cwa_pop"
        return None

    def _restart_psa(self, m: Memory, r, c, origin, occ, swept, cfree, cur, wide, targets) -> None:
        """Transfer to the nearest wide leftover and sweep it with a new PSA run.

        The run heads along the longest stretch of leftover configurations
        and shifts to the perpendicular with the longer one; on arrival
        :func:`.psa.restart_heading` may turn the lanes to the other axis.
        """
        dist = occupancy.bfs_distance(cfree, cur)
        d = np.where(wide & (dist >= 0), dist, np.iinfo(np.int64).max)
        target = divmod(int(np.argmin(d)), d.shape[1])
        todo = psa.covers_unswept(np.where(targets, 0, 1), targets, self.w) & cfree
        stretch = psa.stretches(todo, target)
        heading = max(range(4), key=lambda k: stretch[k])
        side = max((psa.left_of(heading), psa.right_of(heading)), key=lambda k: stretch[k])
        path = self._plan(occ, swept, cfree, cur, target)
        assert path is not None, "the target is reachable (it lies in cfree's region)"
        m.path = deque((p[0] + origin[0], p[1] + origin[1]) for p in path)
        m.goal = (target[0] + origin[0], target[1] + origin[1])
        m.run_heading, m.run_side, m.mode = heading, side, "transfer"
        m.run += 1
        m.log.append(("restart", (r, c), m.goal))

    def _remaining(self, m: Memory, cells: np.ndarray) -> np.ndarray:
        o = m.map.off
        occ = m.map.occ[cells[:, 0] + o, cells[:, 1] + o]
        swept = m.map.swept[cells[:, 0] + o, cells[:, 1] + o]
        return cells[(~swept) & (occ != OBSTACLE)]

    def _cwa_pop(self, m: Memory, r: int, c: int, h: int) -> int | None:
        if self.cwa_order == "nearest" and len(m.cwa_stack) > 1:
            origin, _, _, cfree, cur = self._known(m, r, c)
            dist = occupancy.bfs_distance(cfree, cur)
            best, best_k = None, len(m.cwa_stack) - 1
            for k, (_, cells) in enumerate(m.cwa_stack):
                cells = self._remaining(m, cells)
                t = (
                    cwa.nearest_cover(dist, cells - np.array(origin), self.w)
                    if len(cells)
                    else None
                )
                if t is not None and (best is None or dist[t] < best):
                    best, best_k = dist[t], k
            m.cwa_stack.append(m.cwa_stack.pop(best_k))
        while m.cwa_stack:
            seed, cells = m.cwa_stack.pop()
            cells = self._remaining(m, cells)
            if not len(cells):
                continue
            origin, occ, swept, cfree, cur = self._known(m, r, c)
            dist = occupancy.bfs_distance(cfree, cur)
            first = self._remaining(m, np.array([seed]))
            aim = first if len(first) else cells
            target = cwa.nearest_cover(dist, aim - np.array(origin), self.w)
            if target is None:
                continue
            path = self._plan(occ, swept, cfree, cur, target)
            if path is None:  # pragma: no cover - BFS found it, the quadtree must too
                continue
            m.path = deque((p[0] + origin[0], p[1] + origin[1]) for p in path)
            m.cwa_cells, m.mode = cells, "cwa_follow"
            m.log.append(("cwa", (r, c), (target[0] + origin[0], target[1] + origin[1])))
            return None
        m.mode = "cwa_scan"
        return None

    def _cwa_follow(self, m: Memory, r: int, c: int, h: int) -> int | None:
        assert m.cwa_cells is not None, "set before following"
        cells = self._remaining(m, m.cwa_cells)
        m.cwa_cells = cells
        if not len(cells):
            m.mode = "cwa_pop"
            return None
        origin, _, _, cfree, cur = self._known(m, r, c)
        dist = occupancy.bfs_distance(cfree, cur)
        target = cwa.nearest_cover(dist, cells - np.array(origin), self.w)
        if target is None:
            m.mode = "cwa_pop"
            return None
        m.path = deque(
            (p[0] + origin[0], p[1] + origin[1]) for p in occupancy.descend(dist, target)
        )
        if not m.path:  # standing on it, yet cells remain: they are not coverable from here
            m.mode = "cwa_pop"
        return None

    def _done(self, m: Memory, r: int, c: int, h: int) -> int:
        return LEFT  # nothing left that the robot knows of: turn in place


class PsaCwaNearestPolicy(PsaCwaPolicy):
    """PSA + CWA taking the nearest pending point first instead of the stacks' order.

    Not the paper's algorithm (it pops a LIFO stack and scans CWA top-right to
    bottom-left): an ablation that shows what the order costs in travel.
    """

    pop_order = "nearest"
    cwa_order = "nearest"


class PsaCwaDeadReckoningPolicy(PsaCwaPolicy):
    """PSA + CWA trusting the dead-reckoned pose under odometry error: the ablation
    of the localiser (:mod:`.localise`), as the policy was before it."""

    localise = False


class PsaCwaOneMapPolicy(PsaCwaPolicy):
    """PSA + CWA localised on one map filed at the estimate (Monte Carlo localisation,
    :mod:`.localise`): the ablation of the map per particle (:mod:`.fastslam`)."""

    particle_maps = False


class PsaCwaBfsTransferPolicy(PsaCwaPolicy):
    """PSA + CWA with transfers along the shortest path over all known free
    configurations: the ablation of the quadtree's route (:func:`.quadtree.bfs_plan`)."""

    transfer = "bfs"


class PsaNoCornerWorkPolicy(PsaCwaPolicy):
    """PSA (with its restarts on wide leftovers) and no corner work: the ablation of CWA."""

    corner_work = False
