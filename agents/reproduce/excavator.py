"""Reproduction of the excavator paper (002): Newton-Raphson IK, and the dig cycle.

The paper (section 5) solves one case: bucket angle pi/8, tip at [15, 0, 0]
(its units), 20 Newton-Raphson iterations from the initial pose, and shows
every element of the error V converging to zero (Fig. 4) and the initial and
final poses (Fig. 5). It gives no other numbers. We run:

1. the paper's case on our machine (:func:`newton_raphson.paper_target`: a
   ground-level target on the x axis at 0.8 of the maximum reach, bucket
   22.5 deg below the pin), 20 iterations from the rest pose, analytic and
   central-difference Jacobians, and the damped variant beside it;
2. IK on random reachable poses (joint angles drawn in the ranges): the
   convergence rate and iterations of eq. 13 from the rest pose (the
   paper's literal start; with the swing pointed at the target; with swing
   and bucket angle aligned), of the projected variant and of
   Levenberg-Marquardt;
3. Newton-Raphson beside Levenberg-Marquardt near the arm's singularity
   (stick almost in line with the boom); IK on unreachable targets: the
   reasons given, and that none is reported as converged;
4. IK probes: a flipped-bucket target, and 3,000 targets
   sampled in Cartesian space (the reasons; no "no solution" reason where
   the closed form has an in-limit solution; no wrong pose, both bucket axes,
   reported converged) (:mod:`.excavator_ik`);
5. the dig-cycle scripted policy (the paper's announced next step) on seeded
   scenes of the dig world: bucket fill at the end of the dig, soil
   delivered, spill, pipe contacts, cycle time;
6. probes of the world, run as a reviewer would (:mod:`.excavator_probes`);
7. speed: IK solves per second, and env steps per second beside
   Gymnasium's ``Reacher-v5`` measured in the same run.
"""

from __future__ import annotations

import json
import pathlib
import time
from typing import Any

import numpy as np

from motiongym.agents.reproduce import excavator_ik as ik
from motiongym.agents.reproduce import excavator_probes
from motiongym.baselines.excavator import newton_raphson as nr
from motiongym.envs.excavator.config import DEFAULT_MACHINE as M
from motiongym.envs.excavator.kinematics import link_frames
from motiongym.envs.excavator.observation import layout

DIG_IDS = ("motiongym/Excavator-v0", "motiongym/Excavator-v1")
DELIVERED = 0.8  # m3 (loose in v1): the target for one cycle
V_NAMES = ("E(1,1)", "E(3,1)", "E(1,4)", "E(2,4)", "E(3,4)")


def paper_case() -> dict[str, Any]:
    """Section 5 on our machine: V per iteration for NR (both Jacobians) and LM."""
    tip, beta = nr.paper_target(M)
    runs = {
        "newton_analytic": nr.solve(tip, beta, M, stop_early=False),
        "newton_numeric": nr.solve(tip, beta, M, stop_early=False, jacobian_mode="numeric"),
        "lm": nr.solve(tip, beta, M, stop_early=False, method="lm"),
    }
    first_below = {
        name: int(np.argmax(np.max(np.abs(r.errors), axis=1) < 1e-6)) for name, r in runs.items()
    }
    return {
        "target_tip": tip.tolist(),
        "target_beta": beta,
        "q_start": list(M.q_rest),
        "runs": {
            name: {
                "q": r.q.tolist(),
                "converged": r.converged,
                "reason": r.reason,
                "position_error_m": r.position_error,
                "angle_error_rad": r.angle_error,
                "V": r.errors.tolist(),
                "first_iteration_max_V_below_1e-6": first_below[name],
            }
            for name, r in runs.items()
        },
    }


