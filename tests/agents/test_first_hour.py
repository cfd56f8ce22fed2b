"""What a newcomer meets first: --version, every flag's default in its help, evaluate
and compare sharing a folder, tables that never cut a cell, the random row, figures."""

from __future__ import annotations

import argparse
import io
import json
from importlib.metadata import version

import numpy as np
import pytest
import torch

from motiongym.agents.cli import build_parser, main
from motiongym.agents.environments import make_env
from motiongym.agents.evaluation.episodes import Evaluation, evaluate
from motiongym.agents.evaluation.report import (
    PIPED_WIDTH,
    _bar_errors,
    comparison_table,
    make_console,
    plotted_measures,
)
from motiongym.agents.models.predictors import RANDOM, available_policies, load_predictor
from motiongym.envs import ENV_IDS

SWEEPER = "motiongym/Sweeper-v0"


def test_version_is_the_installed_distributions(capsys):
    with pytest.raises(SystemExit) as exit_info:
        main(["--version"])
    assert exit_info.value.code == 0
    assert capsys.readouterr().out.strip() == f"motiongym {version('motiongym')}"


def _flags():
    parser = build_parser()
    (commands,) = [a for a in parser._actions if isinstance(a, argparse._SubParsersAction)]
    for name, sub in commands.choices.items():
        for action in sub._actions:
            if action.option_strings and action.dest != "help" and not action.required:
                yield name, action


# Ids name the flag, never the action's repr: that holds function addresses, which differ
# between pytest-xdist workers, and the workers must collect the same tests.
@pytest.mark.parametrize(
    ("command", "action"),
    [pytest.param(c, a, id=f"{c}{a.option_strings[-1]}") for c, a in _flags()],
)
def test_every_optional_flags_help_states_its_default(command, action):
    assert "default" in (action.help or ""), f"{command} {action.option_strings}"


def test_evaluate_and_compare_share_a_folder_without_overwriting(capsys, tmp_path):
    common = ["--episodes", "2", "--out", str(tmp_path), "--no-progress"]
    room = ["--env-kwargs", "map_name=room"]
    assert main(["evaluate", SWEEPER, "--policy", "psa-cwa", *common, *room]) == 0
    evaluated = {p.name: p.read_bytes() for p in tmp_path.iterdir()}
    assert set(evaluated) == {f"Sweeper-v0_psa-cwa_evaluation.{x}" for x in ("json", "csv", "png")}
    out = capsys.readouterr().out
    assert "95% interval" in out and "coverage (fraction)" in out
    argv = ["compare", SWEEPER, "--policies", "psa-cwa", RANDOM, *common, *room]
    assert main(argv) == 0
    for name, content in evaluated.items():  # compare wrote beside them, over none
        assert (tmp_path / name).read_bytes() == content
    written = {p.name for p in tmp_path.iterdir()} - set(evaluated)
    assert {"Sweeper-v0_comparison.png", "Sweeper-v0_comparison_random.json"} <= written
    data = json.loads((tmp_path / "Sweeper-v0_comparison.json").read_text())
    assert [run["policy"] for run in data] == ["psa-cwa", RANDOM]
    assert data[0]["units"]["coverage"] == "fraction"


def _evaluation(policy: str, episodes: list[dict[str, float]]) -> Evaluation:
    units = {"return": "reward", "length": "steps", "steps": "steps", "bumps": "count"}
    return Evaluation(SWEEPER, policy, episodes, {**units, "is_success": "rate"})


def _long_named_evaluations() -> list[Evaluation]:
    episode = {"seed": 0, "return": 1.5, "length": 10, "is_success": 1.0}
    names = ["potential-field", "potential-field-extended", "resolved-rate", "ppo", "random"]
    return [_evaluation(name, [episode, {**episode, "seed": 1, "return": 2.5}]) for name in names]


def test_piped_tables_are_wide_and_never_cut_a_cell(monkeypatch):
    monkeypatch.delenv("COLUMNS", raising=False)
    buffer = io.StringIO()
    console = make_console(buffer)  # a StringIO is no terminal: a pipe or a file
    assert console.width == PIPED_WIDTH
    console.print(comparison_table(_long_named_evaluations()))
    text = buffer.getvalue()
    assert "potential-field-extended" in text and "…" not in text
    narrow = io.StringIO()  # even squeezed into 60 columns, cells fold, never cut
    make_console(narrow).__class__(file=narrow, width=60).print(
        comparison_table(_long_named_evaluations())
    )
    assert "…" not in narrow.getvalue()


def test_figures_omit_measures_always_zero_or_repeated_and_clip_rates():
    episodes = [
        {"seed": s, "return": r, "length": n, "steps": n, "bumps": 0.0, "is_success": w}
        for s, r, n, w in ((0, 1.0, 5, 1.0), (1, 2.0, 7, 0.0))
    ]
    evaluations = [_evaluation("a", episodes), _evaluation("b", episodes[:1])]
    assert plotted_measures(evaluations) == ["return", "length", "is_success"]
    errors = _bar_errors([0.9, 0.1], [0.6, 0.0], [1.0, 0.4], "rate")  # the summary's bounds
    np.testing.assert_allclose(errors, [[0.3, 0.1], [0.1, 0.3]])
    errors = _bar_errors([2.0, -1.0], [-1.0, -4.0], [5.0, 2.0], "m")  # may be negative
    np.testing.assert_allclose(errors, [[3.0, 3.0], [3.0, 3.0]])
    np.testing.assert_allclose(_bar_errors([2.0], [-1.0], [5.0], "steps"), [[2.0], [3.0]])
    # a rate of 0 whose Wilson bound lies 5.6e-17 above it (spiral-stc's in compare)
    assert (_bar_errors([0.0], [5.551e-17], [0.5615], "rate") >= 0).all()


@pytest.mark.parametrize("env_id", ENV_IDS)
def test_random_is_a_policy_of_every_id_and_repeats_its_episodes(env_id):
    assert RANDOM in available_policies(env_id)
    env = make_env(env_id, {"max_episode_steps": 30})
    policy = load_predictor(RANDOM, env_id, env)
    first = evaluate(env, policy, [7, 8], env_id, RANDOM, progress=False)
    again = evaluate(env, load_predictor(RANDOM, env_id, env), [7, 8], env_id, RANDOM, False)
    assert first.episodes == again.episodes
    observation, _ = env.reset(seed=0)
    actions = []
    for seed in (7, 8):  # run_episode seeds torch with the episode's seed
        torch.manual_seed(seed)
        start = np.ones(1, dtype=bool)
        draws = [
            policy.predict(observation, episode_start=start if i == 0 else start & False)[0]
            for i in range(10)
        ]
        actions.append(np.asarray(draws, dtype=float))
    env.close()
    assert not np.array_equal(*actions)


def test_random_sweeper_keeps_to_the_action_masks():
    env = make_env(SWEEPER, {"max_episode_steps": 2000, "map_name": "room"})
    evaluation = evaluate(env, load_predictor(RANDOM, SWEEPER, env), [3], SWEEPER, RANDOM, False)
    (episode,) = evaluation.episodes
    env.close()
    assert episode["bumps"] == 0 and episode["turns"] > 100
