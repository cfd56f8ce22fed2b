"""The sweeper's learner-side map memory (motiongym.agents.learners.sweeper), checked against
the world's own state (the true map and sweep counts), not against the code that builds it."""

from __future__ import annotations

import gymnasium as gym
import numpy as np
import pytest
import yaml

from motiongym.agents.errors import UsageError
from motiongym.agents.learners.memory import MapMemoryPredictor, check_memory_kwargs
from motiongym.agents.learners.sweeper import MEMORY_KEY, MapMemoryWrapper, SweeperMapMemory
from motiongym.agents.training.config import validate_block
from motiongym.baselines import make_policy
from motiongym.baselines.sweeper.belief import FREE, OBSTACLE
from motiongym.envs.core import ArgumentError

SWEEPER = "motiongym/Sweeper-v1"


def _teacher(env):
    kwargs = gym.spec(SWEEPER).kwargs
    return make_policy(SWEEPER, "nearest-unswept", env.observation_space, env.action_space, kwargs)


def _true_crop(state, h: int, n: int, w: int) -> tuple[np.ndarray, np.ndarray]:
    """``(obstacle, swept)`` of the true world over the ``n x n`` cells centred on the
    footprint's centre, heading up (outside the map: obstacle, not swept)."""
    obstacle, sweeps = state.scenario.obstacle, state.sweeps
    H, W = obstacle.shape
    half = n // 2
    rows = np.arange(n)[:, None] + state.row + w // 2 - half
    cols = np.arange(n)[None, :] + state.col + w // 2 - half
    inside = (rows >= 0) & (rows < H) & (cols >= 0) & (cols < W)
    r, c = rows.clip(0, H - 1), cols.clip(0, W - 1)
    true_obstacle = np.where(inside, obstacle[r, c], True)
    true_swept = np.where(inside, sweeps[r, c] > 0, False)
    k = (1 - h) % 4
    return np.rot90(true_obstacle, k), np.rot90(true_swept, k)


def test_the_memory_agrees_with_the_world_along_a_whole_run():
    """Along the greedy teacher's full sweep (seed 3): the memory's map holds exactly the
    cells the world swept, every known cell is what the true map says, and the level-0 crop
    (heading up) shows the true obstacles where it shows any and no ``todo`` on swept
    floor; at the end (every reachable cell swept) nothing is ``todo`` at any level."""
    env = MapMemoryWrapper(gym.make(SWEEPER))
    teacher = _teacher(env)
    observation, _ = env.reset(seed=3)
    memory, state, n, w = env.memory, env.unwrapped.world.state, env.memory.crop, 3
    done, start, steps = False, True, 0
    while not done:
        action, _ = teacher.predict(observation, episode_start=np.array([start]))
        start = False
        observation, _, terminated, truncated, info = env.step(action)
        done = terminated or truncated
        steps += 1
        H, W = state.scenario.obstacle.shape
        o = memory.map.off
        occ = memory.map.occ[o : o + H, o : o + W]
        assert np.array_equal(memory.map.swept[o : o + H, o : o + W], state.sweeps > 0)
        assert (state.scenario.obstacle[occ == OBSTACLE]).all()
        assert not (state.scenario.obstacle[occ == FREE]).any()
        if steps % 25 == 0 or done:
            h = int(observation["pose"][2])
            true_obstacle, true_swept = _true_crop(state, h, n, w)
            crop = observation[MEMORY_KEY]
            shown = crop[1] > 0.5
            assert (true_obstacle[shown]).all()
            assert not (crop[0] > 0)[true_swept | true_obstacle].any()
    assert info["is_success"] and steps > 300
    assert observation[MEMORY_KEY][0::3].max() == 0.0


