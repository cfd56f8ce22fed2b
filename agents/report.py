"""Tables and figures of evaluations: one policy, or several side by side."""

from __future__ import annotations

import json
from pathlib import Path

from matplotlib.figure import Figure
from rich.console import Console
from rich.table import Table

from motiongym.agents.evaluate import Evaluation

console = Console()


def _number(value: float) -> str:
    return f"{value:.4g}"


def summary_table(evaluation: Evaluation) -> Table:
    """Mean, std, min and max of each measure over one policy's episodes."""
    n = len(evaluation.episodes)
    table = Table(title=f"{evaluation.policy} on {evaluation.env_id} ({n} episodes)")
    for column in ("measure", "mean", "std", "min", "max"):
        table.add_column(column, justify="left" if column == "measure" else "right")
    for key, stats in evaluation.summary().items():
        table.add_row(key, *(_number(stats[s]) for s in ("mean", "std", "min", "max")))
    return table


def comparison_rows(evaluations: list[Evaluation]) -> list[list[str]]:
    """One row per measure: its name, then "mean ± 95 % half-width" per policy."""
    summaries = [evaluation.summary() for evaluation in evaluations]
    return [
        [key]
        + [
            f"{_number(s[key]['mean'])} ± {_number(s[key]['ci95'])}" if key in s else "-"
            for s in summaries
        ]
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


def comparison_figure(evaluations: list[Evaluation], path: Path) -> Path:
    """A bar per policy for each measure, with 95 % interval error bars."""
    measures = evaluations[0].measures
    columns = min(4, len(measures))
    rows = -(-len(measures) // columns)
    figure = Figure(figsize=(3.2 * columns, 2.8 * rows))
    axes = figure.subplots(rows, columns, squeeze=False)
    names = [evaluation.policy for evaluation in evaluations]
    summaries = [evaluation.summary() for evaluation in evaluations]
    for ax, key in zip(axes.flat, measures, strict=False):
        means = [summary[key]["mean"] for summary in summaries]
        errors = [summary[key]["ci95"] for summary in summaries]
        ax.bar(range(len(names)), means, yerr=errors, color=[f"C{i}" for i in range(len(names))])
        ax.set_xticks(range(len(names)), names, rotation=30, ha="right", fontsize=7)
        ax.set_title(key, fontsize=9)
    for ax in list(axes.flat)[len(measures) :]:
        ax.axis("off")
    figure.suptitle(evaluations[0].env_id)
    figure.tight_layout()
    path.parent.mkdir(parents=True, exist_ok=True)
    figure.savefig(path, dpi=110)
    return path


def write_comparison(evaluations: list[Evaluation], out_dir: Path, stem: str) -> list[Path]:
    """Each policy's JSON/CSV, a combined JSON and the comparison figure."""
    written: list[Path] = []
    for evaluation in evaluations:
        written += evaluation.write(out_dir, f"{stem}_{_file_safe(evaluation.policy)}")
    combined = out_dir / f"{stem}_comparison.json"
    combined.write_text(json.dumps([e.to_json() for e in evaluations], indent=2))
    table = out_dir / f"{stem}_comparison.md"
    table.write_text(comparison_markdown(evaluations))
    written += [combined, table]
    written.append(comparison_figure(evaluations, out_dir / f"{stem}_comparison.png"))
    return written


def _file_safe(name: str) -> str:
    return "".join(c if c.isalnum() or c in "-_." else "_" for c in Path(name).name)
