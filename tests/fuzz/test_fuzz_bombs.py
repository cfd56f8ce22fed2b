"""Hostile input the property-based suite does not draw: each class one fast case or a few.

Code named by a string (the goal IDs' ``fields``), decompression bombs
(zip members, ``.npz`` headers that lie, huge sparse files), YAML alias
bombs, deep nesting, size caps, image and text maps, render sizes past
MuJoCo's default framebuffer, output folders that cannot be written, bounds
of network sizes. The property: one clear error naming the argument (exit
2 on the command line), before the content is parsed; nothing runs.
Files are small or sparse; no case reads more than a few MB.
"""

from __future__ import annotations

import argparse
import io
import json
import shutil
import struct
import sys
import time
import zipfile
import zlib
from pathlib import Path

import gymnasium as gym
import numpy as np
import pytest
from zip_members import rewrite_zip

import motiongym  # noqa: F401
from motiongym.agents import limits
from motiongym.agents.cli import _env_kwargs, _file, _folder, main
from motiongym.agents.environments import make_env
from motiongym.agents.errors import UsageError
from motiongym.agents.models.files import NORMALIZATION_FILE, load_normalization
from motiongym.agents.models.predictors import load_predictor
from motiongym.agents.models.pretrained import pretrained_models, verify_manifest, write_manifest
from motiongym.agents.training.config import load_config
from motiongym.envs.core import ArgumentError
from motiongym.envs.sweeper.maps import MAX_SIDE, MapError, load_map_file

ENV_ID = "motiongym/HarvestArm-v0"  # a shipped PPO model with normalisation statistics
BILLION_LAUGHS = "\n".join(
    ["a: &a [x, x, x, x, x, x, x, x, x]"]
    + [f"{c}: &{c} [{', '.join([f'*{p}'] * 9)}]" for p, c in zip("abcdefg", "bcdefgh", strict=True)]
)


@pytest.fixture
def folder(tmp_path):
    copy = tmp_path / "run"
    shutil.copytree(pretrained_models(ENV_ID)["ppo"], copy)
    return copy


def _load(path):
    return load_predictor(str(path), ENV_ID, make_env(ENV_ID))


# ---------------------------------------------------------------- import by string


@pytest.mark.parametrize(
    "fields", ["builtins:print", "sys:exit", "subprocess:run", "builtins:input", "this:s", "os"]
)
def test_goal_fields_never_import_a_module_named_by_a_string(fields, capsys):
    before = set(sys.modules)
    with pytest.raises(ArgumentError, match="fields must be one of the registered goal fields"):
        gym.make("motiongym/HarvestArmGoal-v1", fields=fields)
    assert "this" not in set(sys.modules) - before
    assert capsys.readouterr().out == ""


def test_goal_fields_from_the_command_line_are_a_usage_error(tmp_path, capsys):
    code = main(
        [
            "evaluate",
            "motiongym/HarvestArmGoal-v1",
            "--policy",
            "random",
            "--episodes",
            "1",
            "--env-kwargs",
            "fields=builtins:print",
            "--out",
            str(tmp_path / "out"),
        ]
    )
    assert code == 2
    assert "fields must be one of the registered goal fields" in capsys.readouterr().err


def test_a_registered_goal_fields_name_and_a_python_callable_still_work():
    from motiongym.envs.harvest_arm.goal import goal_fields

    spec = gym.spec("motiongym/HarvestArmPlanarGoal-v1")
    named = gym.make(spec.id).observation_space
    called = gym.make(spec.id, fields=goal_fields).observation_space
    assert named == called


# ---------------------------------------------------------------- YAML and JSON


def test_a_yaml_alias_bomb_is_refused_before_it_expands(tmp_path):
    config = tmp_path / "bomb.yml"
    config.write_text(f"ppo:\n  n_timesteps: 1\n  policy: MlpPolicy\n{BILLION_LAUGHS}\n")
    start = time.perf_counter()
    with pytest.raises(UsageError, match="YAML aliases are not allowed"):
        load_config(config, "ppo")
    with pytest.raises(UsageError, match="YAML aliases are not allowed"):
        _env_kwargs([f"grid={{{BILLION_LAUGHS.replace(chr(10), ', ')}}}"])
    assert time.perf_counter() - start < 2.0


def test_deep_nesting_and_large_files_are_refused_before_parsing(tmp_path):
    deep = tmp_path / "deep.yml"
    deep.write_text("ppo: " + "[" * 20_000 + "]" * 20_000 + "\n")
    with pytest.raises(UsageError, match="nested deeper than"):
        load_config(deep, "ppo")
    large = tmp_path / "large.yml"
    with large.open("wb") as handle:  # sparse: no bytes written, the size is what counts
        handle.truncate(6 << 20)
    with pytest.raises(UsageError, match=r"bytes of YAML; at most \d+ allowed"):
        load_config(large, "ppo")
    many = tmp_path / "many.yml"
    many.write_text("ppo: [" + "1, " * 60_000 + "1]\n")  # under the byte cap, too many values
    with pytest.raises(UsageError, match="YAML values"):
        load_config(many, "ppo")
    with pytest.raises(UsageError, match="bytes of YAML"):
        _env_kwargs(["dof=" + "1" * (1 << 17)])


