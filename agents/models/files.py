"""Reading model folders without running anything from them.

A model folder comes from anyone (a download, a colleague, a shipped model),
so nothing in it is unpickled, ever:

* **SB3 archives** (``model.zip``). SB3 stores most of a model as JSON, but
  some entries (the policy class, the spaces, schedules, buffers) as
  cloudpickle under ``":serialized:"``, which its loader would unpickle.
  :func:`load_archive` reads the JSON first and supplies every such entry
  itself through SB3's ``custom_objects`` (the spaces of the environment it
  will act in, the policy class identified by its module and docstring among
  the algorithms' own policy aliases, schedules rebuilt from plain numbers,
  empty buffers), so SB3 never unpickles. An archive member, a serialized
  entry or a data entry we do not know (not an attribute of the algorithm)
  is refused with its name. The weights (``*.pth``)
  are read by SB3 with ``torch.load(weights_only=True)``, which refuses
  pickled code.
* **Observation normalisation** (``vecnormalize.npz``): VecNormalize's
  running mean, variance and count as plain arrays, read with
  ``allow_pickle=False``; every statistic must be finite and every variance
  non-negative. SB3's ``vecnormalize.pkl`` is a pickle and is never read: a
  folder that has only that file is refused with the way out.
* **Sizes** are checked before anything is read (:mod:`motiongym.agents.limits`):
  archive members' declared sizes (each and together at most 1 GiB, the
  ``data`` JSON at most 16 MiB, a member past 1 MiB at most 10 times its
  stored size), ``.npy`` headers against their members, nesting of JSON;
  a run's ``config.yml`` whose ``net_arch`` is not the archive's is refused.
* **Manifests** (:mod:`motiongym.agents.models.pretrained`): ``motiongym train`` and
  ``ship`` write ``manifest.json`` (the SHA-256 of every file); a folder with
  one is verified before use, a folder without one loads only when the user
  says ``--trust`` (the archive is still read as above).
"""

from __future__ import annotations

import json
import sys
import zipfile
from collections import deque
from pathlib import Path
from typing import Any

import numpy as np
from gymnasium import spaces
from stable_baselines3.common.base_class import BaseAlgorithm
from stable_baselines3.common.save_util import data_to_json
from stable_baselines3.common.vec_env import VecEnv, VecNormalize

from motiongym.agents.errors import UsageError
from motiongym.agents.limits import check_zip, load_json, load_npz

NORMALIZATION_FILE = "vecnormalize.npz"
PICKLED_NORMALIZATION = "vecnormalize.pkl"
ARCHIVE_MEMBERS = {"data", "_stable_baselines3_version", "system_info.txt"}
# Serialized entries we supply ourselves; anything else serialized is refused.
RUNTIME_ENTRIES: dict[str, Any] = {  # rollout state, irrelevant to acting: start empty
    "_last_obs": None,
    "_last_original_obs": None,
    "_last_episode_starts": None,
    "ep_info_buffer": deque(maxlen=100),
    "ep_success_buffer": deque(maxlen=100),
    "rollout_buffer_class": None,
    "replay_buffer_class": None,
    "action_noise": None,
}
MAX_MEMBER_BYTES = 1 << 30  # no archive member unpacks past 1 GiB
MAX_ARCHIVE_BYTES = 1 << 30  # nor all of them together
MAX_DATA_BYTES = 16 << 20  # the data JSON (a few kB to a few MB in SB3's own files)
MAX_NORMALIZATION_BYTES = 64 << 20  # a normalisation file's arrays, all together
# (low, high]: VecNormalize clips to [-clip_obs, clip_obs], divides by sqrt(var + epsilon)
# and weighs its statistics by count (the steps seen, at least SB3's initial 1e-4).
NORMALIZATION_RANGES = {"clip_obs": (0.0, 1e6), "epsilon": (0.0, 1.0), "count": (0.0, 1e15)}
# Entries SB3 writes that a model gets only when set up (with its environment): with
# the attributes of a model made without setting up, every entry a data JSON may hold.
SETUP_ENTRIES = {
    "observation_space",
    "action_space",
    "lr_schedule",
    "n_envs",
    "exploration_schedule",
    *(f"{net}batch_norm_stats{t}" for net in ("", "actor_", "critic_") for t in ("", "_target")),
}
OPTIMIZERS = ("Adam", "AdamW", "RMSprop", "SGD")  # torch.optim classes a policy may name


