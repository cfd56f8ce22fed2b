"""PSA + CWA under odometry error on Sweeper-v1: the localiser, its ablation, and "done"."""

from __future__ import annotations

import gymnasium as gym
import numpy as np
import pytest

import motiongym  # noqa: F401
from motiongym.agents.evaluation.episodes import run_episode
from motiongym.baselines.sweeper.belief import RobotMap
from motiongym.baselines.sweeper.localise import Localiser
from motiongym.baselines.sweeper.psa_cwa import (
    PsaCwaDeadReckoningPolicy,
    PsaCwaOneMapPolicy,
    PsaCwaPolicy,
)
from motiongym.envs.sweeper import generator

ENV_ID = "motiongym/Sweeper-v1"
NOISE = {"heading_noise": 0.01, "slip_noise": 0.05}


def l_shape() -> np.ndarray:
    """An L-shaped hall (a map nobody tuned on)."""
    g = np.zeros((36, 44), bool)
    g[0, :] = g[-1, :] = g[:, 0] = g[:, -1] = True
    g[:21, 22:] = True
    return g


def spiral() -> np.ndarray:
    """A spiral corridor five to six cells wide."""
    g = np.zeros((41, 41), bool)
    g[0, :] = g[-1, :] = g[:, 0] = g[:, -1] = True
    g[6, 6:35] = g[6:35, 34] = g[34, 6:35] = g[12:35, 6] = True
    g[12, 6:29] = g[12:29, 28] = g[28, 12:29] = g[18:29, 12] = g[18, 12:23] = True
    return g


def office() -> np.ndarray:
    """Two rows of offices off a corridor, a door five wide into each, two desks."""
    g = np.zeros((40, 52), bool)
    g[0, :] = g[-1, :] = g[:, 0] = g[:, -1] = True
    g[17, :] = g[23, :] = True
    for c in (13, 26, 39):
        g[:17, c] = g[24:, c] = True
    for c0 in (3, 16, 29, 42):
        g[17, c0 : c0 + 5] = False
        g[23, c0 + 2 : c0 + 7] = False
    g[6:9, 4:9] = g[30:33, 30:35] = True
    return g


def corridors() -> np.ndarray:
    """Six corridors 4-7 cells wide, joined end to end by 5-wide gaps (a serpentine)."""
    g = np.zeros((44, 50), bool)
    g[0, :] = g[-1, :] = g[:, 0] = g[:, -1] = True
    r = 0
    for i, width in enumerate((4, 5, 6, 4, 7, 5)):
        r += width + 1
        if r >= 43:
            break
        g[r, :] = True
        g[r, 1:6] = False if i % 2 else g[r, 1:6]
        g[r, -6:-1] = g[r, -6:-1] if i % 2 else False
    return g


def pillars() -> np.ndarray:
    """A hall with a 4 x 4 grid of 2 x 2 pillars (periodic: every pillar looks alike)."""
    g = np.zeros((40, 46), bool)
    g[0, :] = g[-1, :] = g[:, 0] = g[:, -1] = True
    for r in range(7, 36, 9):
        for c in range(7, 42, 10):
            g[r : r + 2, c : c + 2] = True
    return g


def procedural(seed: int, kind: str):
    """A map of the training generator from a seed no test or study used before."""
    return lambda: generator.random_map(np.random.default_rng(seed), 3, kind)


UNSEEN = {"L": l_shape, "office": office, "spiral": spiral}
NEW_UNSEEN = {
    "corridors": corridors,
    "pillars": pillars,
    "apartment 4242": procedural(4242, "apartment"),
    "room 4243": procedural(4243, "room"),
    "maze 4244": procedural(4244, "maze"),
}


def coverage_at_done(cls, seed: int, **kwargs) -> tuple[float, bool]:
    """Coverage at the step the policy declares itself done (read by the loop's hook)."""
    env = gym.make(ENV_ID, **kwargs)
    policy = cls(env.observation_space, env.action_space, {**gym.spec(ENV_ID).kwargs, **kwargs})
    seen = {"done": False}

    def hook(step) -> bool:
        seen["coverage"] = step.info["coverage"]
        seen["done"] = policy.diagnostics()["done"]
        return seen["done"]

    run_episode(env, policy, seed, hook=hook)
    return seen["coverage"], seen["done"]


def test_no_localiser_without_noise_and_full_coverage_on_v1() -> None:
    env = gym.make(ENV_ID)
    policy = PsaCwaPolicy(env.observation_space, env.action_space, gym.spec(ENV_ID).kwargs)
    assert policy.new_memory().loc is None and policy.max_stalls == 0
    for map_name in ("room", "apartment", "maze"):
        coverage, done = coverage_at_done(PsaCwaPolicy, 0, map_name=map_name)
        assert coverage == 1.0  # the environment ends on full coverage before "done"


