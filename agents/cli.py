"""The ``motiongym`` command: list, evaluate, compare, train, dataset, ship, record, benchmarks,
reproduce, bench; sweep and rllib (Ray, :mod:`motiongym.agents.integrations.ray_commands`).

Bad input (an unknown ID, policy, algorithm, experiment or configuration key, a
malformed YAML file, a model built for another space) ends in one line on
standard error that names the problem and the valid choices, and exit code 2.
"""

from __future__ import annotations

import argparse
import os
import sys
import warnings
from pathlib import Path
from typing import Any

from motiongym.agents.environments import (
    LONG_EPISODE,
    check_env_id,
    long_episodes_note,
    make_env,
    short_name,
)
from motiongym.agents.errors import UsageError
from motiongym.agents.evaluation.episodes import EVALUATION_SEED, Evaluation
from motiongym.baselines.registry import UnknownPolicyError
from motiongym.envs import ENV_IDS
from motiongym.envs.core import ArgumentError

DEFAULT_EPISODES = 10
MAX_SEED = 2**32 - 1  # NumPy, Gymnasium and torch all take seeds in [0, 2**32)
MAX_ENV_KWARG_BYTES = 64 * 1024  # one --env-kwargs value


class _Parser(argparse.ArgumentParser):
    """argparse with the command's own error style: one line, exit 2."""

    def error(self, message: str) -> None:  # type: ignore[override]
        print(f"motiongym: error: {message}", file=sys.stderr)
        raise SystemExit(2)


def package_version() -> str:
    """The installed distribution's version (pyproject.toml's)."""
    from importlib.metadata import PackageNotFoundError, version

    try:
        return version("motiongym")
    except PackageNotFoundError:  # run from a source tree that was never installed
        return "unknown (not installed)"


def _count(text: str) -> int:
    """A positive whole number (episodes, timesteps)."""
    try:
        value = int(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"must be a whole number >= 1, got {text!r}") from None
    if value < 1:
        raise argparse.ArgumentTypeError(f"must be a whole number >= 1, got {value}")
    return value


def _seed(text: str) -> int:
    try:
        value = int(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"must be a whole number, got {text!r}") from None
    if not 0 <= value <= MAX_SEED:
        raise argparse.ArgumentTypeError(f"must be in [0, {MAX_SEED}], got {value}")
    return value


def _folder(text: str) -> Path:
    """An output folder: it may not exist yet, but may not be a file, and what of it
    exists must be a writable folder (checked before any work, not after it)."""
    path = Path(text)
    _check_names(text)
    if path.exists() and not path.is_dir():
        raise argparse.ArgumentTypeError(f"{text!r} is a file, not a folder")
    _check_writable_above(text, path)
    return path


def _file(text: str) -> Path:
    """An output file: it may not exist yet, but may not be a folder; its folder must
    be (or be makeable in) a writable folder."""
    path = Path(text)
    _check_names(text)
    if path.is_dir():
        raise argparse.ArgumentTypeError(f"{text!r} is a folder, not a file")
    _check_writable_above(text, path.parent)
    return path


PSEUDO_FILESYSTEMS = ("/proc", "/sys", "/dev")  # kernel interfaces, never output folders


def _shown(text: str) -> str:
    return text if len(text) <= 80 else f"{text[:80]}... ({len(text)} characters)"


def _check_names(text: str) -> None:
    """Refuse an output path with a name (a part between slashes) or a whole longer than
    Linux allows (255 and 4095 bytes), before anything looks it up."""
    long = [part for part in Path(text).parts if len(os.fsencode(part)) > 255]
    if long:
        raise argparse.ArgumentTypeError(
            f"{_shown(text)!r}: a name of {len(os.fsencode(long[0]))} bytes; at most 255 allowed"
        )
    if len(os.fsencode(text)) > 4095:
        raise argparse.ArgumentTypeError(
            f"{_shown(text)!r}: a path of {len(os.fsencode(text))} bytes; at most 4095 allowed"
        )


