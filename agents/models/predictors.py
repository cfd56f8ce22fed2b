"""Turning a policy name or a model path into an SB3-style predictor.

A *predictor* is anything with SB3's ``predict(observation, state,
episode_start, deterministic)``: a scripted policy from
:mod:`motiongym.baselines`, or a trained SB3 model. A policy is named by

* a scripted policy's name declared for the environment ID (``psa-cwa``);
* ``random``, for every ID: uniform actions, within the action masks where the
  environment gives them (:class:`RandomPolicy`), the floor every policy
  should beat;
* a trained model: a ``.zip`` written by SB3, or a run folder written by
  ``motiongym train`` (holding ``model.zip`` and, if the run normalised
  observations, ``vecnormalize.npz``, which is applied here). Nothing in a
  model folder is unpickled (:mod:`motiongym.agents.models.files`); a folder's
  ``manifest.json`` is verified first, and one without needs ``trust``.
  An rl-zoo3 run (``logs/<algo>/<env-name>_<n>/``, ``<env-name>`` the ID
  with ``/`` as ``-``) keeps its model in ``<env-name>.zip`` and its
  normalisation in ``<env-name>/vecnormalize.pkl``, a pickle: it is found,
  named and refused (a pickle runs code when loaded; motiongym never unpickles
  a file from a folder it is handed), with the two lines that convert it to
  ``vecnormalize.npz`` beside the model where the user trusts the file,
  which is then applied; a model from outside motiongym with no normalisation found is
  evaluated on raw observations, with a warning that says so. A run whose
  ``config.yml`` says ``vec_env: pettingzoo`` trained one policy for every
  agent; it acts in the single-agent environment through
  :class:`~motiongym.agents.training.multiagent.SharedPolicyPredictor`. A run whose
  ``config.yml`` says ``deterministic: false`` samples its actions
  (:class:`SampledModel`) whatever its caller asks; one that says
  ``residual: <policy>`` adds its output to that scripted policy's
  (:class:`~motiongym.agents.training.residual.ResidualPredictor`); one that says
  ``memory: <name>`` was trained on observations with a memory added
  (:mod:`motiongym.agents.learners`), which
  :class:`~motiongym.agents.learners.memory.MapMemoryPredictor` builds from the
  observations it is given, reset at each episode's start.

The algorithm of a bare ``.zip`` is read from the policy class saved in it
(PPO and A2C share theirs, and either predicts the same way).
"""

from __future__ import annotations

import copy
from pathlib import Path
from typing import Any

import gymnasium as gym
import numpy as np
import torch
from gymnasium import spaces
from sb3_contrib import MaskablePPO
from stable_baselines3.common.base_class import BaseAlgorithm
from stable_baselines3.common.vec_env import DummyVecEnv, VecEnv, VecNormalize

from motiongym.agents.environments import resolved_env_kwargs
from motiongym.agents.errors import UsageError
from motiongym.agents.learners import memories
from motiongym.agents.learners.memory import MapMemoryPredictor
from motiongym.agents.limits import load_npz, read_yaml_file
from motiongym.agents.models.files import (
    MAX_NORMALIZATION_BYTES,
    NORMALIZATION_FILE,
    PICKLED_NORMALIZATION,
    load_archive,
    load_normalization,
    warn,
)
from motiongym.agents.models.pretrained import MANIFEST, pretrained_models, verify_manifest
from motiongym.agents.training.multiagent import (
    SharedPolicyPredictor,
    SharedPolicyVecEnv,
    check_single_agent_view,
    parallel_factory,
)
from motiongym.baselines import make_policy, scripted_policies

MODEL_FILE = "model.zip"
CONFIG_FILE = "config.yml"
MAX_TEXT_BYTES = 1 << 20  # config.yml and manifest.json: a run's are a few hundred bytes
RUN_RECORD = ("env_id", "algo", "seed", "config_file")  # what train adds to the block
RANDOM = "random"


