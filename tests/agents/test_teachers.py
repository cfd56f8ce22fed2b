"""The scripted policies as teachers: residual learning and behaviour cloning, by number."""

from __future__ import annotations

import json

import gymnasium as gym
import numpy as np
import pytest
import torch
from stable_baselines3 import PPO, SAC

from motiongym.agents.training.residual import ResidualPredictor, ResidualWrapper, zero_correction
from motiongym.baselines import make_policy

REACH = "motiongym/ExcavatorReach-v1"


def _scripted_episode(env_id: str, policy: str, seed: int):
    env = gym.make(env_id)
    pol = make_policy(env_id, policy, env.observation_space, env.action_space, env.spec.kwargs)
    obs, _ = env.reset(seed=seed)
    actions, done = [], False
    while not done:
        action, _ = pol.predict(obs)
        obs, _, terminated, truncated, info = env.step(action)
        actions.append(action)
        done = terminated or truncated
    return np.array(actions), obs, info


def test_residual_with_zero_correction_is_the_scripted_policy():
    """Silver et al.'s starting point: f = 0 acts exactly as pi_0 (same actions, same end)."""
    actions, last, info = _scripted_episode(REACH, "newton-raphson-reach", seed=4)
    env = ResidualWrapper(gym.make(REACH), "newton-raphson-reach")
    obs, _ = env.reset(seed=4)
    applied = []
    for _ in range(len(actions)):
        obs, _, terminated, truncated, step_info = env.step(np.zeros(4, np.float32))
        applied.append(step_info["base_action"])
    np.testing.assert_array_equal(applied, actions)
    np.testing.assert_array_equal(obs, last)
    assert terminated and step_info["is_success"] == info["is_success"] is True


@pytest.mark.parametrize("algorithm", [SAC, PPO])
def test_zero_correction_makes_the_untrained_agent_its_scripted_policy(algorithm):
    """Silver et al.'s initialisation: after zero_correction the untrained agent's action is
    the scripted one, step by step; SB3's own initialisation (the ablation) moves it."""
    actions, _, _ = _scripted_episode(REACH, "newton-raphson-reach", seed=100_000)
    env = gym.make(REACH)
    scripted = make_policy(
        REACH, "newton-raphson-reach", env.observation_space, env.action_space, env.spec.kwargs
    )
    wrapped = ResidualWrapper(gym.make(REACH), "newton-raphson-reach", 0.3)
    acted = {}
    for init in ("sb3", "zero"):
        model = algorithm("MlpPolicy", wrapped, seed=0, device="cpu")
        if init == "zero":
            zero_correction(model)
        predictor = ResidualPredictor(model, scripted, 0.3, env.action_space)
        obs, _ = env.reset(seed=100_000)
        acted[init] = []
        for t in range(len(actions)):
            action, _ = predictor.predict(obs, episode_start=np.array([t == 0]))
            obs, *_ = env.step(action)
            acted[init].append(action)
    np.testing.assert_array_equal(acted["zero"], actions)
    assert np.abs(np.array(acted["sb3"][0]) - actions[0]).max() > 1e-3
    with pytest.raises(ValueError, match="linear action output"):
        zero_correction(type("Model", (), {"policy": object()})())


def test_residual_correction_is_scaled_and_clipped_to_the_action_box():
    env = ResidualWrapper(gym.make(REACH), "newton-raphson-reach", scale=0.5)
    obs, _ = env.reset(seed=0)
    base, _ = env.policy.predict(obs)
    sent = []
    inner_step = env.env.step
    env.env.step = lambda a: sent.append(np.array(a)) or inner_step(a)
    env.step(np.array([1.0, -1.0, 0.2, 0.0], np.float32))
    expected = np.clip(base + 0.5 * np.array([1.0, -1.0, 0.2, 0.0]), -1.0, 1.0)
    np.testing.assert_allclose(sent[0], expected, atol=1e-6)