def _check_writable_above(text: str, path: Path) -> None:
    """Refuse, before any work, an output path that could not be written: a place
    under a file, a kernel interface (:data:`PSEUDO_FILESYSTEMS`) or a folder the
    user cannot write in."""
    shown = _shown(text)
    try:
        existing = path.absolute()
        while not existing.exists() and existing != existing.parent:
            existing = existing.parent
        resolved = existing.resolve()
    except OSError as error:
        raise argparse.ArgumentTypeError(f"{shown!r}: {error.strerror or error}") from None
    if not existing.is_dir():
        raise argparse.ArgumentTypeError(f"{shown!r} lies under {str(existing)!r}, a file")
    if any(resolved == Path(p) or Path(p) in resolved.parents for p in PSEUDO_FILESYSTEMS):
        raise argparse.ArgumentTypeError(
            f"{shown!r} lies under {str(resolved)!r}, a kernel interface; choose a folder "
            "outside " + ", ".join(PSEUDO_FILESYSTEMS)
        )
    if not os.access(existing, os.W_OK):
        raise argparse.ArgumentTypeError(f"{shown!r}: cannot write in {str(existing)!r}")


def _env_kwargs(pairs: list[str]) -> dict[str, Any]:
    """``["dof=5", "map_name=maze"]`` -> ``{"dof": 5, "map_name": "maze"}`` (values as YAML,
    read by :func:`motiongym.agents.limits.load_yaml`: no aliases, at most
    :data:`MAX_ENV_KWARG_BYTES` each); a key given twice is refused."""
    from motiongym.agents.limits import load_yaml

    kwargs = {}
    for pair in pairs:
        key, sep, value = pair.partition("=")
        if not sep or not key:
            raise UsageError(f"--env-kwargs takes KEY=VALUE pairs, got {pair[:100]!r}")
        if key in kwargs:
            raise UsageError(f"--env-kwargs gives {key!r} twice; give each key once")
        kwargs[key] = load_yaml(
            value,
            f"--env-kwargs {key[:100]}",
            MAX_ENV_KWARG_BYTES,
            malformed=f"--env-kwargs {pair[:100]!r}: the value is not YAML",
        )
    return kwargs


def note(message: str) -> None:
    """One line on standard error, before long work (never in the tables)."""
    print(f"motiongym: {message}", file=sys.stderr)


def _capped(env_kwargs: dict[str, Any], max_steps: int | None) -> dict[str, Any]:
    """``env_kwargs`` with ``--max-steps`` as gym.make's ``max_episode_steps``."""
    if max_steps is None:
        return env_kwargs
    given = env_kwargs.get("max_episode_steps", max_steps)
    if given != max_steps:
        raise UsageError(
            f"--max-steps {max_steps} and --env-kwargs max_episode_steps={given} disagree"
        )
    return {**env_kwargs, "max_episode_steps": max_steps}


def _evaluations(env_id: str, policies: list[str], args: argparse.Namespace) -> list[Evaluation]:
    """Every policy on the same seeded episodes of ``env_id``."""
    from motiongym.agents.evaluation.episodes import evaluate
    from motiongym.agents.models.predictors import load_predictor, policy_label

    env_kwargs = _capped(_env_kwargs(args.env_kwargs), args.max_steps)
    if args.seed + args.episodes - 1 > MAX_SEED:
        raise UsageError(f"--seed {args.seed} + --episodes {args.episodes} passes {MAX_SEED}")
    env = make_env(env_id, env_kwargs)
    seeds = range(args.seed, args.seed + args.episodes)
    predictors = [
        (load_predictor(policy, env_id, env, env_kwargs, trust=args.trust), policy_label(policy))
        for policy in policies
    ]
    long = long_episodes_note(env_id, env_kwargs, args.episodes)
    if long is not None:  # said once every policy has loaded, before the first episode
        note(f"{long} (--max-steps N caps them)")
    results = [
        evaluate(env, predictor, seeds, env_id, label, not args.no_progress)
        for predictor, label in predictors
    ]
    env.close()
    return results


def cmd_list(args: argparse.Namespace) -> None:
    from rich.table import Table

    from motiongym.agents.evaluation.report import console
    from motiongym.agents.models.predictors import available_policies

    table = Table(title="motiongym environments")
    table.add_column("ID")
    table.add_column("policies")
    for env_id in ENV_IDS:
        table.add_row(env_id, ", ".join(available_policies(env_id)) or "-")
    console.print(table)


def cmd_evaluate(args: argparse.Namespace) -> None:
    from motiongym.agents.evaluation.report import console, summary_table, write_evaluation

    check_env_id(args.env_id)
    (evaluation,) = _evaluations(args.env_id, [args.policy], args)
    console.print(summary_table(evaluation))
    for path in write_evaluation(evaluation, args.out, short_name(args.env_id)):
        console.print(f"wrote {path}")


# Gymnasium's warning on making an ID that has a newer version.
OUT_OF_DATE = r".*The environment motiongym/\w+-v\d+ is out of date"


