"""Property-based hostile files (Hypothesis): model folders and training configs.

Model folders: a shipped model (with its normalisation statistics) copied,
then one file truncated or one byte flipped, loaded both ways a user can
(``--trust`` without a manifest, or with a manifest rewritten to match, as an
attacker would); and payloads planted where a loader might unpickle
(``vecnormalize.pkl``, a serialized entry of ``model.zip``'s data JSON, the
weights, the statistics, the run's config). The property: a
:class:`~motiongym.agents.errors.UsageError` (one line) or a predictor whose
action is finite and in the action space; a planted payload never runs (it
only ``echo``\\ s into a marker file, which must never appear).

Config files: a block of Hypothesis-generated YAML values for the run
settings and common algorithm keys; the property: ``UsageError`` naming the
file, or a validated block whose counts and rates lie in their ranges.
"""

from __future__ import annotations

import base64
import contextlib
import io
import json
import os
import pickle
import shutil
from pathlib import Path

import numpy as np
import pytest
import yaml
from fuzzing import OUTCOMES
from hypothesis import given
from hypothesis import strategies as st
from zip_members import rewrite_zip

from motiongym.agents.environments import make_env
from motiongym.agents.errors import UsageError
from motiongym.agents.models.predictors import load_predictor
from motiongym.agents.models.pretrained import pretrained_models, write_manifest
from motiongym.agents.training.config import RUN_SETTINGS, load_config

ENV_ID = "motiongym/HarvestArm-v0"  # a shipped PPO model with normalisation statistics
FILES = ("model.zip", "vecnormalize.npz", "config.yml", "manifest.json")


class Payload:
    """A pickle that, if ever unpickled, echoes into ``marker``."""

    def __init__(self, marker: Path) -> None:
        self.marker = marker

    def __reduce__(self):
        return (os.system, (f"echo pwned > {self.marker}",))


@pytest.fixture(scope="module")
def shipped() -> Path:
    return pretrained_models(ENV_ID)["ppo"]


@pytest.fixture(scope="module")
def env():
    return make_env(ENV_ID)


def _copy(shipped: Path, root: Path) -> Path:
    folder = root / "run"
    shutil.rmtree(folder, ignore_errors=True)
    shutil.copytree(shipped, folder)
    return folder


def _outcome(area: str, folder: Path, env, trust: bool) -> None:
    """Load ``folder``: a one-line usage error, or a predictor acting finitely."""
    try:
        with contextlib.redirect_stderr(io.StringIO()):  # the --trust warning, every time
            predictor = load_predictor(str(folder), ENV_ID, env, trust=trust)
    except UsageError as error:
        assert str(error) and "\n" not in str(error), error
        OUTCOMES[f"{area}: clear error"] += 1
        return
    observation, _ = env.reset(seed=0)
    action, _ = predictor.predict(observation, deterministic=True)
    assert np.isfinite(action).all() and env.action_space.contains(action.astype(np.float32))
    OUTCOMES[f"{area}: valid"] += 1


def _seal(folder: Path, attacker: bool) -> bool:
    """Rewrite the manifest to match (an attacker), or remove it (the user says --trust)."""
    if attacker:
        write_manifest(folder)
        return False
    (folder / "manifest.json").unlink(missing_ok=True)
    return True


@given(
    name=st.sampled_from(FILES),
    cut=st.floats(0.0, 1.0, exclude_max=True),
    flip=st.booleans(),
    mask=st.integers(1, 255),
    attacker=st.booleans(),
)
def test_a_damaged_model_folder_is_a_clear_error_or_a_sound_predictor(
    shipped, env, tmp_path_factory, name, cut, flip, mask, attacker
):
    folder = _copy(shipped, tmp_path_factory.getbasetemp())
    path = folder / name
    content = bytearray(path.read_bytes())
    position = int(cut * len(content))
    if flip:
        content[position] ^= mask
    else:
        del content[position:]
    path.write_bytes(bytes(content))
    # a damaged manifest is loaded as it is; any other damaged file with the manifest
    # rewritten to match (an attacker) or removed (--trust)
    trust = False if name == "manifest.json" else _seal(folder, attacker)
    _outcome(f"model folder, {'flipped' if flip else 'truncated'} {name}", folder, env, trust)