def algorithm_classes() -> dict[str, type[BaseAlgorithm]]:
    """The SB3 and sb3-contrib algorithms by lower-case name (PPO before A2C)."""
    from sb3_contrib import TQC, MaskablePPO, RecurrentPPO
    from stable_baselines3 import A2C, DQN, PPO, SAC, TD3

    classes: list[type[BaseAlgorithm]] = [PPO, A2C, SAC, TD3, DQN, MaskablePPO, RecurrentPPO, TQC]
    return {cls.__name__.lower(): cls for cls in classes}


def read_archive_data(path: Path) -> dict[str, Any]:
    """The archive's ``data`` JSON, after checking its members are the expected ones
    and that no member unpacks past :data:`MAX_MEMBER_BYTES`."""
    try:
        with zipfile.ZipFile(path) as archive:
            names = archive.namelist()
            unknown = [n for n in names if n not in ARCHIVE_MEMBERS and not n.endswith(".pth")]
            if unknown:
                raise UsageError(f"{path}: unexpected archive member(s) {unknown}; refused")
            if "data" not in names:
                raise UsageError(f"{path} is not a Stable-Baselines3 model file (no data entry)")
            check_zip(path, archive, MAX_MEMBER_BYTES, MAX_ARCHIVE_BYTES)
            if archive.getinfo("data").file_size > MAX_DATA_BYTES:
                raise UsageError(
                    f"{path}: its data entry declares {archive.getinfo('data').file_size} "
                    f"bytes; at most {MAX_DATA_BYTES} allowed"
                )
            data = load_json(archive.read("data"), f"{path} (data)", MAX_DATA_BYTES)
    except UsageError:
        raise
    except Exception as error:  # noqa: BLE001 - any failure to read a file from anyone
        raise UsageError(f"{path} is not a Stable-Baselines3 model file ({error})") from None
    if not isinstance(data, dict):
        raise UsageError(f"{path}: its data entry is not a JSON object")
    return data


def saved_policy(path: Path, data: dict[str, Any]) -> tuple[type[BaseAlgorithm], type]:
    """The algorithm and policy class of the archive, identified without unpickling.

    SB3 writes the policy class's ``__module__`` and ``__doc__`` as plain text
    beside its pickle; the class is the one of the known algorithms' policy
    aliases with both equal.
    """
    entry = data.get("policy_class")
    if not isinstance(entry, dict):
        raise UsageError(f"{path}: no policy class recorded")
    module, doc = entry.get("__module__"), entry.get("__doc__")
    found = [
        (algorithm, policy)
        for algorithm in algorithm_classes().values()
        for policy in algorithm.policy_aliases.values()
        if policy.__module__ == module and str(policy.__doc__) == doc
    ]
    # SAC's CnnPolicy and MultiInputPolicy share module and docstring; their
    # recorded __init__ text ("<function MultiInputPolicy.__init__ ...>") tells them apart.
    init = str(entry.get("__init__", ""))
    named = [f for f in found if f"<function {f[1].__name__}.__init__" in init]
    if named or found:
        return (named or found)[0]
    raise UsageError(f"{path}: no known algorithm saves policies of module {module!r}")


def _space_record(space: spaces.Space) -> dict[str, Any]:
    record = json.loads(data_to_json({"space": space}))["space"]
    return {k: v for k, v in record.items() if k not in (":serialized:", "_np_random")}