def cmd_compare(args: argparse.Namespace) -> None:
    from motiongym.agents.evaluation.report import (
        comparison_summary,
        comparison_table,
        console,
        robust_table,
        write_comparison,
    )
    from motiongym.agents.evaluation.statistics import robust_statistics
    from motiongym.agents.models.predictors import available_policies
    from motiongym.baselines import scripted_policies

    if args.all == (args.env_id is not None):
        raise UsageError("compare takes an environment ID or --all, not both")
    env_ids = ENV_IDS if args.all else [check_env_id(args.env_id)]
    written: dict[str, list[Path]] = {}
    with warnings.catch_warnings():
        if args.all:  # old versions are compared on purpose: Gymnasium's note on each is noise
            warnings.filterwarnings("ignore", OUT_OF_DATE, DeprecationWarning)
        for env_id in env_ids:
            policies = args.policies or available_policies(env_id)
            if not policies:
                console.print(f"{env_id}: no policies to compare")
                continue
            evaluations = _evaluations(env_id, policies, args)
            paper = next(iter(scripted_policies(env_id)), None)  # declared first
            robust = robust_statistics(evaluations, paper)
            console.print(comparison_table(evaluations))
            console.print(robust_table(evaluations, paper, robust))
            written[env_id] = write_comparison(
                evaluations, args.out, short_name(env_id), paper, robust
            )
            for path in written[env_id]:
                console.print(f"wrote {path}")
    if len(env_ids) > 1 and written:
        console.print(comparison_summary(written, args.out, args.episodes))


def cmd_train(args: argparse.Namespace) -> None:
    from motiongym.agents.evaluation.report import console
    from motiongym.agents.training.train import train

    run_dir = train(
        args.env_id,
        args.algo,
        config_path=args.config,
        seed=args.seed,
        out_root=args.out,
        n_timesteps=args.timesteps,
        progress=not args.no_progress,
    )
    console.print(f"run folder: {run_dir}")


def cmd_dataset(args: argparse.Namespace) -> None:
    from motiongym.agents.evaluation.report import console
    from motiongym.agents.integrations.dataset import record_dataset

    check_env_id(args.env_id)
    if args.seed + args.episodes - 1 > MAX_SEED:
        raise UsageError(f"--seed {args.seed} + --episodes {args.episodes} passes {MAX_SEED}")
    path, rate = record_dataset(
        args.env_id,
        args.policy,
        args.episodes,
        args.out,
        seed=args.seed,
        env_kwargs=_env_kwargs(args.env_kwargs),
    )
    console.print(f"wrote {path} ({args.episodes} episodes, success {rate:.0%})")


def cmd_ship(args: argparse.Namespace) -> None:
    from motiongym.agents.evaluation.report import console
    from motiongym.agents.models.ship import describe, ship

    shipped = ship(
        args.run_dirs, n_episodes=args.episodes, root=args.into, force=args.force, announce=note
    )
    console.print(
        f"shipped to {shipped.folder}: {describe(shipped.score)} on the held-out episodes"
    )
    if shipped.previous is not None:
        console.print(f"replaced a model with {describe(shipped.previous)} on the same episodes")


def cmd_record(args: argparse.Namespace) -> None:
    from motiongym.agents.evaluation.record import record
    from motiongym.agents.evaluation.report import console
    from motiongym.baselines import scripted_policies

    check_env_id(args.env_id)
    policy = args.policy or next(iter(scripted_policies(args.env_id)), "random")
    recording = record(
        args.env_id,
        policy,
        args.seed,
        args.out,
        _env_kwargs(args.env_kwargs),
        every=args.every,
        trust=args.trust,
    )
    episode = recording.episode
    console.print(
        f"{policy} on {args.env_id}, seed {args.seed}: {episode['length']} steps, "
        f"return {episode['return']:.4g}, {recording.frames} frames at {recording.fps:g} fps"
    )
    for path in (recording.mp4, recording.gif):
        if path is not None:
            console.print(f"wrote {path}")
    for note in recording.notes:
        print(f"motiongym: {note}", file=sys.stderr)


def cmd_benchmarks(args: argparse.Namespace) -> None:
    from motiongym.agents.evaluation.benchmarks import write_benchmarks
    from motiongym.agents.evaluation.report import console

    try:
        path = write_benchmarks(args.out, n_episodes=args.episodes, ids=args.ids)
    except ValueError as error:
        raise UsageError(str(error)) from None
    console.print(f"wrote {path}")


def cmd_reproduce(args: argparse.Namespace) -> None:
    from motiongym.agents.reproduce import reproduce

    reproduce(args.experiment, args.out / args.experiment, quick=args.quick, seeds=args.seeds)


