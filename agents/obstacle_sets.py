"""A features extractor for the harvest arm that treats the obstacles as a set.

The potential field the arm's teacher follows (Ryu et al., eq. 5-11;
:mod:`motiongym.baselines.harvest_arm`) is a *sum of per-obstacle terms*:
each obstacle pushes the gripper (eq. 5, 7) and the closest point of each
link (eq. 9-10) away from it by the same function of their relative
geometry, whatever slot of the observation it sits in. A flat network over
the concatenated slots must learn that function once per slot and per link
from the scenes it is shown. :class:`HarvestObstacleSet` builds the sum's
structure in (Deep Sets, Zaheer et al. 2017, "Deep Sets", NeurIPS, Theorem 2:
``rho(sum_k phi(x_k))``):

* **link-obstacle pairs** ``(l, k)``: link ``l`` is the segment of joint
  points ``p_l p_{l+1}``, obstacle ``k`` the segment ``a_k b_k`` (a sphere
  has ``a = b``). Their closest points (Ericson's clamped segment-segment
  solution, :func:`closest_points`) give the vector ``w`` from the
  obstacle's closest point to the link's (the direction eq. 9 pushes the
  link's control point), its parameter ``s`` in [0, 1] along the link (where
  the control point lies), the observed surface clearance (``distances``),
  the obstacle's radius and bar flag. One network ``phi_link``, shared by
  every pair, maps these; per link, the results are pooled over the present
  obstacles (masked sum and max): ``(L, 2 h)``, kept in link order (a link's
  push moves the joints through its own Jacobian).
* **gripper-obstacle terms** ``k`` (eq. 5, 7's field at the gripper): the
  vector from the obstacle's closest point to the gripper, its surface
  clearance, the radius, the bar flag and the unit direction to the fruit
  (the virtual plane of the field is normal to it); ``phi_gripper``,
  pooled the same way: ``2 h``.
* **the arm and the target**: ``sin_q``, ``cos_q``, the joint points
  relative to the base, the unit direction gripper -> fruit and its
  distance (eq. 7's field sets the gripper's speed by the direction alone,
  except in the last control period).

The joint rates ``qdot`` are not read: the teacher's action is a function
of the pose and the scene alone (its ``markov`` form), so the rates can
only offer the copycat shortcut. Lengths are divided by ``LENGTH_SCALE``
(obstacles act within 0.2 m, Table 1's ``rho0``) so that inputs are of
order one; the extractor reads the raw observation (a block with
``normalize: false``): per-entry statistics would break the differences.

Every slice is read by name from the environment's own
:class:`motiongym.envs.harvest_arm.observation.ObservationLayout`, built from
the same keyword arguments as the environment (``planar``, ``dof``,
``n_obstacles``). The output is invariant to the order of the obstacle slots
(tested), and empty slots (``mask`` 0) do not count.
"""

from __future__ import annotations

import torch
from gymnasium import spaces
from stable_baselines3.common.torch_layers import BaseFeaturesExtractor
from torch import nn

from motiongym.envs.harvest_arm.model import ArmKinematics
from motiongym.envs.harvest_arm.observation import ObservationLayout
from motiongym.envs.harvest_arm.params import HarvestArmParams

LENGTH_SCALE = 0.1  # m, lengths enter the networks in decimetres
_EPS = 1e-9


def _dot(x: torch.Tensor, y: torch.Tensor) -> torch.Tensor:
    return (x * y).sum(-1)


def closest_points(
    p0: torch.Tensor, p1: torch.Tensor, q0: torch.Tensor, q1: torch.Tensor
) -> tuple[torch.Tensor, torch.Tensor, torch.Tensor]:
    """Closest points of segments ``p0 p1`` and ``q0 q1`` (broadcast ``(..., dim)``).

    The torch form of :func:`motiongym.envs.geometry.closest_points_between_segments`
    (Ericson 2005, section 5.1.9, degenerate cases folded in; equal to it to
    rounding, tested). Returns ``(s, on_p, on_q)``: the parameter along
    ``p0 p1`` (``...``) and the two points (``..., dim``).
    """
    d1, d2, r = p1 - p0, q1 - q0, p0 - q0
    a = _dot(d1, d1).clamp_min(_EPS)
    e = _dot(d2, d2).clamp_min(_EPS)
    b, c, f = _dot(d1, d2), _dot(d1, r), _dot(d2, r)
    denom = a * e - b * b
    parallel = denom <= _EPS * a * e
    s = torch.where(parallel, -c * e, b * f - c * e) / torch.where(parallel, a * e, denom)
    s = s.clamp(0.0, 1.0)
    t = (b * s + f) / e
    clamped = t.clamp(0.0, 1.0)
    s = torch.where(t == clamped, s, ((b * clamped - c) / a).clamp(0.0, 1.0))
    return s, p0 + s[..., None] * d1, q0 + clamped[..., None] * d2


def _mlp(n_in: int, hidden: int) -> nn.Sequential:
    return nn.Sequential(nn.Linear(n_in, hidden), nn.ReLU(), nn.Linear(hidden, hidden), nn.ReLU())


def _pool(values: torch.Tensor, mask: torch.Tensor) -> torch.Tensor:
    """Masked sum and max over the obstacle axis -2: ``(..., K, h) -> (..., 2 h)``.

    ``mask`` ``(..., K)`` (1 present); with no obstacle present both are 0.
    """
    m = mask[..., None]
    total = (values * m).sum(-2)
    most = values.masked_fill(m == 0, float("-inf")).amax(-2)
    most = torch.where(torch.isfinite(most), most, torch.zeros_like(most))
    return torch.cat([total, most], -1)


