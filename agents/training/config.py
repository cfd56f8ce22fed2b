"""Training configurations: YAML in ``configs/``, one file per environment ID.

A file ``configs/<Name>-vN.yml`` (rl-baselines3-zoo style) holds one block
per algorithm (``ppo``, ``sac``, ``maskableppo``, ...); the first block is
the tuned choice, which ``motiongym train`` trains unless told another. A block's keys are
either the run settings below or keyword arguments of the algorithm's
constructor (``learning_rate``, ``n_steps``, ...); any other key is rejected
with its name. ``policy_kwargs`` is a mapping, never code: the activation
function is named (``tanh``, ``relu``, ``elu``, ``leaky_relu``), and so is a
features extractor (``features_extractor_class: sweeper_egocentric``, see
:mod:`motiongym.agents.learners`; its keywords in
``features_extractor_kwargs``).

Run settings:

============== ===================================================== ==========
key            meaning                                               default
============== ===================================================== ==========
n_envs         parallel environments (1 to 1024; ``n_steps * n_envs`` 1
               at most 10**7)
n_timesteps    environment steps to train for                        required
policy         SB3 policy name (``MlpPolicy``, ``MultiInputPolicy``) required
policy_kwargs  network and activation (mapping)                      {}
env_kwargs     keywords for ``gym.make``                             {}
normalize      VecNormalize: false, true, or a mapping of its kwargs false
vec_env        ``dummy``, ``subproc``, ``native`` (the ID's own       dummy
               NumPy-batched vector env, see agents/training/vector.py) or
               ``pettingzoo`` (one policy shared by the agents of
               the ID's PettingZoo version, see
               agents/training/multiagent.py; ``n_envs`` counts its copies)
eval_freq      steps between evaluations (over all envs)             10000
n_eval_episodes episodes per evaluation                              5
checkpoint_freq steps between checkpoints (over all envs)            50000
replay_buffer_class ``her`` (SB3's ``HerReplayBuffer``, for the goal IDs none
               of :mod:`motiongym.envs.goal`; off-policy only), its
               keywords in ``replay_buffer_kwargs``
               (``n_sampled_goal``, ``goal_selection_strategy``
               ``future``/``final``/``episode``, ``copy_info_dict``:
               true where the reward reads ``info``)
residual       a scripted policy's name: train a residual agent          null
               (:mod:`motiongym.agents.training.residual`: the env receives
               that policy's action plus the learned correction);
               ``vec_env`` dummy or subproc
residual_scale the correction's range, in (0, 2], as a multiple of   1.0
               the action bounds
residual_kwargs that scripted policy's own keywords (mapping), e.g.     {}
               ``tolerance`` of the dig cycle
demonstrations a Minari dataset folder (``motiongym dataset``): the   null
               policy is behaviour-cloned on it
               (:mod:`motiongym.agents.training.imitation`) before RL;
               normalisation statistics: the demonstrations', frozen
bc_epochs      epochs of that behaviour cloning (and of each DAgger   20
               refit)
imitate        a scripted policy's name: DAgger                      null
               (:mod:`motiongym.agents.training.dagger`) teaches the policy
               before RL, the teacher queried on the learner's own
               states; normalisation statistics: the teacher's
               states, frozen. With ``n_timesteps: 0`` no RL follows
imitate_kwargs the teacher's own keywords (mapping), e.g.              {}
               ``replan: true`` for the excavator reach teacher
dagger_iterations learner-acting DAgger iterations after the          4
               teacher's (0: plain behaviour cloning)
dagger_episodes episodes rolled out per DAgger iteration             50
memory         a learner-side memory added to the observation:         null
               ``sweeper_map`` (:mod:`motiongym.agents.learners.sweeper`:
               the robot's own map, built from its observations, as
               robot-centred crops under the key ``memory``) or
               ``dual_arm_map`` (:mod:`motiongym.agents.learners.dual_arm`:
               robot 2's waits and their collisions, from the tasks,
               in place of the observation); the
               training envs are wrapped with it and a loaded model
               builds it from the observations it is given.
               ``vec_env`` dummy or subproc; not with ``residual``
memory_kwargs  the memory's settings (mapping): ``levels``, ``crop``,  {}
               ``factor`` (sweeper_map); ``lags``, ``bin_steps``,
               ``bins`` (dual_arm_map)
deterministic  how the model acts in evaluations (the training        true
               callback's, ``evaluate``, ``compare``, ``ship``): its
               most likely action (true) or one sampled from its
               distribution (false), for a memoryless policy whose
               mode loops where its samples do not; saved in the
               run's ``config.yml`` and so honoured for shipped models
============== ===================================================== ==========

Bounds that keep a run's memory finite: ``policy_kwargs.net_arch`` at most
16 hidden layers of at most 4096 units and 2**24 weights between one
network's hidden layers (``[4096, 4096]``); ``n_steps * n_envs`` at most
10**7. A configuration file is at most 256 kB of YAML, without aliases
(:mod:`motiongym.agents.limits`).
"""