def test_diagnostics_report_done_and_pose() -> None:
    env = gym.make(ENV_ID, **NOISE)
    policy = PsaCwaPolicy(env.observation_space, env.action_space, NOISE)
    obs, _ = env.reset(seed=0)
    policy.predict(obs, episode_start=np.ones(1, bool))
    d = policy.diagnostics()
    assert set(d) == {"mode", "done", "pose", "spread", "log"} and d["done"] is False
    assert d["pose"] == tuple(int(v) for v in obs["pose"][:2]) and d["spread"] == 0.0


def _obs(row: int, col: int, heading: int, bump: bool) -> dict:
    S = 3 + 2 * 3
    free = np.zeros(S * S, np.float32)
    return {"sensed": free, "known": free, "pose": np.array([row, col, heading, bump], np.float32)}


def test_a_move_is_read_from_the_heading_not_the_clipped_reckoning() -> None:
    """The environment clips the dead-reckoned cell to the map: a forward move at the
    edge leaves it unchanged. The localiser still moves its particles one cell along the
    heading (east: column + 1); a bump or a turn does not move them."""
    loc = Localiser(3, 3, heading_noise=0.0, slip_noise=0.0, n=8)
    robot_map = RobotMap(3, 3)
    assert loc.locate(robot_map, _obs(5, 5, 0, False)) == (5, 5)
    assert loc.locate(robot_map, _obs(5, 5, 0, False)) == (5, 6)  # moved, reckoning clipped
    assert loc.locate(robot_map, _obs(5, 5, 0, True)) == (5, 6)  # a bump
    assert loc.locate(robot_map, _obs(5, 5, 1, False)) == (5, 6)  # a turn
    assert loc.locate(robot_map, _obs(4, 5, 1, False)) == (4, 6)  # north


def test_localised_beats_dead_reckoning_on_the_room() -> None:
    # measured (seeds 0-3, a map per particle): localised 99.7 / 99.9 / 99.3 / 99.2 %, dead
    # reckoning 97.2 / 64.1 / 92.9 / 96.9 % (mean 87.8 %): one seed alone does not separate them
    loc, dead = [], []
    for seed in range(4):
        cov, done = coverage_at_done(PsaCwaPolicy, seed, map_name="room", **NOISE)
        loc.append(cov)
        assert done or cov == 1.0
        cov, done = coverage_at_done(PsaCwaDeadReckoningPolicy, seed, map_name="room", **NOISE)
        dead.append(cov)
        assert done or cov == 1.0
    assert min(loc) > 0.97 and np.mean(dead) < 0.9
    assert all(a > b for a, b in zip(loc, dead, strict=True))


@pytest.mark.study
def test_localised_beats_dead_reckoning_on_unseen_maps() -> None:
    """L, office, spiral (written here, never tuned on), seeds 0-2; measured mean (min):
    99.2 % (97.6 %) localised (a map per particle), 62.1 % (24.8 %) dead reckoning."""
    ours, ablation = [], []
    for make in (l_shape, office, spiral):
        for seed in range(3):
            ours.append(coverage_at_done(PsaCwaPolicy, seed, grid=make(), **NOISE)[0])
            ablation.append(
                coverage_at_done(PsaCwaDeadReckoningPolicy, seed, grid=make(), **NOISE)[0]
            )
    assert np.mean(ours) > np.mean(ablation) + 0.1
    assert np.min(ours) > np.min(ablation)


@pytest.mark.study
def test_localised_beats_dead_reckoning_on_new_unseen_maps() -> None:
    """Corridors, pillars, generator maps from fresh seeds (apartment 4242, room 4243,
    maze 4244), seeds 0-1, heading 0.01 + slip 0.05. Measured, coverage at done:
    localised 99.7 % mean, 99.2 % min; dead reckoning 80.6 %, 8.6 %. Seeds 0-6 of
    these five maps and the L, office and spiral (56 runs): 99.3 % mean, 93.0 % min
    (docs/experiments/Sweeper-v1.md, fourth pass); the issue's 97 % minimum is not met."""
    ours, ablation = [], []
    for make in NEW_UNSEEN.values():
        for seed in range(2):
            ours.append(coverage_at_done(PsaCwaPolicy, seed, grid=make(), **NOISE)[0])
            ablation.append(
                coverage_at_done(PsaCwaDeadReckoningPolicy, seed, grid=make(), **NOISE)[0]
            )
    assert np.mean(ours) > 0.99 and np.min(ours) > 0.97
    assert np.mean(ours) > np.mean(ablation) + 0.1


class NoVotes(PsaCwaPolicy):
    """Ablation: the localised policy's map keeps the latest window, not votes."""

    evidence = 0


class NoStalls(PsaCwaPolicy):
    """Ablation: done at the first scan that finds nothing new (and bump marks kept)."""

    def __init__(self, *args, **kwargs) -> None:
        super().__init__(*args, **kwargs)
        self.max_stalls = 0


class NoSteer(PsaCwaPolicy):
    """Ablation: turn to the next cell's direction and move forward, as without noise."""

    steering = False


class NoDiffuse(PsaCwaPolicy):
    """Ablation: no heading-error diffusion of the particles on a forward move."""

    diffuse = False


