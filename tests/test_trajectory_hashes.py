"""Behaviour kept under every registered ID: recorded trajectory hashes.

``tests/data/trajectory_hashes.json`` holds, for every (ID, policy) pair, the
SHA-256 of the first ``STEPS`` steps of seeded episodes (observations,
actions, rewards, termination flags and every numeric ``info`` value, as
bytes) and, for ``random``, of seeded random actions. It was recorded before
the restructuring of issue 13; a refactor must leave every hash as it is. A
deliberate change of behaviour comes with a new ID version (the old one
keeps its hashes) or, for a scripted policy, a re-recording named in the
commit (``python tests/test_trajectory_hashes.py --record``).
"""

from __future__ import annotations

import hashlib
import json
import os
import sys
from pathlib import Path

import gymnasium as gym
import numpy as np
import pytest

os.environ.setdefault("MUJOCO_GL", "egl")

import motiongym  # noqa: E402,F401
from motiongym.baselines import make_policy, scripted_policies  # noqa: E402
from motiongym.envs import ENV_IDS  # noqa: E402

DATA = Path(__file__).parent / "data" / "trajectory_hashes.json"
STEPS = 400
SEEDS = (3, 11)


def _update(h, value) -> None:
    if isinstance(value, dict):
        for key in sorted(value):
            h.update(str(key).encode())
            _update(h, value[key])
    elif isinstance(value, (str, bytes)):
        h.update(value.encode() if isinstance(value, str) else value)
    elif isinstance(value, (bool, int, float, np.number, np.bool_, np.ndarray, list, tuple)):
        a = np.asarray(value)
        if a.dtype == object:
            for v in value:
                _update(h, v)
        else:
            h.update(
                np.ascontiguousarray(
                    a, dtype=np.float64 if a.dtype.kind in "biuf" else a.dtype
                ).tobytes()
            )
    # anything else (None, objects) carries no behaviour to pin


def trajectory_hash(env_id: str, policy_name: str) -> str:
    h = hashlib.sha256()
    env = gym.make(env_id)
    for seed in SEEDS:
        observation, info = env.reset(seed=seed)
        _update(h, observation)
        if policy_name == "random":
            env.action_space.seed(seed)
            policy = None
        else:
            policy = make_policy(
                env_id,
                policy_name,
                env.observation_space,
                env.action_space,
                dict(gym.spec(env_id).kwargs),
            )
        for t in range(STEPS):
            if policy is None:
                action = env.action_space.sample()
            else:
                action, _ = policy.predict(observation, episode_start=t == 0)
            observation, reward, terminated, truncated, info = env.step(action)
            for part in (action, observation, reward, terminated, truncated, info):
                _update(h, part)
            if terminated or truncated:
                break
    env.close()
    return h.hexdigest()


def _pairs() -> list[tuple[str, str]]:
    return [(i, p) for i in ENV_IDS for p in ("random", *scripted_policies(i))]


def _recorded() -> dict[str, str]:
    return json.loads(DATA.read_text()) if DATA.exists() else {}


@pytest.mark.parametrize(("env_id", "policy_name"), _pairs())
def test_trajectory_unchanged(env_id, policy_name):
    key = f"{env_id} {policy_name}"
    recorded = _recorded()
    if key not in recorded:
        pytest.skip(f"no hash recorded for {key} (new ID or policy)")
    assert trajectory_hash(env_id, policy_name) == recorded[key]


if __name__ == "__main__" and "--record" in sys.argv:
    only = [a for a in sys.argv[1:] if a != "--record"]
    table = _recorded()
    for env_id, name in _pairs():
        if only and not any(o in f"{env_id} {name}" for o in only):
            continue
        table[f"{env_id} {name}"] = trajectory_hash(env_id, name)
        print(env_id, name, table[f"{env_id} {name}"][:12], flush=True)
    DATA.write_text(json.dumps(table, indent=1, sort_keys=True) + "\n")