def test_a_deeply_nested_manifest_is_a_clear_error(folder):
    (folder / "manifest.json").write_text("[" * 100_000)
    with pytest.raises(UsageError, match="JSON nested deeper than"):
        verify_manifest(folder)


def test_a_key_given_twice_on_the_command_line_is_refused():
    with pytest.raises(UsageError, match="'dof' twice"):
        _env_kwargs(["dof=5", "dof=6"])


# ---------------------------------------------------------------- decompression


def test_a_zip_member_that_unpacks_far_past_its_size_is_refused_unread(folder):
    def change(members):
        members["policy.pth"] = bytes(40 << 20)  # 40 MB of zeros: about 40 kB deflated

    def deflated(path, change):
        rewrite_zip(path, change)
        with zipfile.ZipFile(path) as archive:  # rewrite compressed, as an attacker would
            members = {name: archive.read(name) for name in archive.namelist()}
        with zipfile.ZipFile(path, "w", zipfile.ZIP_DEFLATED) as archive:
            for name, content in members.items():
                archive.writestr(name, content)

    deflated(folder / "model.zip", change)
    write_manifest(folder)
    assert (folder / "model.zip").stat().st_size < 4 << 20
    with pytest.raises(UsageError, match=f"a ratio over {limits.MAX_RATIO:g} is refused"):
        _load(folder)


def test_a_data_entry_past_its_cap_is_refused_unread(folder):
    def change(members):
        members["data"] = b" " * (20 << 20) + members["data"]  # valid JSON, 20 MB

    rewrite_zip(folder / "model.zip", change)
    write_manifest(folder)
    with pytest.raises(UsageError, match=r"(data entry declares|ratio over)"):
        _load(folder)


def _npy_with_header(shape: tuple[int, ...], payload: bytes) -> bytes:
    buffer = io.BytesIO()
    np.lib.format.write_array_header_1_0(
        buffer, {"descr": "<f8", "fortran_order": False, "shape": shape}
    )
    return buffer.getvalue() + payload


def test_an_npz_member_whose_header_claims_gigabytes_is_refused_before_allocation(tmp_path):
    path = tmp_path / NORMALIZATION_FILE
    with zipfile.ZipFile(path, "w") as archive:
        archive.writestr("mean.npy", _npy_with_header((1 << 29,), bytes(80)))  # 4 GiB claimed
    with pytest.raises(UsageError, match=r"declares shape \(536870912,\)"):
        limits.load_npz(path, 1 << 20, 1 << 20)


def test_normalisation_settings_out_of_range_are_refused(folder):
    venv = None
    for name, value in (("clip_obs", -5.0), ("count", -1e300), ("epsilon", 0.0)):
        arrays = dict(np.load(folder / NORMALIZATION_FILE))
        arrays[name] = np.float64(value)
        path = folder / f"{name}.npz"
        with path.open("wb") as handle:
            np.savez(handle, **arrays)
        with pytest.raises(UsageError, match=f"{name} must be one number in"):
            load_normalization(path, venv)


def test_a_huge_sparse_file_is_not_hashed(folder):
    with (folder / "model.zip").open("r+b") as handle:
        handle.truncate((limits.MAX_HASHED_BYTES) + 1)  # sparse: nothing written
    start = time.perf_counter()
    with pytest.raises(UsageError, match=r"bytes; at most \d+ allowed"):
        verify_manifest(folder, ("model.zip",))
    assert time.perf_counter() - start < 1.0


def test_a_run_config_whose_net_arch_contradicts_the_model_is_refused(folder):
    config = folder / "config.yml"
    config.write_text(config.read_text().replace("- 256\n", "- 32\n"))
    write_manifest(folder)
    with pytest.raises(UsageError, match="net_arch"):
        _load(folder)


# ---------------------------------------------------------------- maps


def _png(width: int, height: int, pixels: bytes) -> bytes:
    """A grey PNG whose header says ``width`` x ``height``, holding ``pixels`` deflated."""

    def chunk(kind: bytes, data: bytes) -> bytes:
        crc = zlib.crc32(kind + data) & 0xFFFFFFFF
        return struct.pack(">I", len(data)) + kind + data + struct.pack(">I", crc)

    header = struct.pack(">IIBBBBB", width, height, 8, 0, 0, 0, 0)
    body = chunk(b"IDAT", zlib.compress(pixels)) + chunk(b"IEND", b"")
    return b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", header) + body