class NoSidestep(PsaCwaPolicy):
    """Ablation: after a bump the map does not explain, replan from the same spot (and
    the bump marks stay walls once it moves on)."""

    sidestep = False


LOS = (l_shape, office, spiral)
OPEN = (office, NEW_UNSEEN["pillars"], NEW_UNSEEN["corridors"], spiral)


@pytest.mark.study
@pytest.mark.parametrize(
    ("ablation", "maps"),
    [
        (NoVotes, OPEN),
        (NoStalls, LOS),
        (NoSidestep, LOS),
        (PsaCwaDeadReckoningPolicy, LOS),
        (PsaCwaOneMapPolicy, LOS),
        (NoSteer, OPEN),
        (NoDiffuse, OPEN),
    ],
)
def test_each_mechanism_earns_its_place(ablation, maps) -> None:
    """Seeds 0-2, heading 0.01 + slip 0.05, coverage at done; each mechanism tested where it
    is at work. Measured (docs/experiments/Sweeper-v1.md, fourth pass), mean (min): the
    shipped policy 99.3 % (98.0 %) on L, office, spiral and 99.7 % (99.2 %) on office,
    pillars, corridors, spiral; on the second set votes clipped at 1 96.7 % (80.3 %) and
    no steering 97.8 % (79.2 %; on the first set it measured no loss, 99.5 % (98.3 %));
    against the policy with votes clipped at 100 (99.2 % (97.6 %) on the first set), one
    map for all particles 96.6 % (77.2 %), and on the second set no diffusion 93.8 %
    (50.4 %) against 99.8 % (99.3 %)."""
    ours, theirs = [], []
    for make in maps:
        for seed in range(3):
            ours.append(coverage_at_done(PsaCwaPolicy, seed, grid=make(), **NOISE)[0])
            theirs.append(coverage_at_done(ablation, seed, grid=make(), **NOISE)[0])
    assert np.mean(ours) > np.mean(theirs) + 0.01
    assert np.min(ours) > np.min(theirs)


def test_a_step_whose_planning_does_not_settle_moves_on() -> None:
    """Room, slip 0.1, seed 0: every heading had bumped from the estimated cell (slips moved
    the robot, not the estimate) and the modes replanned the same path for ever, turning in
    place (over 10 min without an end). With MAX_ROUNDS and the bumps forgotten it sweeps
    the room (99.9 %) and declares itself done in under 1,000 steps."""
    kwargs = {"map_name": "room", "heading_noise": 0.0, "slip_noise": 0.1}
    env = gym.make(ENV_ID, **kwargs)
    policy = PsaCwaPolicy(env.observation_space, env.action_space, kwargs)
    seen = {"steps": 0, "done": False}

    def hook(step) -> bool:
        seen["steps"], seen["coverage"] = step.index + 1, step.info["coverage"]
        seen["done"] = policy.diagnostics()["done"]
        return seen["done"] or seen["steps"] >= 3000

    run_episode(env, policy, 0, hook=hook)
    assert (seen["done"] or seen["coverage"] == 1.0) and seen["steps"] < 1000
    assert seen["coverage"] > 0.99


class NoSkip(PsaCwaPolicy):
    """Ablation: a move that lands on a later cell of the plan (a diagonal step under
    odometry error) is not skipped to; the plan is followed from its first cell."""

    skip_ahead = False


@pytest.mark.study
def test_skipping_to_a_later_cell_of_the_plan_earns_its_place() -> None:
    """On the 56 development runs (docs/experiments/Sweeper-v1.md) the ablation gives 97.8 %
    mean, 65.3 % min against 99.5 %, 97.2 %; its two worst runs are checked here."""
    for name, seed in (("corridors", 5), ("spiral", 3)):
        grid = NEW_UNSEEN[name] if name in NEW_UNSEEN else UNSEEN[name]
        ours = coverage_at_done(PsaCwaPolicy, seed, grid=grid(), **NOISE)[0]
        theirs = coverage_at_done(NoSkip, seed, grid=grid(), **NOISE)[0]
        assert ours > 0.97 and ours > theirs + 0.1


def test_the_continuous_pose_falls_back_to_the_cells_particles_when_their_weights_underflow():
    """Particles in the estimated cell whose weights have all underflowed to 0 (the rest
    hold the mass): the pose is their plain mean, not a division by zero; with weight in
    the cell, the weighted mean of the cell's particles only; the heading error is the
    weighted mean of all particles."""
    loc = Localiser(3, 3, heading_noise=0.0, slip_noise=0.0, n=4)
    loc.y = np.array([5.2, 4.8, 9.0, 9.0])
    loc.x = np.array([7.0, 7.4, 2.0, 2.0])
    loc.e = np.array([0.0, 0.0, 0.1, 0.3])
    loc.cell = (5, 7)
    loc.wt = np.array([0.0, 0.0, 0.5, 0.5])
    assert np.allclose(loc.continuous(), (5.0, 7.2, 0.2))
    loc.wt = np.array([0.3, 0.1, 0.3, 0.3])
    assert np.allclose(loc.continuous(), (5.1, 7.1, 0.12))
