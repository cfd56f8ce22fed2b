"""The ``sweep`` and ``rllib`` subcommands of ``motiongym`` (Ray, the optional extra
``motiongym[ray]``): their options and handlers, added to the command by
:func:`add_ray_commands`. Without Ray installed both say how to install it."""

from __future__ import annotations

import argparse
from pathlib import Path

from motiongym.envs import ENV_IDS


def cmd_sweep(args: argparse.Namespace) -> None:
    from motiongym.agents.evaluation.report import console
    from motiongym.agents.integrations.sweep import SWEEP_FILE, import_ray, sweep, trial_specs

    import_ray()  # before any check: without Ray, say how to install it
    configs = args.configs or [None]
    specs = trial_specs(args.env_ids, configs, args.seeds, args.out, args.algo, args.timesteps)
    console.print(f"{len(specs)} trials: {len(args.env_ids)} IDs x {len(configs)} configs x "
                  f"{len(args.seeds)} seeds")  # fmt: skip
    groups = sweep(specs, args.out, args.address, args.num_cpus, args.cpus_per_trial)
    for key, group in groups.items():
        print(f"{key}: {len(group['run_dirs'])} runs; ship the best with\n  {group['ship']}")
    console.print(f"wrote {args.out / SWEEP_FILE}")


def cmd_rllib(args: argparse.Namespace) -> None:
    from motiongym.agents.evaluation.report import console
    from motiongym.agents.integrations.rllib_runs import train_rllib
    from motiongym.agents.integrations.sweep import import_ray

    import_ray()
    run_dir = train_rllib(
        args.env_id,
        args.iterations,
        args.out,
        config_path=args.config,
        seed=args.seed,
        multi_agent=args.multi_agent,
        address=args.address,
    )
    console.print(f"run folder: {run_dir}")


def _address_option(parser: argparse.ArgumentParser) -> None:
    parser.add_argument(
        "--address",
        help="a running Ray cluster's address, e.g. HEAD:6379 or 'auto' (default: start a "
        "local Ray for this command)",
    )


def add_ray_commands(commands, count, seed, folder) -> None:  # argparse's subparsers action
    """``sweep`` and ``rllib`` with the command's own argument types (counts, seeds, folders)."""
    from motiongym.agents.models.files import algorithm_classes

    sweep = commands.add_parser(
        "sweep", help="many train runs (IDs x configs x seeds) as Ray Tune trials (motiongym[ray])"
    )
    sweep.add_argument("env_ids", nargs="+", metavar="env_id", help="environment IDs")
    sweep.add_argument(
        "--seeds", type=seed, nargs="+", default=[0, 1, 2], help="training seeds (default 0 1 2)"
    )
    sweep.add_argument(
        "--configs",
        type=Path,
        nargs="+",
        help="YAML files, one group of runs each (default: each ID's configs/<Name>-vN.yml)",
    )
    sweep.add_argument(
        "--algo",
        choices=sorted(algorithm_classes()),
        help="an algorithm block of the configs (default: each file's first)",
    )
    sweep.add_argument("--timesteps", type=count, help="override n_timesteps (default: config's)")
    sweep.add_argument(
        "--out", type=folder, default=Path("runs/sweep"), help="folder (default runs/sweep)"
    )
    _address_option(sweep)
    sweep.add_argument(
        "--num-cpus", type=count, help="CPUs of the local Ray (default: all of this machine's)"
    )
    sweep.add_argument(
        "--cpus-per-trial", type=float, default=1.0, help="CPUs Tune reserves per run (default 1)"
    )
    sweep.set_defaults(handler=cmd_sweep)

    rllib = commands.add_parser(
        "rllib", help="RLlib PPO on one ID from configs/rllib/ppo.yml (motiongym[ray])"
    )
    rllib.add_argument("env_id", help=f"environment ID, one of {', '.join(ENV_IDS[:2])}, ...")
    rllib.add_argument("--iterations", type=count, default=10, help="PPO iterations (default 10)")
    rllib.add_argument(
        "--multi-agent",
        action="store_true",
        help="the ID's PettingZoo env, one policy shared by its agents "
        "(default: the Gymnasium env)",
    )
    rllib.add_argument("--config", type=Path, help="YAML file (default: configs/rllib/ppo.yml)")
    rllib.add_argument("--seed", type=seed, default=0, help="seed (default 0)")
    rllib.add_argument(
        "--out", type=folder, default=Path("runs/rllib"), help="folder (default runs/rllib)"
    )
    _address_option(rllib)
    rllib.set_defaults(handler=cmd_rllib)