@pytest.mark.parametrize(
    "name, content, message",
    [
        ("noise.png", bytes(range(256)) * 16, "not a readable PNG"),
        ("cut.png", _png(40, 30, bytes(41 * 30))[:60], "(not a readable PNG|has no free cell)"),
        ("wide.png", _png(5_000, 300, bytes(100)), "5000 x 300 pixels; at most"),
        ("huge.png", _png(20_000, 20_000, bytes(100)), "(pixels; at most|not a readable PNG)"),
        ("bytes.txt", b"###\n#\xff#\n###\n", "is not UTF-8 text"),
        ("feed.txt", b"#####\n#...#\x0c#...#\n#####\n", r"character '\\x0c'"),
        ("separator.txt", "#####\n#...#\u2028#...#\n#####\n".encode(), r"character '\\u2028'"),
    ],
)
def test_a_bad_map_file_is_one_map_error(tmp_path, name, content, message):
    path = tmp_path / name
    path.write_bytes(content)
    with pytest.raises(MapError, match=message):
        load_map_file(path)
    with pytest.raises(ValueError, match=message):
        gym.make("motiongym/Sweeper-v1", map_file=str(path))


def test_a_map_of_many_rows_is_refused_at_once(tmp_path):
    path = tmp_path / "rows.txt"
    path.write_bytes(b"#\n" * 500_000)  # 1 MB: under the byte cap, far past MAX_SIDE lines
    start = time.perf_counter()
    with pytest.raises(MapError, match=f"at most {MAX_SIDE}"):
        load_map_file(path)
    assert time.perf_counter() - start < 1.0


# ---------------------------------------------------------------- render sizes


@pytest.mark.parametrize(
    "env_id, kwargs",
    [
        ("motiongym/HarvestArm-v1", {"render_size": (700, 1100)}),
        ("motiongym/ExcavatorReach-v1", {"render_size": (480, 1000)}),
    ],
)
def test_render_sizes_past_the_default_framebuffer_render(env_id, kwargs):
    env = gym.make(env_id, render_mode="rgb_array", **kwargs)
    env.reset(seed=0)
    assert env.render().shape == (*kwargs["render_size"], 3)
    env.close()


# ---------------------------------------------------------------- output folders


@pytest.mark.parametrize(
    "text, message",
    [
        ("/proc/motiongym", "kernel interface"),
        ("/sys/motiongym", "kernel interface"),
        ("out/" + "a" * 300, "a name of 300 bytes"),
    ],
)
def test_an_output_that_cannot_be_written_is_refused_before_work(text, message):
    for check in (_folder, _file):
        with pytest.raises(argparse.ArgumentTypeError, match=message):
            check(text)


def test_record_every_is_bounded_before_the_episode(tmp_path, capsys):
    code = main(["record", "motiongym/Sweeper-v1", "--every", "1000000000", "--out", str(tmp_path)])
    assert code == 2
    assert "--every must be in [1, " in capsys.readouterr().err
    assert not any(tmp_path.iterdir())


# ---------------------------------------------------------------- ruinous settings


@pytest.mark.parametrize(
    "setting, message",
    [
        ("policy_kwargs: {net_arch: [65536, 65536, 65536]}", "net_arch layer size"),
        ("policy_kwargs: {net_arch: [4096, 4096, 4096]}", "weights between its hidden layers"),
        ("policy_kwargs: {net_arch: [" + "8, " * 40 + "8]}", "at most 16 layer sizes"),
        ("n_envs: 1024\n  n_steps: 100000", r"n_steps \* n_envs must be at most"),
    ],
)
def test_ruinous_network_and_rollout_sizes_are_refused(tmp_path, setting, message):
    config = tmp_path / "config.yml"
    config.write_text(f"ppo:\n  n_timesteps: 1\n  policy: MlpPolicy\n  {setting}\n")
    with pytest.raises(UsageError, match=message):
        load_config(config, "ppo")


def test_json_limits_hold_for_plain_documents():
    assert limits.load_json(json.dumps({"a": [1, 2]}), "x", 100) == {"a": [1, 2]}
    assert limits.load_yaml("a: [1, 2]\nb: {c: 3}\n", "x") == {"a": [1, 2], "b": {"c": 3}}


def test_bench_with_an_unknown_id_writes_nothing(tmp_path, capsys):
    import tempfile

    before = set(Path(tempfile.gettempdir()).glob("SB3-*"))
    assert main(["bench", "motiongym/Nope-v0", "--out", str(tmp_path / "bench")]) == 2
    assert "unknown environment ID 'motiongym/Nope-v0'" in capsys.readouterr().err
    assert set(Path(tempfile.gettempdir()).glob("SB3-*")) == before
    assert not (tmp_path / "bench").exists()


def test_a_key_given_twice_in_a_config_is_refused(tmp_path):
    config = tmp_path / "twice.yml"
    config.write_text("ppo:\n  n_timesteps: 1\n  policy: MlpPolicy\n  n_timesteps: 2\n")
    with pytest.raises(UsageError, match=r"key 'n_timesteps' given twice \(line 4\)"):
        load_config(config, "ppo")
