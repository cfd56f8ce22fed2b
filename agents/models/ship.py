"""Shipping the best of a set of training runs into ``agents/models/pretrained/``.

A model already shipped under the same ID and label is evaluated on the same
held-out episodes first; it is replaced only when the best run scores at
least as well (success rate, then mean return), or when forced.
"""

from __future__ import annotations

import json
import shutil
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path

from motiongym.agents.environments import check_env_id, long_episodes_note, make_env, short_name
from motiongym.agents.errors import UsageError
from motiongym.agents.evaluation.episodes import EVALUATION_SEED, Evaluation, evaluate
from motiongym.agents.limits import load_npz, read_json_file
from motiongym.agents.models.predictors import CONFIG_FILE, MODEL_FILE, load_model, run_config
from motiongym.agents.models.pretrained import (
    LEARNING_CURVES,
    METRICS,
    SHIPPED_FILES,
    pretrained_root,
    write_manifest,
)


def agent_kind(config: dict) -> str:
    """How a run's agent learned: ``demonstrations`` (``imitate`` or ``demonstrations``),
    ``residual`` (acts through a scripted policy), else ``scratch``."""
    if config.get("imitate") or config.get("demonstrations"):
        return "demonstrations"
    return "residual" if config.get("residual") else "scratch"


def shipped_label(config: dict) -> str:
    """The folder name of a run's model under its ID: the algorithm, ``-shared`` for a
    shared-parameter multi-agent run (``vec_env: pettingzoo``), ``-residual`` for a
    correction of a scripted policy (``residual: <policy>``), ``-dagger`` for one taught
    by DAgger (``imitate``), so that each kind ships beside the others."""
    label = config["algo"] + ("-shared" if config.get("vec_env") == "pettingzoo" else "")
    if config.get("residual"):
        return label + "-residual"
    return label + ("-dagger" if config.get("imitate") else "")


def _run_config(run_dir: Path) -> dict:
    """The run's ``config.yml``, validated as the loaders do, with its ID and seed."""
    config_file = run_dir / CONFIG_FILE
    if not config_file.is_file():
        raise UsageError(f"{run_dir} is not a training run folder (no config.yml)")
    config = run_config(run_dir / MODEL_FILE)
    check_env_id(config.get("env_id"))
    if isinstance(config.get("seed"), bool) or not isinstance(config.get("seed"), int):
        raise UsageError(f"{config_file}: 'seed' must be an integer, got {config.get('seed')!r}")
    return config


def _imitation_seconds(run_dir: Path) -> dict[str, float]:
    """``{"dagger_seconds": s}``: the wall-clock time of a run's DAgger (none without)."""
    file = run_dir / "dagger.json"
    if not file.is_file():
        return {}
    return {"dagger_seconds": float(read_json_file(file, 1 << 20)["seconds"])}


def _learning_curve_rows(run_dir: Path, seed: int) -> list[str]:
    """``seed,steps,mean return,success rate`` per evaluation of the run's callback."""
    file = run_dir / "eval" / "evaluations.npz"
    if not file.is_file():
        return []
    data = load_npz(file, 64 << 20, 64 << 20)
    returns = data["results"].mean(axis=1)
    successes = (
        data["successes"].mean(axis=1) if "successes" in data else [float("nan")] * len(returns)
    )
    return [
        f"{seed},{int(steps)},{ret:.6g},{success:.6g}"
        for steps, ret, success in zip(data["timesteps"], returns, successes, strict=True)
    ]


Score = tuple[float, float]  # (success rate, mean return) on the held-out episodes


def score(summary: dict[str, dict[str, float]]) -> Score:
    """What ``ship`` ranks by: success rate (0 without ``is_success``), then mean return."""
    success = summary["is_success"]["mean"] if "is_success" in summary else 0.0
    return success, summary["return"]["mean"]


def describe(value: Score) -> str:
    return f"success {100 * value[0]:.0f} %, mean return {value[1]:.4g}"


@dataclass
class Shipped:
    """Where the model went, its score, and the replaced model's (None if none)."""

    folder: Path
    score: Score
    previous: Score | None


def _previous_score(folder: Path, env, env_id: str, seeds: range, label: str) -> Score | None:
    """The score of the model shipped at ``folder`` on ``seeds``, None if none is there."""
    if not (folder / "model.zip").is_file():
        return None
    try:
        predictor = load_model(folder, env, env_id)
    except UsageError as error:
        raise UsageError(
            f"the model shipped at {folder} cannot be evaluated ({error}); "
            "--force replaces it unseen"
        ) from error
    return score(evaluate(env, predictor, seeds, env_id, label).summary())