def check_space(path: Path, data: dict[str, Any], kind: str, space: spaces.Space, what: str):
    """Raise unless the archive's recorded ``kind`` space is ``space`` (compared as text)."""
    stored = data.get(kind)
    if not isinstance(stored, dict):
        raise UsageError(f"{path}: no {kind.replace('_', ' ')} recorded")
    stored = {k: v for k, v in stored.items() if k not in (":serialized:", "_np_random")}
    if stored != _space_record(space):
        shown = stored.get("spaces") or stored.get("_shape") or stored.get("n")
        raise UsageError(
            f"model {path} was trained for another {kind.replace('_', ' ')}: "
            f"{stored.get(':type:')} {shown} ({what} has {_space_text(space)})"
        )


def _space_text(space: spaces.Space) -> str:
    """A one-line name of ``space``: its class and shape (or its n, or its keys)."""
    if isinstance(space, spaces.Dict):
        return f"Dict({', '.join(space.spaces)})"
    if isinstance(space, spaces.Discrete):
        return f"Discrete({space.n})"
    return f"{type(space).__name__}{space.shape}"


def _train_freq(stored: dict[str, Any]):
    from stable_baselines3.common.type_aliases import TrainFreq, TrainFrequencyUnit

    try:
        frequency = int(stored.get("frequency", 1))
        unit = TrainFrequencyUnit(str(stored.get("unit", "step")).split(".")[-1].lower())
    except (TypeError, ValueError):
        frequency, unit = 1, TrainFrequencyUnit.STEP
    return TrainFreq(frequency, unit)


def _policy_kwargs(path: Path, stored: dict[str, Any], run: dict[str, Any]) -> dict[str, Any]:
    """The policy's keywords rebuilt without unpickling.

    SB3 writes each entry's text beside the pickle. An entry the run's config
    gives is taken from there; an optimizer class is looked up by name among
    :data:`OPTIMIZERS`; any other entry must be a plain literal (numbers, lists,
    dicts of them); anything else is refused with its name.
    """
    import ast

    import torch

    out: dict[str, Any] = {}
    for key, text in stored.items():
        if key in (":type:", ":serialized:"):
            continue
        if key in run:
            out[key] = run[key]
        elif key == "optimizer_class":
            name = str(text).rstrip("'>").split(".")[-1]
            if name not in OPTIMIZERS:
                raise UsageError(f"{path}: policy optimizer {text!r} is not one of {OPTIMIZERS}")
            out[key] = getattr(torch.optim, name)
        else:
            try:
                out[key] = ast.literal_eval(str(text))
            except (ValueError, SyntaxError, TypeError, MemoryError, RecursionError):
                raise UsageError(
                    f"{path}: policy_kwargs entry {key!r} is stored as code; load the model "
                    "from its run folder, whose config.yml names it"
                ) from None
    return out


def _schedule(value: float):
    from stable_baselines3.common.utils import ConstantSchedule

    return ConstantSchedule(float(value))


def _plain_rate(entry: Any) -> float:
    """A learning rate saved as a number, or as SB3's ``ConstantSchedule`` (its ``val``)."""
    if isinstance(entry, (int, float)):
        return float(entry)
    value = entry.get("val") if isinstance(entry, dict) else None
    return float(value) if isinstance(value, (int, float)) else 0.0


def _check_net_arch(path: Path, data: dict[str, Any], run: dict[str, Any]) -> None:
    """Refuse a run config whose ``net_arch`` is not the one the archive was saved with."""
    import ast

    stored = data.get("policy_kwargs")
    if "net_arch" not in run or not isinstance(stored, dict) or "net_arch" not in stored:
        return
    saved = stored["net_arch"]
    if isinstance(saved, str):
        try:
            saved = ast.literal_eval(saved)
        except (ValueError, SyntaxError, TypeError, MemoryError, RecursionError):
            return  # not a literal: SB3's loading compares the weights' shapes
    if saved != run["net_arch"]:
        raise UsageError(
            f"{path}: the run's config.yml gives net_arch {_short(run['net_arch'])}, the model "
            f"was saved with {_short(saved)}; refused"
        )


