"""Tables and figures of evaluations: one policy, or several side by side.

Tables never cut a cell: piped or written to a file (no terminal to measure)
the console is :data:`PIPED_WIDTH` columns wide unless ``COLUMNS`` says
otherwise, and a cell wider than its column folds onto the next line.
Every 95 % interval is the summary's (:meth:`Evaluation.summary
<motiongym.agents.evaluation.episodes.Evaluation.summary>`): ``mean ± half-width``
where it is symmetric, ``mean [low, high]`` where it is not (Wilson's interval of a
rate, or an interval clipped to [0, 1]). Beside it, a second table gives each
measure's interquartile mean over runs x episodes and each policy's probability of
improvement over the paper's algorithm, both with stratified bootstrap intervals
(:func:`~motiongym.agents.evaluation.statistics.robust_statistics`). Figures label
every panel with its measure and unit, clip a count's interval at 0, and leave out a
measure that is 0 on every episode of every policy or that repeats an earlier
measure's values.
"""

from __future__ import annotations

import csv
import json
import os
from pathlib import Path
from typing import IO, Any

import numpy as np
from matplotlib.figure import Figure
from rich.console import Console
from rich.table import Table

from motiongym.agents.evaluation.episodes import Evaluation
from motiongym.agents.evaluation.statistics import (
    BOOTSTRAP_RESAMPLES,
    COUNT_UNITS,
    IMPROVEMENT_MEASURES,
    RATE_UNITS,
    robust_statistics,
)

PIPED_WIDTH = 200  # columns of a table written to a pipe or a file


def make_console(file: IO[str] | None = None) -> Console:
    """A console on ``file`` (default standard output) that measures a terminal, and
    is :data:`PIPED_WIDTH` wide elsewhere."""
    probe = Console(file=file)
    if probe.is_terminal or "COLUMNS" in os.environ:
        return probe
    return Console(file=file, width=PIPED_WIDTH)


console = make_console()


def _number(value: float) -> str:
    return f"{value:.4g}"


def _unit(evaluation: Evaluation, key: str) -> str:
    unit = evaluation.units.get(key, "")
    return f"{key} ({unit})" if unit else key


def _interval(stats: dict[str, float]) -> str:
    """``± half-width`` for an interval symmetric about the mean, else ``[low, high]``."""
    mean, half = stats["mean"], stats["ci95"]
    if np.isclose(stats["low"], mean - half) and np.isclose(stats["high"], mean + half):
        return f"± {_number(half)}"
    return f"[{_number(stats['low'])}, {_number(stats['high'])}]"


def summary_table(evaluation: Evaluation) -> Table:
    """Mean, its 95 % interval, std, min and max of each measure over one policy's
    episodes."""
    n = len(evaluation.episodes)
    table = Table(title=f"{evaluation.policy} on {evaluation.env_id} ({n} episodes)")
    for column in ("measure (unit)", "mean", "95% interval", "std", "min", "max"):
        table.add_column(column, justify="left" if column.startswith("measure") else "right")
    for key, stats in evaluation.summary().items():
        cells = [_number(stats["mean"]), _interval(stats)]
        cells += [_number(stats[s]) for s in ("std", "min", "max")]
        table.add_row(_unit(evaluation, key), *cells)
    _fold(table)
    return table


def _fold(table: Table) -> None:
    """Fold over-wide cells onto the next line instead of cutting them with an ellipsis."""
    for column in table.columns:
        column.overflow = "fold"


def comparison_rows(evaluations: list[Evaluation]) -> list[list[str]]:
    """One row per measure: its name, then the mean and its 95 % interval per policy
    (``mean ± half-width``, or ``mean [low, high]`` where not symmetric)."""
    summaries = [evaluation.summary() for evaluation in evaluations]
    return [
        [_unit(evaluations[0], key)]
        + [f"{_number(s[key]['mean'])} {_interval(s[key])}" if key in s else "-" for s in summaries]
        for key in evaluations[0].measures
    ]