def test_residual_refuses_a_policy_of_another_id_and_bad_arguments():
    other = gym.make("motiongym/ExcavatorReach-v0")
    policy = make_policy(
        "motiongym/ExcavatorReach-v0", "newton-raphson-reach",
        other.observation_space, other.action_space, other.spec.kwargs,
    )  # fmt: skip
    with pytest.raises(
        ValueError, match=r"made for motiongym/ExcavatorReach-v1.*ExcavatorReach-v0"
    ):
        ResidualWrapper(gym.make(REACH), policy)
    with pytest.raises(ValueError, match="scripted policies: newton-raphson-reach"):
        ResidualWrapper(gym.make(REACH), "potential-field")
    with pytest.raises(ValueError, match="scale"):
        ResidualWrapper(gym.make(REACH), "newton-raphson-reach", scale=0.0)
    with pytest.raises(ValueError, match="Box action space"):
        ResidualWrapper(gym.make("motiongym/Sweeper-v0"), "boustrophedon")
    reach = gym.make(REACH)
    reach_policy = make_policy(
        REACH,
        "newton-raphson-reach",
        reach.observation_space,
        reach.action_space,
        reach.spec.kwargs,
    )
    with pytest.raises(TypeError, match="tolerance"):
        ResidualWrapper(gym.make(REACH), "newton-raphson-reach", policy_kwargs={"tolerance": 0.1})
    with pytest.raises(ValueError, match="policy_kwargs go with a policy's name"):
        ResidualWrapper(gym.make(REACH), reach_policy, policy_kwargs={"replan": True})


def _dig_with_corrections(tolerance: float | None, corrections, seeds) -> list[tuple]:
    """``dig-cycle`` through a 0.05-scale residual wrapper fed ``corrections(step)``:
    (delivered, steps, the teacher's last stage and waypoint) per episode."""
    kwargs = {} if tolerance is None else {"tolerance": tolerance}
    env = ResidualWrapper(gym.make("motiongym/Excavator-v1"), "dig-cycle", 0.05, kwargs)
    out = []
    for seed in seeds:
        env.reset(seed=seed)
        done, steps = False, 0
        while not done:
            _, _, terminated, truncated, info = env.step(corrections(steps))
            steps += 1
            done = terminated or truncated
        where = env.policy.diagnostics()
        out.append((info["is_success"], steps, where["stage"], where["waypoint"]))
    return out


def test_a_correction_stalls_the_dig_cycle_only_below_its_goal_tolerance():
    """The cause of the residual agents' lost digs (docs/experiments/Excavator-v1.md): the
    dig cycle passes each joint goal only within its tolerance, and a step's correction leaves
    the dead-beat tracking c * rate_max * dt past it. Half of a 0.05-scale correction on the
    bucket (2.5 mrad a step) holds the default 2 mrad teacher at its first goal for the whole
    episode; with the gate at 0.01 rad the same correction delivers. Corrections drawn as an
    untrained SAC actor explores (tanh of a unit normal, every step): 0-1 of 4 deliveries at
    2 mrad, 4 of 4 at 0.01 rad (training seeds, not held-out ones)."""
    bucket = np.array([0.0, 0.0, 0.0, 0.5], np.float32)
    seeds = range(5000, 5004)
    assert _dig_with_corrections(None, lambda t: bucket, seeds) == [(False, 600, "approach", 0)] * 4
    assert all(r[0] for r in _dig_with_corrections(0.01, lambda t: bucket, seeds))
    delivered = {}
    for tolerance in (None, 0.01):
        rng = np.random.default_rng(0)
        noise = lambda t, rng=rng: np.tanh(rng.normal(size=4)).astype(np.float32)  # noqa: E731
        delivered[tolerance] = sum(r[0] for r in _dig_with_corrections(tolerance, noise, seeds))
    assert delivered[None] <= 1 and delivered[0.01] == 4


@pytest.mark.parametrize(
    ("lines", "message"),
    [
        ("  residual_kwargs:\n    replan: true\n", "residual_kwargs needs residual"),
        ("  residual: newton-raphson-reach\n  residual_kwargs: 3\n", "residual_kwargs must be a"),
        (
            "  residual: newton-raphson-reach\n  residual_kwargs:\n    tolerance: 0.01\n",
            "residual_kwargs for 'newton-raphson-reach': .*tolerance",
        ),
    ],
)
def test_bad_residual_blocks_are_refused_by_name(tmp_path, lines, message):
    from motiongym.agents.errors import UsageError
    from motiongym.agents.training.train import train

    config = tmp_path / "residual.yml"
    config.write_text("sac:\n  n_timesteps: 64\n  policy: MlpPolicy\n" + lines)
    with pytest.raises(UsageError, match=message):
        train(REACH, "sac", config, out_root=tmp_path, progress=False)
    assert not (tmp_path / "ExcavatorReach-v1").exists()


