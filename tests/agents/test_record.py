"""``motiongym record``: an episode's GIF (always) and MP4 (with the video extra)."""

from __future__ import annotations

import pytest
from PIL import Image

from motiongym.agents.cli import main
from motiongym.agents.evaluation.record import mp4_available, record

SWEEPER = "motiongym/Sweeper-v0"


def test_record_writes_a_gif_of_every_kth_step_at_real_time(tmp_path):
    kwargs = {"map_name": "room", "max_episode_steps": 25}
    recording = record(SWEEPER, "psa-cwa", 4, tmp_path, kwargs, every=4)
    assert recording.episode["length"] == 25  # truncated by the cap
    assert recording.frames == 7  # after steps 0, 4, ..., 24 (the last, 24, among them)
    assert recording.fps == pytest.approx(30 / 4)
    with Image.open(recording.gif) as gif:
        assert gif.n_frames == recording.frames
        assert gif.size == (320, 240)
        assert abs(gif.info["duration"] - 1000 / 7.5) <= 10  # GIF keeps centiseconds
        assert gif.info["loop"] == 0
    assert recording.gif.name == "Sweeper-v0_psa-cwa_seed4.gif"
    with pytest.raises(ValueError, match="every must be an integer >= 1, got 0"):
        record(SWEEPER, "psa-cwa", 4, tmp_path, kwargs, every=0)


@pytest.mark.skipif(not mp4_available(), reason='needs pip install "motiongym[video]"')
def test_record_writes_an_mp4_with_the_same_frames(tmp_path, capsys):
    import imageio.v3 as iio

    argv = ["record", "motiongym/ExcavatorReach-v0", "--every", "5", "--out", str(tmp_path)]
    assert main(argv) == 0
    out = capsys.readouterr().out
    assert "newton-raphson-reach on motiongym/ExcavatorReach-v0, seed 0" in out  # the default
    mp4 = tmp_path / "ExcavatorReach-v0_newton-raphson-reach_seed0.mp4"
    video = iio.imread(mp4)
    with Image.open(mp4.with_suffix(".gif")) as gif:
        assert video.shape[0] == gif.n_frames >= 2
    assert video.shape[1:] == (480, 640, 3)
    assert iio.immeta(mp4)["fps"] == pytest.approx(2.0)


def test_record_without_ffmpeg_still_writes_the_gif_and_says_how(tmp_path, capsys, monkeypatch):
    monkeypatch.setattr("motiongym.agents.evaluation.record.mp4_available", lambda: False)
    argv = ["record", SWEEPER, "--policy", "random", "--out", str(tmp_path)]
    assert main([*argv, "--env-kwargs", "max_episode_steps=3"]) == 0
    captured = capsys.readouterr()
    assert 'pip install "motiongym[video]"' in captured.err
    assert [p.suffix for p in tmp_path.iterdir()] == [".gif"]


def test_the_readmes_gifs_exist_and_are_small():
    import re
    from pathlib import Path

    root = Path(__file__).parents[2]
    gifs = re.findall(r"\((docs/media/[^)]+\.gif)\)", (root / "README.md").read_text())
    assert len(gifs) == 4  # one per world
    for gif in gifs:
        assert (root / gif).stat().st_size < 2_000_000, gif
        with Image.open(root / gif) as image:
            assert image.n_frames > 10 and image.size[0] == 320