from __future__ import annotations

import inspect
from importlib import resources
from pathlib import Path
from typing import TYPE_CHECKING, Any

from motiongym.agents.environments import short_name
from motiongym.agents.errors import UsageError
from motiongym.agents.learners import features_extractors, memories
from motiongym.agents.learners.memory import check_memory_kwargs
from motiongym.agents.limits import read_yaml_file
from motiongym.agents.models.files import algorithm_classes
from motiongym.envs.core import ArgumentError, check_bool, check_choice, check_float, check_int

if TYPE_CHECKING:
    from stable_baselines3.common.base_class import BaseAlgorithm

RUN_SETTINGS: dict[str, Any] = {
    "n_envs": 1,
    "n_timesteps": None,
    "policy": None,
    "policy_kwargs": {},
    "env_kwargs": {},
    "normalize": False,
    "vec_env": "dummy",
    "eval_freq": 10_000,
    "n_eval_episodes": 5,
    "checkpoint_freq": 50_000,
    "deterministic": True,
    "residual": None,
    "residual_scale": 1.0,
    "residual_kwargs": {},
    "demonstrations": None,
    "bc_epochs": 20,
    "imitate": None,
    "imitate_kwargs": {},
    "dagger_iterations": 4,
    "dagger_episodes": 50,
    "memory": None,
    "memory_kwargs": {},
}
REQUIRED = ("n_timesteps", "policy")
VEC_ENVS = ("dummy", "subproc", "native", "pettingzoo")
# Replay buffers a block may name -> their SB3 class names; their keywords.
REPLAY_BUFFERS = {"her": "HerReplayBuffer"}
HER_KWARGS = ("n_sampled_goal", "goal_selection_strategy", "copy_info_dict")
GOAL_SELECTION = ("future", "final", "episode")
# Activation names accepted in policy_kwargs -> their torch.nn class names.
ACTIVATIONS = {"tanh": "Tanh", "relu": "ReLU", "elu": "ELU", "leaky_relu": "LeakyReLU"}
# Constructor arguments the run itself provides.
_PROVIDED = {
    "self",
    "policy",
    "env",
    "policy_kwargs",
    "tensorboard_log",
    "seed",
    "device",
    "verbose",
    "_init_setup_model",
}


def default_config_path(env_id: str) -> Path:
    """The shipped configuration file of ``env_id``."""
    return Path(str(resources.files("motiongym.configs") / f"{short_name(env_id)}.yml"))


def _document(path: Path) -> dict[str, Any]:
    """The YAML file at ``path`` as ``{algorithm: block}``, or a named error."""
    if not path.is_file():
        raise UsageError(f"no configuration file at {path}")
    document = read_yaml_file(path)
    if not isinstance(document, dict) or not document:
        raise UsageError(f"{path} must map algorithm names to blocks of settings")
    return document


def first_block(path: Path) -> str:
    """The algorithm of the file's first block: the tuned choice, trained by default."""
    return next(iter(_document(path)))


def load_config(path: Path, algo: str) -> dict[str, Any]:
    """The validated block ``algo`` of the YAML file at ``path``, defaults filled in."""
    document = _document(path)
    if algo not in document:
        raise UsageError(
            f"{path} has no block for algorithm {algo!r}; blocks: {', '.join(document)}"
        )
    return validate_block(document[algo], algo, f"{path} [{algo}]")


