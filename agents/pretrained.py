"""The trained models shipped in ``agents/pretrained/``.

Layout: ``pretrained/<Name>-vN/<algo>/`` holds a run folder's ``model.zip``,
``config.yml``, ``command.txt``, ``metrics.json``, optionally
``vecnormalize.pkl``, and ``manifest.json``: the SHA-256 of every other file.
The manifest is checked before a model is used.
"""

from __future__ import annotations

import hashlib
import json
from importlib import resources
from pathlib import Path

from motiongym.agents.environments import short_name
from motiongym.agents.errors import UsageError

MANIFEST = "manifest.json"


def pretrained_root() -> Path:
    return Path(str(resources.files("motiongym.agents") / "pretrained"))


def sha256(path: Path) -> str:
    return hashlib.sha256(path.read_bytes()).hexdigest()


def write_manifest(folder: Path) -> Path:
    """Record the SHA-256 of every file of ``folder`` (but the manifest)."""
    digests = {
        p.name: sha256(p) for p in sorted(folder.iterdir()) if p.is_file() and p.name != MANIFEST
    }
    path = folder / MANIFEST
    path.write_text(json.dumps(digests, indent=2) + "\n")
    return path


def verify_manifest(folder: Path) -> None:
    """Raise :class:`UsageError` unless every file matches the manifest."""
    manifest = folder / MANIFEST
    if not manifest.is_file():
        raise UsageError(f"{folder} has no {MANIFEST}")
    for name, digest in json.loads(manifest.read_text()).items():
        path = folder / name
        if not path.is_file():
            raise UsageError(f"{path} is listed in {manifest} but missing")
        if sha256(path) != digest:
            raise UsageError(f"{path} does not match its SHA-256 in {manifest}")


def pretrained_models(env_id: str) -> dict[str, Path]:
    """``{label: folder}`` of the models shipped for ``env_id`` (label ``<algo>``)."""
    root = pretrained_root() / short_name(env_id)
    if not root.is_dir():
        return {}
    return {
        folder.name: folder for folder in sorted(root.iterdir()) if (folder / "model.zip").is_file()
    }


SHIPPED_FILES = ("model.zip", "vecnormalize.pkl", "config.yml", "command.txt")


def ship(
    run_dir: Path, n_episodes: int = 20, seed: int = 100_000, root: Path | None = None
) -> Path:
    """Copy a training run into ``pretrained/`` with its metrics and manifest.

    The run's ``config.yml`` names the ID and algorithm; the model is
    evaluated on ``n_episodes`` held-out seeds from ``seed`` and the summary
    saved as ``metrics.json``; the manifest is written last.
    """
    import shutil

    import yaml

    from motiongym.agents.environments import make_env
    from motiongym.agents.evaluate import EVALUATION_SEED, evaluate
    from motiongym.agents.predictors import load_model

    config_file = run_dir / "config.yml"
    if not config_file.is_file():
        raise UsageError(f"{run_dir} is not a training run folder (no config.yml)")
    config = yaml.safe_load(config_file.read_text())
    env_id, algo = config["env_id"], config["algo"]
    folder = (root or pretrained_root()) / short_name(env_id) / algo
    folder.mkdir(parents=True, exist_ok=True)
    for name in SHIPPED_FILES:
        if (run_dir / name).is_file():
            shutil.copy2(run_dir / name, folder / name)
    env = make_env(env_id, config.get("env_kwargs"))
    model = load_model(folder, env, env_id)
    seed = EVALUATION_SEED if seed is None else seed
    evaluation = evaluate(env, model, range(seed, seed + n_episodes), env_id, algo)
    metrics = {"env_id": env_id, "algo": algo, "run": run_dir.name, **evaluation.to_json()}
    (folder / "metrics.json").write_text(json.dumps(metrics, indent=2))
    write_manifest(folder)
    return folder
