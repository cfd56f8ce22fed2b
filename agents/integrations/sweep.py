"""``motiongym sweep``: whole ``motiongym train`` runs (IDs x configs x seeds) as Ray Tune trials.

Ray is the optional extra ``motiongym[ray]``; nothing else in motiongym needs it.
Each trial is one :func:`motiongym.agents.training.train.train` call in a Ray worker
and writes the usual run folder, under ``<out>/<config>/`` so that two
configurations of one ID never share a folder:

``<out>/<config>/<Name>-vN/<algo>_seed<seed>_<time>/`` (``<config>`` is the
configuration file's stem, ``default`` for ``configs/<Name>-vN.yml``).

Tune spreads the trials over the cluster at ``address`` (``ray start --head``
on one machine, ``ray start --address HEAD:6379`` on the others; every node
needs motiongym installed and ``<out>`` on storage they all share), or over a
local Ray started for the sweep when no address is given. Tune's own records
go to ``<out>/tune/``. The sweep writes ``<out>/sweep.json``: per (ID,
config) its seeds' run folders and the ``motiongym ship`` command that
evaluates them on the held-out episodes and ships the best.
"""

from __future__ import annotations

import itertools
import json
import shlex
from pathlib import Path
from typing import Any

from motiongym.agents.environments import check_env_id
from motiongym.agents.errors import UsageError
from motiongym.agents.limits import load_npz

RAY_EXTRA = "pip install 'motiongym[ray]'"
DEFAULT_CONFIG = "default"  # the group name of configs/<Name>-vN.yml
SWEEP_FILE = "sweep.json"
REPORTED = ("run_dir", "eval_return", "eval_success")  # what a trial reports to Tune


def import_ray() -> Any:
    """The ``ray`` module, or one usage error that says how to install it."""
    try:
        import ray
    except ImportError:
        raise UsageError(f"this command needs Ray, an optional extra: {RAY_EXTRA}") from None
    return ray


def start_ray(address: str | None, num_cpus: int | None = None) -> bool:
    """Connect to the Ray cluster at ``address``, or start a local one on 127.0.0.1 (no
    dashboard) with ``num_cpus`` (None: all); False if Ray was already running here."""
    ray = import_ray()
    if ray.is_initialized():
        return False
    if address is None:
        ray.init(
            address="local",
            num_cpus=num_cpus,
            include_dashboard=False,
            log_to_driver=False,
            configure_logging=False,
            _node_ip_address="127.0.0.1",
        )
    else:
        ray.init(address=address, log_to_driver=False, configure_logging=False)
    return True


def trial_specs(
    env_ids: list[str],
    configs: list[Path | None],
    seeds: list[int],
    out: Path,
    algo: str | None = None,
    timesteps: int | None = None,
) -> list[dict[str, Any]]:
    """Every (ID, config, seed) as a Tune trial's config (plain values: Tune stores them).

    Paths are made absolute: a Tune trial runs in its own working folder, on any node.
    """
    for env_id in env_ids:
        check_env_id(env_id)
    names = [DEFAULT_CONFIG if c is None else c.stem for c in configs]
    if len(set(names)) != len(names):
        raise UsageError(f"--configs: two files share a name ({', '.join(names)}); rename one")
    for config in configs:
        if config is not None and not config.is_file():
            raise UsageError(f"--configs: no configuration file at {config}")
    if len(set(seeds)) != len(seeds):
        raise UsageError(f"--seeds: a seed is given twice ({seeds})")
    return [
        {
            "env_id": env_id,
            "config": None if config is None else str(config.resolve()),
            "config_name": name,
            "seed": seed,
            "algo": algo,
            "timesteps": timesteps,
            "out": str((out / name).resolve()),
        }
        for env_id, (config, name), seed in itertools.product(
            env_ids, zip(configs, names, strict=True), seeds
        )
    ]


