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
  link's control point), its unit direction and length, its parameter ``s``
  in [0, 1] along the link (where the control point lies), the observed
  surface clearance (``distances``), the obstacle's radius and bar flag. One
  network ``phi_link``, shared by every pair, maps these; per link, the
  results are pooled over the present obstacles (masked sum and max):
  ``(L, 2 h)``, kept in link order (a link's push moves the joints through
  its own Jacobian).
* **gripper-obstacle terms** ``k`` (eq. 5, 7's field at the gripper): the
  vector from the obstacle's closest point to the gripper, its unit
  direction and length, the surface clearance ``rho``, the radius, the bar
  flag and the unit direction to the fruit (the virtual plane of the field
  is normal to it); ``phi_gripper``, pooled the same way: ``2 h``.
* **the arm and the target**: ``sin_q``, ``cos_q``, the joint points
  relative to the base, the unit direction gripper -> fruit and its
  distance (eq. 7's field sets the gripper's speed by the direction alone,
  except in the last control period).

Clearances also enter as ``exp(-clearance / s)`` for ``s`` in
:data:`RADIAL_SCALES` (1, 3, 10 cm): eq. 5's push grows as ``1 / rho^3``
inside 20 cm, a steepness that ReLU layers fed the clearance alone resolve
poorly. With ``waist_frame`` (default) every vector is expressed in the
frame of the first joint, which turns about z through the origin on both
arms, and ``q_0`` is dropped: scenes that differ by a turn about z are one
input.

Every slice is read by name from the environment's own
:func:`motiongym.envs.harvest_arm.observation.layout_for`, built from
the same keyword arguments as the environment (``planar``, ``dof``,
``n_obstacles``). The output is invariant to the order of the obstacle slots
(tested), and empty slots (``mask`` 0) do not count.
"""

from __future__ import annotations

import torch
from gymnasium import spaces
from stable_baselines3.common.torch_layers import BaseFeaturesExtractor
from torch import nn

from motiongym.envs.harvest_arm.observation import layout_for, obstacle_width, point_count
from motiongym.envs.harvest_arm.params import HarvestArmParams

LENGTH_SCALE = 0.1  # m, lengths enter the networks in decimetres
RADIAL_SCALES = (0.01, 0.03, 0.1)  # m, clearances also enter as exp(-clearance / s)
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


def _turn(v: torch.Tensor, c: torch.Tensor, s: torch.Tensor) -> torch.Tensor:
    """``(B, ..., dim)`` vectors turned about z by the angle of cosine ``c``, sine ``s`` (B,)."""
    shape = (-1,) + (1,) * (v.dim() - 2)
    c, s = c.reshape(shape), s.reshape(shape)
    x, y = v[..., 0], v[..., 1]
    return torch.cat([torch.stack([c * x - s * y, s * x + c * y], -1), v[..., 2:]], -1)


def _radial(clearance: torch.Tensor) -> torch.Tensor:
    """``(..., 1) -> (..., len(RADIAL_SCALES))``: ``exp(-max(clearance, 0) / s)`` per scale."""
    c = clearance.clamp_min(0.0)
    return torch.cat([torch.exp(-c / s) for s in RADIAL_SCALES], -1)


class HarvestObstacleSet(BaseFeaturesExtractor):
    """The harvest arm's observation through per-obstacle networks pooled over the slots.

    Args:
        observation_space: the environment's Box (its shape is checked against
            the layout of ``planar``, ``dof``, ``n_obstacles``).
        planar, dof, n_obstacles: the environment's keyword arguments of the same
            names (None: the variant's default, as the environment).
        hidden: width ``h`` of the shared per-obstacle networks (two ReLU layers).
        features_dim: output width (a ReLU layer over the pooled and the arm's features).
        waist_frame: express every vector in the frame of the first joint (turned by
            ``-q_0`` about z; both arms' first joint turns about z through the origin)
            and drop ``q_0`` from the inputs. A scene turned about z with the arm is
            then the same input; the teacher's field turns with it (its fixed sides
            are built from z), except at the waist's joint limit.
    """

    def __init__(
        self,
        observation_space: spaces.Box,
        planar: bool = False,
        dof: int | None = None,
        n_obstacles: int | None = None,
        hidden: int = 32,
        features_dim: int = 256,
        waist_frame: bool = True,
    ) -> None:
        params = HarvestArmParams(dof=dof, planar=planar, n_obstacles=n_obstacles)  # type: ignore[arg-type]
        arm = params.arm
        layout, n_points = layout_for(params), point_count(arm)
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
        if not isinstance(waist_frame, bool):
            raise ValueError(f"waist_frame must be true or false, got {waist_frame!r}")
        super().__init__(observation_space, features_dim)
        self.layout, self.slices, self.waist_frame = layout, layout.slices, waist_frame
        self.link_radius = params.link_radius
        d, n, L, R = arm.dim, arm.dof, n_points - 1, len(RADIAL_SCALES)
        self.dim, self.n_points, self.n_slots = d, n_points, params.n_obstacles
        # w, w / |w|, |w|, s, clearance, radial(clearance), radius, is_bar
        self.phi_link = _mlp(2 * d + 5 + R, hidden)
        # g, g / |g|, fruit direction, |g|, rho, radial(rho), radius, is_bar
        self.phi_gripper = _mlp(3 * d + 4 + R, hidden)
        n_angles = n - 1 if waist_frame else n
        n_arm = 2 * n_angles + (n_points - 1) * d + d + 1
        self.head = nn.Sequential(
            nn.Linear(L * 2 * hidden + 2 * hidden + n_arm, features_dim), nn.ReLU()
        )

    def parse(self, observations: torch.Tensor) -> dict[str, torch.Tensor]:
        """Named, shaped views of a batch ``(B, size)`` (the layout's names), in the world
        frame (not turned)."""
        s, d, K = self.slices, self.dim, self.n_slots
        obstacles = observations[:, s["obstacles"]].reshape(-1, K, obstacle_width(d))
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
            "distances": observations[:, s["distances"]].reshape(-1, self.n_points - 1, K),
        }

    def forward(self, observations: torch.Tensor) -> torch.Tensor:
        o = self.parse(observations)
        sin_q, cos_q = o["sin_q"], o["cos_q"]
        if self.waist_frame:  # turn by -q_0
            c, s = cos_q[:, 0], -sin_q[:, 0]
            for key in ("points", "a", "b", "fruit_error"):
                o[key] = _turn(o[key], c, s)
            sin_q, cos_q = sin_q[:, 1:], cos_q[:, 1:]
        points, a, b, mask = o["points"], o["a"], o["b"], o["mask"]  # (B,P,d) (B,K,d) (B,K)
        radius, bar = o["radius"][..., None], o["is_bar"][..., None]  # (B, K, 1) m, -
        # link-obstacle pairs (B, L, K, .)
        s_link, on_link, on_obstacle = closest_points(
            points[:, :-1, None], points[:, 1:, None], a[:, None], b[:, None]
        )
        w = on_link - on_obstacle  # (B, L, K, d) m
        w_norm = w.norm(dim=-1, keepdim=True)
        clearance = o["distances"][..., None]  # (B, L, K, 1) m
        L = w.shape[1]
        pairs = torch.cat(
            [
                w / LENGTH_SCALE,
                w / w_norm.clamp_min(_EPS),
                w_norm / LENGTH_SCALE,
                s_link[..., None],
                clearance / LENGTH_SCALE,
                _radial(clearance),
                radius[:, None].expand(-1, L, -1, -1) / LENGTH_SCALE,
                bar[:, None].expand(-1, L, -1, -1),
            ],
            -1,
        )
        links = _pool(self.phi_link(pairs), mask[:, None, :]).flatten(1)  # (B, L * 2h)
        # gripper-obstacle terms (B, K, .)
        gripper = points[:, -1]
        error = o["fruit_error"]
        distance = error.norm(dim=-1, keepdim=True)  # (B, 1) m
        direction = error / distance.clamp_min(_EPS)
        _, _, c_obstacle = closest_points(gripper[:, None], gripper[:, None], a, b)
        g = gripper[:, None] - c_obstacle  # (B, K, d) m
        g_norm = g.norm(dim=-1, keepdim=True)
        rho = g_norm - radius - self.link_radius  # (B, K, 1) m, eq. 5's surface clearance
        terms = torch.cat(
            [
                g / LENGTH_SCALE,
                g / g_norm.clamp_min(_EPS),
                direction[:, None].expand_as(g),
                g_norm / LENGTH_SCALE,
                rho / LENGTH_SCALE,
                _radial(rho),
                radius / LENGTH_SCALE,
                bar,
            ],
            -1,
        )
        grip = _pool(self.phi_gripper(terms), mask)  # (B, 2h)
        arm = torch.cat(
            [
                sin_q,
                cos_q,
                ((points[:, 1:] - points[:, :1]) / LENGTH_SCALE).flatten(1),
                direction,
                distance / LENGTH_SCALE,
            ],
            -1,
        )
        return self.head(torch.cat([links, grip, arm], -1))


# Names a config may give ``features_extractor_class`` -> the class.
FEATURES_EXTRACTORS: dict[str, type[BaseFeaturesExtractor]] = {
    "harvest_obstacle_set": HarvestObstacleSet,
}
