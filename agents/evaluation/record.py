"""``motiongym record``: one episode of a policy as an MP4 and a GIF.

The episode runs through :func:`~motiongym.agents.evaluation.episodes.run_episode` (the
one episode loop) with ``render_mode="rgb_array"``; a step hook keeps the
frame after every ``every``-th step (rendering changes nothing in the
dynamics). The GIF is written with Pillow (a dependency), scaled to at most
:data:`GIF_WIDTH` pixels wide; the MP4 with imageio's bundled ffmpeg
(``pip install "motiongym[video]"``: imageio-ffmpeg ships its own ffmpeg
binary and moves none of our pins). Without it the GIF is still written and
the MP4 is reported missing, with the command that adds it.
"""

from __future__ import annotations

import importlib.util
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np
from PIL import Image

from motiongym.agents.environments import make_env, short_name
from motiongym.agents.errors import UsageError
from motiongym.agents.evaluation.episodes import Step, run_episode
from motiongym.agents.models.predictors import load_predictor, policy_label

GIF_WIDTH = 320  # pixels; the README's GIFs stay well under 2 MB
VIDEO_EXTRA = 'pip install "motiongym[video]"'
MAX_FRAME_SECONDS = 60  # the longest a recorded frame may show


def mp4_available() -> bool:
    """Whether imageio and its bundled ffmpeg (the ``video`` extra) are installed."""
    return all(importlib.util.find_spec(name) for name in ("imageio", "imageio_ffmpeg"))


@dataclass
class Recording:
    """The files written (the MP4 absent without the ``video`` extra) and the episode."""

    gif: Path
    mp4: Path | None
    episode: dict[str, float]
    frames: int
    fps: float
    notes: list[str] = field(default_factory=list)


def write_gif(frames: list[np.ndarray], path: Path, fps: float, width: int = GIF_WIDTH) -> Path:
    """An endlessly looping GIF of ``frames`` (H x W x 3 uint8), at most ``width`` wide."""
    height, frame_width = frames[0].shape[:2]
    scale = min(1.0, width / frame_width)
    size = (max(1, round(frame_width * scale)), max(1, round(height * scale)))
    images = [Image.fromarray(frame).resize(size, Image.Resampling.LANCZOS) for frame in frames]
    duration = max(20, round(1000 / fps))  # ms per frame; browsers floor shorter ones
    images[0].save(
        path, save_all=True, append_images=images[1:], duration=duration, loop=0, optimize=True
    )
    return path


def write_mp4(frames: list[np.ndarray], path: Path, fps: float) -> Path:
    """An H.264 MP4 through imageio's bundled ffmpeg (sizes padded to even numbers)."""
    import imageio.v2 as imageio

    height, width = frames[0].shape[:2]
    pad = ((0, height % 2), (0, width % 2), (0, 0))
    writer: Any = imageio.get_writer(path, fps=fps, codec="libx264", macro_block_size=1)
    with writer:  # a format's writer (append_data), typed as the base class
        for frame in frames:
            writer.append_data(np.pad(frame, pad, mode="edge"))
    return path


def record(
    env_id: str,
    policy: str,
    seed: int,
    out_dir: Path,
    env_kwargs: dict[str, Any] | None = None,
    every: int = 1,
    trust: bool = False,
) -> Recording:
    """Run ``policy`` for one episode from ``reset(seed=seed)``; write
    ``<ID>_<policy>_seed<S>.gif`` (and ``.mp4``) into ``out_dir``.

    ``every``: keep one frame in ``every`` steps (the videos play at the
    environment's ``render_fps / every``, so in real time); at most
    ``MAX_FRAME_SECONDS * render_fps``, so that a frame lasts at most
    :data:`MAX_FRAME_SECONDS` (GIF stores a frame's time in 16 bits).
    """
    if isinstance(every, bool) or not isinstance(every, int) or every < 1:
        raise ValueError(f"every must be an integer >= 1, got {every!r}")
    env = make_env(env_id, env_kwargs, render_mode="rgb_array")
    render_fps = float(env.metadata.get("render_fps", 30))
    most = max(1, int(MAX_FRAME_SECONDS * render_fps))
    if every > most:
        env.close()
        raise UsageError(
            f"--every must be in [1, {most}] for {env_id} (it renders {render_fps:g} frames "
            f"per second; a frame lasts at most {MAX_FRAME_SECONDS} s), got {every}"
        )
    predictor = load_predictor(policy, env_id, env, env_kwargs, trust=trust)
    frames: list[np.ndarray] = []

    def keep(step: Step) -> None:
        if step.index % every == 0 or step.terminated or step.truncated:
            frames.append(np.asarray(env.render()))

    episode = run_episode(env, predictor, seed, hook=keep)
    fps = render_fps / every
    env.close()
    out_dir.mkdir(parents=True, exist_ok=True)
    stem = out_dir / f"{short_name(env_id)}_{policy_label(policy)}_seed{seed}"
    gif = write_gif(frames, stem.with_suffix(".gif"), fps)
    mp4, notes = None, []
    if mp4_available():
        mp4 = write_mp4(frames, stem.with_suffix(".mp4"), fps)
    else:
        notes.append(f"no MP4: imageio-ffmpeg is not installed ({VIDEO_EXTRA})")
    return Recording(gif, mp4, episode, len(frames), fps, notes)