@pytest.fixture(scope="module")
def demonstrations(tmp_path_factory):
    pytest.importorskip("minari")
    from motiongym.agents.integrations.dataset import (
        load_demonstrations,
        record_dataset,
        transitions,
    )

    env_id = "motiongym/HarvestArmPlanarGoal-v1"
    path, _ = record_dataset(env_id, "potential-field", 2, tmp_path_factory.mktemp("ds"))
    env = gym.make(env_id)
    return env, transitions(load_demonstrations(path, env)), path


@pytest.mark.parametrize("algorithm", [SAC, PPO])
def test_behaviour_cloning_fits_the_teacher(demonstrations, algorithm):
    """The cloned policy's actions on the teacher's states: at least 10x closer than before."""
    from motiongym.agents.training.imitation import behaviour_clone

    torch.manual_seed(0)
    env, (observations, actions), _ = demonstrations
    model = algorithm("MultiInputPolicy", env, policy_kwargs={"net_arch": [64, 64]}, seed=0)
    before = np.mean((model.predict(observations, deterministic=True)[0] - actions) ** 2)
    history = behaviour_clone(model, observations, actions, epochs=40, batch_size=64)
    after = np.mean((model.predict(observations, deterministic=True)[0] - actions) ** 2)
    assert len(history) == 40 and history[-1] < 0.1 * history[0]
    assert after < 0.1 * before
    with pytest.raises(ValueError, match="same length"):
        behaviour_clone(model, observations, actions[:-1])


def test_a_residual_run_trains_and_evaluates_with_its_scripted_policy(tmp_path):
    """``residual: newton-raphson-reach`` in a block: the run trains through the wrapper and
    its model acts through ResidualPredictor (the scripted action plus the correction)."""
    from motiongym.agents.environments import make_env
    from motiongym.agents.errors import UsageError
    from motiongym.agents.evaluation.episodes import evaluate
    from motiongym.agents.models.predictors import load_predictor
    from motiongym.agents.models.ship import ship
    from motiongym.agents.training.residual import ResidualPredictor
    from motiongym.agents.training.train import train

    config = tmp_path / "residual.yml"
    config.write_text(
        "sac:\n  n_timesteps: 64\n  policy: MlpPolicy\n  learning_starts: 16\n  batch_size: 16\n"
        "  eval_freq: 64\n  n_eval_episodes: 1\n  residual: newton-raphson-reach\n"
        "  residual_scale: 0.3\n  env_kwargs:\n    max_episode_steps: 30\n"
    )
    run_dir = train(REACH, "sac", config, out_root=tmp_path, progress=False)
    env = make_env(REACH, {"max_episode_steps": 30})
    predictor = load_predictor(str(run_dir), REACH, env)
    assert isinstance(predictor, ResidualPredictor) and predictor.scale == 0.3
    assert 0 < evaluate(env, predictor, [2], REACH, "res", progress=False).episodes[0]["length"]
    shipped = ship([run_dir], n_episodes=1, root=tmp_path / "pretrained")
    assert shipped.folder.name == "sac-residual"  # the label says the kind, as metrics.json
    assert json.loads((shipped.folder / "metrics.json").read_text())["kind"] == "residual"
    assert isinstance(load_predictor(str(shipped.folder), REACH, env), ResidualPredictor)
    config.write_text(config.read_text().replace("newton-raphson-reach", "potential-field"))
    with pytest.raises(UsageError, match="not a scripted policy of motiongym/ExcavatorReach-v1"):
        train(REACH, "sac", config, out_root=tmp_path, progress=False)


def test_a_run_with_demonstrations_clones_before_rl(demonstrations, tmp_path):
    """``demonstrations`` in a block: the policy is cloned (the losses fall) before training;
    a dataset of another ID is refused by name."""
    import json

    from motiongym.agents.errors import UsageError
    from motiongym.agents.training.train import train

    _, _, path = demonstrations
    config = tmp_path / "bc.yml"
    config.write_text(
        "sac:\n  n_timesteps: 64\n  policy: MultiInputPolicy\n  learning_starts: 41\n"
        "  batch_size: 16\n  replay_buffer_class: her\n  eval_freq: 64\n  n_eval_episodes: 1\n"
        f"  normalize: {{norm_reward: false}}\n  demonstrations: {path}\n  bc_epochs: 8\n"
        "  env_kwargs:\n    max_episode_steps: 40\n    collision: 0.0\n"
    )
    env_id = "motiongym/HarvestArmPlanarGoal-v1"
    run_dir = train(env_id, "sac", config, out_root=tmp_path, progress=False)
    losses = json.loads((run_dir / "behaviour_cloning.json").read_text())["loss"]
    assert len(losses) == 8 and losses[-1] < 0.5 * losses[0]
    with pytest.raises(UsageError, match="recorded on 'motiongym/HarvestArmPlanarGoal-v1'"):
        train("motiongym/HarvestArmGoal-v1", "sac", config, out_root=tmp_path, progress=False)