def test_a_single_leftover_cell_shows_far_away_at_the_coarse_level():
    """One free, unswept cell 30 cells north of the robot (heading north) in a swept room:
    level 2 (blocks of 9 x 9 cells) shows it as 1/81 in the block straight ahead, three
    blocks up; levels 0 and 1 (11 and 33 cells across) do not reach it."""
    from motiongym.baselines.sweeper.belief import UNKNOWN

    memory = SweeperMapMemory(3, 3)
    o = memory.map.off
    memory.map.occ[o : o + 60, o : o + 60] = FREE
    memory.map.swept[o : o + 60, o : o + 60] = True
    memory.map.swept[o + 10, o + 41] = False  # the leftover, 30 rows above the centre
    memory.map.occ[o + 70 :, :] = UNKNOWN
    crop = memory.crops(39, 40, 1)  # footprint centre (40, 41), heading north (up)
    assert crop[0].max() == 0.0 and crop[3].max() == 0.0
    # 30 rows up is block (30 + 4) // 9 = 3 rows above the centre block (5, 5)
    assert np.count_nonzero(crop[6]) == 1
    assert crop[6][2, 5] == pytest.approx(1 / 81)


def test_todo_leaves_out_floor_no_footprint_fits_over():
    """A room with a 1-cell notch in its north wall: after the teacher's full sweep the
    notch is free, sensed and unswept, so without the open-footprint test it would read
    ``todo`` for ever (and pull the learner to it); the memory shows nothing to do."""
    grid = np.ones((17, 20), bool)
    grid[2:-1, 1:-1] = False
    grid[1, 9] = False  # the notch in the 2-cell north wall: in no free 3 x 3 footprint
    env = MapMemoryWrapper(gym.make(SWEEPER, grid=grid))
    teacher = _teacher(env)
    observation, _ = env.reset(seed=0)
    done, start = False, True
    while not done:
        action, _ = teacher.predict(observation, episode_start=np.array([start]))
        start = False
        observation, _, terminated, truncated, info = env.step(action)
        done = terminated or truncated
    assert info["is_success"]
    o, memory = env.memory.map.off, env.memory.map
    free_unswept = (memory.occ == FREE) & ~memory.swept
    assert free_unswept[o + 1, o + 9] and free_unswept.sum() == 1  # the notch alone
    assert observation[MEMORY_KEY][0::3].max() == 0.0


def test_crops_turn_with_the_heading():
    """An obstacle cell two cells east of the footprint's centre is straight ahead
    (above the centre) when the robot heads east, on its right when it heads north,
    behind it heading west, on its left heading south."""
    memory = SweeperMapMemory(3, 3, levels=1)
    o = memory.map.off
    memory.map.occ[o + 11, o + 13] = OBSTACLE  # centre (11, 11)
    c = memory.crop // 2
    where = {0: (c - 2, c), 1: (c, c + 2), 2: (c + 2, c), 3: (c, c - 2)}
    for heading, cell in where.items():
        obstacle = memory.crops(10, 10, heading)[1]
        assert obstacle[cell] == 1.0 and obstacle.sum() == 1.0


def test_the_wrapper_forgets_the_episode_on_reset():
    """After 100 teacher steps, a reset leaves only what the first observation shows:
    the start footprint swept and one window sensed."""
    env = MapMemoryWrapper(gym.make(SWEEPER))
    teacher = _teacher(env)
    observation, _ = env.reset(seed=0)
    for k in range(100):
        action, _ = teacher.predict(observation, episode_start=np.array([k == 0]))
        observation, *_ = env.step(action)
    assert env.memory.map.swept.sum() > 100
    fresh, _ = env.reset(seed=1)
    assert env.memory.map.swept.sum() == 9
    memory = SweeperMapMemory.for_env(env)
    assert np.array_equal(fresh[MEMORY_KEY], memory.observe(fresh)[MEMORY_KEY])
    assert env.observation_space.contains(fresh)


class _Echo:
    """A stand-in model: records the observations it is given."""

    def __init__(self):
        self.seen = []

    def predict(self, observation, state=None, episode_start=None, deterministic=True, **kw):
        self.seen.append(observation[MEMORY_KEY].copy())
        return np.asarray(0), state


