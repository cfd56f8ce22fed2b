"""Soil interaction of physics v1: which bucket motions cut, and what they cost.

Cutting (the bucket's cutting edge and the soil ahead of it)
    A backhoe bucket cuts with its edge moving forward into the soil with the
    opening ahead: the edge's motion ``v`` must lie within
    ``CUT_CONE`` (60 deg) of the opening's normal ``n`` (Hemami 1994,
    "Fundamentals of excavation"; Zelenin et al. 1985, cutting as the blade
    advancing along its face). Any other motion of the edge into the ground -
    heel first, sideways, a curled bucket plunged - meets the bucket's back
    or side plates, which do not cut: the soil stops it (the edge may not go
    deeper than it already is). A cut lowers the swept cells to the edge
    (:meth:`.soil.Terrain.carve`).

Resistance (the fundamental earthmoving equation)
    Reece (1964), McKyes (1985, "Soil cutting and tillage", ch. 4):
    ``F = w (gamma d^2 N_gamma + c d N_c + q d N_q)`` for an edge of width
    ``w`` at depth of cut ``d``; without surcharge ``q`` and with ``N_gamma``,
    ``N_c`` of one soil and rake (:func:`.soil.cutting_force`). The cut area
    is ``w d``, so the force grows with depth and area. The machine's
    digging force ``F_dig`` (stick crowd, 100 kN for the class) is a load the
    hydraulics can just hold: a function's speed falls linearly with its load
    (the pressure-flow line of a pressure-compensated pump at its power
    limit), so the step advances the fraction ``1 - F / F_dig`` (0 at and
    beyond the stall depth, 1.35 m for the default loam and a 1.2 m bucket),
    with no creep floor: the soil stops the machine.

Bucket, swell and a full bucket
    Bank soil swells when cut: the bucket and the truck hold loose volume,
    ``loose = swell * bank`` (swell 1.25, common earth / loam: Caterpillar
    Performance Handbook, table "Approximate material characteristics"); the
    rated 1.0 m3 is heaped (loose). A bucket without room left still cuts,
    but what it cannot hold is pushed ahead of the edge (deposited ``PUSH``
    ahead along the opening's horizontal direction) instead of vanishing.
    Soil is conserved: ``terrain volume + (fill + truck soil) / swell`` is
    constant to round-off (spilled soil returns to the ground as bank volume).
"""

from __future__ import annotations

import math

CUT_CONE = math.cos(math.radians(60.0))  # cos of the widest angle between motion and opening
PUSH = 0.8  # m: where a full bucket's surplus lands ahead of the edge
DEPTH_TOLERANCE = 0.02  # m: one fifth of a cell: what carving leaves under the edge


def cuts(v, n) -> bool:
    """Whether the edge moving by ``v`` cuts: within :data:`CUT_CONE` of the opening ``n``."""
    speed = math.sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2])
    if speed < 1e-9:
        return False
    return v[0] * n[0] + v[1] * n[1] + v[2] * n[2] >= CUT_CONE * speed


def stall_fraction(force: float, dig_force: float) -> float:
    """Fraction of a step the hydraulics advance against ``force`` (N): ``1 - F / F_dig``."""
    return max(0.0, 1.0 - force / dig_force)
