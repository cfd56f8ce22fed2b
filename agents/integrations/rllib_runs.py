"""RLlib: every ID in RLlib's environment registry; PPO on one ID from ``configs/rllib/ppo.yml``.

Ray is the optional extra ``motiongym[ray]``. RLlib spreads one run's
sampling over ``num_env_runners`` Ray workers (on a cluster: over its
machines); :func:`register_ids` puts every registered ID in RLlib's (Tune's)
environment registry under its own name, so ``PPOConfig().environment(ID)``
works, and the dual-arm cell's PettingZoo parallel env under
``pettingzoo:<ID>`` (RLlib's ``ParallelPettingZooEnv``, one policy shared by
both arms). Dictionary observations (the Sweeper and goal IDs) are flattened
(Gymnasium's ``FlattenObservation``): RLlib's default model takes vectors.

A run writes ``<out>/<Name>-vN/rllib_ppo_seed<seed>_<time>/``: ``checkpoint/``
(RLlib's), ``config.yml`` (the resolved settings) and ``progress.json`` (per
iteration: environment steps sampled and mean episode return).
"""

from __future__ import annotations

import json
import time
from functools import partial
from importlib import resources
from pathlib import Path
from typing import Any

import gymnasium as gym
import yaml

from motiongym.agents.environments import check_env_id, short_name
from motiongym.agents.errors import UsageError
from motiongym.agents.integrations.sweep import import_ray, start_ray
from motiongym.agents.limits import read_yaml_file
from motiongym.envs import ENV_IDS
from motiongym.systems import declared

SECTIONS = ("training", "env_runners", "model", "env_config")
MULTI_AGENT_PREFIX = "pettingzoo:"
SHARED_POLICY = "shared"


def default_rllib_config() -> Path:
    return Path(str(resources.files("motiongym.configs") / "rllib" / "ppo.yml"))


def make_single(env_id: str, env_config: dict[str, Any]) -> gym.Env:
    """``env_id`` made with ``env_config``, dictionary observations flattened."""
    env = gym.make(env_id, **dict(env_config))
    if isinstance(env.observation_space, gym.spaces.Dict):
        env = gym.wrappers.FlattenObservation(env)
    return env


def make_multi(env_id: str, env_config: dict[str, Any]) -> Any:
    """``env_id``'s PettingZoo parallel env as RLlib's ``ParallelPettingZooEnv``."""
    from ray.rllib.env.wrappers.pettingzoo_env import ParallelPettingZooEnv

    from motiongym.agents.training.multiagent import parallel_factory

    return ParallelPettingZooEnv(parallel_factory(env_id)(**dict(env_config)))


def register_ids() -> list[str]:
    """Register every ID (and ``pettingzoo:<ID>`` where it has a parallel env) with
    RLlib; return the names registered."""
    from ray.tune.registry import register_env

    names = []
    for env_id in ENV_IDS:
        register_env(env_id, partial(make_single, env_id))
        names.append(env_id)
    for env_id in declared("envs", "PARALLEL_ENVS"):
        register_env(MULTI_AGENT_PREFIX + env_id, partial(make_multi, env_id))
        names.append(MULTI_AGENT_PREFIX + env_id)
    return names


def load_rllib_settings(env_id: str, path: Path | None = None) -> dict[str, dict[str, Any]]:
    """``default`` updated section by section with ``env_id``'s block; unknown sections or
    top-level keys that are not IDs are refused by name."""
    path = path or default_rllib_config()
    if not path.is_file():
        raise UsageError(f"no RLlib configuration file at {path}")
    document = read_yaml_file(path) or {}
    if not isinstance(document, dict):
        raise UsageError(f"{path}: expected a mapping of 'default' and IDs")
    for key, block in document.items():
        if key != "default" and key not in ENV_IDS:
            raise UsageError(f"{path}: {key!r} is neither 'default' nor an ID")
        unknown = set(block or {}) - set(SECTIONS)
        if unknown:
            valid = ", ".join(SECTIONS)
            raise UsageError(
                f"{path} [{key}]: unknown section(s) {sorted(unknown)}; valid: {valid}"
            )
    settings: dict[str, dict[str, Any]] = {s: {} for s in SECTIONS}
    for key in ("default", env_id):
        for section, values in (document.get(key) or {}).items():
            settings[section].update(values or {})
    return settings


