"""``motiongym reproduce sweeper``'s report: the figures and the printed tables of the
studies :mod:`.sweeper` runs (kept apart: the studies measure, this module shows)."""

from __future__ import annotations

import pathlib

import numpy as np

from motiongym.envs.sweeper import maps


def figures(out_dir: pathlib.Path, results: dict, pictures: dict[str, np.ndarray]) -> list[str]:
    """Write the PNG figures; ``pictures``: each shipped map's frame after a PSA + CWA run."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    files = []
    fig, axes = plt.subplots(1, 3, figsize=(15, 5))
    for ax, name in zip(axes, maps.SHIPPED_MAPS, strict=True):
        ax.imshow(pictures[name])
        fig_no = dict(room=10, apartment=13, maze=14)[name]
        ax.set_title(f"{name}: PSA + CWA (paper Fig. {fig_no})", fontsize=10)
        ax.axis("off")
    fig.tight_layout()
    files.append("sweeper_maps.png")
    fig.savefig(out_dir / files[-1], dpi=100)
    plt.close(fig)

    sp = results["start_position"]
    fig, ax = plt.subplots(figsize=(6, 6))
    grid = maps.shipped_map("maze")
    background = np.where(grid[..., None], [0.0, 0.0, 0.0], [0.75, 0.85, 1.0])  # walls, no start
    ax.imshow(background)
    img = np.ma.masked_invalid(sp["image"])
    im = ax.imshow(img, cmap="gray_r", interpolation="nearest")
    fig.colorbar(im, ax=ax, label="travel (cells); darker = longer; blue: not a start")
    ax.set_title(f"travel per start cell (Fig. 15): spread {100 * sp['spread']:.1f} %")
    files.append("sweeper_start_position.png")
    fig.savefig(out_dir / files[-1], dpi=100)
    plt.close(fig)

    ori = results["orientation"]
    fig, (ax0, ax1) = plt.subplots(1, 2, figsize=(12, 4))
    ax0.bar([r["heading"] for r in ori["rows"]], [r["travel"] for r in ori["rows"]])
    ax0.set_ylabel("travel (cells)")
    ax0.set_title(
        f"start heading at {tuple(ori['start'])} (Fig. 16): spread {100 * ori['spread']:.1f} %"
    )
    turned = ori["walls_turned"]["rows"]
    ax1.plot([r["angle"] for r in turned], [r["travel_ratio"] for r in turned], "o-")
    ax1.set_xlabel("maze turned on the grid (deg): walls become staircases")
    ax1.set_ylabel("travel / (area / W)")
    ax2 = ax1.twinx()
    ax2.plot(
        [r["angle"] for r in turned], [100 * r["left_to_cwa"] for r in turned], "s--", color="C1"
    )
    ax2.set_ylabel("left unswept by PSA (%)", color="C1")
    ax1.set_title("walls at an angle on the grid (not the paper's setting)")
    fig.tight_layout()
    files.append("sweeper_orientation.png")
    fig.savefig(out_dir / files[-1], dpi=100)
    plt.close(fig)

    rows = [r for r in results["odometry"]["rows"] if r["map"] == "maze"]
    fig, ax = plt.subplots(figsize=(8, 4))
    for k, localise in enumerate((True, False)):
        sel = [r for r in rows if r["localise"] is localise]
        x = np.arange(len(sel)) + 0.4 * k
        label = "localised" if localise else "dead reckoning"
        ax.bar(x, [100 * r["coverage"] for r in sel], width=0.4, label=label)
    ax.set_xticks(np.arange(len(sel)) + 0.2)
    ax.set_xticklabels([f"h{r['heading_noise']}/s{r['slip_noise']}" for r in sel], rotation=45)
    ax.set_ylabel("coverage when it declared done (%)")
    ax.set_title(f"odometry error on the {sel[0]['map']} (Fig. 20): heading rad / slip")
    ax.legend()
    fig.tight_layout()
    files.append("sweeper_odometry.png")
    fig.savefig(out_dir / files[-1], dpi=100)
    plt.close(fig)
    return files


def _share_text(shares: dict[str, float]) -> str:
    return "/".join(f"{100 * shares[k]:.0f}" for k in ("lane", "shift", "transfer", "cwa"))


def print_results(results: dict) -> None:
    """The studies beside the paper's figures, as rich tables."""
    from rich.console import Console
    from rich.table import Table

    console = Console(width=120)
    t = Table(title=f"Sweeper: PSA + CWA coverage and travel (W = {results['robot_width']} cells)")
    for col in (
        "map",
        "coverage min",
        "ratio mean / max",
        "bound mean (H)",
        "below bound",
        "no-hole formula, below",
        "nearest-first, below",
        "travel % l/s/t/c",
        "transfer quadtree / BFS",
    ):
        t.add_column(col)
    for name, row in results["coverage"].items():
        procedural = name == "procedural"
        t.add_row(
            f"procedural x{row['episodes']}" if procedural else name,
            f"{100 * row['coverage_min']:.1f} %"
            + (f" ({row['all_swept']} all swept)" if procedural else ""),
            f"{row['travel_ratio_mean']:.2f}"
            + ("" if procedural else f" / {row['travel_ratio_max']:.2f}"),
            f"{row['smartdfs_ratio_mean']:.2f} ({','.join(map(str, row['holes']))})",
            f"{row['below_smartdfs']}/{row['episodes']}",
            f"{row['simple_ratio_mean']:.2f}, {row['below_simple']}/{row['episodes']}",
            ""
            if procedural
            else f"{row['nearest_first_ratio_mean']:.2f}, {row['nearest_first_below_smartdfs']}",
            _share_text(row["travel_shares"]),
            f"{row['transfer_mean']:.0f} / {row['transfer_bfs_mean']:.0f}",
        )
    cw = results["corner_work"]
    t.add_row(
        f"corner room x{cw['episodes']} (v1)",
        f"{100 * cw['coverage_min']:.1f} % (PSA {100 * cw['psa_coverage_mean']:.1f} %)",
        *[""] * 5,
        _share_text(cw["travel_shares"]),
        f"no CWA: {100 * cw['no_cwa_coverage_mean']:.1f} %",
    )
    console.print(t)
    console.print(
        "paper: full coverage of Fig. 6, 11 and 12 whatever the obstacles. ratio: travel / "
        "(area / W); bound: W x steps / (area / W), steps C + E/2 - 3 (SmartDFS, no holes) or "
        "C + E/2 + 3H - 2 (H obstacles), robot-scale cells anchored at the start; the "
        "no-hole formula C + E/2 - 3 on every map is stricter; nearest-first: an ablation "
        "(psa-cwa-nearest), not the paper's stack order. travel % lanes/shifts/transfers "
        "(between runs)/CWA; transfer: cells moved between runs along the quadtree's chain of "
        "free squares (paper 3.2) / along the shortest path over all known free cells (the "
        "ablation). corner room: walls at 45 degrees to the lanes (paper Fig. 6, 9 -> 10), "
        "PSA's coverage when it hands over to CWA and the ablation without CWA"
    )

    sp, ori, wk = results["start_position"], results["orientation"], results["weak_baseline"]
    t = Table(title="Sensitivity and baseline: ours vs paper")
    for col in ("measure", "ours", "paper"):
        t.add_column(col)
    t.add_row(
        f"start position spread of travel, (max - min) / min and / max (maze, {sp['starts']} "
        "starts heading east)",
        f"{100 * sp['spread']:.1f} / {100 * sp['spread_of_max']:.1f} % "
        f"({sp['travel_min']:.0f}..{sp['travel_max']:.0f} cells)",
        "3.2 / 3.1 % (20193..20843 base units, every start)",
    )
    t.add_row(
        "  same starts: 5-95 % range / median; turns; steps (time)",
        f"{100 * sp['spread_p5_p95']:.1f} %; {100 * sp['turns_spread']:.0f} %; "
        f"{100 * sp['steps_spread']:.0f} %",
        "travel only",
    )
    t.add_row(
        "  alignment: range of mean travel over starts (row, column) mod "
        f"{results['robot_width']}; variance share",
        f"{100 * sp['alignment_range']:.1f} % of the mean; "
        f"{100 * sp['alignment_variance_share']:.0f} % of the variance",
        "periodic in the start (Fig. 15), all of the 3 %",
    )
    t.add_row(
        "  std of travel: all / sweeping (lanes, shifts) / between runs (transfers, CWA)",
        f"{sp['travel_std']:.1f} / {sp['sweeping_std']:.1f} / {sp['between_runs_std']:.1f} cells",
        "",
    )
    for row in results["start_scale"]:
        t.add_row(
            f"  maze x{row['k']} ({row['reading']}, {row['starts']} random starts): spread; "
            "5-95 % / median; travel",
            f"{100 * row['spread']:.1f} %; {100 * row['spread_p5_p95']:.1f} %; "
            f"{row['travel_mean']:.0f} cells = {row['travel_mean_widths']:.0f} robot widths",
            "3.2 % at about 20,500 base units (robot width not given)" if row["k"] == 1 else "",
        )
    t.add_row(
        f"start orientation spread (maze, 4 headings at {tuple(ori['start'])})",
        f"{100 * ori['spread']:.1f} % (over {ori['starts']} starts: mean "
        f"{100 * ori['spread_starts_mean']:.1f} %, max {100 * ori['spread_starts_max']:.1f} %)",
        "< 3 %",
    )
    turned = ori["walls_turned"]
    t.add_row(
        f"maze turned on the grid, {len(turned['rows'])} angles (staircase walls)",
        f"travel {100 * turned['spread']:.0f} %, ratio {100 * turned['ratio_spread']:.0f} %",
        "not the paper's setting",
    )
    t.add_row(
        "weak baseline coverage, empty room",
        f"{100 * wk['weak_coverage_same_steps']:.1f} % at PSA's steps, "
        f"{100 * wk['weak_coverage_5x_steps']:.1f} % at 5x",
        "about 90 %",
    )
    t.add_row(
        "weak baseline overlap / PSA overlap",
        f"{100 * wk['weak_overlap_same_steps']:.0f} % / {100 * wk['psa_overlap']:.0f} %",
        "much overlap (Fig. 1)",
    )
    console.print(t)

    t = Table(title="Odometry error on Sweeper-v1 (paper: open problem, Fig. 20)")
    for col in ("heading (rad/action)", "slip", "map", "localised", "coverage", "min", "early"):
        t.add_column(col)
    for r in results["odometry"]["rows"]:
        t.add_row(
            f"{r['heading_noise']}",
            f"{r['slip_noise']}",
            r["map"],
            "yes" if r["localise"] else "no",
            f"{100 * r['coverage']:.1f} %",
            f"{100 * r['coverage_min']:.1f} %",
            f"{r['early_stops']}/{r['episodes']}",
        )
    console.print(t)
    for name, row in results["odometry"]["summary"].items():
        console.print(
            f"{name}: coverage {100 * row['coverage']:.1f} % mean, "
            f"{100 * row['coverage_min']:.1f} % worst, "
            f"{row['early_stops']} of {row['episodes']} stopped early"
        )