def validate_block(block: Any, algo: str, where: str) -> dict[str, Any]:
    """Check one algorithm block's keys and types; return it with defaults."""
    classes = algorithm_classes()
    if algo not in classes:
        raise UsageError(f"unknown algorithm {algo!r}; valid: {', '.join(classes)}")
    if not isinstance(block, dict):
        raise UsageError(f"{where} must be a mapping of settings")
    constructor = set(inspect.signature(classes[algo].__init__).parameters) - _PROVIDED
    unknown = set(block) - set(RUN_SETTINGS) - constructor
    if unknown:
        valid = sorted(set(RUN_SETTINGS) | constructor)
        raise UsageError(
            f"unknown key {sorted(unknown)[0]!r} in {where}; valid keys: {', '.join(valid)}"
        )
    config = {**RUN_SETTINGS, **block}
    for key in REQUIRED:
        if config[key] is None:
            raise UsageError(f"{where} needs {key!r}")
    for key in ("policy_kwargs", "env_kwargs"):
        if not isinstance(config[key], dict):
            raise UsageError(f"{where}: {key!r} must be a mapping")
    activation = config["policy_kwargs"].get("activation_fn", "tanh")
    if activation not in ACTIVATIONS:
        raise UsageError(
            f"{where}: activation_fn {activation!r} unknown; valid: {', '.join(ACTIVATIONS)}"
        )
    extractor = config["policy_kwargs"].get("features_extractor_class")
    if extractor is not None and extractor not in features_extractors():
        raise UsageError(
            f"{where}: features_extractor_class {extractor!r} unknown; "
            f"valid: {', '.join(sorted(features_extractors()))}"
        )
    if not isinstance(config["policy_kwargs"].get("features_extractor_kwargs", {}), dict):
        raise UsageError(f"{where}: 'features_extractor_kwargs' must be a mapping")
    if not isinstance(config["deterministic"], bool):
        raise UsageError(f"{where}: 'deterministic' must be true or false")
    if config["vec_env"] not in VEC_ENVS:
        raise UsageError(f"{where}: vec_env must be one of {', '.join(VEC_ENVS)}")
    try:
        _check_values(config, classes[algo])
    except ArgumentError as error:
        raise UsageError(f"{where}: {error}") from error
    return config


# Ranges of the run settings and of common constructor arguments: key -> check. The
# upper bounds keep a run's memory and time finite (a 10**12-step rollout buffer).
_INT_RANGES: dict[str, tuple[int, int | None]] = {
    "n_envs": (1, 1024),
    "n_timesteps": (0, 10**11),  # 0: imitation only (``imitate`` or ``demonstrations``)
    "eval_freq": (1, 10**11),
    "n_eval_episodes": (1, 100_000),
    "checkpoint_freq": (1, 10**11),
    "n_steps": (2, 10**7),  # the rollout buffer holds n_steps * n_envs transitions
    "batch_size": (1, 10**7),
    "n_epochs": (1, 10_000),
    "buffer_size": (1, 10**8),
    "learning_starts": (0, 10**11),
    "sde_sample_freq": (-1, None),
    "stats_window_size": (1, None),
}
_FLOAT_RANGES: dict[str, tuple[float, float, bool]] = {  # low, high, low open
    "learning_rate": (0.0, 10.0, True),
    "gamma": (0.0, 1.0, True),
    "gae_lambda": (0.0, 1.0, False),
    "vf_coef": (0.0, 1e6, False),
    "max_grad_norm": (0.0, 1e6, True),
    "clip_range": (0.0, 10.0, True),
    "tau": (0.0, 1.0, True),
}


MAX_LAYERS = 16  # hidden layers of one network
MAX_LAYER_SIZE = 4096  # units of one hidden layer
MAX_HIDDEN_WEIGHTS = 1 << 24  # weights between one network's hidden layers (64 MB float32)
MAX_ROLLOUT = 10**7  # n_steps * n_envs: the transitions an on-policy rollout buffer holds


def _shown(value: Any) -> str:
    text = repr(value)
    return text if len(text) <= 80 else f"{text[:80]}... ({len(text)} characters)"


