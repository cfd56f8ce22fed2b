"""Training an SB3 algorithm on an environment ID from a ``configs/`` block.

A run writes one folder, ``<out>/<Name>-vN/<algo>_seed<seed>_<time>/``:

* ``model.zip``: the final model; ``vecnormalize.npz`` (plain arrays) if the
  run normalised;
* ``manifest.json``: the SHA-256 of every file above, written last (a folder
  without it is refused by the loaders unless the user says ``--trust``);
* ``config.yml``: the resolved block, with the ID, algorithm and seed;
* ``command.txt``: the command that made the run;
* ``eval/``: ``evaluations.npz`` and ``best_model.zip`` (SB3's EvalCallback),
  ``learning_curve.png`` (mean evaluation return against steps);
* ``checkpoints/``, ``tb/`` (TensorBoard), ``monitor/`` (per-episode CSVs);
* ``behaviour_cloning.json``: with ``demonstrations`` in the block, the
  mean loss of each cloning epoch (the policy is cloned before RL; with
  normalisation, its statistics are the demonstrations', frozen for the run);
* with ``memory: <name>`` in the block, every environment (training, the
  evaluation callback's, DAgger's) is wrapped with that memory
  (:mod:`motiongym.agents.learners`), which adds its entry to the
  observation; the loaders rebuild it from ``config.yml``;
* ``dagger.json``: with ``imitate: <policy>`` in the block, each DAgger
  iteration's figures (:mod:`motiongym.agents.training.dagger`: the policy is taught
  by that scripted policy before RL, none with ``n_timesteps: 0``; with
  normalisation, its statistics are the teacher's states', frozen).

Seeds: training environment ``k`` is seeded ``seed + k``; the evaluation
callback's environment ``seed + 10_000``. Evaluations use seeds from
``motiongym.agents.evaluation.episodes.EVALUATION_SEED`` up, far from both.

``vec_env: pettingzoo`` trains one policy shared by every agent of the ID's
PettingZoo version (:mod:`motiongym.agents.training.multiagent`): ``n_envs`` copies
made with ``env_kwargs``, one SB3 environment per (copy, agent), so steps (``n_timesteps``,
``eval_freq``, ``checkpoint_freq``) count agent steps, ``n_agents`` per
environment step; the evaluation callback runs one copy.
"""

from __future__ import annotations

import json
import shlex
import shutil
import sys
import time
import warnings
from pathlib import Path
from typing import Any

import gymnasium as gym
import numpy as np
import torch
import yaml
from matplotlib.figure import Figure
from matplotlib.ticker import EngFormatter
from stable_baselines3.common.base_class import BaseAlgorithm
from stable_baselines3.common.callbacks import (
    CheckpointCallback,
    EvalCallback,
    ProgressBarCallback,
)
from stable_baselines3.common.env_util import make_vec_env
from stable_baselines3.common.off_policy_algorithm import OffPolicyAlgorithm
from stable_baselines3.common.on_policy_algorithm import OnPolicyAlgorithm
from stable_baselines3.common.type_aliases import TrainFreq, TrainFrequencyUnit
from stable_baselines3.common.vec_env import (
    DummyVecEnv,
    SubprocVecEnv,
    VecMonitor,
    VecNormalize,
)

from motiongym.agents.environments import (
    check_env_id,
    check_make_kwargs,
    importable_id,
    made_kwargs,
    short_name,
)
from motiongym.agents.errors import UsageError
from motiongym.agents.learners import features_extractors, memories
from motiongym.agents.models.files import (
    NORMALIZATION_FILE,
    algorithm_classes,
    save_normalization,
)
from motiongym.agents.models.predictors import CONFIG_FILE, MODEL_FILE
from motiongym.agents.models.pretrained import write_manifest
from motiongym.agents.training.config import (
    ACTIVATIONS,
    algorithm_kwargs,
    default_config_path,
    first_block,
    load_config,
)
from motiongym.agents.training.multiagent import SharedPolicyVecEnv, parallel_factory
from motiongym.agents.training.residual import ResidualWrapper, zero_correction
from motiongym.agents.training.vector import VectorEnvAdapter
from motiongym.baselines import scripted_policies
from motiongym.envs.core import ArgumentError, check_int

_EVAL_CALLBACK_SEED_OFFSET = 10_000


