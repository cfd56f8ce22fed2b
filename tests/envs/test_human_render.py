"""``render_mode="human"``: a window for every ID and the PettingZoo env, a clear error
where no display exists, and PettingZoo's render and state tests."""

from __future__ import annotations

import os
import shutil
import subprocess
import sys
import time

import gymnasium as gym
import pytest
from pettingzoo.test import render_test, state_test
from pettingzoo.utils.conversions import parallel_to_aec

import motiongym  # noqa: F401
from motiongym.envs import ENV_IDS
from motiongym.envs.dual_arm import parallel_env
from motiongym.envs.sweeper.vector_env import SweeperVectorEnv

# one ID per world in the default suite, the others with the slow tests
ONE_PER_WORLD = {f"motiongym/{n}-v1" for n in ("Sweeper", "HarvestArm", "DualArmCell", "Excavator")}
IDS = [i if i in ONE_PER_WORLD else pytest.param(i, marks=pytest.mark.slow) for i in ENV_IDS]


@pytest.fixture
def no_display(monkeypatch):
    monkeypatch.delenv("DISPLAY", raising=False)
    monkeypatch.delenv("WAYLAND_DISPLAY", raising=False)


@pytest.mark.parametrize("env_id", ENV_IDS)
def test_human_without_a_display_is_refused_when_made(no_display, env_id):
    with pytest.raises(ValueError, match=r"render_mode='human' needs a display .*unset"):
        gym.make(env_id, render_mode="human")


def test_pettingzoo_and_vector_env_without_a_display(no_display):
    with pytest.raises(ValueError, match="render_mode='human' needs a display"):
        parallel_env(render_mode="human")
    with pytest.raises(ValueError, match="render_mode must be one of"):
        SweeperVectorEnv(num_envs=2, render_mode="human")  # frames of many worlds: rgb only


@pytest.mark.parametrize("env_id", IDS)
def test_human_mode_shows_a_frame_after_reset_and_every_step(drawing_display, env_id):
    env = gym.make(env_id, render_mode="human")
    env.reset(seed=0)
    for _ in range(2):
        env.step(env.action_space.sample())
    assert env.render() is None  # shown, not returned
    world = getattr(env.unwrapped, "base", env.unwrapped)  # a goal env shows its base's
    window = world._window
    assert window.shown == 4 and window.image.get_array().shape[2] == 3
    assert window.title == getattr(env.unwrapped, "base_id", env_id)
    env.close()
    assert world._window is None and window.figure is None


def test_pettingzoo_render_and_state_tests_pass(drawing_display):
    def make(render_mode=None):
        return parallel_to_aec(parallel_env(render_mode=render_mode))

    render_test(make)
    state_test(make(), parallel_env())


XVFB_REASON = "no Xvfb on this machine (not installed by pip; apt-get install xvfb)"


@pytest.mark.skipif(shutil.which("Xvfb") is None, reason=XVFB_REASON)
def test_human_windows_open_under_a_virtual_display(tmp_path):
    display = f":{os.getpid() % 500 + 100}"
    server = subprocess.Popen(["Xvfb", display, "-screen", "0", "800x600x24"])
    try:
        time.sleep(1.0)
        script = (
            "import gymnasium as gym, matplotlib, motiongym\n"
            "from motiongym.envs import ENV_IDS\n"
            "for env_id in ENV_IDS:\n"
            "    env = gym.make(env_id, render_mode='human')\n"
            "    env.reset(seed=0); env.step(env.action_space.sample())\n"
            "    assert env.unwrapped._window.shown == 2\n"
            "    env.close()\n"
            "print(matplotlib.get_backend())\n"
        )
        environment = {**os.environ, "DISPLAY": display, "MUJOCO_GL": "egl"}
        environment.pop("MPLBACKEND", None)
        result = subprocess.run(
            [sys.executable, "-c", script], env=environment, capture_output=True, text=True
        )
        assert result.returncode == 0, result.stderr[-2000:]
        assert result.stdout.strip().lower() in {"tkagg", "qtagg", "gtk3agg", "gtk4agg"}
    finally:
        server.terminate()
        server.wait(timeout=10)
