"""Scripted policies as teachers: their episodes recorded as Minari datasets.

``motiongym dataset ID --policy NAME --episodes N --out DIR`` runs the
scripted policy ``NAME`` declared for ``ID`` on ``N`` seeded episodes (episode
``i`` reset with seed ``seed + i``; the default :data:`DATASET_SEED` is far from
the evaluation seeds, so demonstrations never show a held-out scene) and
writes them with Minari's ``DataCollector`` (Farama's offline-RL format,
observations, actions, rewards, terminations, truncations and every ``info``
key) under ``DIR/<dataset id>``, with the observation and action spaces of
the environment made (with ``env_kwargs``, its spec too), so that the
metadata describe the data. The metadata name the teacher:
``algorithm_name`` is ``"<policy> (motiongym <version>)"`` and the keys
:data:`METADATA_KEYS` hold the ID, the policy's name, class and version (the
package's: a scripted policy changes only with a release) and the first seed.

:func:`load_demonstrations` opens such a folder for an environment and
refuses, with a ``ValueError`` naming both, a dataset recorded on another ID
or with other spaces. Minari is the optional extra ``motiongym[offline]``
(in ``dev``); without it these raise a :class:`UsageError` that says so.
"""

from __future__ import annotations

import contextlib
import os
import warnings
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import gymnasium as gym
import numpy as np

from motiongym.agents.environments import check_env_id, made_kwargs, make_env, short_name
from motiongym.agents.errors import UsageError
from motiongym.agents.evaluation.episodes import Step, run_episode
from motiongym.agents.limits import read_json_file
from motiongym.baselines import make_policy, scripted_policies

DATASET_SEED = 500_000  # first episode's seed; evaluations start at 100_000 and count up
MAX_METADATA_BYTES = 1 << 20  # a dataset's metadata.json (a few kB)
METADATA_KEYS = ("env_id", "policy_name", "policy_class", "policy_version", "first_seed")


def _minari():
    try:
        import minari
    except ImportError as error:  # pragma: no cover - minari is in dev
        raise UsageError(
            "Minari datasets need the optional extra: pip install 'motiongym[offline]'"
        ) from error
    return minari


@contextlib.contextmanager
def _datasets_root(root: Path) -> Iterator[None]:
    """Minari's dataset folder (``MINARI_DATASETS_PATH``) set to ``root`` meanwhile."""
    before = os.environ.get("MINARI_DATASETS_PATH")
    os.environ["MINARI_DATASETS_PATH"] = str(root.resolve())
    try:
        yield
    finally:
        if before is None:
            del os.environ["MINARI_DATASETS_PATH"]
        else:
            os.environ["MINARI_DATASETS_PATH"] = before


def dataset_id(env_id: str, policy: str) -> str:
    """``motiongym/<Name>-vN/<policy>-v0``: Minari's ``namespace/env_name/dataset-vK``."""
    return f"motiongym/{short_name(env_id)}/{policy}-v0"


def record_dataset(
    env_id: str,
    policy: str,
    episodes: int,
    out: Path,
    seed: int = DATASET_SEED,
    env_kwargs: dict[str, Any] | None = None,
) -> tuple[Path, float]:
    """Record ``episodes`` episodes of the scripted ``policy`` on ``env_id``.

    Returns:
        ``(dataset folder, success rate of the recorded episodes)``.
    """
    from motiongym import __version__

    minari = _minari()
    check_env_id(env_id)
    if policy not in scripted_policies(env_id):
        choices = ", ".join(sorted(scripted_policies(env_id))) or "none"
        raise UsageError(f"unknown policy {policy!r} for {env_id}; scripted policies: {choices}")
    if episodes < 1:
        raise UsageError(f"episodes must be at least 1, got {episodes}")
    name = dataset_id(env_id, policy)
    path = Path(out) / name
    if path.exists():
        raise UsageError(f"{path} exists already; remove it or choose another --out")
    env = make_env(env_id, env_kwargs)  # the keywords checked as for every command
    teacher = make_policy(env_id, policy, env.observation_space, env.action_space, made_kwargs(env))
    buffers = [_episode(minari, env, teacher, seed + i, i) for i in range(episodes)]
    successes = sum(bool(b.infos["is_success"][-1]) for b in buffers)
    with _datasets_root(Path(out)), warnings.catch_warnings():
        warnings.filterwarnings("ignore", "`(code_permalink|author_email)` is set to None")
        dataset = minari.create_dataset_from_buffers(
            dataset_id=name,
            buffer=buffers,
            # the spec made (its keywords) where they are not the registered ones
            env=env.spec if env_kwargs and env.spec else env_id,
            eval_env=env.spec if env_kwargs and env.spec else env_id,
            observation_space=env.observation_space,  # the spaces of the data it holds
            action_space=env.action_space,
            algorithm_name=f"{policy} (motiongym {__version__})",
            author="motiongym",
            description=f"scripted {policy!r} on {env_id}, seeds {seed}-{seed + episodes - 1}",
            data_format="hdf5",
        )
        dataset.storage.update_metadata(
            dict(
                zip(
                    METADATA_KEYS,
                    (env_id, policy, scripted_policies(env_id)[policy], __version__, seed),
                    strict=True,
                )
            )
        )
    env.close()
    return path, successes / episodes