def cmd_bench(args: argparse.Namespace) -> None:
    from motiongym.agents.bench.throughput import bench

    bench(args.out, quick=args.quick, env_ids=args.ids or None)


def _env_kwargs_option(parser: argparse.ArgumentParser) -> None:
    parser.add_argument(
        "--env-kwargs",
        nargs="*",
        default=[],
        metavar="KEY=VALUE",
        help="keywords for gym.make (the environment's own, or max_episode_steps); "
        "values read as YAML (default: none, the registered task)",
    )


def _trust_option(parser: argparse.ArgumentParser) -> None:
    parser.add_argument(
        "--trust",
        action="store_true",
        help="load a model folder without manifest.json (nothing in it is ever unpickled; "
        "default: refuse it)",
    )


def _evaluation_options(parser: argparse.ArgumentParser) -> None:
    parser.add_argument(
        "--episodes",
        type=_count,
        default=DEFAULT_EPISODES,
        help=f"episodes per policy (default {DEFAULT_EPISODES})",
    )
    parser.add_argument(
        "--seed",
        type=_seed,
        default=EVALUATION_SEED,
        help=f"seed of the first episode; episode i uses seed+i (default {EVALUATION_SEED})",
    )
    _env_kwargs_option(parser)
    parser.add_argument(
        "--max-steps",
        type=_count,
        default=None,
        help="cap every episode at N steps, a capped episode ending truncated (default: the "
        "ID's own limit, the benchmarks' protocol; an ID whose limit passes "
        f"{LONG_EPISODE:,} steps is announced before it starts)",
    )
    parser.add_argument(
        "--out", type=_folder, default=Path("results"), help="output folder (default results)"
    )
    parser.add_argument(
        "--no-progress", action="store_true", help="no progress bar (default: a progress bar)"
    )
    _trust_option(parser)