def _short(value: Any) -> str:
    text = repr(value)
    return text if len(text) <= 80 else f"{text[:80]}..."


def load_archive(
    path: Path,
    observation_space: spaces.Space,
    action_space: spaces.Space,
    what: str,
    policy_kwargs: dict[str, Any] | None = None,
) -> BaseAlgorithm:
    """The SB3 model saved at ``path``, for ``observation_space`` / ``action_space``.

    ``policy_kwargs``: the run's own (from its ``config.yml``), needed when the
    archive holds them serialized (a features extractor class).
    """
    data = read_archive_data(path)
    algorithm, policy = saved_policy(path, data)
    # Every algorithm's own constructor takes _init_setup_model (the base class's does not).
    fresh = algorithm(policy=policy, env=None, device="cpu", _init_setup_model=False)  # type: ignore[call-arg]
    extra = sorted(set(data) - set(fresh.__dict__) - SETUP_ENTRIES)
    if extra:  # SB3 would set each as an attribute of the model
        raise UsageError(f"{path}: unknown data entr{'y' if len(extra) == 1 else 'ies'} {extra}")
    check_space(path, data, "observation_space", observation_space, what)
    check_space(path, data, "action_space", action_space, what)
    _check_net_arch(path, data, policy_kwargs or {})
    rate = data.get("learning_rate", 0.0)
    steps = data.get("train_freq", {}) if isinstance(data.get("train_freq"), dict) else {}
    supply: dict[str, Any] = {
        "policy_class": policy,
        "observation_space": observation_space,
        "action_space": action_space,
        "lr_schedule": _schedule(rate if isinstance(rate, (int, float)) else 0.0),
        # rl-zoo3 saves the rate as a schedule object (its plain "val" beside the pickle);
        # a rate plays no part in acting, so any other schedule becomes 0.
        "learning_rate": _schedule(_plain_rate(rate)),
        "target_entropy": float(-np.prod(action_space.shape or ())),  # SB3's "auto"
        "clip_range": _schedule(0.2),
        "clip_range_vf": None,
        "exploration_schedule": _schedule(0.0),
        "train_freq": _train_freq(steps),
        **RUNTIME_ENTRIES,
    }
    serialized = [k for k, v in data.items() if isinstance(v, dict) and ":serialized:" in v]
    if "policy_kwargs" in serialized:
        supply["policy_kwargs"] = _policy_kwargs(path, data["policy_kwargs"], policy_kwargs or {})
    always = ("policy_class", "observation_space", "action_space")  # serialized or not
    custom = {key: supply[key] for key in (*serialized, *always) if key in supply}
    if data.get("replay_buffer_kwargs"):  # HER's keywords: no replay buffer is needed to act
        custom["replay_buffer_kwargs"] = {}
    unknown = sorted(set(serialized) - set(supply))
    if unknown:
        raise UsageError(
            f"{path}: serialized entr{'y' if len(unknown) == 1 else 'ies'} "
            f"{unknown} would run code on loading; refused"
        )
    try:
        model = algorithm.load(path, device="cpu", custom_objects=custom)
    except Exception as error:  # noqa: BLE001 - corrupt weights or plain entries from anyone
        problem = " ".join(str(error).split())[:300]
        raise UsageError(f"{path}: cannot load it ({type(error).__name__}: {problem})") from None
    for name, tensor in model.policy.state_dict().items():
        if tensor.is_floating_point() and not bool(tensor.isfinite().all()):
            raise UsageError(f"{path}: weights {name} are not finite numbers; refused")
    return model


# ---------------------------------------------------------------- normalisation