def _plant(folder: Path, where: str, key: str, blob: bytes) -> None:
    """Put the pickle ``blob`` at ``where`` in the folder (``key``: which entry)."""
    encoded = base64.b64encode(blob).decode()
    if where == "vecnormalize.pkl":
        (folder / "vecnormalize.npz").unlink()
        (folder / "vecnormalize.pkl").write_bytes(blob)
    elif where == "data entry":

        def change(members):
            data = json.loads(members["data"])
            entry = data.get(key) if isinstance(data.get(key), dict) else {}
            data[key] = {**entry, ":type:": "<class 'object'>", ":serialized:": encoded}
            members["data"] = json.dumps(data).encode()

        rewrite_zip(folder / "model.zip", change)
    elif where == "weights":

        def change(members):
            members["policy.pth"] = blob

        rewrite_zip(folder / "model.zip", change)
    elif where == "statistics":
        with np.load(folder / "vecnormalize.npz") as file:
            arrays = {name: file[name] for name in file.files}
        arrays[key] = np.array([Payload(Path("unused"))], dtype=object)
        buffer = io.BytesIO()
        np.savez(buffer, **arrays)
        (folder / "vecnormalize.npz").write_bytes(buffer.getvalue())
    else:  # the run's config: a YAML tag that an unsafe loader would call
        text = (folder / "config.yml").read_text()
        (folder / "config.yml").write_text(f"{text}{key}: !!python/object/apply:os.system [x]\n")


DATA_KEYS = [
    "policy_class",
    "observation_space",
    "action_space",
    "lr_schedule",
    "clip_range",
    "policy_kwargs",
    "_last_obs",
    "ep_info_buffer",
    "innocent",
    "n_steps",
]


@given(
    where=st.sampled_from(["vecnormalize.pkl", "data entry", "weights", "statistics", "config"]),
    key=st.sampled_from(DATA_KEYS),
    attacker=st.booleans(),
)
def test_a_planted_payload_never_runs(shipped, env, tmp_path_factory, where, key, attacker):
    root = tmp_path_factory.getbasetemp()
    folder = _copy(shipped, root)
    marker = root / "marker"
    marker.unlink(missing_ok=True)
    blob = pickle.dumps(Payload(marker))
    if where == "statistics":
        key = "mean"
    _plant(folder, where, key, blob)
    trust = _seal(folder, attacker)
    _outcome(f"planted payload in {where}", folder, env, trust)
    assert not marker.exists(), f"payload in {where} ({key}) ran"


YAML_VALUES = st.one_of(
    st.none(),
    st.booleans(),
    st.integers(-(2**70), 2**70),
    st.floats(allow_nan=True, allow_infinity=True),
    st.text(max_size=8),
    st.lists(st.integers(-5, 300), max_size=3),
    st.dictionaries(st.sampled_from(["net_arch", "activation_fn", "bogus"]), st.integers(-3, 64)),
)
CONFIG_KEYS = sorted(
    {*RUN_SETTINGS, "learning_rate", "gamma", "n_steps", "batch_size", "ent_coef", "clip_range"}
)


PLAUSIBLE = st.one_of(st.integers(1, 256), st.floats(1e-4, 0.999), st.sampled_from(["dummy", True]))


@given(
    settings=st.dictionaries(
        st.sampled_from(CONFIG_KEYS), st.one_of(YAML_VALUES, PLAUSIBLE), max_size=3
    )
)
def test_a_generated_config_is_a_named_error_or_a_valid_block(tmp_path_factory, settings):
    block = {"n_timesteps": 64, "policy": "MlpPolicy", **settings}
    path = tmp_path_factory.getbasetemp() / "generated.yml"
    path.write_text(yaml.safe_dump({"ppo": block}))
    try:
        config = load_config(path, "ppo")
    except UsageError as error:
        assert str(path) in str(error) and "\n" not in str(error), error
        OUTCOMES["config file: clear error"] += 1
        return
    assert config["n_envs"] >= 1 and config["n_timesteps"] >= 1
    assert config["eval_freq"] >= 1 and config["checkpoint_freq"] >= 1
    for key in ("learning_rate", "gamma"):
        assert key not in config or 0 < config[key] <= 10
    OUTCOMES["config file: valid"] += 1