def build_parser() -> argparse.ArgumentParser:
    from motiongym.agents.models.files import algorithm_classes
    from motiongym.agents.reproduce import EXPERIMENTS

    parser = _Parser(
        prog="motiongym", description="Scripted and learned control of classic robot motion tasks."
    )
    parser.add_argument("--version", action="version", version=f"motiongym {package_version()}")
    commands = parser.add_subparsers(dest="command", required=True)

    listing = commands.add_parser("list", help="environment IDs and their policies")
    listing.set_defaults(handler=cmd_list)

    evaluate = commands.add_parser("evaluate", help="run one policy on seeded episodes")
    evaluate.add_argument("env_id", help="environment ID, e.g. motiongym/Sweeper-v0")
    evaluate.add_argument(
        "--policy",
        required=True,
        help="a scripted or shipped policy's name, a model .zip or a run folder",
    )
    _evaluation_options(evaluate)
    evaluate.set_defaults(handler=cmd_evaluate)

    compare = commands.add_parser("compare", help="run several policies on the same seeds")
    compare.add_argument("env_id", nargs="?", help="environment ID (or --all)")
    compare.add_argument(
        "--all", action="store_true", help="every registered ID (default: the one ID given)"
    )
    compare.add_argument(
        "--policies",
        nargs="+",
        help="names or model paths (default: every scripted and shipped policy, and random)",
    )
    _evaluation_options(compare)
    compare.set_defaults(handler=cmd_compare)

    train = commands.add_parser("train", help="train an SB3 algorithm from configs/")
    train.add_argument("env_id", help="environment ID")
    train.add_argument(
        "--algo",
        choices=sorted(algorithm_classes()),
        help="an algorithm block of the config (default: its first, the tuned one)",
    )
    train.add_argument("--config", type=Path, help="YAML file (default: configs/<Name>-vN.yml)")
    train.add_argument("--seed", type=_seed, default=0, help="training seed (default 0)")
    train.add_argument(
        "--timesteps",
        type=_count,
        help="override the config's n_timesteps (default: the config's; try 5000 for a "
        "first look, the tuned budgets take hours)",
    )
    train.add_argument(
        "--out", type=_folder, default=Path("runs"), help="where run folders go (default runs)"
    )
    train.add_argument(
        "--no-progress", action="store_true", help="no progress bar (default: a progress bar)"
    )
    train.set_defaults(handler=cmd_train)

    from motiongym.agents.integrations.dataset import DATASET_SEED

    dataset = commands.add_parser(
        "dataset", help="record a scripted policy's episodes as a Minari dataset (offline RL)"
    )
    dataset.add_argument("env_id", help="environment ID")
    dataset.add_argument("--policy", required=True, help="a scripted policy's name")
    dataset.add_argument("--episodes", type=_count, required=True, help="episodes to record")
    dataset.add_argument(
        "--seed",
        type=_seed,
        default=DATASET_SEED,
        help=f"seed of the first episode; episode i uses seed+i (default {DATASET_SEED}, "
        "clear of the evaluation seeds)",
    )
    _env_kwargs_option(dataset)
    dataset.add_argument(
        "--out", type=_folder, default=Path("datasets"), help="datasets root (default datasets)"
    )
    dataset.set_defaults(handler=cmd_dataset)

    ship = commands.add_parser(
        "ship", help="evaluate the seeds' runs of one ID and algorithm, ship the best"
    )
    ship.add_argument(
        "run_dirs", type=Path, nargs="+", help="run folders written by motiongym train"
    )
    ship.add_argument(
        "--episodes", type=_count, default=20, help="held-out evaluation episodes (default 20)"
    )
    ship.add_argument(
        "--into",
        type=_folder,
        help="folder that holds <ID>/<label>/ (default: the package's agents/models/pretrained)",
    )
    ship.add_argument(
        "--force",
        action="store_true",
        help="replace a shipped model that scores better (default: refuse, printing both scores)",
    )
    ship.set_defaults(handler=cmd_ship)

    recorder = commands.add_parser("record", help="one episode as an MP4 and a GIF")
    recorder.add_argument("env_id", help="environment ID, e.g. motiongym/Sweeper-v0")
    recorder.add_argument(
        "--policy",
        help="a policy name, model .zip or run folder (default: the paper's scripted policy)",
    )
    recorder.add_argument(
        "--seed", type=_seed, default=0, help="the episode's reset seed (default 0)"
    )
    recorder.add_argument(
        "--every", type=_count, default=1, help="keep one frame in N steps (default 1: every step)"
    )
    _env_kwargs_option(recorder)
    recorder.add_argument(
        "--out",
        type=_folder,
        default=Path("results/record"),
        help="folder (default results/record)",
    )
    _trust_option(recorder)
    recorder.set_defaults(handler=cmd_record)

    benchmarks = commands.add_parser(
        "benchmarks", help="regenerate BENCHMARKS.md: scripted vs learned on every ID"
    )
    benchmarks.add_argument(
        "--episodes", type=_count, default=20, help="held-out episodes (default 20)"
    )
    benchmarks.add_argument(
        "--out", type=_file, default=Path("BENCHMARKS.md"), help="file (default BENCHMARKS.md)"
    )
    benchmarks.add_argument(
        "--ids",
        nargs="+",
        default=None,
        help="regenerate only these IDs' sections (default: all)",
    )
    benchmarks.set_defaults(handler=cmd_benchmarks)

    reproduce = commands.add_parser("reproduce", help="a paper's evaluation beside its figures")
    reproduce.add_argument("experiment", choices=sorted(EXPERIMENTS))
    reproduce.add_argument(
        "--quick", action="store_true", help="reduced protocol (default: the full one)"
    )
    reproduce.add_argument(
        "--seeds",
        type=_count,
        default=None,
        help="trials per row where the experiment takes it (default: the experiment's own)",
    )
    reproduce.add_argument(
        "--out",
        type=_folder,
        default=Path("results/reproduce"),
        help="output folder; the experiment's own subfolder is made (default results/reproduce)",
    )
    reproduce.set_defaults(handler=cmd_reproduce)

    bench = commands.add_parser("bench", help="throughput against references in the same run")
    bench.add_argument("ids", nargs="*", help="environment IDs (default: all)")
    bench.add_argument(
        "--quick", action="store_true", help="shorter timings (default: the full timings)"
    )
    bench.add_argument(
        "--out", type=_folder, default=Path("results/bench"), help="folder (default results/bench)"
    )
    bench.set_defaults(handler=cmd_bench)

    from motiongym.agents.integrations.ray_commands import add_ray_commands

    add_ray_commands(commands, _count, _seed, _folder)
    return parser


def main(argv: list[str] | None = None) -> int:
    parser = build_parser()
    try:
        args = parser.parse_args(argv)
    except SystemExit as exit_:  # a usage error, already printed on one line
        if exit_.code == 2:
            return 2
        raise  # --help
    try:
        args.handler(args)
    except (UsageError, UnknownPolicyError, ArgumentError) as error:
        message = " ".join(str(error).split())  # one line, whatever the message holds
        print(f"motiongym: error: {message}", file=sys.stderr)
        return 2
    return 0


if __name__ == "__main__":
    sys.exit(main())