def _comparison_title(evaluations: list[Evaluation]) -> str:
    counts = sorted({len(evaluation.episodes) for evaluation in evaluations})
    n = " or ".join(str(count) for count in counts)
    return f"{evaluations[0].env_id}: mean ± 95% interval over {n} episodes per policy"


def comparison_table(evaluations: list[Evaluation]) -> Table:
    """One row per measure, one column per policy (rich, for the terminal)."""
    table = Table(title=_comparison_title(evaluations))
    table.add_column("measure")
    for evaluation in evaluations:
        table.add_column(evaluation.policy, justify="right")
    for row in comparison_rows(evaluations):
        table.add_row(*row)
    _fold(table)
    return table


def comparison_markdown(evaluations: list[Evaluation]) -> str:
    """The same table as Markdown (for generated reports)."""
    names = [evaluation.policy for evaluation in evaluations]
    lines = [
        _comparison_title(evaluations),
        "",
        "| measure | " + " | ".join(names) + " |",
        "|---|" + "---:|" * len(names),
    ]
    lines += ["| " + " | ".join(row) + " |" for row in comparison_rows(evaluations)]
    return "\n".join(lines) + "\n"


def _estimate(stats: dict[str, float], name: str) -> str:
    return (
        f"{_number(stats[name])} [{_number(stats[name + '_low'])}, "
        f"{_number(stats[name + '_high'])}]"
    )


def robust_rows(
    evaluations: list[Evaluation], reference: str | None, robust: list | None = None
) -> list[list[str]]:
    """One row per measure with its interquartile mean and stratified bootstrap interval
    per policy (``IQM [low, high]``; not for a 0/1 ``rate``, whose IQM is 0 or 1: read
    its mean and Wilson interval), then one per measure of
    :data:`~motiongym.agents.evaluation.statistics.IMPROVEMENT_MEASURES` with each
    policy's probability of improvement over ``reference`` (the paper's algorithm; the
    reference's own cell says so). ``robust``: :func:`robust_statistics`' result, if
    already computed."""
    robust = robust if robust is not None else robust_statistics(evaluations, reference)
    first = evaluations[0]
    rows = [
        [f"IQM {_unit(first, key)}"]
        + [_estimate(r[key], "iqm") if key in r else "-" for r in robust]
        for key in first.measures
        if first.units.get(key, "") != "rate"
    ]
    for key in IMPROVEMENT_MEASURES:
        if not any("p_improvement" in r.get(key, {}) for r in robust):
            continue
        rows.append(
            [f"P({key} > {reference}'s)"]
            + [
                "(reference)"
                if e.policy == reference
                else _estimate(r[key], "p_improvement")
                if "p_improvement" in r.get(key, {})
                else "-"
                for e, r in zip(evaluations, robust, strict=True)
            ]
        )
    return rows


def _robust_title(evaluations: list[Evaluation], reference: str | None) -> str:
    against = (
        f"probability of improvement over {reference}"
        if any(e.policy == reference for e in evaluations)
        else "no probability of improvement (the paper's algorithm is not compared)"
    )
    return (
        f"{evaluations[0].env_id}: interquartile mean over runs x episodes and {against}; "
        f"stratified bootstrap 95% intervals ({BOOTSTRAP_RESAMPLES} resamples, runs as strata)"
    )


def robust_table(
    evaluations: list[Evaluation], reference: str | None, robust: list | None = None
) -> Table:
    """:func:`robust_rows` for the terminal."""
    table = Table(title=_robust_title(evaluations, reference))
    table.add_column("statistic")
    for evaluation in evaluations:
        table.add_column(evaluation.policy, justify="right")
    for row in robust_rows(evaluations, reference, robust):
        table.add_row(*row)
    _fold(table)
    return table


def robust_markdown(
    evaluations: list[Evaluation], reference: str | None, robust: list | None = None
) -> str:
    """:func:`robust_rows` as Markdown."""
    names = [evaluation.policy for evaluation in evaluations]
    lines = [
        _robust_title(evaluations, reference),
        "",
        "| statistic | " + " | ".join(names) + " |",
        "|---|" + "---:|" * len(names),
    ]
    lines += ["| " + " | ".join(row) + " |" for row in robust_rows(evaluations, reference, robust)]
    return "\n".join(lines) + "\n"


