"""Behaviour kept under every registered ID: recorded trajectory hashes.

``tests/data/trajectory_hashes.json`` holds, for every (ID, policy) pair, the
SHA-256 of the first ``STEPS`` steps of seeded episodes (observations,
actions, rewards, termination flags and every numeric ``info`` value, as
bytes) and, for ``random``, of seeded random actions. A refactor must leave
every hash as it is; a pair without a record fails, so a new ID or policy is
recorded when it is added. A deliberate change of behaviour comes with a new
ID version (the old one keeps its hashes) or, for a scripted policy, a
re-recording named in the commit
(``python tests/test_trajectory_hashes.py --record [substring ...]``).

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
from collections.abc import Iterator
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


def _leaves(value) -> Iterator[bytes | np.ndarray]:
    """What a step's part holds, in a fixed order: dict keys (sorted) and strings as bytes,
    numbers as arrays; anything else (None, objects) carries no behaviour to pin."""
    if isinstance(value, dict):
        for key in sorted(value):
            yield str(key).encode()
            yield from _leaves(value[key])
    elif isinstance(value, (str, bytes)):
        yield value.encode() if isinstance(value, str) else value
    elif isinstance(value, (bool, int, float, np.number, np.bool_, np.ndarray, list, tuple)):
        a = np.asarray(value)
        if a.dtype == object:
            for v in value:
                yield from _leaves(v)
        else:
            yield a


def _fingerprint(fp: np.ndarray, t: int, parts: tuple) -> None:
    """Add step ``t``'s parts to ``fp`` (one row per part: count, sum, squares, t-weighted)."""
    for row, part in zip(fp, parts, strict=True):
        numbers = [
            leaf.astype(np.float64).ravel()
            for leaf in _leaves(part)
            if isinstance(leaf, np.ndarray) and leaf.dtype.kind in "biuf"
        ]
        x = np.concatenate(numbers) if numbers else np.zeros(0)
        row += (x.size, x.sum(), (x * x).sum(), (t + 1) * x.sum())


def _update(h, value) -> None:
    for leaf in _leaves(value):
        if isinstance(leaf, bytes):
            h.update(leaf)
        else:
            kind = np.float64 if leaf.dtype.kind in "biuf" else leaf.dtype
            h.update(np.ascontiguousarray(leaf, dtype=kind).tobytes())


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
    assert key in recorded, (
        f"no hash recorded for {key}: record it with "
        f"`python tests/test_trajectory_hashes.py --record '{key}'`"
    )
    digest, fingerprint = trajectory_hash(env_id, policy_name)
    if digest == recorded[key]:
        return
    expected = _recorded(FINGERPRINTS).get(key)
    assert expected is not None, f"{key}: hash differs and no fingerprint is recorded"
    np.testing.assert_allclose(fingerprint, expected, rtol=RTOL, atol=1e-12, err_msg=key)


def test_fingerprint_tolerates_last_bits_not_a_change():
    """The fallback's two sides: a last-bit difference (what BLAS kernels make) passes,
    a change of behaviour of one part in a million fails."""
    rng = np.random.default_rng(0)
    steps = [(rng.normal(size=4), rng.normal(size=10), 1.0, False, False, {"d": 0.5})
             for _ in range(50)]  # fmt: skip

    def fingerprint(scale: float) -> np.ndarray:
        fp = np.zeros((len(PARTS), 4))
        for t, (a, o, r, te, tr, info) in enumerate(steps):
            _fingerprint(fp, t, (a, o * (1 + scale * (t == 20)), r, te, tr, info))
        return fp

    base = fingerprint(0.0)
    np.testing.assert_allclose(fingerprint(1e-15), base, rtol=RTOL, atol=1e-12)
    with pytest.raises(AssertionError):
        np.testing.assert_allclose(fingerprint(1e-6), base, rtol=RTOL, atol=1e-12)


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