def _check_values(config: dict[str, Any], algorithm: type[BaseAlgorithm]) -> None:
    """Types and ranges of the block's values, in the environments' message style."""
    for key, (low, high) in _INT_RANGES.items():
        if key in config:
            check_int(key, config[key], low, high)
    for key, (least, most, low_open) in _FLOAT_RANGES.items():
        if key in config:
            check_float(key, config[key], least, most, low_open=low_open)
    params = inspect.signature(algorithm).parameters  # its __init__'s, less self
    for key in ("ent_coef", "target_kl", "clip_range_vf"):
        value = config.get(key)
        automatic = key in params and isinstance(params[key].default, str)  # SAC's "auto"
        if value is not None and not (automatic and str(value).startswith("auto")):
            check_float(key, value, 0.0, 1e6)
    for key, value in config.items():  # a switch is true or false, not a truthy value
        if key in params and isinstance(params[key].default, bool):
            check_bool(key, value)
    for key in ("train_freq", "gradient_steps"):
        if key in config and not isinstance(config[key], (list, tuple)):
            check_int(key, config[key], -1 if key == "gradient_steps" else 1)
    check_choice("policy", config["policy"], sorted(algorithm.policy_aliases))
    _check_policy_kwargs(config["policy_kwargs"], algorithm.policy_aliases[config["policy"]])
    if not (isinstance(config["normalize"], (bool, dict))):
        raise ArgumentError(
            f"normalize must be true, false or a mapping, got {config['normalize']!r}"
        )
    if isinstance(config["normalize"], dict):
        _check_normalize(config["normalize"])
    arch = config["policy_kwargs"].get("net_arch")
    if isinstance(arch, dict) and not set(arch) <= {"pi", "vf", "qf"}:
        raise ArgumentError(f"net_arch keys must be among pi, vf, qf, got {sorted(arch)}")
    layers = arch.values() if isinstance(arch, dict) else [arch] if arch is not None else []
    for layer in layers:
        if not isinstance(layer, list) or len(layer) > MAX_LAYERS:
            raise ArgumentError(
                f"net_arch must be a list of at most {MAX_LAYERS} layer sizes, got {_shown(arch)}"
            )
        for size in layer:
            check_int("net_arch layer size", size, 1, MAX_LAYER_SIZE)
        weights = sum(a * b for a, b in zip(layer, layer[1:], strict=False))
        if weights > MAX_HIDDEN_WEIGHTS:
            raise ArgumentError(
                f"net_arch {layer} has {weights} weights between its hidden layers; at most "
                f"{MAX_HIDDEN_WEIGHTS} allowed (e.g. [4096, 4096])"
            )
    if "n_steps" in config and config["n_steps"] * config["n_envs"] > MAX_ROLLOUT:
        raise ArgumentError(
            f"n_steps * n_envs must be at most {MAX_ROLLOUT} (the rollout buffer's "
            f"transitions), got {config['n_steps']} * {config['n_envs']}"
        )
    _check_replay_buffer(config)
    if config["residual"] is not None and not isinstance(config["residual"], str):
        raise ArgumentError(
            f"residual must be a scripted policy's name, got {config['residual']!r}"
        )
    check_float("residual_scale", config["residual_scale"], 0.0, 2.0, low_open=True)
    if not isinstance(config["residual_kwargs"], dict):
        raise ArgumentError(f"residual_kwargs must be a mapping, got {config['residual_kwargs']!r}")
    if config["residual_kwargs"] and config["residual"] is None:
        raise ArgumentError("residual_kwargs needs residual")
    if config["demonstrations"] is not None and not isinstance(config["demonstrations"], str):
        raise ArgumentError(
            f"demonstrations must be a dataset folder, got {config['demonstrations']!r}"
        )
    check_int("bc_epochs", config["bc_epochs"], 1, 100_000)
    _check_imitation(config)
    _check_memory(config)
    if "log_std_init" in config["policy_kwargs"]:
        check_float("log_std_init", config["policy_kwargs"]["log_std_init"], -20.0, 20.0)


def _check_imitation(config: dict[str, Any]) -> None:
    """``imitate`` a name, not with ``demonstrations`` nor ``residual``; 0 steps only with one."""
    name = config["imitate"]
    if name is not None and not isinstance(name, str):
        raise ArgumentError(f"imitate must be a scripted policy's name, got {name!r}")
    if name is not None and (config["demonstrations"] or config["residual"]):
        raise ArgumentError("imitate cannot be combined with demonstrations or residual")
    if not isinstance(config["imitate_kwargs"], dict):
        raise ArgumentError(f"imitate_kwargs must be a mapping, got {config['imitate_kwargs']!r}")
    check_int("dagger_iterations", config["dagger_iterations"], 0, 10_000)
    check_int("dagger_episodes", config["dagger_episodes"], 1, 10**6)
    if config["n_timesteps"] == 0 and not (name or config["demonstrations"]):
        raise ArgumentError("n_timesteps 0 (no RL) needs imitate or demonstrations")