class RandomPolicy:
    """Uniform random actions: the reference row of ``compare`` for every ID.

    At each episode start the action space's generator is seeded from torch's
    generator, which :func:`~motiongym.agents.evaluation.episodes.run_episode` seeds from
    the episode's seed: the same episode draws the same actions in every
    evaluation. Where the environment gives action masks (the sweeper), the
    action is drawn among the allowed ones, as a masked agent's would be.
    """

    def __init__(self, env: gym.Env) -> None:
        self.env = env
        self.unwrapped: Any = env.unwrapped  # action_masks() where the environment has it
        self.space = copy.deepcopy(env.action_space)
        self.masked = hasattr(env.unwrapped, "action_masks")

    def predict(self, observation, state=None, episode_start=None, deterministic=True):
        if episode_start is None or bool(np.all(episode_start)):
            self.space.seed(int(torch.randint(0, 2**31 - 1, (1,)).item()))
        if self.masked:
            mask = np.asarray(self.unwrapped.action_masks(), dtype=np.int8)
            return self.space.sample(mask=mask), state
        return self.space.sample(), state


class NormalizedModel:
    """A trained model behind the observation normalisation it was trained with."""

    def __init__(self, model: BaseAlgorithm, normalization: VecNormalize) -> None:
        self.model = model
        self.normalization = normalization

    def predict(self, observation, state=None, episode_start=None, deterministic=True, **kwargs):
        observation = self.normalization.normalize_obs(observation)
        return self.model.predict(observation, state, episode_start, deterministic, **kwargs)


class MaskedModel:
    """A MaskablePPO model given its environment's action masks at every prediction.

    The harness steps ``env`` with this predictor's actions, so
    ``env.unwrapped.action_masks()`` is the mask of the observation being
    acted on (for the sweeper, a function of that observation alone).
    """

    def __init__(self, model: Any, env: gym.Env) -> None:
        if not hasattr(env.unwrapped, "action_masks"):
            raise UsageError(f"{env.spec.id if env.spec else env} gives no action masks")
        self.model = model
        self.env = env
        self.unwrapped: Any = env.unwrapped

    def predict(self, observation, state=None, episode_start=None, deterministic=True):
        masks = self.unwrapped.action_masks()
        return self.model.predict(
            observation, state, episode_start, deterministic, action_masks=masks
        )


class SampledModel:
    """A model that samples its actions, for a run trained to be evaluated that way.

    The run's ``deterministic: false`` setting (see
    :mod:`motiongym.agents.training.config`) overrides the caller's ``deterministic``:
    the harness asks every policy for its deterministic action, and this one's
    is a sample. :func:`motiongym.agents.evaluation.episodes.run_episode` seeds the
    sampling from the episode's seed.
    """

    def __init__(self, model: Any) -> None:
        self.model = model

    def predict(self, observation, state=None, episode_start=None, deterministic=True):
        return self.model.predict(observation, state, episode_start, deterministic=False)


def model_path(path: Path) -> Path:
    """The model file of a path that is a ``.zip``, a run folder, or an rl-zoo3 run
    folder (its final model ``<env-name>.zip``, beside its ``<env-name>/`` folder)."""
    candidate = path / MODEL_FILE if path.is_dir() else path
    if path.is_dir() and not candidate.is_file():
        zoo = [z for z in sorted(path.glob("*.zip")) if z.with_suffix("").is_dir()]
        candidate = zoo[0] if len(zoo) == 1 else candidate
    if not candidate.is_file():
        raise UsageError(f"no model file at {candidate}")
    return candidate


def zoo_normalization(file: Path, env_id: str) -> None:
    """Refuse an rl-zoo3 run whose ``<env-name>/vecnormalize.pkl`` is not yet converted to
    ``vecnormalize.npz`` beside the model ``file`` (named, with the conversion)."""
    pickled = file.parent / env_id.replace("/", "-") / PICKLED_NORMALIZATION
    if not pickled.is_file() or (file.parent / NORMALIZATION_FILE).is_file():
        return
    raise UsageError(
        f"found the rl-zoo3 run's observation normalisation {pickled}: a pickle, which can "
        "run any code when loaded, so motiongym never loads it; where you trust the file, "
        "convert it to plain arrays: from motiongym.agents.models.files import "
        "save_normalization; save_normalization(VecNormalize.load(PKL, DummyVecEnv([lambda: "
        f"gym.make(ID)])), Path('{file.parent / NORMALIZATION_FILE}'))"
    )


