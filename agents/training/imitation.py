"""Behaviour cloning: an SB3 policy regressed on a scripted teacher's actions.

The demonstrations are a Minari dataset of :mod:`motiongym.agents.integrations.dataset`
(checked to be of the environment's ID and spaces). The loss is the mean
squared error between the policy's deterministic action and the teacher's,
in the policy's own action scale (SAC, TQC, TD3 squash to [-1, 1]:
``scale_action``; PPO acts with its Gaussian mean), minimised with Adam on
the network that outputs the action (the ``actor`` of off-policy algorithms,
the whole policy of on-policy ones). For a discrete action space (the
sweeper's MaskablePPO) the loss is the cross-entropy of the teacher's action
under the policy's distribution (its mean negative log-probability; the mask
is not applied: the teacher never takes a masked action, and the unmasked
loss only also moves probability off masked actions, which the mask at
acting time removes anyway). The result is a starting point for RL
fine-tuning (``model.learn``): the "from demonstrations" agents (``demonstrations``
in a config block).
"""

from __future__ import annotations

from typing import Any

import numpy as np
import torch
from gymnasium import spaces
from stable_baselines3.common.base_class import BaseAlgorithm


def behaviour_clone(
    model: BaseAlgorithm,
    observations: Any,
    actions: np.ndarray,
    epochs: int = 20,
    batch_size: int = 256,
    learning_rate: float = 1e-3,
    seed: int = 0,
) -> list[float]:
    """Fit ``model``'s policy to ``(observations, actions)``; the mean loss of each epoch.

    ``observations``: an array (n, ...) or a dict of them (Dict spaces), as
    :func:`motiongym.agents.integrations.dataset.transitions` returns; ``actions`` (n, k),
    or (n,) or (n, 1) integers for a discrete action space.
    """
    policy: Any = model.policy  # an actor-critic's (get_distribution) or an actor's (actor)
    n = len(actions)
    count = len(next(iter(observations.values()))) if isinstance(observations, dict) else None
    if (count if count is not None else len(observations)) != n or n == 0:
        raise ValueError(f"observations and actions must have the same length >= 1, got {n}")
    discrete = isinstance(policy.action_space, spaces.Discrete)
    if discrete:
        target = torch.as_tensor(np.asarray(actions).reshape(-1), dtype=torch.long)
    else:
        scaled = policy.scale_action(actions) if policy.squash_output else np.asarray(actions)
        target = torch.as_tensor(scaled, dtype=torch.float32)
    network = getattr(policy, "actor", policy)
    optimizer = torch.optim.Adam(network.parameters(), lr=learning_rate)
    rng = np.random.default_rng(seed)
    policy.set_training_mode(True)
    history = []
    for _ in range(epochs):
        order = rng.permutation(n)
        losses = []
        for start in range(0, n, batch_size):
            rows = order[start : start + batch_size]
            batch = (
                {k: v[rows] for k, v in observations.items()}
                if isinstance(observations, dict)
                else observations[rows]
            )
            obs_tensor, _ = policy.obs_to_tensor(batch)
            if discrete:
                loss = -policy.get_distribution(obs_tensor).log_prob(target[rows]).mean()
            else:
                loss = torch.nn.functional.mse_loss(policy._predict(obs_tensor, True), target[rows])
            optimizer.zero_grad()
            loss.backward()
            optimizer.step()
            losses.append(loss.item())
        history.append(float(np.mean(losses)))
    policy.set_training_mode(False)
    return history