STATISTICS_COLUMNS = (
    "policy",
    "measure",
    "unit",
    "episodes",
    "runs",
    "mean",
    "low",
    "high",
    "iqm",
    "iqm_low",
    "iqm_high",
    "reference",
    "p_improvement",
    "p_improvement_low",
    "p_improvement_high",
)


def write_statistics_csv(
    evaluations: list[Evaluation], reference: str | None, path: Path, robust: list | None = None
) -> Path:
    """One row per policy and measure: :data:`STATISTICS_COLUMNS` (the mean and its 95 %
    interval, the IQM and the probability of improvement over ``reference`` with their
    bootstrap intervals; empty where it does not apply)."""
    robust = robust if robust is not None else robust_statistics(evaluations, reference)
    path.parent.mkdir(parents=True, exist_ok=True)
    with path.open("w", newline="") as handle:
        writer = csv.DictWriter(handle, fieldnames=STATISTICS_COLUMNS, restval="")
        writer.writeheader()
        for evaluation, extra in zip(evaluations, robust, strict=True):
            for key, stats in evaluation.summary().items():
                row: dict[str, Any] = {"policy": evaluation.policy, "measure": key}
                row |= {"unit": evaluation.units.get(key, ""), "episodes": len(evaluation.episodes)}
                row |= {k: stats[k] for k in ("mean", "low", "high")} | extra[key]
                row["runs"] = int(extra[key]["runs"])
                if "p_improvement" in extra[key]:
                    row["reference"] = reference
                writer.writerow(row)
    return path


def plotted_measures(evaluations: list[Evaluation]) -> list[str]:
    """The measures worth a panel: not 0 on every episode of every policy, and not
    a repeat of an earlier measure's values (the sweeper's ``steps`` is its length)."""
    kept: list[str] = []
    columns: list[list[float]] = []
    for key in evaluations[0].measures:
        values = [e[key] for evaluation in evaluations for e in evaluation.episodes if key in e]
        if not np.any(values) or values in columns:
            continue
        kept.append(key)
        columns.append(values)
    return kept


def _bar_errors(means: list[float], lows: list[float], highs: list[float], unit: str) -> np.ndarray:
    """Lower and upper error-bar lengths of the intervals ``[low, high]`` (a rate's lie in
    [0, 1] already), a count's or duration's clipped at 0. A length is never negative:
    a rate of 0 has a Wilson bound of about 1e-17 above it, in rounding."""
    means_ = np.asarray(means)
    lower, upper = means_ - np.asarray(lows), np.asarray(highs) - means_
    if unit in COUNT_UNITS:
        lower = np.minimum(lower, means_)
    return np.maximum(np.vstack([lower, upper]), 0.0)