def ppo_config(
    env_id: str, settings: dict[str, dict[str, Any]], seed: int = 0, multi_agent: bool = False
) -> Any:
    """RLlib's ``PPOConfig`` for ``env_id`` from :func:`load_rllib_settings`'s ``settings``."""
    from ray.rllib.algorithms.ppo import PPOConfig

    name = MULTI_AGENT_PREFIX + env_id if multi_agent else env_id
    config = (
        PPOConfig()
        .environment(name, env_config=settings["env_config"])
        .debugging(seed=seed)
        .rl_module(model_config=settings["model"])
    )
    try:
        config = config.training(**settings["training"]).env_runners(**settings["env_runners"])
    except TypeError as error:  # a keyword the method does not take
        raise UsageError(f"RLlib settings for {env_id}: {error}") from None
    if multi_agent:
        from ray.rllib.core.rl_module.multi_rl_module import MultiRLModuleSpec
        from ray.rllib.core.rl_module.rl_module import RLModuleSpec

        config = config.multi_agent(
            policies={SHARED_POLICY}, policy_mapping_fn=lambda agent_id, *args, **kw: SHARED_POLICY
        ).rl_module(
            rl_module_spec=MultiRLModuleSpec(
                rl_module_specs={SHARED_POLICY: RLModuleSpec(model_config=settings["model"])}
            )
        )
    return config


def _summary(result: dict[str, Any]) -> dict[str, float]:
    runners = result.get("env_runners", {})
    return {
        "env_steps": float(runners.get("num_env_steps_sampled_lifetime", float("nan"))),
        "episode_return_mean": float(runners.get("episode_return_mean", float("nan"))),
    }


def train_rllib(
    env_id: str,
    iterations: int,
    out: Path,
    config_path: Path | None = None,
    seed: int = 0,
    multi_agent: bool = False,
    overrides: dict[str, dict[str, Any]] | None = None,
    address: str | None = None,
) -> Path:
    """``iterations`` of RLlib PPO on ``env_id`` (its PettingZoo env with ``multi_agent``)
    on the Ray at ``address`` (None: a local one); return the run folder."""
    check_env_id(env_id)
    if multi_agent and env_id not in declared("envs", "PARALLEL_ENVS"):
        raise UsageError(
            f"{env_id} has no PettingZoo parallel env; IDs with one: "
            f"{', '.join(declared('envs', 'PARALLEL_ENVS'))}"
        )
    settings = load_rllib_settings(env_id, config_path)
    for section, values in (overrides or {}).items():
        settings[section].update(values)
    ray = import_ray()
    run_dir = out / short_name(env_id) / f"rllib_ppo_seed{seed}_{time.strftime('%Y%m%d-%H%M%S')}"
    run_dir.mkdir(parents=True, exist_ok=True)
    resolved = {"env_id": env_id, "seed": seed, "multi_agent": multi_agent, **settings}
    (run_dir / "config.yml").write_text(yaml.safe_dump(resolved, sort_keys=False))
    started = start_ray(address)
    try:
        register_ids()
        algorithm = ppo_config(env_id, settings, seed, multi_agent).build_algo()
        progress = []
        for _ in range(iterations):
            progress.append(_summary(algorithm.train()))
        algorithm.save_to_path(str((run_dir / "checkpoint").resolve()))
        algorithm.stop()
    finally:
        if started:
            ray.shutdown()
    (run_dir / "progress.json").write_text(json.dumps(progress, indent=2))
    return run_dir