class HarvestObstacleSet(BaseFeaturesExtractor):
    """The harvest arm's observation through per-obstacle networks pooled over the slots.

    Args:
        observation_space: the environment's Box (its shape is checked against
            the layout of ``planar``, ``dof``, ``n_obstacles``).
        planar, dof, n_obstacles: the environment's keyword arguments of the same
            names (None: the variant's default, as the environment).
        hidden: width ``h`` of the shared per-obstacle networks (two ReLU layers).
        features_dim: output width (a ReLU layer over the pooled and the arm's features).
    """

    def __init__(
        self,
        observation_space: spaces.Box,
        planar: bool = False,
        dof: int | None = None,
        n_obstacles: int | None = None,
        hidden: int = 64,
        features_dim: int = 256,
    ) -> None:
        params = HarvestArmParams(dof=dof, planar=planar, n_obstacles=n_obstacles)  # type: ignore[arg-type]
        arm = params.arm
        n_points = ArmKinematics(arm, params.link_radius, params.dt).n_points
        layout = ObservationLayout(arm.dof, arm.dim, n_points, params.n_obstacles)
        if observation_space.shape != (layout.size,):
            raise ValueError(
                f"observation_space must be the harvest arm's observation for planar={planar}, "
                f"dof={arm.dof}, n_obstacles={params.n_obstacles} (shape ({layout.size},)), "
                f"got shape {observation_space.shape}; pass the environment's keyword arguments"
            )
        if not isinstance(hidden, int) or hidden < 1:
            raise ValueError(f"hidden must be a positive integer, got {hidden!r}")
        if not isinstance(features_dim, int) or features_dim < 1:
            raise ValueError(f"features_dim must be a positive integer, got {features_dim!r}")
        super().__init__(observation_space, features_dim)
        self.layout = layout
        self.slices = layout.slices
        d, n, L = arm.dim, arm.dof, layout.n_links
        self.dim, self.n_points, self.n_slots = d, n_points, params.n_obstacles
        self.phi_link = _mlp(d + 4 + 1, hidden)  # w, s, clearance, radius, is_bar; + |w|
        self.phi_gripper = _mlp(2 * d + 4, hidden)  # g - c, fruit direction, rho, r, bar, |g - c|
        n_arm = 2 * n + (n_points - 1) * d + d + 1
        self.head = nn.Sequential(
            nn.Linear(L * 2 * hidden + 2 * hidden + n_arm, features_dim), nn.ReLU()
        )

    def parse(self, observations: torch.Tensor) -> dict[str, torch.Tensor]:
        """Named, shaped views of a batch ``(B, size)`` (the layout's names)."""
        s, d, K = self.slices, self.dim, self.n_slots
        obstacles = observations[:, s["obstacles"]].reshape(-1, K, self.layout.obstacle_width)
        return {
            "sin_q": observations[:, s["sin_q"]],
            "cos_q": observations[:, s["cos_q"]],
            "points": observations[:, s["points"]].reshape(-1, self.n_points, d),
            "fruit_error": observations[:, s["fruit_error"]],
            "a": obstacles[..., :d],
            "b": obstacles[..., d : 2 * d],
            "radius": obstacles[..., 2 * d],
            "is_bar": obstacles[..., 2 * d + 1],
            "mask": observations[:, s["mask"]],
            "distances": observations[:, s["distances"]].reshape(-1, self.layout.n_links, K),
        }

    def forward(self, observations: torch.Tensor) -> torch.Tensor:
        o = self.parse(observations)
        points, a, b, mask = o["points"], o["a"], o["b"], o["mask"]  # (B,P,d) (B,K,d) (B,K)
        radius, bar = o["radius"] / LENGTH_SCALE, o["is_bar"]  # (B, K)
        # link-obstacle pairs (B, L, K, .)
        s, on_link, on_obstacle = closest_points(
            points[:, :-1, None], points[:, 1:, None], a[:, None], b[:, None]
        )
        w = (on_link - on_obstacle) / LENGTH_SCALE  # (B, L, K, d)
        L = w.shape[1]
        pairs = torch.cat(
            [
                w,
                w.norm(dim=-1, keepdim=True),
                s[..., None],
                o["distances"][..., None] / LENGTH_SCALE,
                radius[:, None, :, None].expand(-1, L, -1, -1),
                bar[:, None, :, None].expand(-1, L, -1, -1),
            ],
            -1,
        )
        links = _pool(self.phi_link(pairs), mask[:, None, :]).flatten(1)  # (B, L * 2h)
        # gripper-obstacle terms (B, K, .)
        gripper = points[:, -1]
        error = o["fruit_error"]
        distance = error.norm(dim=-1, keepdim=True)  # (B, 1) m
        direction = error / distance.clamp_min(_EPS)
        _, _, c = closest_points(gripper[:, None], gripper[:, None], a, b)
        g = (gripper[:, None] - c) / LENGTH_SCALE  # (B, K, d)
        g_norm = g.norm(dim=-1)
        terms = torch.cat(
            [
                g,
                direction[:, None].expand_as(g),
                (g_norm - radius)[..., None],
                g_norm[..., None],
                radius[..., None],
                bar[..., None],
            ],
            -1,
        )
        grip = _pool(self.phi_gripper(terms), mask)  # (B, 2h)
        arm = torch.cat(
            [
                o["sin_q"],
                o["cos_q"],
                ((points[:, 1:] - points[:, :1]) / LENGTH_SCALE).flatten(1),
                direction,
                distance / LENGTH_SCALE,
            ],
            -1,
        )
        return self.head(torch.cat([links, grip, arm], -1))