def _check_memory(config: dict[str, Any]) -> None:
    """``memory`` a name of :func:`~motiongym.agents.learners.memories`, its keywords
    valid; in a dummy or subproc vec env (it wraps each env), not with ``residual``."""
    name = config["memory"]
    if name is None:
        if config["memory_kwargs"]:
            raise ArgumentError("memory_kwargs needs memory")
        return
    check_choice("memory", name, sorted(memories()))
    check_memory_kwargs(config["memory_kwargs"], name)
    if config["vec_env"] not in ("dummy", "subproc"):
        raise ArgumentError(f"memory needs vec_env dummy or subproc, got {config['vec_env']!r}")
    if config["residual"] is not None:
        raise ArgumentError("memory cannot be combined with residual")


def _check_replay_buffer(config: dict[str, Any]) -> None:
    """``replay_buffer_class`` a name of :data:`REPLAY_BUFFERS`, its keywords known."""
    name = config.get("replay_buffer_class")
    kwargs = config.get("replay_buffer_kwargs") or {}
    if name is None:
        if kwargs:
            raise ArgumentError("replay_buffer_kwargs needs replay_buffer_class")
        return
    check_choice("replay_buffer_class", name, sorted(REPLAY_BUFFERS))
    if not isinstance(kwargs, dict) or set(kwargs) - set(HER_KWARGS):
        raise ArgumentError(
            f"replay_buffer_kwargs must be a mapping with keys among {', '.join(HER_KWARGS)}, "
            f"got {kwargs!r}"
        )
    if "n_sampled_goal" in kwargs:
        check_int("n_sampled_goal", kwargs["n_sampled_goal"], 1, 1000)
    if "goal_selection_strategy" in kwargs:
        check_choice("goal_selection_strategy", kwargs["goal_selection_strategy"], GOAL_SELECTION)
    if not isinstance(kwargs.get("copy_info_dict", False), bool):
        raise ArgumentError(
            f"copy_info_dict must be true or false, got {kwargs['copy_info_dict']!r}"
        )


def _check_policy_kwargs(kwargs: dict[str, Any], policy: type) -> None:
    """Every key a keyword of the policy class, its switches true or false."""
    params = inspect.signature(policy).parameters  # its __init__'s, less self
    if any(p.kind == p.VAR_KEYWORD for p in params.values()):
        return
    valid = sorted(set(params) - {"self", "observation_space", "action_space", "lr_schedule"})
    for key, value in kwargs.items():
        if key not in valid:
            raise ArgumentError(f"unknown policy_kwargs key {key!r}; valid: {', '.join(valid)}")
        if isinstance(params[key].default, bool):
            check_bool(f"policy_kwargs.{key}", value)


def _str_list(name: str, value: Any) -> list[str]:
    if not isinstance(value, list) or not all(isinstance(v, str) for v in value):
        raise ArgumentError(f"{name} must be a list of observation keys, got {value!r}")
    return value


# VecNormalize's keywords a config's normalize mapping may set: key -> check.
_NORMALIZE_CHECKS = {
    "norm_obs": check_bool,
    "norm_reward": check_bool,
    "clip_obs": lambda k, v: check_float(k, v, 0.0, 1e6, low_open=True),
    "clip_reward": lambda k, v: check_float(k, v, 0.0, 1e6, low_open=True),
    "gamma": lambda k, v: check_float(k, v, 0.0, 1.0, low_open=True),
    "epsilon": lambda k, v: check_float(k, v, 0.0, 1.0, low_open=True),
    "norm_obs_keys": _str_list,
}


def _check_normalize(options: dict[str, Any]) -> None:
    unknown = sorted(set(options) - set(_NORMALIZE_CHECKS), key=str)
    if unknown:
        raise ArgumentError(
            f"unknown normalize key(s) {unknown}; valid: {', '.join(_NORMALIZE_CHECKS)}"
        )
    for key, value in options.items():
        _NORMALIZE_CHECKS[key](f"normalize.{key}", value)


def algorithm_kwargs(config: dict[str, Any]) -> dict[str, Any]:
    """The block's keys that go to the algorithm's constructor (replay buffer named: its class)."""
    kwargs = {key: value for key, value in config.items() if key not in RUN_SETTINGS}
    if kwargs.get("replay_buffer_class") is not None:
        import stable_baselines3

        name = REPLAY_BUFFERS[kwargs["replay_buffer_class"]]
        kwargs["replay_buffer_class"] = getattr(stable_baselines3, name)
        kwargs["replay_buffer_kwargs"] = dict(kwargs.get("replay_buffer_kwargs") or {})
    return kwargs
