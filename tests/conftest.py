"""Test-wide setup: offscreen MuJoCo rendering on the CPU (EGL/Mesa).

MuJoCo reads ``MUJOCO_GL`` when it is first imported, so it is set here,
before any test module imports it.
"""

from __future__ import annotations

import os

os.environ.setdefault("MUJOCO_GL", "egl")
