"""The core contract: the base environment's loop, the conventions and their errors."""

from __future__ import annotations

import dataclasses
import sys
import warnings
from pathlib import Path
from typing import ClassVar

import numpy as np
import pytest

from motiongym.envs import checks, core

sys.path.insert(0, str(Path(__file__).parent))
import toy_world  # noqa: E402


def test_the_toy_world_obeys_the_protocols():
    env = toy_world.ToyLineEnv()
    assert isinstance(env.world, core.World)
    assert isinstance(env.task, core.Task)
    assert isinstance(env, core.SystemEnv)


def test_the_base_loop_sums_the_terms_and_fills_info():
    env = toy_world.ToyLineEnv(time=0.25)
    observation, info = env.reset(seed=1, options={"start": 3})
    assert observation[0] == 3.0
    assert info == {"is_success": False, "cost": 0.0, "reward_time": 0.0}
    _, reward, terminated, truncated, info = env.step(1)
    assert reward == -0.25 == info["reward_time"]
    assert truncated is False and terminated is info["is_success"]


def test_step_before_reset_and_bad_actions_are_refused():
    env = toy_world.ToyLineEnv()
    with pytest.raises(RuntimeError, match="reset"):
        env.step(0)
    env.reset(seed=0)
    for bad in (2, -1, 1.5, "1", 2**70):
        with pytest.raises(ValueError, match=r"action must be in Discrete\(2\)"):
            env.step(bad)


def test_same_seed_same_episode():
    def run(seed):
        env = toy_world.ToyLineEnv()
        out = [env.reset(seed=seed)[0]]
        out += [env.step(i % 2)[0] for i in range(5)]
        return np.array(out)

    np.testing.assert_array_equal(run(4), run(4))


def test_render_size_is_the_frames_shape():
    env = toy_world.ToyLineEnv(render_mode="rgb_array", render_size=(20, 30))
    env.reset(seed=0)
    assert env.render().shape == (20, 30, 3)


@pytest.mark.parametrize(
    ("value", "match"),
    [
        ((8, 30), r"render_size\[0\] must be an integer in \[16, 2048\], got 8"),
        ((20, 5000), r"render_size\[1\] must be an integer in \[16, 2048\], got 5000"),
        (640, r"render_size must be \(rows, columns\)"),
        ("640x480", r"render_size must be \(rows, columns\)"),
        ((20.0, 30), r"render_size\[0\] must be an integer"),
    ],
)
def test_render_size_errors_name_the_keyword(value, match):
    with pytest.raises(core.ArgumentError, match=match):
        toy_world.ToyLineEnv(render_size=value)


def test_weights_are_magnitudes():
    assert core.check_weight("time", 0.0) == 0.0
    with pytest.raises(core.ArgumentError, match=r"give time=0.05 for the same reward"):
        core.check_weight("time", -0.05)
    with pytest.raises(core.ArgumentError, match=r"success is paid \(added\), so no weight"):
        core.check_weight("success", -1.0, cost=False)
    for bad in (float("nan"), float("inf"), 1e308, True, "1"):
        with pytest.raises(core.ArgumentError, match="time must be"):
            core.check_weight("time", bad)


@dataclasses.dataclass(frozen=True)
class _Params:
    render_size: tuple[int, int] = (360, 480)
    start_noise: float = 0.0

    DEPRECATED: ClassVar[dict[str, core.Deprecated]] = {
        "width": core.Deprecated("render_size", lambda v, cur: (cur[0], v)),
        "height": core.Deprecated("render_size", lambda v, cur: (v, cur[1])),
        "noise": core.Deprecated("start_noise"),
    }


def test_a_deprecated_keyword_converts_and_warns_once(recwarn):
    checks._warned.clear()
    with pytest.warns(core.MotiongymDeprecationWarning, match="'width' is deprecated"):
        p = core.params_from_kwargs(_Params, {"width": 640})
    assert p.render_size == (360, 640)
    p = core.params_from_kwargs(_Params, {"width": 800, "height": 600})
    assert p.render_size == (600, 800)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        assert core.params_from_kwargs(_Params, {"width": 640}).render_size == (360, 640)
        assert core.params_from_kwargs(_Params, {"render_size": (20, 20)}).render_size == (20, 20)
    assert core.params_from_kwargs(_Params, {"noise": 0.5}).start_noise == 0.5


def test_old_and_new_name_together_is_an_error():
    with pytest.raises(core.ArgumentError, match="give 'start_noise' or its deprecated"):
        core.params_from_kwargs(_Params, {"noise": 0.5, "start_noise": 0.1})


def test_a_deprecated_reset_option_converts_and_warns_once():
    checks._warned.clear()
    valid = {"start": lambda name, v: core.check_int(name, v, 0)}
    old = {"q": core.Deprecated("start")}
    with pytest.warns(core.MotiongymDeprecationWarning, match="reset option: 'q'"):
        assert core.check_options({"q": 3}, valid, old) == {"start": 3}
    with pytest.raises(core.ArgumentError, match=r"options\['start'\] must be an integer"):
        core.check_options({"q": -1}, valid, old)
    with pytest.raises(core.ArgumentError, match=r"unknown reset option\(s\) \['x'\]"):
        core.check_options({"x": 1}, valid, old)