def ship(
    run_dirs: list[Path],
    n_episodes: int = 20,
    seed: int | None = None,
    root: Path | None = None,
    force: bool = False,
    announce: Callable[[str], None] | None = None,
) -> Shipped:
    """Evaluate the runs of one ID and algorithm (training seeds) and ship the best.

    Every run is evaluated on the same ``n_episodes`` held-out seeds from
    ``seed`` (default :data:`~motiongym.agents.evaluation.episodes.EVALUATION_SEED`, as
    ``compare`` uses) in the registered task (training-only ``env_kwargs``
    such as a curriculum's are not applied). The best run (success rate, then
    mean return) is copied into ``pretrained/<Name>-vN/<label>/`` with
    ``metrics.json``: each run's summary and episodes (and whether it acted on
    its most likely or on sampled actions, its ``deterministic`` setting), and the summary pooled
    over every run's episodes (the reported "over seeds and episodes"
    figures); ``learning_curves.csv``: every run's evaluation-callback curve.
    The manifest is written last.

    A model already in that folder is evaluated on the same episodes; if it
    scores better than the best run, nothing is written and a
    :class:`UsageError` gives both scores, unless ``force``. ``announce``, if
    given, is told before the evaluations start what they may cost where the
    ID's episodes are long (:func:`~motiongym.agents.environments.long_episodes_note`).
    """
    if not run_dirs:
        raise UsageError("ship needs at least one run folder")
    configs = [_run_config(run_dir) for run_dir in run_dirs]
    env_id, label = configs[0]["env_id"], shipped_label(configs[0])
    for run_dir, config in zip(run_dirs, configs, strict=True):
        if (config["env_id"], shipped_label(config)) != (env_id, label):
            raise UsageError(
                f"{run_dir} trained {shipped_label(config)} on {config['env_id']}, "
                f"not {label} on {env_id}: ship the runs of one ID and algorithm together"
            )
    seed = EVALUATION_SEED if seed is None else seed
    seeds = range(seed, seed + n_episodes)
    env = make_env(env_id)
    long = long_episodes_note(env_id, None, n_episodes)
    if announce is not None and long is not None:
        announce(f"{long}, for each run and the model shipped there (the ID's own limit)")
    runs, pooled = [], Evaluation(env_id, label)
    for run_dir, config in zip(run_dirs, configs, strict=True):
        evaluation = evaluate(env, load_model(run_dir, env, env_id), seeds, env_id, label)
        pooled.episodes += evaluation.episodes
        runs.append(
            {
                "run": run_dir.name,
                "training_seed": config["seed"],
                "deterministic": config.get("deterministic", True),
                **_imitation_seconds(run_dir),
                **evaluation.to_json(),
            }
        )
    best = max(range(len(runs)), key=lambda i: score(runs[i]["summary"]))
    best_score = score(runs[best]["summary"])
    folder = (root or pretrained_root()) / short_name(env_id) / label
    previous = None if force else _previous_score(folder, env, env_id, seeds, label)
    env.close()
    if previous is not None and previous > best_score:
        raise UsageError(
            f"not shipped: the model at {folder} scores better on the {n_episodes} held-out "
            f"episodes ({describe(previous)}) than the best run {runs[best]['run']} "
            f"({describe(best_score)}); --force replaces it anyway"
        )
    if folder.is_dir():
        shutil.rmtree(folder)
    folder.mkdir(parents=True)
    for name in SHIPPED_FILES:
        if (run_dirs[best] / name).is_file():
            shutil.copy2(run_dirs[best] / name, folder / name)
    metrics = {
        "env_id": env_id,
        "policy": label,
        "kind": agent_kind(configs[best]),
        "shipped_run": runs[best]["run"],
        "held_out_seeds": list(seeds),
        "pooled": pooled.summary(),
        "runs": runs,
    }
    (folder / METRICS).write_text(json.dumps(metrics, indent=2))
    rows = ["training_seed,timesteps,mean_return,success_rate"]
    for run_dir, config in zip(run_dirs, configs, strict=True):
        rows += _learning_curve_rows(run_dir, config["seed"])
    (folder / LEARNING_CURVES).write_text("\n".join(rows) + "\n")
    write_manifest(folder)
    return Shipped(folder, best_score, previous)
