"""motiongym: four classic robot motion problems as Gymnasium environments.

Importing the package registers every environment under the ``motiongym/``
namespace (see :mod:`motiongym.envs.registration`), so that
``gym.make("motiongym:motiongym/Sweeper-v0")`` works without an import.

Headless rendering: MuJoCo picks its OpenGL backend from ``MUJOCO_GL`` when
it is first imported. Where that variable is unset and there is no display
(Linux without ``DISPLAY`` or ``WAYLAND_DISPLAY``), this package sets it to
``egl`` (offscreen, Mesa or a GPU driver) before anything imports MuJoCo, so
``render()`` works on a server with no environment variable set. A value the
user set is never changed.
"""

from __future__ import annotations

import os
import sys


def _choose_headless_gl() -> None:
    headless = not (os.environ.get("DISPLAY") or os.environ.get("WAYLAND_DISPLAY"))
    if sys.platform.startswith("linux") and headless:
        os.environ.setdefault("MUJOCO_GL", "egl")


_choose_headless_gl()

from motiongym.envs import ENV_IDS  # noqa: E402

__version__ = "0.1.0"
__all__ = ["ENV_IDS", "__version__"]