def _normalized(model: BaseAlgorithm, file: Path, venv: VecEnv) -> Any:
    """``model`` behind the run's saved observation normalisation, if it has one."""
    normalization_file = file.parent / NORMALIZATION_FILE
    if not normalization_file.is_file():
        if (file.parent / PICKLED_NORMALIZATION).is_file():
            raise UsageError(
                f"{file.parent / PICKLED_NORMALIZATION} is a pickle, which motiongym never "
                f"loads; the run's statistics are read from {NORMALIZATION_FILE} (plain arrays)"
            )
        return model
    return NormalizedModel(model, load_normalization(normalization_file, venv))


def run_config(file: Path) -> dict[str, Any]:
    """The resolved configuration of the run beside the model ``file`` ({} for a bare model)."""
    config_file = file.parent / CONFIG_FILE
    if not config_file.is_file():
        return {}
    config = read_yaml_file(config_file)
    if not isinstance(config, dict):
        raise UsageError(f"{config_file} must be a mapping of the run's settings")
    return validated_run_config(config, config_file)


def validated_run_config(config: dict[str, Any], config_file: Path) -> dict[str, Any]:
    """A run's resolved ``config.yml`` checked as a configuration block is
    (:func:`motiongym.agents.training.config.validate_block`), its ``algo`` among ours."""
    from motiongym.agents.training.config import validate_block

    block = {k: v for k, v in config.items() if k not in RUN_RECORD}
    algo = config.get("algo")
    if not isinstance(algo, str):
        raise UsageError(f"{config_file}: 'algo' must name an algorithm, got {algo!r}")
    return {**config, **validate_block(block, algo, str(config_file))}


def check_provenance(file: Path, trust: bool) -> None:
    """Verify the manifest of the folder holding ``file`` (it must list ``file`` and
    every other file the loader reads); without one, require ``trust``. Every file the
    loader reads must be a regular file, not a link (to a device that never ends, or to
    a file outside the folder), and the text files at most :data:`MAX_TEXT_BYTES`."""
    folder = file.parent
    for name in (file.name, NORMALIZATION_FILE, CONFIG_FILE, MANIFEST):
        path = folder / name
        if path.is_symlink() or (path.exists() and not path.is_file()):
            raise UsageError(f"{path} is a link or not a regular file; refused")
        if name in (CONFIG_FILE, MANIFEST) and path.exists():
            if path.stat().st_size > MAX_TEXT_BYTES:
                raise UsageError(f"{path} is larger than {MAX_TEXT_BYTES} bytes; refused")
    if (folder / MANIFEST).is_file():
        verify_manifest(folder, (file.name, NORMALIZATION_FILE, CONFIG_FILE))
        return
    if not trust:
        raise UsageError(
            f"{folder} has no {MANIFEST} (motiongym train and ship write one); "
            "pass --trust to load it anyway"
        )
    warn(f"loading {file} without a manifest (--trust); nothing in it is unpickled")


def _run_policy_kwargs(config: dict[str, Any]) -> dict[str, Any] | None:
    if not config:
        return None
    from motiongym.agents.training.train import policy_kwargs

    return policy_kwargs(config)


