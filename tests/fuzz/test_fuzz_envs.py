"""Property-based hostile input (Hypothesis): every ID's keywords, reset options and actions.

The property: a clear error (a ``ValueError`` or ``TypeError`` whose message
names the argument) or a valid result (finite observations and rewards from
a reset and a few steps), never anything else, within a deadline. The
default suite runs a fast slice (``FUZZ_EXAMPLES``, few examples per ID);
``make fuzz`` runs the Hypothesis profile ``fuzz`` (many more) and prints the
counts per outcome.
"""

from __future__ import annotations

import dataclasses
import inspect
import math

import gymnasium as gym
import numpy as np
import pytest

hypothesis = pytest.importorskip("hypothesis")
from fuzzing import OUTCOMES, PROFILE  # noqa: E402
from hypothesis import given  # noqa: E402
from hypothesis import strategies as st  # noqa: E402

import motiongym  # noqa: E402,F401
from motiongym.envs import ENV_IDS  # noqa: E402
from motiongym.envs.excavator.params import DigParams, ReachParams  # noqa: E402
from motiongym.envs.sweeper.params import SweeperParams  # noqa: E402

# The fast slice: the newest version of each world; the full run: every ID.
FUZZED = (
    ENV_IDS
    if PROFILE == "fuzz"
    else tuple(
        i
        for i in ENV_IDS
        if not any(j > i and j.rsplit("-", 1)[0] == i.rsplit("-", 1)[0] for j in ENV_IDS)
    )
)

STEPS = 5

WEIRD = st.one_of(
    st.none(),
    st.booleans(),
    st.integers(min_value=-(2**70), max_value=2**70),
    st.floats(allow_nan=True, allow_infinity=True),
    st.sampled_from([0, 1, -1, 0.0, 1e-300, 1e300, 10**5, "", "no", "room", "maze", "both"]),
    st.text(max_size=5),
    st.lists(st.integers(-3, 3), max_size=3),
    st.complex_numbers(max_magnitude=1e3),
)


# Values a world may well accept, so that combinations get past the first check.
PLAUSIBLE = st.one_of(
    st.integers(1, 8), st.floats(0.01, 2.0), st.booleans(), st.sampled_from(["room", "swept"])
)

# Every world's reset options (and one no world has); values: odd scalars, or vectors and
# point lists of plausible lengths with odd entries (positions, joint angles, obstacles).
OPTION_KEYS = ["pairs", "task", "start", "heading", "fruit", "obstacles", "q", "q0", "target"]
ODD = st.one_of(st.floats(allow_nan=True, allow_infinity=True), st.sampled_from([0.0, 0.3, -2.0]))
VECTORS = st.one_of(
    st.lists(ODD, min_size=1, max_size=8),
    st.lists(st.lists(ODD, min_size=3, max_size=4), max_size=40),
)


def keyword_names(env_id: str) -> list[str]:
    """The environment's own keyword arguments (its signature, else its parameters dataclass)."""
    cls = gym.spec(env_id).entry_point
    module, name = cls.split(":")
    import importlib

    env_class = getattr(importlib.import_module(module), name)
    names = [
        p.name
        for p in inspect.signature(env_class.__init__).parameters.values()
        if p.name not in ("self", "kwargs", "render_mode") and p.kind != p.VAR_KEYWORD
    ]
    if not names and hasattr(env_class, "Params"):  # a core.SystemEnv: its dataclass
        names = [f.name for f in dataclasses.fields(env_class.Params)]
    if not names:
        params = {"Sweeper": SweeperParams, "ExcavatorReach": ReachParams, "Excavator": DigParams}
        family = env_id.split("/")[1].rsplit("-", 1)[0]
        names = [f.name for f in dataclasses.fields(params[family])]
    return sorted(set(names) | set(gym.spec(env_id).kwargs))


def _finite(value) -> bool:
    if isinstance(value, dict):
        return all(_finite(v) for v in value.values())
    return bool(np.all(np.isfinite(np.asarray(value, dtype=np.float64))))


def _valid_run(env: gym.Env, seed: int) -> None:
    observation, _ = env.reset(seed=seed)
    assert _finite(observation)
    env.action_space.seed(seed)
    for _ in range(STEPS):
        observation, reward, terminated, truncated, _ = env.step(env.action_space.sample())
        assert _finite(observation) and math.isfinite(reward)
        if terminated or truncated:
            break


@pytest.mark.parametrize("env_id", FUZZED)
@given(data=st.data())
def test_keyword_arguments_give_a_clear_error_or_a_valid_world(env_id, data):
    names = keyword_names(env_id)
    values = st.one_of(WEIRD, PLAUSIBLE)  # one to three keywords, alone or in conflict
    kwargs = data.draw(
        st.dictionaries(st.sampled_from(names), values, min_size=1, max_size=3), label="kwargs"
    )
    try:
        env = gym.make(env_id, **kwargs)
    except (ValueError, TypeError) as error:
        # the argument, or the one it conflicts with (planar=True with dof=7 names dof)
        assert any(n in str(error) for n in kwargs), f"{kwargs!r}: {error}"
        OUTCOMES["kwargs: clear error"] += 1
        return
    try:
        _valid_run(env, seed=data.draw(st.integers(0, 2**31), label="seed"))
    except (ValueError, TypeError) as error:  # a choice refused at reset is still named
        assert any(n in str(error) for n in kwargs), f"{kwargs!r}: {error}"
        OUTCOMES["kwargs: clear error at reset"] += 1
        return
    finally:
        env.close()
    OUTCOMES["kwargs: valid"] += 1


@pytest.mark.parametrize("env_id", FUZZED)
@given(
    options=st.one_of(
        WEIRD,
        st.dictionaries(st.sampled_from(OPTION_KEYS), st.one_of(WEIRD, VECTORS), max_size=2),
    )
)
def test_reset_options_give_a_clear_error_or_a_valid_reset(env_id, options):
    env = gym.make(env_id)
    try:
        observation, _ = env.reset(seed=0, options=options)
    except (ValueError, TypeError) as error:
        assert "option" in str(error), f"{options!r}: {error}"
        OUTCOMES["options: clear error"] += 1
        return
    finally:
        env.close()
    assert _finite(observation)
    OUTCOMES["options: valid"] += 1


@pytest.mark.parametrize("env_id", FUZZED)
@given(action=WEIRD)
def test_actions_are_what_the_space_accepts_or_a_clear_error(env_id, action):
    env = gym.make(env_id)
    env.reset(seed=0)
    try:
        observation, reward, *_ = env.step(action)
    except (ValueError, TypeError) as error:
        assert "action" in str(error).lower(), f"{action!r}: {error}"
        OUTCOMES["actions: clear error"] += 1
        return
    finally:
        env.close()
    assert _finite(observation) and math.isfinite(reward)
    OUTCOMES["actions: valid"] += 1