def comparison_figure(evaluations: list[Evaluation], path: Path) -> Path:
    """A bar per policy for each plotted measure (:func:`plotted_measures`), with
    95 % interval error bars, the measure and its unit on the y axis."""
    measures = plotted_measures(evaluations) or ["return"]
    columns = min(4, len(measures))
    rows = -(-len(measures) // columns)
    figure = Figure(figsize=(3.4 * columns, 3.0 * rows))
    axes = figure.subplots(rows, columns, squeeze=False)
    names = [evaluation.policy for evaluation in evaluations]
    summaries = [evaluation.summary() for evaluation in evaluations]
    for ax, key in zip(axes.flat, measures, strict=False):
        means = [summary[key]["mean"] for summary in summaries]
        unit = evaluations[0].units.get(key, "")
        lows, highs = ([summary[key][s] for summary in summaries] for s in ("low", "high"))
        errors = _bar_errors(means, lows, highs, unit)
        colors = [f"C{i}" for i in range(len(names))]
        ax.bar(range(len(names)), means, yerr=errors, color=colors, capsize=3)
        ax.set_xticks(range(len(names)), names, rotation=30, ha="right", fontsize=7)
        ax.set_ylabel(_unit(evaluations[0], key), fontsize=8)
        ax.set_title(key, fontsize=9)
        if unit in RATE_UNITS:
            ax.set_ylim(0.0, 1.05)
    for ax in list(axes.flat)[len(measures) :]:
        ax.remove()
    n = sorted({len(evaluation.episodes) for evaluation in evaluations})
    figure.suptitle(
        f"{evaluations[0].env_id}: mean and 95 % interval over {' or '.join(map(str, n))} episodes",
        fontsize=10,
    )
    figure.tight_layout()
    path.parent.mkdir(parents=True, exist_ok=True)
    figure.savefig(path, dpi=110)
    return path


def comparison_summary(written: dict[str, list[Path]], out_dir: Path, episodes: int) -> Table:
    """What ``compare`` wrote for several IDs (``{ID: its files}``): one row per ID with
    its table and figure, and a title that says where every file is."""
    n_files = sum(len(paths) for paths in written.values())
    table = Table(
        title=f"compared {len(written)} IDs on {episodes} episodes each: {n_files} files in "
        f"{out_dir}/ (per ID and policy: <ID>_comparison_<policy>.json and .csv)"
    )
    columns = ("ID", "tables (Markdown)", "figure", "all policies (JSON)", "statistics (CSV)")
    for column in columns:
        table.add_column(column)
    for env_id, paths in written.items():
        by_suffix = {p.suffix: p.name for p in paths if p.stem.endswith("_comparison")}
        suffixes = (".md", ".png", ".json", ".csv")
        table.add_row(env_id, *(by_suffix.get(s, "-") for s in suffixes))
    _fold(table)
    return table


def write_evaluation(evaluation: Evaluation, out_dir: Path, stem: str) -> list[Path]:
    """``evaluate``'s files: ``<stem>_<policy>_evaluation.{json,csv,png}``.

    Never the name of a file :func:`write_comparison` writes (those hold
    ``_comparison``), so the two commands can share an output folder.
    """
    name = f"{stem}_{_file_safe(evaluation.policy)}_evaluation"
    written = evaluation.write(out_dir, name)
    written.append(comparison_figure([evaluation], out_dir / f"{name}.png"))
    return written


def write_comparison(
    evaluations: list[Evaluation],
    out_dir: Path,
    stem: str,
    reference: str | None = None,
    robust: list | None = None,
) -> list[Path]:
    """``compare``'s files: each policy's ``<stem>_comparison_<policy>.{json,csv}``, and
    ``<stem>_comparison.{json,md,png,csv}`` (the combined JSON, the tables, the figure,
    the statistics of :func:`write_statistics_csv`). Each policy's
    entry of the combined JSON holds ``robust`` (:func:`robust_statistics` against
    ``reference``, the paper's algorithm) and ``reference``."""
    robust = robust if robust is not None else robust_statistics(evaluations, reference)
    written: list[Path] = []
    for evaluation in evaluations:
        name = f"{stem}_comparison_{_file_safe(evaluation.policy)}"
        written += evaluation.write(out_dir, name)
    combined = out_dir / f"{stem}_comparison.json"
    entries = [
        {**e.to_json(), "reference": reference, "robust": r}
        for e, r in zip(evaluations, robust, strict=True)
    ]
    combined.write_text(json.dumps(entries, indent=2))
    table = out_dir / f"{stem}_comparison.md"
    table.write_text(
        comparison_markdown(evaluations) + "\n" + robust_markdown(evaluations, reference, robust)
    )
    statistics = write_statistics_csv(
        evaluations, reference, out_dir / f"{stem}_comparison.csv", robust
    )
    written += [combined, table, statistics]
    written.append(comparison_figure(evaluations, out_dir / f"{stem}_comparison.png"))
    return written


def _file_safe(name: str) -> str:
    return "".join(c if c.isalnum() or c in "-_." else "_" for c in Path(name).name)
