"""Test-wide setup: offscreen MuJoCo rendering on the CPU (EGL/Mesa).

MuJoCo reads ``MUJOCO_GL`` when it is first imported, so it is set here,
before any test module imports it.

``drawing_display``: a display said to exist, with matplotlib drawing into
Agg, so that ``render_mode="human"`` (which needs a display when made) runs
its whole path on a headless machine, as Gymnasium's ``check_env`` makes it
for every declared render mode.
"""

from __future__ import annotations

import os

import pytest

os.environ.setdefault("MUJOCO_GL", "egl")


@pytest.fixture
def drawing_display(monkeypatch):
    import matplotlib.pyplot as plt

    monkeypatch.setenv("DISPLAY", ":motiongym-test")
    backend = plt.get_backend()
    plt.switch_backend("Agg")
    yield
    plt.switch_backend(backend)
