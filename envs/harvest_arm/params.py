"""The harvest arm's parameters: one frozen dataclass, validated once.

The environment and the scripted policies build :class:`HarvestArmParams`
from the same keyword arguments (:func:`motiongym.envs.core.params_from_kwargs`),
so every default is written here only.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any, ClassVar

from motiongym.envs.core import (
    RENDER_SIDE,
    ArgumentError,
    Deprecated,
    check_bool,
    check_float,
    check_int,
    check_render_size,
    check_weight,
)
from motiongym.envs.harvest_arm.model import PLANAR_DOFS, SPATIAL_DOFS, ArmSpec, arm_spec

MAX_OBSTACLES = 32  # obstacle slots: L * K explicit contact pairs are evaluated every step
REWARD_TERMS = ("progress", "clearance", "collision", "effort", "success", "distance")


def _int_given(name: str, value: object, bounds: tuple[int, ...], given: str) -> int:
    """``check_int`` over ``bounds[0]..bounds[-1]``, the message also naming the
    argument that set the range (``given``): a default refused because of it."""
    try:
        return check_int(name, value, bounds[0], bounds[-1])
    except ArgumentError as error:
        raise ArgumentError(f"{error} (with {given})") from None


def _side(name: str) -> Any:
    """Deprecated ``width`` / ``height``: that side of ``render_size``, checked under its
    old name (so that a bad value is named as the user wrote it)."""
    column = name == "width"

    def convert(value: Any, current: tuple[int, int]) -> tuple[Any, Any]:
        side = check_int(name, value, *RENDER_SIDE)
        return (current[0], side) if column else (side, current[1])

    return convert


@dataclass(frozen=True)
class HarvestArmParams:
    """Every keyword argument of :class:`~motiongym.envs.harvest_arm.env.HarvestArmEnv`.

    Limits (an :class:`~motiongym.envs.core.ArgumentError` names the argument
    otherwise): ``planar`` a bool; ``dof`` an integer in 3-5 (planar) or 5-7
    (spatial), default 5 / 7; ``n_obstacles`` an integer in [1, 32], default
    8 / 10; ``n_bars`` in [0, n_obstacles], default 0 / 3; ``link_radius`` in
    (0, 0.1] m; ``dt`` in (0, 1] s; ``safety_distance`` in (0, 0.5] m;
    ``success_tolerance`` in (0, 0.2] m; the reward weights magnitudes in
    [0, 1e6] (:func:`~motiongym.envs.core.check_weight`); ``render_size``
    ``(rows, columns)``, each in [16, 2048] pixels.

    Deprecated (warn once, removed in the next release): ``width`` and
    ``height`` (pixels), now ``render_size = (height, width)``.
    """

    # None given: the variant's default (ints after __post_init__)
    dof: int = None  # type: ignore[assignment]
    planar: bool = False
    n_obstacles: int = None  # type: ignore[assignment]
    n_bars: int = None  # type: ignore[assignment]
    link_radius: float = 0.02  # m
    dt: float = 0.05  # s, control period
    safety_distance: float = 0.03  # m, the paper's collision-risk distance
    success_tolerance: float = 0.02  # m, gripper to fruit centre
    terminate_on_collision: bool = True
    self_collision: bool = False
    # reward weights (magnitudes; the env's docstring gives each term's sign)
    progress: float = 10.0  # per m of approach to the fruit
    clearance: float = 1.0
    collision: float = 10.0
    effort: float = 0.01
    success: float = 10.0
    distance: float = 0.0  # per m of gripper-fruit distance, every step
    render_size: tuple[int, int] = (360, 480)  # pixels: rows, columns

    DEPRECATED: ClassVar[dict[str, Deprecated]] = {
        "width": Deprecated("render_size", _side("width"), "use render_size=(height, width)"),
        "height": Deprecated("render_size", _side("height"), "use render_size=(height, width)"),
    }

    def __post_init__(self) -> None:
        planar = check_bool("planar", self.planar)
        dofs = PLANAR_DOFS if planar else SPATIAL_DOFS
        given = f"planar={planar}"
        dof = dofs[-1] if self.dof is None else _int_given("dof", self.dof, dofs, given)
        n_obstacles = (8 if planar else 10) if self.n_obstacles is None else self.n_obstacles
        n_obstacles = check_int("n_obstacles", n_obstacles, 1, MAX_OBSTACLES)
        n_bars = (0 if planar else 3) if self.n_bars is None else self.n_bars
        values = {
            "planar": planar,
            "dof": dof,
            "n_obstacles": n_obstacles,
            "n_bars": _int_given("n_bars", n_bars, (0, n_obstacles), f"n_obstacles={n_obstacles}"),
            "link_radius": check_float("link_radius", self.link_radius, 0.0, 0.1, low_open=True),
            "dt": check_float("dt", self.dt, 0.0, 1.0, low_open=True),
            "safety_distance": check_float(
                "safety_distance", self.safety_distance, 0.0, 0.5, low_open=True
            ),
            "success_tolerance": check_float(
                "success_tolerance", self.success_tolerance, 0.0, 0.2, low_open=True
            ),
            "terminate_on_collision": check_bool(
                "terminate_on_collision", self.terminate_on_collision
            ),
            "self_collision": check_bool("self_collision", self.self_collision),
            "render_size": check_render_size("render_size", self.render_size),
        }
        for term in REWARD_TERMS:
            values[term] = check_weight(term, getattr(self, term))
        for name, value in values.items():
            object.__setattr__(self, name, value)

    @property
    def arm(self) -> ArmSpec:
        """The link table of this arm."""
        return arm_spec(self.dof, self.planar)

    @property
    def weights(self) -> dict[str, float]:
        """The reward weights, in the terms' order."""
        return {term: getattr(self, term) for term in REWARD_TERMS}