def save_normalization(normalization: VecNormalize, path: Path) -> Path:
    """Write VecNormalize's statistics and settings as plain arrays (``.npz``)."""
    arrays: dict[str, Any] = {  # arrays and NumPy scalars
        "clip_obs": np.float64(normalization.clip_obs),
        "epsilon": np.float64(normalization.epsilon),
        "norm_obs": np.bool_(normalization.norm_obs),
    }
    rms = normalization.obs_rms
    if isinstance(rms, dict):
        for key, stats in rms.items():
            arrays[f"mean.{key}"], arrays[f"var.{key}"] = stats.mean, stats.var
            arrays[f"count.{key}"] = np.float64(stats.count)
    else:
        arrays["mean"], arrays["var"], arrays["count"] = rms.mean, rms.var, np.float64(rms.count)
    with path.open("wb") as handle:
        np.savez(handle, **arrays)
    return path


def load_normalization(path: Path, venv: VecEnv) -> VecNormalize:
    """VecNormalize over ``venv`` (evaluation mode) from a ``.npz`` written above."""
    arrays = load_npz(path, MAX_NORMALIZATION_BYTES, MAX_NORMALIZATION_BYTES)
    for name, value in arrays.items():
        if value.dtype.kind not in "fb" or not np.isfinite(value.astype(float)).all():
            raise UsageError(f"{path}: {name} is not finite numbers; refused")
        if name.startswith("var") and (value < 0).any():
            raise UsageError(f"{path}: {name} has a negative variance; refused")
    for name, value in arrays.items():
        if name in ("clip_obs", "epsilon") or name.startswith("count"):
            low, high = NORMALIZATION_RANGES[name.split(".")[0]]
            if value.shape != () or not low < float(value) <= high:
                raise UsageError(
                    f"{path}: {name} must be one number in ({low:g}, {high:g}], got "
                    f"{np.array2string(value, threshold=4)}; refused"
                )
    try:
        normalization = VecNormalize(
            venv,
            training=False,
            norm_obs=bool(arrays["norm_obs"]),
            norm_reward=False,
            clip_obs=float(arrays["clip_obs"]),
            epsilon=float(arrays["epsilon"]),
        )
        rms = normalization.obs_rms
        for key, stats in rms.items() if isinstance(rms, dict) else [(None, rms)]:
            suffix = "" if key is None else f".{key}"
            mean, var = arrays[f"mean{suffix}"], arrays[f"var{suffix}"]
            if mean.shape != stats.mean.shape or var.shape != stats.var.shape:
                raise UsageError(
                    f"{path}: statistics of shape {mean.shape} for an observation "
                    f"of shape {stats.mean.shape}"
                )
            whole: Any = venv.observation_space  # a Dict where the statistics are per key
            space = whole if key is None else whole[key]
            _check_plausible(path, suffix, mean, var, space)
            stats.mean, stats.var = mean.astype(np.float64), var.astype(np.float64)
            stats.count = float(arrays[f"count{suffix}"])
    except KeyError as error:
        raise UsageError(f"{path}: missing entry {error}") from error
    return normalization


def _check_plausible(
    path: Path, suffix: str, mean: np.ndarray, var: np.ndarray, space: spaces.Space
) -> None:
    """Statistics of observations in a bounded space: the mean lies inside the box and
    the variance is at most ``(high - low)^2 / 4`` (Popoviciu's inequality)."""
    if not isinstance(space, spaces.Box):
        return
    low, high = space.low.astype(np.float64), space.high.astype(np.float64)
    bounded = np.isfinite(low) & np.isfinite(high)
    span = np.where(bounded, high - low, 0.0)
    slack = 1e-6 * (1.0 + span)
    outside = bounded & ((mean < low - slack) | (mean > high + slack))
    too_wide = bounded & (var > span**2 / 4 + slack)
    if outside.any() or too_wide.any():
        i = int(np.flatnonzero(outside | too_wide)[0])
        raise UsageError(
            f"{path}: mean{suffix}[{i}] = {mean.flat[i]:.6g}, var{suffix}[{i}] = "
            f"{var.flat[i]:.6g} cannot come from observations in [{low.flat[i]:.6g}, "
            f"{high.flat[i]:.6g}]; refused"
        )


def warn(message: str) -> None:
    """One line on stderr."""
    print(f"warning: {message}", file=sys.stderr)
