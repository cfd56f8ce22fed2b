"""The held-out study of boundary following on DualArmCell-v1 (a script, not a test).

For each seed: ``reset(seed=s)`` of ``motiongym/DualArmCell-v1`` samples the pair; then

* the v1 policy (``boundary-following``, told the environment's keywords) runs the
  episode; its delay, outcome, and the least clearance of the motion it ran by the
  independent continuous-time check (:mod:`dual_arm_truth`);
* the environment's brute force: every pure delay below the policy's on the
  environment's own step rule (``StepCheck`` on the environment's float64 trajectories:
  the world's rule, :func:`motiongym.envs.dual_arm.collision.step_collides`), and the
  delay one below run in the environment itself;
* on v0's own pair of the seed (``DualArmCell-v0``'s reset): v0's minimum pure delay
  (clear at every sample, v0's check), whether v1's check rejects it (a collision
  between samples), and its independent continuous-time clearance.

    MUJOCO_GL=egl nice -n 10 .venv/bin/python tests/dual_arm_heldout.py 700000 702000 out.jsonl

prints one JSON row per seed to ``out.jsonl`` and a summary at the end.
"""

from __future__ import annotations

import json
import sys
import time
from pathlib import Path
from typing import Any

import gymnasium as gym
import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))

import dual_arm_truth as truth  # noqa: E402
from dual_arm_runs import run_pure_delay  # noqa: E402

import motiongym  # noqa: E402, F401
from motiongym.baselines import make_policy  # noqa: E402
from motiongym.baselines.dual_arm.step_check import StepCheck  # noqa: E402

V1, V0 = "motiongym/DualArmCell-v1", "motiongym/DualArmCell-v0"


def _run(env: gym.Env, act) -> tuple[dict, np.ndarray, np.ndarray]:
    world = env.unwrapped.world
    joints, t, done, obs = [world.q], 0, False, env.unwrapped.task.observe(world)
    while not done:
        obs, _, terminated, truncated, info = env.step(act(obs, t))
        joints.append(world.q)
        t, done = t + 1, terminated or truncated
    q1, q2 = (np.array([q[r] for q in joints]) for r in (0, 1))
    return info, q1, q2


def study_pair(env: gym.Env, policy, seed: int, v0_env: gym.Env) -> dict[str, Any]:
    start = time.process_time()
    env.reset(seed=seed)
    policy.reset()
    info, q1, q2 = _run(env, lambda obs, t: policy.predict(obs)[0])
    diag = policy.diagnostics()
    delay = diag["delay"]
    row: dict[str, Any] = {
        "seed": seed,
        "delay": delay,
        "success": bool(info["is_success"]),
        "collision": bool(info["collision"]),
        "fallback": diag["fallback"],
        "replans": diag["replans"],
        "clearance_mm": round(truth.motion_clearance(q1, q2) * 1e3, 4),
    }
    t1, t2 = env.unwrapped.world.tasks
    check = StepCheck(t1, t2, 0.0)
    limit = check.n1 if delay is None else delay
    free = [d for d in range(limit + 1) if not check.delay_collides(d)]
    row["env_min"] = free[0] if free else None
    if delay:
        row["env_runs_one_below"] = run_pure_delay(env, seed, delay - 1)
    # v0 on its own pair (DualArmCell-v0's reset of the same seed): its minimum pure
    # delay, clear at every sample (no step end within the margin), on v1's check and in
    # continuous time (the pure delay's own samples, linear between them).
    v0_env.reset(seed=seed)
    u1, u2 = v0_env.unwrapped.world.tasks
    v0_check = StepCheck(u1, u2, 0.0)
    v0 = next(
        d for d in range(v0_check.n1 + 1) if not v0_check.certainly(*v0_check.delay_steps(d)).any()
    )
    row["v0_min"] = v0
    row["v0_collides_on_v1"] = v0_check.delay_collides(v0)
    if row["v0_collides_on_v1"]:
        x = np.arange(max(u1.n_samples, v0 + u2.n_samples) + 1)
        b1 = u1.samples()[np.minimum(x, u1.n_samples)]
        b2 = u2.samples()[np.clip(x - v0, 0, u2.n_samples)]
        row["v0_clearance_mm"] = round(truth.motion_clearance(b1, b2) * 1e3, 4)
    row["cpu_s"] = round(time.process_time() - start, 3)
    return row


def summarise(rows: list[dict[str, Any]]) -> dict[str, Any]:
    n = len(rows)
    solved = [r for r in rows if r["env_min"] is not None]
    equal = sum(r["delay"] == r["env_min"] for r in solved)
    early = [r["seed"] for r in solved if r["delay"] is not None and r["delay"] < r["env_min"]]
    late = [r["seed"] for r in solved if r["delay"] is None or r["delay"] > r["env_min"]]
    v0_bad = [r for r in rows if r["v0_collides_on_v1"]]
    v0_phys = [r for r in v0_bad if r["v0_clearance_mm"] <= 0.0]
    return {
        "pairs": n,
        "with_a_delay_on_v1": len(solved),
        "equal": equal,
        "early": early,
        "late": late,
        "policy_collisions": [r["seed"] for r in rows if r["collision"]],
        "policy_failures": [r["seed"] for r in rows if not r["success"]],
        "replanned": sum(r["replans"] > 0 for r in rows),
        "fallbacks": sum(bool(r["fallback"]) for r in rows),
        "least_clearance_mm": min(r["clearance_mm"] for r in rows),
        "policy_motion_not_clear": [r["seed"] for r in rows if r["clearance_mm"] <= 0.0],
        "one_below_accepted_by_env": [r["seed"] for r in rows if r.get("env_runs_one_below")],
        "v0_min_collides_on_v1": len(v0_bad),
        "v0_min_physically_collides": len(v0_phys),
        "v0_deepest_mm": min((r["v0_clearance_mm"] for r in v0_phys), default=None),
        "cpu_s_median": float(np.median([r["cpu_s"] for r in rows])),
    }


def main(argv: list[str]) -> None:
    lo, hi, out = int(argv[0]), int(argv[1]), Path(argv[2])
    env, v0_env = gym.make(V1), gym.make(V0)
    policy = make_policy(
        V1, "boundary-following", env.observation_space, env.action_space, dict(env.spec.kwargs)
    )
    rows = []
    with out.open("w") as f:
        for seed in range(lo, hi):
            rows.append(study_pair(env, policy, seed, v0_env))
            f.write(json.dumps(rows[-1]) + "\n")
            f.flush()
    print(json.dumps(summarise(rows), indent=1))


if __name__ == "__main__":
    main(sys.argv[1:])