def dig_cycles(n: int, env_id: str, first_seed: int = 0) -> dict[str, Any]:
    """The dig-cycle policy on ``n`` seeded scenes of ``env_id`` (seeds from ``first_seed``).

    Episodes run through :func:`~motiongym.agents.evaluation.episodes.run_episode`; a
    hook times the policy, reads its public ``diagnostics()`` (the cut depth
    it chose) and the zone's marked depth from the observation, and counts
    the steps with a contact of each kind (ground, self: v1 only). A clean
    delivery (the cycle's target): at least :data:`DELIVERED` m3 in the
    truck with no contact at all (pipe, truck, ground but the cut, self).
    """
    import gymnasium as gym

    from motiongym.agents.environments import resolved_env_kwargs
    from motiongym.agents.evaluation.episodes import run_episode
    from motiongym.baselines.registry import make_policy

    env = gym.make(env_id)
    kwargs = resolved_env_kwargs(env_id, None)
    policy = _TimedPolicy(
        make_policy(env_id, "dig-cycle", env.observation_space, env.action_space, kwargs)
    )
    zone = layout("dig")["zone"]
    rows = []
    kinds = ("pipe_contact", "truck_contact", "ground_contact", "self_contact")
    for seed in range(first_seed, first_seed + n):
        seen: dict[str, Any] = dict.fromkeys(kinds, 0.0)

        def hook(step, seen=seen) -> None:
            seen["cut_depth"] = policy.diagnostics().get("cut_depth")
            seen["marked_depth"] = float(step.observation[zone][4])
            for kind in kinds:
                seen[kind] += float(step.info.get(kind, 0.0))

        episode = run_episode(env, policy, seed, hook=hook)
        clean = episode["truck_soil"] >= DELIVERED and all(seen[k] == 0.0 for k in kinds)
        rows.append({**episode, **seen, "success": bool(episode["is_success"]), "clean": clean})
    env.close()

    def stat(key: str) -> dict[str, float]:
        v = np.array([r[key] for r in rows], dtype=float)
        return {"mean": float(v.mean()), "min": float(v.min()), "max": float(v.max())}

    limited = [r for r in rows if r["cut_depth"] is not None]
    return {
        "env_id": env_id,
        "n": n,
        "seeds": f"{first_seed}-{first_seed + n - 1}",
        "success_rate": float(np.mean([r["success"] for r in rows])),
        "clean_delivery_rate": float(np.mean([r["clean"] for r in rows])),
        "episodes_with_contact": {k: int(sum(r[k] > 0 for r in rows)) for k in kinds},
        "dig_fill_m3": stat("dig_fill"),
        "truck_soil_m3": stat("truck_soil"),
        "spill_m3": stat("spill"),
        "outside_zone_m3": stat("outside_zone"),
        "cost_steps_total": float(sum(r["cost"] for r in rows)),
        "min_pipe_clearance_m": float(min(r["pipe_clearance"] for r in rows)),
        "cycle_time_s": stat("elapsed"),
        "depth_limited_by_pipe": int(
            sum(r["cut_depth"] < r["marked_depth"] - 1e-9 for r in limited)
        ),
        "policy_ms_per_step": 1e3 * policy.seconds / max(policy.calls, 1),
        "episodes": rows,
    }


class _TimedPolicy:
    """A predictor that times another one's ``predict`` (and passes ``diagnostics``)."""

    def __init__(self, inner) -> None:
        self.inner, self.seconds, self.calls = inner, 0.0, 0

    def predict(self, observation, state=None, episode_start=None, deterministic=True):
        start = time.perf_counter()
        out = self.inner.predict(observation, state, episode_start, deterministic)
        self.seconds += time.perf_counter() - start
        self.calls += 1
        return out

    def diagnostics(self, index: int = 0) -> dict[str, Any]:
        return self.inner.diagnostics(index)