def load_model(path: Path, env: gym.Env, env_id: str, trust: bool = False) -> Any:
    """Load a trained model and check it was built for ``env``'s spaces.

    Nothing from the folder is unpickled (:mod:`motiongym.agents.models.files`);
    its manifest is verified first, and a folder without one needs ``trust``.
    A shared-policy run acts in ``env`` (the single-agent view) through
    :class:`~motiongym.agents.training.multiagent.SharedPolicyPredictor`; a run with
    ``deterministic: false`` through :class:`SampledModel`.
    """
    file = model_path(path)
    zoo_normalization(file, env_id)
    check_provenance(file, trust)
    config = run_config(file)
    if (file.parent / NORMALIZATION_FILE).is_file():  # its sizes checked before the model loads
        load_npz(file.parent / NORMALIZATION_FILE, MAX_NORMALIZATION_BYTES, MAX_NORMALIZATION_BYTES)
    kwargs = _run_policy_kwargs(config)
    predictor: Any  # the model behind each layer its run asks for
    if config.get("vec_env") == "pettingzoo":  # one policy shared among the agents
        venv = SharedPolicyVecEnv(parallel_factory(env_id), n_copies=1)
        what = f"a shared-policy agent of {env_id}"
        model = load_archive(file, venv.observation_space, venv.action_space, what, kwargs)
        check_single_agent_view(venv, env, env_id)
        predictor = SharedPolicyPredictor(_normalized(model, file, venv), venv.n_agents)
    else:
        what = f"the {env_id} environment"
        memory = config.get("memory")
        seen = env  # the environment as the model saw it in training
        if memory:
            try:
                seen = memories()[memory](env, **config["memory_kwargs"])
            except ValueError as error:
                raise UsageError(f"{file}: {error}") from None
            what += f" with the {memory} memory"
        model = load_archive(file, seen.observation_space, env.action_space, what, kwargs)
        predictor = _normalized(model, file, DummyVecEnv([lambda: seen]))
        if memory:
            predictor = MapMemoryPredictor(predictor, env, memory, **config["memory_kwargs"])
        if isinstance(model, MaskablePPO):
            predictor = MaskedModel(predictor, env)
    beside = (file.parent / NORMALIZATION_FILE, file.parent / PICKLED_NORMALIZATION)
    if not config and not any(f.is_file() for f in beside):
        warn(
            f"no observation normalisation found for {file} ({NORMALIZATION_FILE} beside it, "
            f"or rl-zoo3's {env_id.replace('/', '-')}/{PICKLED_NORMALIZATION}): "
            "evaluating it on raw observations"
        )
    if not config.get("deterministic", True):
        predictor = SampledModel(predictor)
    if config.get("residual"):  # the model learned a correction of a scripted policy
        from motiongym.agents.training.residual import ResidualPredictor

        if not isinstance(env.action_space, spaces.Box):
            raise UsageError(f"{file}: a residual agent acts in a Box, not {env.action_space}")
        kwargs = env.spec.kwargs if env.spec else resolved_env_kwargs(env_id, None)
        scripted = make_policy(
            env_id,
            config["residual"],
            env.observation_space,
            env.action_space,
            kwargs,
            **config.get("residual_kwargs", {}),
        )
        predictor = ResidualPredictor(
            predictor, scripted, config.get("residual_scale", 1.0), env.action_space
        )
    return predictor


def available_policies(env_id: str) -> list[str]:
    """The names ``load_predictor`` accepts for ``env_id`` besides paths: the scripted
    policies, the shipped models, and ``random``."""
    return sorted(scripted_policies(env_id)) + sorted(pretrained_models(env_id)) + [RANDOM]


def load_predictor(
    policy: str,
    env_id: str,
    env: gym.Env,
    env_kwargs: dict[str, Any] | None = None,
    trust: bool = False,
) -> Any:
    """A predictor from a scripted policy's name, a shipped model's name, or a path
    (``trust``: load a model folder that has no manifest)."""
    if policy in scripted_policies(env_id):
        kwargs = resolved_env_kwargs(env_id, env_kwargs)
        return make_policy(env_id, policy, env.observation_space, env.action_space, kwargs)
    if policy == RANDOM:
        return RandomPolicy(env)
    shipped = pretrained_models(env_id)
    if policy in shipped:
        return load_model(shipped[policy], env, env_id)
    path = Path(policy)
    if path.exists():
        return load_model(path, env, env_id, trust)
    choices = ", ".join(available_policies(env_id)) or "none"
    raise UsageError(
        f"unknown policy {policy!r} for {env_id}: not one of the policies ({choices}) "
        "nor an existing model file or run folder"
    )


def policy_label(policy: str) -> str:
    """A short name for a policy in tables: a model's run folder, or the name."""
    path = Path(policy)
    if path.suffix == ".zip":
        return path.parent.name if path.name == MODEL_FILE else path.stem
    return path.name if path.exists() else policy