def stack_steps(items: list[Any]) -> Any:
    """A list of arrays (or of dicts of them) as one array (or a dict of arrays), step first."""
    if isinstance(items[0], dict):
        return {k: np.stack([np.asarray(i[k]) for i in items]) for k in items[0]}
    return np.stack([np.asarray(i) for i in items])


def _episode(minari: Any, env: gym.Env, teacher: Any, seed: int, index: int) -> Any:
    """One episode of ``teacher`` (through the one episode loop,
    :func:`~motiongym.agents.evaluation.episodes.run_episode`) as Minari's
    ``EpisodeBuffer`` (observations and infos one longer: the reset's first)."""
    observations: list[Any] = []
    infos: list[dict[str, Any]] = []
    actions: list[Any] = []
    rewards: list[float] = []
    terminations: list[bool] = []
    truncations: list[bool] = []

    def start(observation: Any, info: dict[str, Any]) -> None:
        observations.append(observation)
        infos.append(info)

    def keep(step: Step) -> None:
        observations.append(step.next_observation)
        infos.append(step.info)
        actions.append(step.action)
        rewards.append(step.reward)
        terminations.append(step.terminated)
        truncations.append(step.truncated)

    run_episode(env, teacher, seed, hook=keep, on_reset=start)
    return minari.data_collector.EpisodeBuffer(
        id=index,
        seed=seed,
        observations=stack_steps(observations),
        actions=stack_steps(actions),
        rewards=list(map(float, rewards)),
        terminations=list(map(bool, terminations)),
        truncations=list(map(bool, truncations)),
        infos=stack_steps(infos),
    )


def load_demonstrations(path: Path | str, env: gym.Env) -> Any:
    """The Minari dataset at ``path``, checked to be of ``env``'s ID and spaces.

    ``env`` is a made environment (its ``spec.id`` and spaces are compared);
    a dataset of another ID or space is a ``ValueError`` naming both.
    """
    minari = _minari()
    folder = Path(path)
    if not (folder / "data" / "metadata.json").is_file():
        raise ValueError(
            f"path must be a Minari dataset folder (with data/metadata.json), got {path}"
        )
    try:  # the metadata checked (size, nesting) before Minari parses them
        read_json_file(folder / "data" / "metadata.json", MAX_METADATA_BYTES)
    except UsageError as error:
        raise ValueError(str(error)) from None
    dataset = minari.MinariDataset(folder / "data")
    meta = dataset.storage.metadata
    env_id = env.spec.id if env.spec else None
    if meta.get("env_id") != env_id:
        raise ValueError(
            f"dataset {path} was recorded on {meta.get('env_id')!r}, not on the environment's "
            f"ID {env_id!r}"
        )
    for kind in ("observation_space", "action_space"):
        if getattr(dataset, kind) != getattr(env, kind):
            raise ValueError(
                f"dataset {path} has the {kind} {_space_text(getattr(dataset, kind))}, the "
                f"environment {_space_text(getattr(env, kind))} (record it with the same "
                "env_kwargs)"
            )
    return dataset


def _space_text(space: Any) -> str:
    """A one-line name of a space: its class and shape (or its keys)."""
    if isinstance(space, gym.spaces.Dict):
        return f"Dict({', '.join(f'{k}: {_space_text(v)}' for k, v in space.spaces.items())})"
    return f"{type(space).__name__}{getattr(space, 'shape', '')}"


def transitions(dataset: Any) -> tuple[Any, np.ndarray]:
    """``(observations, actions)`` of every step: arrays (or a dict of arrays) with rows aligned."""
    observations: list[Any] = []
    actions: list[np.ndarray] = []
    for episode in dataset.iterate_episodes():
        obs = episode.observations
        if isinstance(obs, dict):
            observations.append({k: np.asarray(v)[:-1] for k, v in obs.items()})
        else:
            observations.append(np.asarray(obs)[:-1])
        actions.append(np.asarray(episode.actions))
    if isinstance(observations[0], dict):
        keys = observations[0]
        return {k: np.concatenate([o[k] for o in observations]) for k in keys}, np.concatenate(
            actions
        )
    return np.concatenate(observations), np.concatenate(actions)
