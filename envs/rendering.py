"""Rendering owned by a world: its offscreen renderer and, for ``render_mode="human"``,
its window.

A MuJoCo renderer holds a GL context: it is made on the first ``render()``,
freed by ``close()``, and never pickled (a copied or spawned world makes its
own when it first renders). :class:`Renders` gives every world the same
``render()``: the world draws an RGB frame (``_frame()``); ``"rgb_array"``
returns it, ``"human"`` shows it in a :class:`HumanWindow` and returns None,
and the world shows each frame after ``reset()`` and ``step()`` itself
(Gymnasium's convention: a human-mode environment renders continuously).
Whether a display exists is checked when the environment is made
(:func:`motiongym.envs.core.check_render_mode`), not at the first frame.
"""

from __future__ import annotations

import os
import sys
from typing import Any

import numpy as np


def missing_display() -> str | None:
    """Why no window can open here, or None: on Linux, neither ``DISPLAY`` (X11, a
    virtual one from Xvfb included) nor ``WAYLAND_DISPLAY`` is set."""
    if not sys.platform.startswith("linux"):
        return None  # macOS and Windows always have a desktop session to draw in
    if os.environ.get("DISPLAY") or os.environ.get("WAYLAND_DISPLAY"):
        return None
    return "DISPLAY and WAYLAND_DISPLAY are unset"


class HumanWindow:
    """A matplotlib window showing a world's frames at its ``render_fps``.

    matplotlib picks an interactive backend (TkAgg where tkinter exists, Qt
    where installed) when a display is present; ``plt.pause`` draws the frame
    and runs the window's events for one frame period. Under a non-interactive
    backend (``MPLBACKEND=Agg``: no window to show) the frame is drawn on the
    figure's canvas only.
    """

    def __init__(self, title: str, fps: float) -> None:
        import matplotlib.pyplot as plt

        self._plt = plt
        self.title = title
        self.period = 1.0 / fps
        self.figure: Any = None
        self.image: Any = None
        self.shown = 0  # frames shown so far

    def show(self, frame: np.ndarray) -> None:
        if self.figure is None:
            height, width = frame.shape[:2]
            self.figure = self._plt.figure(self.title, figsize=(width / 100, height / 100))
            axes = self.figure.add_axes((0.0, 0.0, 1.0, 1.0))
            axes.set_axis_off()
            self.image = axes.imshow(frame)
            if self._interactive():
                self._plt.show(block=False)
        else:
            self.image.set_data(frame)
        if self._interactive():
            self._plt.pause(self.period)
        else:
            self.figure.canvas.draw()
        self.shown += 1

    def _interactive(self) -> bool:
        """Whether the figure's backend has windows (a GUI framework behind its canvas)."""
        return getattr(self.figure.canvas, "required_interactive_framework", None) is not None

    def close(self) -> None:
        if self.figure is not None:
            self._plt.close(self.figure)
            self.figure = self.image = None


class OwnsRenderer:
    """Mixin for a class keeping its renderer (anything with ``close()``) in ``_renderer``."""

    _renderer: Any = None

    def close(self) -> None:
        if self._renderer is not None:
            self._renderer.close()
            self._renderer = None

    def __getstate__(self) -> dict[str, Any]:
        state = self.__dict__.copy()
        state["_renderer"] = None
        state.pop("_window", None)
        return state


class Renders(OwnsRenderer):
    """``render()`` for ``"rgb_array"`` and ``"human"`` from the world's ``_frame()``.

    A world lists this mixin before ``gym.Env``, implements ``_frame()`` (an
    H x W x 3 uint8 picture of its state) and calls ``self._show_if_human()``
    at the end of ``reset()`` and ``step()``.
    """

    render_mode: str | None
    metadata: dict[str, Any]
    _window: HumanWindow | None = None

    def _frame(self) -> np.ndarray:
        raise NotImplementedError

    # Any: gym.Env types it with its RenderFrame type variable; this returns an RGB array.
    def render(self) -> Any:  # np.ndarray (rgb_array) or None
        if hasattr(self, "_require_reset"):
            self._require_reset("render")
        if self.render_mode is None:
            return None
        frame = self._frame()
        if self.render_mode != "human":
            return frame
        if self._window is None:
            spec = getattr(self, "spec", None)
            title = spec.id if spec is not None else type(self).__name__
            self._window = HumanWindow(title, float(self.metadata.get("render_fps", 30)))
        self._window.show(frame)
        return None

    def _show_if_human(self) -> None:
        if self.render_mode == "human":
            self.render()

    def close(self) -> None:
        if self._window is not None:
            self._window.close()
            self._window = None
        super().close()