def final_evaluation(run_dir: Path) -> dict[str, float]:
    """The run's last evaluation-callback result: mean return and success rate (NaN if none)."""
    file = run_dir / "eval" / "evaluations.npz"
    if not file.is_file():
        return {"eval_return": float("nan"), "eval_success": float("nan")}
    data = load_npz(file, 64 << 20, 64 << 20)
    success = data["successes"][-1].mean() if "successes" in data else float("nan")
    return {"eval_return": float(data["results"][-1].mean()), "eval_success": float(success)}


def run_trial(spec: dict[str, Any]) -> dict[str, Any]:
    """One trial: one ``train`` run from ``spec`` (:func:`trial_specs`); its folder and
    final evaluation, reported to Tune and returned."""
    from motiongym.agents.training.train import train

    run_dir = train(
        spec["env_id"],
        spec["algo"],
        config_path=None if spec["config"] is None else Path(spec["config"]),
        seed=spec["seed"],
        out_root=Path(spec["out"]),
        n_timesteps=spec["timesteps"],
        progress=False,
    )
    result = {"run_dir": str(run_dir), **final_evaluation(run_dir)}
    try:
        from ray import tune

        tune.report(result)
    except ImportError:  # called without Ray (tests of the trial itself)
        pass
    return result


def _trainable(config: dict[str, Any]) -> dict[str, Any]:
    return run_trial(config["spec"])


def ship_groups(results: list[dict[str, Any]]) -> dict[str, dict[str, Any]]:
    """Run folders grouped by (ID, config), each with the ``ship`` command for its seeds."""
    groups: dict[str, dict[str, Any]] = {}
    for result in sorted(results, key=lambda r: (r["env_id"], r["config_name"], r["seed"])):
        key = f"{result['env_id']} [{result['config_name']}]"
        group = groups.setdefault(key, {"run_dirs": [], "seeds": []})
        group["run_dirs"].append(result["run_dir"])
        group["seeds"].append(result["seed"])
    for group in groups.values():
        group["ship"] = shlex.join(["motiongym", "ship", *group["run_dirs"]])
    return groups


def sweep(
    specs: list[dict[str, Any]],
    out: Path,
    address: str | None = None,
    num_cpus: int | None = None,
    cpus_per_trial: float = 1.0,
) -> dict[str, dict[str, Any]]:
    """Run ``specs`` as Tune trials on the Ray at ``address`` (None: a local one started
    here, with ``num_cpus``); write ``<out>/sweep.json`` and return its groups."""
    ray = import_ray()
    from ray import tune

    if address is not None and num_cpus is not None:
        raise UsageError("--num-cpus sizes a local Ray; a cluster (--address) has its own")
    out.mkdir(parents=True, exist_ok=True)
    started = start_ray(address, num_cpus)
    try:
        tuner = tune.Tuner(
            tune.with_resources(_trainable, {"cpu": cpus_per_trial}),
            param_space={"spec": tune.grid_search(specs)},
            run_config=tune.RunConfig(
                name="motiongym-sweep", storage_path=str((out / "tune").resolve()), verbose=0
            ),
        )
        grid = tuner.fit()
    finally:
        if started:
            ray.shutdown()
    results, failed = [], []
    for result in grid:
        spec = result.config["spec"]
        if result.error is not None or "run_dir" not in (result.metrics or {}):
            failed.append(f"{spec['env_id']} [{spec['config_name']}] seed {spec['seed']}")
            continue
        results.append({**spec, **{k: result.metrics[k] for k in REPORTED}})
    groups = ship_groups(results)
    (out / SWEEP_FILE).write_text(json.dumps({"groups": groups, "failed": failed}, indent=2))
    if failed:
        raise UsageError(
            f"{len(failed)} of {len(specs)} trials failed ({'; '.join(failed)}); Tune's logs "
            f"are in {out / 'tune'}; the others are in {out / SWEEP_FILE}"
        )
    return groups
