"""Behaviour kept under every registered ID: recorded trajectory hashes.

``tests/data/trajectory_hashes.json`` holds, for every (ID, policy) pair, the
SHA-256 of the first ``STEPS`` steps of seeded episodes (observations,
actions, rewards, termination flags and every numeric ``info`` value, as
bytes) and, for ``random``, of seeded random actions. It was recorded before
the restructuring of issue 13; a refactor must leave every hash as it is. A
deliberate change of behaviour comes with a new ID version (the old one
keeps its hashes) or, for a scripted policy, a re-recording named in the
commit (``python tests/test_trajectory_hashes.py --record``).

Bit-identical episodes are what the hash pins on the machine that recorded
it. NumPy's BLAS picks its kernels by processor (and by ``OPENBLAS_CORETYPE``),
and a matrix product's last bit differs between kernels, so beside each hash
``tests/data/trajectory_fingerprints.json`` keeps a fingerprint of the same
episodes: per part (action, observation, reward, terminated, truncated,
info), the count of numbers, their sum, their sum of squares and their
step-weighted sum. Where the hash differs the fingerprint must agree to a
relative 1e-9: kernels differ by about 1e-16 on every ID here (measured with
``OPENBLAS_CORETYPE`` set and unset), a change of behaviour by far more.
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
FINGERPRINTS = DATA.with_name("trajectory_fingerprints.json")
PARTS = ("action", "observation", "reward", "terminated", "truncated", "info")
RTOL = 1e-9
STEPS = 400
SEEDS = (3, 11)


def _numbers(value, out: list[np.ndarray]) -> None:
    """Every number in ``value`` (dicts in key order) appended to ``out`` as float64."""
    if isinstance(value, dict):
        for key in sorted(value):
            _numbers(value[key], out)
    elif isinstance(value, (bool, int, float, np.number, np.bool_, np.ndarray, list, tuple)):
        a = np.asarray(value)
        if a.dtype == object:
            for v in value:
                _numbers(v, out)
        elif a.dtype.kind in "biuf":
            out.append(a.astype(np.float64).ravel())


def _fingerprint(fp: np.ndarray, t: int, parts: tuple) -> None:
    """Add step ``t``'s parts to ``fp`` (one row per part: count, sum, squares, t-weighted)."""
    for row, part in zip(fp, parts, strict=True):
        out: list[np.ndarray] = []
        _numbers(part, out)
        x = np.concatenate(out) if out else np.zeros(0)
        row += (x.size, x.sum(), (x * x).sum(), (t + 1) * x.sum())


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


def trajectory_hash(env_id: str, policy_name: str) -> tuple[str, list[list[float]]]:
    """The SHA-256 of the seeded episodes and their fingerprint."""
    h = hashlib.sha256()
    fp = np.zeros((len(PARTS), 4))
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
            parts = (action, observation, reward, terminated, truncated, info)
            for part in parts:
                _update(h, part)
            _fingerprint(fp, t, parts)
            if terminated or truncated:
                break
    env.close()
    return h.hexdigest(), fp.tolist()


def _pairs() -> list[tuple[str, str]]:
    return [(i, p) for i in ENV_IDS for p in ("random", *scripted_policies(i))]


def _recorded(path: Path = DATA) -> dict:
    return json.loads(path.read_text()) if path.exists() else {}


@pytest.mark.parametrize(("env_id", "policy_name"), _pairs())
def test_trajectory_unchanged(env_id, policy_name):
    key = f"{env_id} {policy_name}"
    recorded = _recorded()
    if key not in recorded:
        pytest.skip(f"no hash recorded for {key} (new ID or policy)")
    digest, fingerprint = trajectory_hash(env_id, policy_name)
    if digest == recorded[key]:
        return
    expected = _recorded(FINGERPRINTS).get(key)
    assert expected is not None, f"{key}: hash differs and no fingerprint is recorded"
    np.testing.assert_allclose(fingerprint, expected, rtol=RTOL, atol=1e-12, err_msg=key)


if __name__ == "__main__" and "--record" in sys.argv:
    only = [a for a in sys.argv[1:] if a != "--record"]
    table, prints = _recorded(), _recorded(FINGERPRINTS)
    for env_id, name in _pairs():
        key = f"{env_id} {name}"
        if only and not any(o in key for o in only):
            continue
        table[key], prints[key] = trajectory_hash(env_id, name)
        print(env_id, name, table[key][:12], flush=True)
    DATA.write_text(json.dumps(table, indent=1, sort_keys=True) + "\n")
    FINGERPRINTS.write_text(json.dumps(prints, indent=1, sort_keys=True) + "\n")
