"""Model folders from anyone: nothing in them runs, bad statistics are refused.

Planted payloads only ``echo`` into a file under the test's temporary folder;
every test asserts that the file never appears.
"""

from __future__ import annotations

import base64
import io
import json
import os
import pickle
import shutil
import zipfile

import numpy as np
import pytest
from zip_members import rewrite_zip

from motiongym.agents.environments import make_env
from motiongym.agents.errors import UsageError
from motiongym.agents.models.files import NORMALIZATION_FILE
from motiongym.agents.models.predictors import load_predictor
from motiongym.agents.models.pretrained import pretrained_models, write_manifest

ENV_ID = "motiongym/HarvestArm-v0"


class Payload:
    def __init__(self, marker):
        self.marker = marker

    def __reduce__(self):
        return (os.system, (f"echo pwned > {self.marker}",))


@pytest.fixture
def folder(tmp_path):
    copy = tmp_path / "run"
    shutil.copytree(pretrained_models(ENV_ID)["ppo"], copy)
    return copy


def _rewrite(folder, change):
    """Apply ``change(members)`` to model.zip's members, then write a matching manifest
    (as an attacker would)."""
    rewrite_zip(folder / "model.zip", change)
    write_manifest(folder)


def _set_data(folder, key, value):
    """model.zip's data JSON with ``key`` set to ``value`` (manifest rewritten)."""

    def change(members):
        data = json.loads(members["data"])
        data[key] = value(data.get(key)) if callable(value) else value
        members["data"] = json.dumps(data).encode()

    _rewrite(folder, change)


def _load(path, trust=False):
    env = make_env(ENV_ID)
    return load_predictor(str(path), ENV_ID, env, trust=trust)


def test_a_shipped_model_copied_with_its_manifest_loads_and_acts(folder):
    predictor = _load(folder)
    env = make_env(ENV_ID)
    observation, _ = env.reset(seed=0)
    action, _ = predictor.predict(observation)
    assert env.action_space.contains(action.astype(np.float32))


def test_a_planted_vecnormalize_pickle_is_never_read(folder, tmp_path):
    marker = tmp_path / "marker"
    (folder / NORMALIZATION_FILE).unlink()
    (folder / "vecnormalize.pkl").write_bytes(pickle.dumps(Payload(marker)))
    write_manifest(folder)  # an attacker writes a matching manifest too
    with pytest.raises(UsageError, match="pickle"):
        _load(folder)
    assert not marker.exists()


def test_an_extra_serialized_entry_in_the_archive_is_refused_by_name(folder, tmp_path):
    marker = tmp_path / "marker"
    blob = base64.b64encode(pickle.dumps(Payload(marker))).decode()
    _set_data(folder, "innocent", {":type:": "<class 'object'>", ":serialized:": blob})
    with pytest.raises(UsageError, match="innocent"):
        _load(folder)
    assert not marker.exists()


def test_an_extra_plain_data_entry_is_refused_by_name(folder):
    _set_data(folder, "predict", "a plain entry SB3 would set over the model's method")
    with pytest.raises(UsageError, match=r"unknown data entry \['predict'\]"):
        _load(folder)


def test_a_replaced_serialized_policy_class_is_never_unpickled(folder, tmp_path):
    marker = tmp_path / "marker"
    blob = base64.b64encode(pickle.dumps(Payload(marker))).decode()
    _set_data(folder, "policy_class", lambda entry: {**entry, ":serialized:": blob})
    _load(folder)  # the class is identified from its plain-text module and docstring
    assert not marker.exists()


def test_an_unknown_archive_member_is_refused(folder):
    with zipfile.ZipFile(folder / "model.zip", "a") as z:
        z.writestr("extra.pkl", b"anything")
    write_manifest(folder)
    with pytest.raises(UsageError, match="extra.pkl"):
        _load(folder)


def test_a_folder_without_manifest_needs_trust_and_warns(folder, capsys):
    (folder / "manifest.json").unlink()
    with pytest.raises(UsageError, match="--trust"):
        _load(folder)
    _load(folder, trust=True)
    assert "without a manifest" in capsys.readouterr().err


def test_a_flipped_byte_in_the_statistics_is_caught(folder):
    path = folder / NORMALIZATION_FILE
    with np.load(path) as file:
        arrays = {name: file[name] for name in file.files}
    arrays["mean"] = arrays["mean"].copy()
    arrays["mean"][3] = 1.6e308  # a flipped exponent byte of 0.884
    np.savez(path, **arrays)
    with pytest.raises(UsageError, match="SHA-256"):
        _load(folder)  # the manifest sees it first
    (folder / "manifest.json").unlink()
    with pytest.raises(UsageError, match="mean\\[3\\]"):
        _load(folder, trust=True)  # and the statistics' own check without it
    arrays["var"] = arrays["var"].copy()
    arrays["mean"][3], arrays["var"][0] = 0.0, float("nan")
    np.savez(path, **arrays)
    with pytest.raises(UsageError, match="not finite"):
        _load(folder, trust=True)


def test_a_truncated_archive_is_one_clear_error(folder):
    archive = folder / "model.zip"
    archive.write_bytes(archive.read_bytes()[:500])
    (folder / "manifest.json").unlink()
    with pytest.raises(UsageError, match="not a Stable-Baselines3 model"):
        _load(folder, trust=True)


def test_a_manifest_must_list_the_files_it_vouches_for(folder):
    manifest = folder / "manifest.json"
    digests = json.loads(manifest.read_text())
    del digests["model.zip"]  # a manifest that leaves the model out verifies nothing
    manifest.write_text(json.dumps(digests))
    with pytest.raises(UsageError, match="does not list \\['model.zip'\\]"):
        _load(folder)
    for text in ("{not json", "[1, 2]", json.dumps({"../model.zip": "0" * 64})):
        manifest.write_text(text)
        with pytest.raises(UsageError, match="manifest.json"):
            _load(folder)


def test_non_finite_weights_are_refused(folder):
    import torch

    def change(members):
        weights = torch.load(io.BytesIO(members["policy.pth"]), weights_only=True)
        weights[name] = weights[name].clone().fill_(float("inf"))
        buffer = io.BytesIO()
        torch.save(weights, buffer)
        members["policy.pth"] = buffer.getvalue()

    name = "mlp_extractor.policy_net.0.weight"
    _rewrite(folder, change)
    with pytest.raises(UsageError, match=f"weights {name} are not finite"):
        _load(folder)


def test_a_run_config_beside_the_model_is_checked_like_a_config_file(folder):
    import yaml

    config = folder / "config.yml"
    settings = yaml.safe_load(config.read_text())
    settings["policy_kwargs"]["net_arch"] = 7
    config.write_text(yaml.safe_dump(settings))
    write_manifest(folder)
    with pytest.raises(UsageError, match="net_arch must be a list"):
        _load(folder)
    config.write_text("- a list, not a mapping\n")
    write_manifest(folder)
    with pytest.raises(UsageError, match="must be a mapping"):
        _load(folder)


def test_links_and_oversized_text_files_are_refused(folder, tmp_path):
    outside = tmp_path / "elsewhere.yml"
    (folder / "config.yml").rename(outside)
    (folder / "config.yml").symlink_to(outside)
    with pytest.raises(UsageError, match="config.yml is a link"):
        _load(folder, trust=True)
    (folder / "config.yml").unlink()
    (folder / "config.yml").write_text("#" * (1 << 21))
    with pytest.raises(UsageError, match="larger than"):
        _load(folder, trust=True)