def policy_kwargs(config: dict[str, Any]) -> dict[str, Any]:
    """The block's ``policy_kwargs`` with the activation's and extractor's names made classes."""
    kwargs = dict(config["policy_kwargs"])
    if "activation_fn" in kwargs:
        kwargs["activation_fn"] = getattr(torch.nn, ACTIVATIONS[kwargs["activation_fn"]])
    if "features_extractor_class" in kwargs:
        kwargs["features_extractor_class"] = features_extractors()[
            kwargs["features_extractor_class"]
        ]
    return kwargs


def steps_to_run(model: BaseAlgorithm, total_timesteps: int) -> int:
    """The environment steps ``model.learn(total_timesteps)`` really takes: SB3 learns in
    whole collections until it has at least ``total_timesteps``, an on-policy algorithm's
    being ``n_steps`` per environment, an off-policy one's ``train_freq`` steps per
    environment (episodes where ``train_freq`` counts them: then ``total_timesteps``,
    a floor)."""
    chunk = model.n_envs
    if isinstance(model, OnPolicyAlgorithm):
        chunk *= model.n_steps
    elif isinstance(model, OffPolicyAlgorithm):
        freq = model.train_freq  # a TrainFreq once the model is set up
        if isinstance(freq, TrainFreq) and freq.unit == TrainFrequencyUnit.STEP:
            chunk *= freq.frequency
    return -(-total_timesteps // chunk) * chunk


class StepsProgressBar(ProgressBarCallback):
    """SB3's progress bar whose total is the steps that will run (:func:`steps_to_run`),
    not the steps asked for: it ends full, never past its total."""

    def _on_training_start(self) -> None:
        from stable_baselines3.common.callbacks import tqdm  # SB3's own (tqdm.rich)
        from tqdm import TqdmExperimentalWarning

        total = steps_to_run(self.model, int(self.locals["total_timesteps"]))
        with warnings.catch_warnings():  # tqdm.rich calls itself experimental on every bar
            warnings.simplefilter("ignore", TqdmExperimentalWarning)
            self.pbar = tqdm(total=total - self.model.num_timesteps)


class PlainCheckpoints(CheckpointCallback):
    """SB3's checkpoints, with the normalisation statistics beside each as plain
    arrays (``model_vecnormalize_<steps>_steps.npz``), never SB3's pickle."""

    def _on_step(self) -> bool:
        if self.n_calls % self.save_freq == 0:
            self.model.save(self._checkpoint_path(extension="zip"))
            normalization = self.model.get_vec_normalize_env()
            if normalization is not None:
                path = self._checkpoint_path("vecnormalize_", extension="npz")
                save_normalization(normalization, Path(path))
        return True


def _monitored(venv, monitor_dir: Path | None, name: str) -> VecMonitor:
    """``venv`` recording its episodes in ``monitor_dir/<name>.monitor.csv`` (if a folder)."""
    if monitor_dir:
        monitor_dir.mkdir(parents=True, exist_ok=True)
    return VecMonitor(venv, str(monitor_dir / name) if monitor_dir else None)


def _vec_env(env_id: str, config: dict[str, Any], n_envs: int, seed: int, monitor_dir: Path | None):
    """The training environments as SB3 wants them, per the block's ``vec_env``."""
    if config["vec_env"] == "pettingzoo":
        factory = parallel_factory(env_id)
        shared = SharedPolicyVecEnv(lambda: factory(**config["env_kwargs"]), n_envs)
        shared.seed(seed)
        return _monitored(shared, monitor_dir, "pettingzoo")
    if config["vec_env"] == "native":
        if not gym.spec(env_id).vector_entry_point:
            raise UsageError(f"{env_id} has no native vector environment; use dummy or subproc")
        native = gym.make_vec(
            env_id, num_envs=n_envs, vectorization_mode="vector_entry_point", **config["env_kwargs"]
        )
        venv = VectorEnvAdapter(native)
        venv.seed(seed)
        return _monitored(venv, monitor_dir, "native")
    vec_env_cls = SubprocVecEnv if config["vec_env"] == "subproc" and n_envs > 1 else DummyVecEnv
    residual, memory = config["residual"], config["memory"]
    wrapper_class: Any = None  # a wrapper that takes keywords (make_vec_env passes them)
    wrapper_kwargs = None
    if residual:
        wrapper_class = ResidualWrapper
        wrapper_kwargs = {
            "policy": residual,
            "scale": config["residual_scale"],
            "policy_kwargs": config["residual_kwargs"],
        }
    elif memory:  # the config's checks keep the two apart
        wrapper_class, wrapper_kwargs = memories()[memory], config["memory_kwargs"]
    return make_vec_env(
        importable_id(env_id),
        n_envs=n_envs,
        seed=seed,
        env_kwargs=config["env_kwargs"],
        monitor_dir=str(monitor_dir) if monitor_dir else None,
        vec_env_cls=vec_env_cls,
        wrapper_class=wrapper_class,
        wrapper_kwargs=wrapper_kwargs,
    )


def _clone(env_id: str, config: dict[str, Any], model, venv, seed: int, run_dir: Path) -> None:
    """Behaviour-clone ``model`` on the block's ``demonstrations`` (checked for ``env_id``)."""
    from motiongym.agents.integrations.dataset import load_demonstrations, transitions
    from motiongym.agents.training.imitation import behaviour_clone

    env = gym.make(env_id, **config["env_kwargs"])
    try:
        observations, actions = transitions(load_demonstrations(config["demonstrations"], env))
    except ValueError as error:
        raise UsageError(f"demonstrations: {error}") from error
    if isinstance(venv, VecNormalize):  # statistics from the teacher's states, then frozen
        if isinstance(observations, dict):
            for key, rms in venv.obs_rms.items():
                rms.update(observations[key])
        else:
            venv.obs_rms.update(observations)
        observations = venv.normalize_obs(observations)
        # Frozen: updated by RL's own first (random) states, the statistics would move the
        # cloned policy's inputs (docs/experiments/ExcavatorReachGoal-v1.md measures it).
        venv.training = False
    losses = behaviour_clone(model, observations, actions, epochs=config["bc_epochs"], seed=seed)
    (run_dir / "behaviour_cloning.json").write_text(json.dumps({"loss": losses}) + "\n")


def _imitate(env_id: str, config: dict[str, Any], model, venv, seed: int, run_dir: Path) -> None:
    """Teach ``model`` by DAgger with the block's ``imitate`` policy as the teacher."""
    from motiongym.agents.training.dagger import dagger, history_json
    from motiongym.baselines import make_policy

    env = bare = gym.make(env_id, **config["env_kwargs"])
    if config["memory"]:  # the learner sees the memory; the teacher the env's observation
        env = memories()[config["memory"]](bare, **config["memory_kwargs"])
    try:
        teacher = make_policy(
            env_id,
            config["imitate"],
            bare.observation_space,
            bare.action_space,
            made_kwargs(bare),
            **config["imitate_kwargs"],
        )
    except (TypeError, ValueError) as error:  # a keyword the teacher lacks, or a bad value
        raise UsageError(f"imitate_kwargs for {config['imitate']!r}: {error}") from None
    started = time.perf_counter()
    history = dagger(
        model,
        env,
        teacher,
        iterations=config["dagger_iterations"],
        episodes=config["dagger_episodes"],
        epochs=config["bc_epochs"],
        normalization=venv if isinstance(venv, VecNormalize) else None,
        training_seed=seed,
        deterministic=config.get("deterministic", True),
    )
    env.close()
    record = {"seconds": time.perf_counter() - started, "iterations": history_json(history)}
    (run_dir / "dagger.json").write_text(json.dumps(record, indent=1) + "\n")


def _check_residual(env_id: str, config: dict[str, Any], where: Path) -> None:
    """A DAgger teacher (``imitate``) and a residual agent's policy: scripted policies of
    ``env_id``; a residual agent in a dummy or subproc vec env."""
    teacher = config["imitate"]
    if teacher is not None and teacher not in scripted_policies(env_id):
        choices = ", ".join(sorted(scripted_policies(env_id))) or "none"
        raise UsageError(
            f"{where}: imitate {teacher!r} is not a scripted policy of {env_id} ({choices})"
        )
    name = config["residual"]
    if name is None:
        return
    if name not in scripted_policies(env_id):
        choices = ", ".join(sorted(scripted_policies(env_id))) or "none"
        raise UsageError(
            f"{where}: residual {name!r} is not a scripted policy of {env_id} ({choices})"
        )
    if config["vec_env"] not in ("dummy", "subproc"):
        raise UsageError(f"{where}: a residual agent needs vec_env dummy or subproc")
    if config["residual_kwargs"]:  # the policy's own check of its keywords, named here
        from motiongym.baselines import make_policy

        env = gym.make(env_id, **config["env_kwargs"])
        try:
            make_policy(
                env_id,
                name,
                env.observation_space,
                env.action_space,
                made_kwargs(env),
                **config["residual_kwargs"],
            )
        except (TypeError, ValueError) as error:
            raise UsageError(f"{where}: residual_kwargs for {name!r}: {error}") from None
        finally:
            env.close()
    if config.get("replay_buffer_class") == "her":  # the stored correction fits one goal only
        raise UsageError(
            f"{where}: a residual agent cannot use replay_buffer_class her: the scripted "
            "action depends on the goal, so a relabelled transition's correction is wrong"
        )


def _check_her(env_id: str, config: dict[str, Any], where: Path) -> None:
    """HER samples whole episodes: learning must start after the first one can end."""
    if config.get("replay_buffer_class") != "her":
        return
    limit = config["env_kwargs"].get("max_episode_steps", gym.spec(env_id).max_episode_steps) or 0
    starts = config.get("learning_starts", 100) // config["n_envs"]
    if starts <= limit:
        raise UsageError(
            f"{where}: with replay_buffer_class her, learning_starts / n_envs must exceed "
            f"{env_id}'s {limit} steps per episode, got {config.get('learning_starts', 100)}"
        )


def _normalize(venv, config: dict[str, Any], training: bool):
    options = config["normalize"]
    if not options:
        return venv
    kwargs = options if isinstance(options, dict) else {}
    if not training:
        kwargs = {**kwargs, "norm_reward": False}
    return VecNormalize(venv, training=training, **kwargs)


def learning_curve_figure(evaluations_file: Path, path: Path, title: str) -> Path | None:
    """Mean evaluation return (± std) against training steps."""
    if not evaluations_file.is_file():
        return None
    data = np.load(evaluations_file)
    steps, results = data["timesteps"], data["results"]
    mean, std = results.mean(axis=1), results.std(axis=1)
    figure = Figure(figsize=(5, 3.2))
    ax = figure.subplots()
    ax.plot(steps, mean)
    ax.fill_between(steps, mean - std, mean + std, alpha=0.3)
    ax.set_xlabel("environment steps")
    ax.xaxis.set_major_formatter(EngFormatter(sep=""))  # 200k, 1M: no run-together labels
    ax.set_ylabel("evaluation return (training reward, mean ± std)")
    ax.set_title(title, fontsize=9)
    figure.tight_layout()
    figure.savefig(path, dpi=110)
    return path


def train(
    env_id: str,
    algo: str | None = None,
    config_path: Path | None = None,
    seed: int = 0,
    out_root: Path = Path("runs"),
    n_timesteps: int | None = None,
    progress: bool = True,
) -> Path:
    """Train ``algo`` (default: the file's first block) on ``env_id``; return the run folder."""
    check_env_id(env_id)
    config_path = config_path or default_config_path(env_id)
    algo = algo or first_block(config_path)
    config = load_config(config_path, algo)
    try:
        if n_timesteps is not None:  # the config's range (agents/training/config.py)
            config["n_timesteps"] = check_int("--timesteps", n_timesteps, 1, 10**11)
        check_make_kwargs(env_id, config["env_kwargs"])
    except ArgumentError as error:
        raise UsageError(f"{config_path} [{algo}]: {error}") from None
    _check_her(env_id, config, config_path)
    _check_residual(env_id, config, config_path)
    stamp = time.strftime("%Y%m%d-%H%M%S")
    run_dir = out_root / short_name(env_id) / f"{algo}_seed{seed}_{stamp}"
    made = [p for p in (run_dir, *run_dir.parents) if not p.exists()]  # deepest first
    try:
        run_dir.mkdir(parents=True, exist_ok=True)
    except OSError as error:
        raise UsageError(f"cannot make the run folder {run_dir}: {error.strerror}") from None
    try:  # a run that fails before learning leaves no half-made folder (nor its parents)
        (run_dir / "command.txt").write_text(shlex.join(sys.argv) + "\n")
        resolved = {"env_id": env_id, "algo": algo, "seed": seed, "config_file": str(config_path)}
        (run_dir / CONFIG_FILE).write_text(yaml.safe_dump({**resolved, **config}, sort_keys=False))

        n_envs = config["n_envs"]
        try:  # the environments' own checks of the config's env_kwargs
            venv = _vec_env(env_id, config, n_envs, seed, run_dir / "monitor")
            eval_venv = _vec_env(env_id, config, 1, seed + _EVAL_CALLBACK_SEED_OFFSET, None)
        except (TypeError, ValueError) as error:
            raise UsageError(f"{config_path} [{algo}]: env_kwargs: {error}") from None
        venv = _normalize(venv, config, True)
        eval_venv = _normalize(eval_venv, config, False)
        if algo == "maskableppo" and not venv.has_attr("action_masks"):
            raise UsageError(
                f"{env_id} with vec_env {config['vec_env']} gives no action masks for maskableppo"
            )
        algorithm = algorithm_classes()[algo]
        try:
            model = algorithm(
                config["policy"],
                venv,
                policy_kwargs=policy_kwargs(config),
                tensorboard_log=str(run_dir / "tb"),
                seed=seed,
                device="cpu",
                verbose=0,
                **algorithm_kwargs(config),
            )
        except (AssertionError, ValueError, TypeError, RuntimeError) as error:  # SB3's
            # checks of spaces and policy; a policy_kwargs or features_extractor_kwargs key
            # it lacks (TypeError) or a layer size torch refuses (RuntimeError)
            raise UsageError(f"{algo} cannot train on {env_id}: {error}") from error
        if config["residual"]:  # the untrained agent acts as the scripted policy
            zero_correction(model)
        if config["demonstrations"]:
            _clone(env_id, config, model, venv, seed, run_dir)
        if config["imitate"]:
            _imitate(env_id, config, model, venv, seed, run_dir)
        eval_dir = run_dir / "eval"
        EvalCallbackClass: type[EvalCallback] = EvalCallback
        if algo == "maskableppo":
            from sb3_contrib.common.maskable.callbacks import MaskableEvalCallback

            EvalCallbackClass = MaskableEvalCallback
        callbacks = [
            EvalCallbackClass(
                eval_venv,
                eval_freq=max(config["eval_freq"] // venv.num_envs, 1),
                # Every slot of the one evaluation env runs n_eval_episodes episodes.
                n_eval_episodes=config["n_eval_episodes"] * eval_venv.num_envs,
                best_model_save_path=str(eval_dir),
                log_path=str(eval_dir),
                deterministic=config["deterministic"],
                verbose=0,
            ),
            PlainCheckpoints(
                save_freq=max(config["checkpoint_freq"] // venv.num_envs, 1),
                save_path=str(run_dir / "checkpoints"),
                name_prefix="model",
            ),
        ]
    except BaseException:
        shutil.rmtree(run_dir, ignore_errors=True)
        for folder in made[1:]:  # the parents this run made, if left empty
            if folder.is_dir() and not any(folder.iterdir()):
                folder.rmdir()
        raise
    try:
        if config["n_timesteps"]:
            asked = int(config["n_timesteps"])
            if progress and steps_to_run(model, asked) != asked:
                print(
                    f"motiongym: {algo} learns in whole rollouts ({steps_to_run(model, 1):,} "
                    f"steps): --timesteps {asked:,} runs {steps_to_run(model, asked):,} steps",
                    file=sys.stderr,
                )
            model.learn(
                total_timesteps=asked,
                callback=[*callbacks, StepsProgressBar()] if progress else callbacks,
            )
    except (ValueError, RuntimeError, FloatingPointError) as error:  # diverged (NaN logits)
        problem = " ".join(str(error).split())[:200]
        raise UsageError(
            f"training stopped at step {model.num_timesteps} ({problem}); {run_dir} keeps its "
            "checkpoints and logs but has no model.zip nor manifest.json; lower learning_rate "
            "or enable normalize"
        ) from None
    model.save(run_dir / MODEL_FILE)
    if isinstance(venv, VecNormalize):
        save_normalization(venv, run_dir / NORMALIZATION_FILE)
    learning_curve_figure(
        eval_dir / "evaluations.npz",
        eval_dir / "learning_curve.png",
        f"{algo} on {env_id}, seed {seed}",
    )
    venv.close()
    eval_venv.close()
    write_manifest(run_dir)
    return run_dir
