"""Rendering on a machine with no display and no ``MUJOCO_GL`` set.

Importing motiongym chooses EGL when there is no display (src/motiongym/__init__.py);
every registered ID must then render in a fresh process.
"""

from __future__ import annotations

import os
import subprocess
import sys

SCRIPT = """
import gymnasium as gym
import numpy as np
from motiongym.envs import ENV_IDS
for env_id in ENV_IDS:
    env = gym.make(env_id, render_mode="rgb_array")
    env.reset(seed=0)
    frame = env.render()
    assert frame.ndim == 3 and frame.shape[2] == 3 and frame.std() > 0, env_id
    env.close()
import os
print(os.environ["MUJOCO_GL"])
"""


def test_every_id_renders_headless_without_environment_variables():
    env = {
        k: v for k, v in os.environ.items() if k not in ("MUJOCO_GL", "DISPLAY", "WAYLAND_DISPLAY")
    }
    done = subprocess.run(
        [sys.executable, "-c", SCRIPT], env=env, capture_output=True, text=True, timeout=300
    )
    assert done.returncode == 0, done.stderr[-2000:]
    assert done.stdout.split()[-1] == "egl"


def test_a_user_choice_of_backend_is_kept():
    env = {k: v for k, v in os.environ.items() if k not in ("DISPLAY", "WAYLAND_DISPLAY")}
    env["MUJOCO_GL"] = "osmesa-not-touched"
    code = "import os, motiongym; print(os.environ['MUJOCO_GL'])"
    done = subprocess.run([sys.executable, "-c", code], env=env, capture_output=True, text=True)
    assert done.stdout.strip() == "osmesa-not-touched"
