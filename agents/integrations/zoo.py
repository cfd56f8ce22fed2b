"""rl-zoo3 hyperparameter files, ``configs/zoo/<algo>.yml``, made from ``configs/``.

rl-zoo3's ``--conf-file`` holds one algorithm's settings keyed by environment
ID. A block's keys are either the zoo's own (:data:`ZOO_KEYS`) or keyword
arguments of the algorithm's constructor; the zoo passes everything else to
the constructor, so a motiongym run setting it does not know would reach
PPO's constructor and fail. Each ID's ``configs/<ID>.yml`` block of the
algorithm is converted:

* kept: ``n_envs``, ``n_timesteps``, ``policy``, ``normalize`` (a bool or a
  mapping, as the zoo reads it) and every constructor argument;
* ``policy_kwargs`` becomes the Python expression the zoo evaluates
  (``dict(net_arch=[256, 256], activation_fn=nn.Tanh)``), ``her`` the zoo's
  ``HerReplayBuffer``;
* ``env_kwargs``, ``eval_freq``, ``n_eval_episodes`` and ``checkpoint_freq``
  are the zoo's command-line options (``--env-kwargs``, ``--eval-freq``,
  ``--eval-episodes``, ``--save-freq``): the file's header gives each ID's
  command with them;
* left out, with the reason in the header: what the zoo cannot run
  (``maskableppo``, ``vec_env`` ``native`` or ``pettingzoo``, a residual or
  behaviour-cloned start, motiongym's own features extractors) and
  ``deterministic: false`` (the zoo evaluates deterministically).

Regenerate with ``python -m motiongym.agents.integrations.zoo`` (a test checks that the
files match).
"""

from __future__ import annotations

import sys
from pathlib import Path
from typing import Any

import yaml

from motiongym.agents.limits import read_yaml_file
from motiongym.agents.training.config import ACTIVATIONS, default_config_path
from motiongym.envs import ENV_IDS

ALGORITHMS = ("ppo", "sac", "tqc")  # the algorithms of configs/ that the zoo has
# Keys the zoo reads itself (rl_zoo3.exp_manager); the rest go to the constructor.
ZOO_KEYS = (
    "n_envs", "n_timesteps", "policy", "policy_kwargs", "normalize", "frame_stack",
    "env_wrapper", "vec_env_wrapper", "callback", "monitor_kwargs", "noise_type", "noise_std",
)  # fmt: skip
# motiongym run settings that are zoo command-line options: key -> option.
OPTIONS = {
    "eval_freq": "--eval-freq",
    "n_eval_episodes": "--eval-episodes",
    "checkpoint_freq": "--save-freq",
}


def _policy_kwargs(kwargs: dict[str, Any]) -> str:
    parts = []
    for key, value in kwargs.items():
        if key == "activation_fn":
            parts.append(f"activation_fn=nn.{ACTIVATIONS[value]}")
        else:
            parts.append(f"{key}={value!r}")
    return f"dict({', '.join(parts)})"


def refusal(block: dict[str, Any]) -> str | None:
    """Why the zoo cannot train this block (None: it can)."""
    if block.get("vec_env", "dummy") not in ("dummy", "subproc"):
        return f"vec_env {block['vec_env']} is motiongym's"
    if "features_extractor_class" in block.get("policy_kwargs", {}):
        return "its features extractor is motiongym's"
    for key in ("residual", "demonstrations"):
        if block.get(key):
            return f"{key} is motiongym's"
    if block.get("deterministic", True) is False:
        return "it is evaluated by sampling; the zoo evaluates deterministically"
    return None


def zoo_block(block: dict[str, Any]) -> tuple[dict[str, Any], list[str]]:
    """The zoo's block and the command-line options that carry the rest."""
    out, options = {}, []
    for key, value in block.items():
        if key in OPTIONS:
            options.append(f"{OPTIONS[key]} {value}")
        elif key == "env_kwargs":
            options.append("--env-kwargs " + " ".join(f"{k}:{v!r}" for k, v in value.items()))
        elif key == "policy_kwargs":
            out[key] = _policy_kwargs(value)
        elif key == "replay_buffer_class":
            out[key] = "HerReplayBuffer"
        elif key not in ("vec_env", "deterministic"):
            out[key] = value
    return out, options


def zoo_file(algo: str) -> str:
    """The text of ``configs/zoo/<algo>.yml``."""
    blocks, commands, left_out = {}, [], []
    for env_id in ENV_IDS:
        path = default_config_path(env_id)
        document = read_yaml_file(path) if path.is_file() else {}
        if algo not in document:
            continue
        reason = refusal(document[algo])
        if reason:
            left_out.append(f"#   {env_id}: {reason}")
            continue
        blocks[env_id], options = zoo_block(document[algo])
        command = f"--algo {algo} --env {env_id} {' '.join(options)}".strip()
        commands.append(f"#   python -m rl_zoo3.train {command}")
    header = [
        f"# rl-zoo3 settings for {algo}, keyed by ID (made by",
        "# python -m motiongym.agents.integrations.zoo from configs/<ID>.yml; do not edit).",
        "# Each ID's command (add --gym-packages",
        f"# motiongym --conf-file configs/zoo/{algo}.yml):",
        *commands,
    ]
    if left_out:
        header += ["# Left out (the zoo cannot run them):", *left_out]
    return "\n".join(header) + "\n" + yaml.safe_dump(blocks, sort_keys=False)


def write_zoo_files(folder: Path) -> list[Path]:
    folder.mkdir(parents=True, exist_ok=True)
    paths = []
    for algo in ALGORITHMS:
        path = folder / f"{algo}.yml"
        path.write_text(zoo_file(algo))
        paths.append(path)
    return paths


if __name__ == "__main__":
    root = Path(sys.argv[1]) if len(sys.argv) > 1 else Path("configs/zoo")
    for written in write_zoo_files(root):
        print(f"wrote {written}")