def test_the_predictor_builds_what_the_wrapper_showed_in_training():
    """On the same two episodes, a model behind MapMemoryPredictor in the bare environment
    is given the memory the training wrapper puts in the observation, step for step; its
    memory is emptied at the second episode's start."""
    bare, wrapped = gym.make(SWEEPER), MapMemoryWrapper(gym.make(SWEEPER))
    teacher = _teacher(bare)
    echo = _Echo()
    predictor = MapMemoryPredictor(echo, bare)
    for seed in (5, 6):
        observation, _ = bare.reset(seed=seed)
        shown, _ = wrapped.reset(seed=seed)
        for k in range(120):
            predictor.predict(observation, episode_start=np.array([k == 0]))
            assert np.array_equal(echo.seen[-1], shown[MEMORY_KEY])
            action, _ = teacher.predict(observation, episode_start=np.array([k == 0]))
            observation, *_ = bare.step(action)
            shown, *_ = wrapped.step(action)


def test_memory_settings_are_checked_by_name():
    assert check_memory_kwargs({}) == {"levels": 3, "crop": 11, "factor": 3}
    with pytest.raises(ArgumentError, match="unknown memory_kwargs key 'pooling'"):
        check_memory_kwargs({"pooling": "max"})
    with pytest.raises(ArgumentError, match="memory_kwargs.levels"):
        check_memory_kwargs({"levels": 0})
    with pytest.raises(ArgumentError, match="crop must be odd"):
        check_memory_kwargs({"crop": 10})
    block = {"n_timesteps": 0, "policy": "MultiInputPolicy", "imitate": "nearest-unswept"}
    with pytest.raises(UsageError, match="memory"):
        validate_block({**block, "memory": "sweeper"}, "maskableppo", "here")
    with pytest.raises(UsageError, match="vec_env dummy or subproc"):
        validate_block({**block, "memory": "sweeper_map", "vec_env": "native"}, "maskableppo", "x")
    with pytest.raises(UsageError, match="memory_kwargs needs memory"):
        validate_block({**block, "memory_kwargs": {"levels": 2}}, "maskableppo", "here")
    with pytest.raises(ValueError, match="needs a sweeper environment"):
        MapMemoryWrapper(gym.make("CartPole-v1"))


MEMORY_BLOCK = {
    "n_envs": 1,
    "n_timesteps": 0,
    "policy": "MultiInputPolicy",
    "policy_kwargs": {
        "features_extractor_class": "sweeper_map_pyramid",
        "features_extractor_kwargs": {"channels": [8]},
        "net_arch": [16],
    },
    "memory": "sweeper_map",
    "imitate": "nearest-unswept",
    "dagger_iterations": 1,
    "dagger_episodes": 1,
    "bc_epochs": 2,
    "vec_env": "dummy",
    "deterministic": False,
    "env_kwargs": {"max_episode_steps": 60},
}


def test_a_run_with_the_memory_trains_loads_and_evaluates(tmp_path):
    """A tiny DAgger run with the memory: its config names it, the loaded model acts in
    the bare environment (the loader adds the memory), and a model loaded without it
    is refused by name (its observation space lacks the entry)."""
    from motiongym.agents.evaluation.episodes import evaluate
    from motiongym.agents.models.predictors import load_predictor
    from motiongym.agents.training.train import train

    path = tmp_path / "memory.yml"
    path.write_text(yaml.safe_dump({"maskableppo": MEMORY_BLOCK}))
    run_dir = train(SWEEPER, "maskableppo", path, out_root=tmp_path / "runs", progress=False)
    env = gym.make(SWEEPER, max_episode_steps=50)
    predictor = load_predictor(str(run_dir), SWEEPER, env)
    episodes = evaluate(env, predictor, [100000], SWEEPER, "memory", progress=False).episodes
    assert episodes[0]["length"] == 50
    config = yaml.safe_load((run_dir / "config.yml").read_text())
    config.pop("memory")
    (run_dir / "config.yml").write_text(yaml.safe_dump(config))
    (run_dir / "manifest.json").unlink()
    with pytest.raises(UsageError, match="another observation space"):
        load_predictor(str(run_dir), SWEEPER, env, trust=True)