@pytest.mark.parametrize(
    "name",
    [
        "HarvestArm-v1-residual",
        "HarvestArmPlanar-v1-residual",
        "ExcavatorReach-v1-residual",
        "Excavator-v1-residual",
        "Excavator-v0-residual",
    ],
)
def test_shipped_residual_blocks_train_a_few_steps(name, tmp_path):
    """Each shipped residual block, shortened, trains through its scripted policy;
    with HER it is refused (a relabelled goal changes the scripted action)."""
    from importlib import resources

    import yaml

    from motiongym.agents.errors import UsageError
    from motiongym.agents.training.train import train

    env_id = "motiongym/" + name.removesuffix("-residual")
    path = resources.files("motiongym.configs") / f"{name}.yml"
    block = yaml.safe_load(path.read_text())["sac"]
    block.update(n_timesteps=48, learning_starts=16, batch_size=16, eval_freq=48)
    block.update(
        n_eval_episodes=1, env_kwargs={**block.get("env_kwargs", {}), "max_episode_steps": 24}
    )
    config = tmp_path / "tiny.yml"
    config.write_text(yaml.safe_dump({"sac": block}))
    assert (train(env_id, "sac", config, out_root=tmp_path, progress=False) / "model.zip").is_file()
    block.update(replay_buffer_class="her", learning_starts=30)
    config.write_text(yaml.safe_dump({"sac": block}))
    with pytest.raises(UsageError, match="cannot use replay_buffer_class her"):
        train(env_id, "sac", config, out_root=tmp_path, progress=False)


def _shipped_residuals() -> list[tuple[str, str]]:
    from motiongym.agents.models.pretrained import METRICS, pretrained_models
    from motiongym.envs import ENV_IDS

    return [
        (env_id, name)
        for env_id in ENV_IDS
        for name, folder in pretrained_models(env_id).items()
        if json.loads((folder / METRICS).read_text()).get("kind") == "residual"
    ]


class _NoCorrection:
    """A learned part that always proposes no correction (the ablation)."""

    def __init__(self, shape: tuple[int, ...]) -> None:
        self.shape = shape

    def predict(self, observation, state=None, episode_start=None, deterministic=True):
        return np.zeros(self.shape, np.float32), state


@pytest.mark.slow
@pytest.mark.parametrize(("env_id", "name"), _shipped_residuals())
def test_a_shipped_residual_agent_without_its_correction_is_its_teacher(env_id, name):
    """The ablation of a shipped residual agent on its first three held-out episodes: with the
    correction it repeats the episodes in metrics.json (to 1e-4 relative: the network's float32
    arithmetic is not bit-identical across CPUs, 5e-6 seen between the recording machine and
    ours); switched off it repeats the scripted
    policy's episodes exactly (the difference between the two is the learned part's), the
    scripted policy made with the run's ``residual_kwargs``."""
    import yaml

    from motiongym.agents.environments import make_env
    from motiongym.agents.evaluation.episodes import evaluate
    from motiongym.agents.models.predictors import load_predictor
    from motiongym.agents.models.pretrained import METRICS, pretrained_models

    folder = pretrained_models(env_id)[name]
    metrics = json.loads((folder / METRICS).read_text())
    shipped = next(run for run in metrics["runs"] if run["run"] == metrics["shipped_run"])
    seeds = metrics["held_out_seeds"][:3]
    env = make_env(env_id)
    agent = load_predictor(name, env_id, env)
    on = evaluate(env, agent, seeds, env_id, name, progress=False).episodes
    for episode, recorded in zip(on, shipped["episodes"][:3], strict=True):
        assert episode == pytest.approx(recorded, rel=1e-4)
    config = yaml.safe_load((folder / "config.yml").read_text())
    teacher = make_policy(  # the scripted policy with the keywords it acted with in training
        env_id,
        config["residual"],
        env.observation_space,
        env.action_space,
        env.spec.kwargs,
        **config.get("residual_kwargs", {}),
    )
    agent.learned = _NoCorrection(env.action_space.shape)
    off = evaluate(env, agent, seeds, env_id, "off", progress=False).episodes
    assert off == evaluate(env, teacher, seeds, env_id, "teacher", progress=False).episodes