def speed(n_steps: int) -> dict[str, float]:
    """IK solves/s and env steps/s (uniform random actions) beside Reacher-v5."""
    import gymnasium as gym

    import motiongym  # noqa: F401  (registers the IDs)

    tip, beta = nr.paper_target(M)
    n_ik = max(n_steps // 20, 50)
    start = time.perf_counter()
    for _ in range(n_ik):
        nr.solve(tip, beta, M)
    ik_rate = n_ik / (time.perf_counter() - start)

    # Interleaved chunks, so that a busy machine slows every environment alike.
    ids = ("Reacher-v5", "motiongym/Excavator-v0", "motiongym/ExcavatorReach-v0")
    runs = {}
    for env_id in ids:
        env = gym.make(env_id)
        env.reset(seed=0)
        rng = np.random.default_rng(0)
        actions = rng.uniform(-1, 1, size=(n_steps, *(env.action_space.shape or ()))).astype(
            np.float32
        )
        runs[env_id] = (env, actions)
    seconds = dict.fromkeys(ids, 0.0)
    chunk = max(n_steps // 10, 1)
    for start in range(0, n_steps, chunk):
        for env_id, (env, actions) in runs.items():
            t = time.perf_counter()
            for a in actions[start : start + chunk]:
                _, _, terminated, truncated, _ = env.step(a)
                if terminated or truncated:
                    env.reset()
            seconds[env_id] += time.perf_counter() - t
    for env, _ in runs.values():
        env.close()
    reacher, dig, reach = (n_steps / seconds[i] for i in ids)
    return {
        "ik_solves_per_s_paper_case": ik_rate,
        "reacher_v5_steps_per_s": reacher,
        "excavator_v0_steps_per_s": dig,
        "excavator_reach_v0_steps_per_s": reach,
        "excavator_v0_ratio_to_reacher": dig / reacher,
        "excavator_reach_v0_ratio_to_reacher": reach / reacher,
    }


def _figures(out_dir: pathlib.Path, case: dict[str, Any]) -> list[str]:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    run = case["runs"]["newton_analytic"]
    v = np.array(run["V"])  # (21, 5)
    fig, axes = plt.subplots(1, 2, figsize=(10, 4))
    for j, name in enumerate(V_NAMES):
        axes[0].plot(range(len(v)), v[:, j], marker="o", ms=3, label=name)
        axes[1].semilogy(range(len(v)), np.abs(v[:, j]) + 1e-17, marker="o", ms=3, label=name)
    axes[0].set(xlabel="iteration", ylabel="V element", title="Fig. 4: convergence of V (20 it.)")
    axes[1].set(xlabel="iteration", ylabel="|V element|", title="same, log scale")
    axes[0].legend()
    fig.tight_layout()
    fig4 = out_dir / "fig4_convergence.png"
    fig.savefig(fig4, dpi=120)
    plt.close(fig)

    fig = plt.figure(figsize=(6, 5))
    ax = fig.add_subplot(projection="3d")
    for q, style, label in ((case["q_start"], "--", "initial"), (run["q"], "-", "Newton-Raphson")):
        frames = link_frames(np.array(q), M)
        pts = np.array([[0, 0, 0]] + [f[:3, 3] for f in frames])
        ax.plot(pts[:, 0], pts[:, 1], pts[:, 2], style, marker="o", label=label)
    ax.scatter(*case["target_tip"], color="red", s=40, label="target tip")
    ax.set(xlabel="x (m)", ylabel="y (m)", zlabel="z (m)", title="Fig. 5: initial and final pose")
    ax.set(xlim=(-1, 10), ylim=(-3, 3), zlim=(-1.5, 5.5))
    ax.set_box_aspect((11, 6, 7))
    ax.legend()
    fig5 = out_dir / "fig5_pose.png"
    fig.savefig(fig5, dpi=120)
    plt.close(fig)
    return [str(fig4), str(fig5)]


def _print(results: dict[str, Any]) -> None:
    from rich.console import Console
    from rich.table import Table

    case = results["paper_case"]["runs"]["newton_analytic"]
    table = Table(title="Excavator (paper 002): ours vs the paper")
    table.add_column("measure")
    table.add_column("ours")
    table.add_column("paper")
    table.add_row(
        "paper case: max |V| after 20 NR iterations",
        f"{np.max(np.abs(case['V'][-1])):.1e}",
        "-> 0 (Fig. 4)",
    )
    table.add_row(
        "paper case: tip / angle error",
        f"{case['position_error_m'] * 1e3:.2g} mm / {case['angle_error_rad']:.1g} rad",
        "(Fig. 5, no number)",
    )
    table.add_row(
        "paper case: first iteration with max |V| < 1e-6",
        str(case["first_iteration_max_V_below_1e-6"]),
        "< 20",
    )
    for name, r in results["random_poses"].items():
        table.add_row(
            f"random reachable poses, {name}",
            f"{100 * r['converged_rate']:.1f} % conv., it. median {r['iterations_median']}, "
            f"max {r['iterations_max']}; wrong {r['wrong_pose_reported_converged']}",
            "-",
        )
    for name, r in results["near_singular"].items():
        table.add_row(
            f"near-singular poses (stick ~ boom line), {name}",
            f"{100 * r['converged_rate']:.1f} % conv. {r['reasons']}",
            "-",
        )
    c = results["issue_case"]
    table.add_row(
        "flipped bucket: converged / reason / q2+q3+q4",
        f"{c['converged']} / {c['reason']} / {c['q2+q3+q4']:.3f} rad",
        "-",
    )
    cart = results["cartesian_ik"]
    for name in ("newton_rest", "newton_rest_swing_aligned", "fallback_chain"):
        r = cart[name]
        table.add_row(
            f"{cart['n']} Cartesian targets ({cart['with_in_limit_solution']} solvable), {name}",
            f"{100 * r['converged_rate_of_solvable']:.1f} % of solvable conv.; wrong "
            f"{r['wrong_pose_reported_converged']}; 'no solution' for solvable "
            f"{r['no_solution_reason_with_in_limit_solution']}; {r['reasons']}",
            "-",
        )
    u = results["unreachable"]
    table.add_row(
        "unreachable targets reported converged",
        f"{u['reported_converged']} / {u['n']}  {u['reasons']}",
        "-",
    )
    for d in results["dig_cycle"].values():
        table.add_row(
            f"dig cycle {d['env_id']}: success / >= {DELIVERED} m3 with 0 contacts "
            f"(seeds {d['seeds']})",
            f"{100 * d['success_rate']:.1f} % / {100 * d['clean_delivery_rate']:.1f} %; "
            f"episodes with contact {d['episodes_with_contact']}",
            "(next step announced)",
        )
        table.add_row(
            f"dig fill / delivered / spill / outside zone (mean m3), {d['env_id']}",
            f"{d['dig_fill_m3']['mean']:.2f} / {d['truck_soil_m3']['mean']:.2f} / "
            f"{d['spill_m3']['mean']:.3f} / {d['outside_zone_m3']['mean']:.3f}",
            "-",
        )
        table.add_row(
            f"cycle time (mean, max s); depth limited by pipe, {d['env_id']}",
            f"{d['cycle_time_s']['mean']:.1f}, {d['cycle_time_s']['max']:.1f}; "
            f"{d['depth_limited_by_pipe']} / {d['n']}",
            "-",
        )
    for probes in results["probes"].values():
        for row in excavator_probes.table_rows(probes):
            table.add_row(*row)
    s = results["speed"]
    table.add_row("IK solves/s (paper case)", f"{s['ik_solves_per_s_paper_case']:.0f}", "-")
    table.add_row(
        "Excavator-v0 steps/s vs Reacher-v5",
        f"{s['excavator_v0_steps_per_s']:.0f} vs {s['reacher_v5_steps_per_s']:.0f} "
        f"({s['excavator_v0_ratio_to_reacher']:.2f}x)",
        "-",
    )
    table.add_row(
        "ExcavatorReach-v0 steps/s vs Reacher-v5",
        f"{s['excavator_reach_v0_steps_per_s']:.0f} "
        f"({s['excavator_reach_v0_ratio_to_reacher']:.2f}x)",
        "-",
    )
    Console().print(table)


def run(out_dir: pathlib.Path, quick: bool = False) -> dict[str, Any]:
    """Run the reproduction; write figures and ``excavator.json`` into ``out_dir``."""
    out_dir = pathlib.Path(out_dir)
    out_dir.mkdir(parents=True, exist_ok=True)
    results: dict[str, Any] = {
        "machine": M.as_dict(),
        "paper_case": paper_case(),
        "random_poses": ik.random_poses(100 if quick else 1000),
        "near_singular": ik.near_singular(40 if quick else 200),
        "unreachable": ik.unreachable(40 if quick else 200),
        "issue_case": ik.issue_case(),
        "cartesian_ik": ik.cartesian_ik(300 if quick else 3000),
        "dig_cycle": {
            env_id: dig_cycles(8 if quick else 200, env_id, first_seed=1000) for env_id in DIG_IDS
        },
        "probes": {env_id: excavator_probes.run_probes(env_id) for env_id in DIG_IDS},
        "speed": speed(2000 if quick else 20000),
    }
    results["figures"] = _figures(out_dir, results["paper_case"])
    (out_dir / "excavator.json").write_text(json.dumps(results, indent=2))
    _print(results)
    return results
