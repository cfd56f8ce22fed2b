"""The exact minimum pure delay on the environment's check, found by boundary following.

Boundary following (paper section III, :mod:`.boundary_following`) searches a
collision map; its answer is exact only for that map. Here the map's cells are
verdicts of ``DualArmCell-v1``'s own step check (:mod:`.step_check`), on the
paper's axes (robot 1's samples, robot 2's travelled length, ``N_l`` levels):

1. If the arms collide at rest, at their start or at their end configurations,
   no delay can help: reported as such (``delay=None``), never as a delay.
2. Boundary following on the *lower* map
   (:meth:`.CollisionMap.from_steps`, ``bound="lower"``: a cell is blocked
   only when a configuration that every step through it passes collides)
   gives ``d_lo``. Every delay free on the environment's check is free on
   that map (proof in ``from_steps``), so the true minimum ``D*`` is at
   least the map's minimum, which boundary following finds (it equals the
   exhaustive minimum of its map; :mod:`.boundary_following`).
3. The pure delays ``d_lo, d_lo + 1, ...`` are checked exactly on the
   environment's check (:meth:`.StepCheck.delay_collides`); the first free
   one is ``D*``. Delays ``>= N1`` all meet the same steps (robot 2 moves
   against robot 1's end configuration), so the scan ends at ``N1``: none
   free means no pure delay avoids collision.

Where boundary following fails on the lower map the scan starts at 0. The
answer is never a colliding delay (step 3 checks it on the environment's own
check) and equals ``D*`` whenever boundary following returns its map's
minimum; the upper map (``bound="upper"``: a delay free there is free on the
environment's check) is the ablation without step 3.
"""

from __future__ import annotations

import functools
import itertools
from dataclasses import dataclass

import numpy as np

from motiongym.baselines.dual_arm.boundary_following import BoundaryResult, boundary_following
from motiongym.baselines.dual_arm.collision_map import CollisionMap
from motiongym.baselines.dual_arm.step_check import StepCheck
from motiongym.envs.dual_arm.task import Trajectory


@dataclass
class DelayPlan:
    """Outcome of :func:`exact_delay_search`.

    Attributes:
        delay: robot 2's start delay in samples (None: no pure delay exists).
        lower: ``d_lo``, boundary following's delay on the lower map (None if it failed).
        checked: pure delays checked on the environment's check.
        evaluated: lower-map cells evaluated by boundary following.
        halvings: step verdicts that needed halving.
        reason: why there is no delay ("" when there is one).
        search: boundary following's own result on the lower map.
    """

    delay: int | None
    lower: int | None = None
    checked: int = 0
    evaluated: int = 0
    halvings: int = 0
    reason: str = ""
    search: BoundaryResult | None = None


def exact_delay_search(
    traj1: Trajectory, traj2: Trajectory, n_levels: int = 100, margin: float = 0.0
) -> DelayPlan:
    """The minimum collision-free pure delay of robot 2 (steps 1-3 above)."""
    if isinstance(n_levels, bool) or not isinstance(n_levels, int | np.integer) or n_levels < 1:
        raise ValueError(f"n_levels must be an integer >= 1, got {n_levels!r}")
    if not np.isfinite(margin) or margin < 0:
        raise ValueError(f"margin must be a finite number >= 0 m, got {margin!r}")
    check = StepCheck(traj1, traj2, margin)
    at_rest = check.at_rest_collides()
    if at_rest:
        return DelayPlan(None, reason=f"the arms collide at rest ({at_rest} configurations)")
    cmap = CollisionMap.from_steps(check, traj2, n_levels, "lower")
    search = boundary_following(cmap)
    plan = DelayPlan(None, search.delay, evaluated=search.evaluated, search=search)
    for delay in range(min(search.delay or 0, check.n1), check.n1 + 1):
        plan.checked += 1
        if not check.delay_collides(delay):
            plan.delay = delay
            break
    else:
        plan.reason = "no pure delay avoids collision"
    plan.halvings = check.halvings
    return plan


def plan_paper_case() -> DelayPlan:
    """:func:`exact_delay_search` on the paper case (a benchmark hook)."""
    from motiongym.envs.dual_arm.task import paper_case

    return exact_delay_search(*paper_case())


BENCH_SEEDS = tuple(range(20_000, 20_010))  # the pairs timed by ``motiongym bench``
_bench_turn = itertools.count()


@functools.cache
def bench_pairs() -> tuple[tuple[Trajectory, Trajectory], ...]:
    """The sampled colliding pairs of ``BENCH_SEEDS``, sampled once on the first call
    (sampling is not planning; the first call's time is the median's outlier)."""
    from motiongym.envs.dual_arm.task import sample_pair

    return tuple(sample_pair(np.random.default_rng(seed), "colliding") for seed in BENCH_SEEDS)


def plan_sampled_pair() -> DelayPlan:
    """:func:`exact_delay_search` on the next of ``BENCH_SEEDS``' pairs, in turn (a
    benchmark hook: the median over calls is a per-pair planning time)."""
    return exact_delay_search(*bench_pairs()[next(_bench_turn) % len(BENCH_SEEDS)])
