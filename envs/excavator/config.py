"""One documented 20-tonne-class backhoe excavator: the paper's Table 1 filled in.

The paper's link lengths are in its Fig. 3, which the text does not carry.
We use a machine of the 20 t class, the
most common crawler excavator, with numbers rounded from public spec sheets
of that class (Caterpillar 320 / Komatsu PC210 / Volvo EC220 brochures):

* boom 5.7 m (the "reach boom"), stick 2.9 m, bucket pin-to-tip 1.5 m; the
  bent boom is modelled as its straight pin-to-pin line, as in Vähä and
  Skibniewski (1993), the paper's kinematic reference;
* boom-foot pin about 2.0 m above the ground, 0.15 m ahead of the swing axis
  (``L1``), swing axis on the track centre (``L0 = 0``), boom centred (``d2 = 0``);
  this gives a maximum ground-level reach of 10.05 m (joint limits ignored;
  9.7 m within them), a maximum digging depth of 6.7 m and a cutting height
  of 10.5 m, close to the spec-sheet values of the class (9.9 m, 6.7 m,
  9.5 m);
* joint ranges chosen to reproduce those envelopes (boom -50 deg to +69 deg
  from horizontal, stick folded 30 deg to 155 deg under the boom, bucket
  rotation 183 deg);
* hydraulic joint-rate limits: swing 11 rpm (1.15 rad/s, spec sheets give
  11-12 rpm); boom, stick and bucket rates from the cylinder speeds behind the
  class's typical 2.5-3.5 s single-function times (0.6, 0.7, 1.0 rad/s);
* bucket 1.0 m3 heaped (ISO 7451), 1.2 m cutting width; digging forces at the
  bucket tip: bucket breakout 140 kN, stick crowd 100 kN (ISO 6015 figures of
  the class); we use the smaller one as the force available to drag the tip;
* soil: a medium loam, unit weight 18 kN/m3, cohesion 10 kPa, with the
  factors of the fundamental earthmoving equation (see :mod:`.soil`).

Everything else reads these numbers from :data:`DEFAULT_MACHINE`, so a
different machine is one new instance.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, fields

import numpy as np

from motiongym.envs.core import ArgumentError, check_float, check_shape


@dataclass(frozen=True)
class Machine:
    """Link table (paper Table 1, Craig's modified DH), limits and bucket.

    Lengths in m, angles in rad, rates in rad/s, volumes in m3, forces in N.
    """

    # Table 1: a0 = -L0, d1 (row 1 of T_1^M), a1 = L1, d2, a2 = L2, a3 = L3, L4.
    L0: float = 0.0  # swing axis offset from the base origin along x_M (m)
    d1: float = 2.0  # boom-foot pin height above the ground (m)
    L1: float = 0.15  # swing axis to boom-foot pin (m)
    d2: float = 0.0  # lateral offset of the boom plane (m)
    L2: float = 5.7  # boom, pin to pin (m)
    L3: float = 2.9  # stick, pin to pin (m)
    L4: float = 1.5  # bucket pin to cutting edge (m)
    # Joint limits (theta1 swing, theta2 boom, theta3 stick, theta4 bucket).
    q_min: tuple[float, float, float, float] = (-math.pi, -0.87, -2.7, -2.3)
    q_max: tuple[float, float, float, float] = (math.pi, 1.2, -0.52, 0.9)
    rate_max: tuple[float, float, float, float] = (1.15, 0.6, 0.7, 1.0)
    # Rest: bucket lowered to the ground 4.4 m out (the IK's start, as in the paper).
    q_rest: tuple[float, float, float, float] = (0.0, 0.3, -1.8, -1.2)
    # Ready: bucket curled and raised 2 m (where an episode starts).
    q_ready: tuple[float, float, float, float] = (0.0, 0.6, -1.9, -1.6)
    # Capsule radii of the links for clearance (boom, stick, bucket shell).
    link_radius: tuple[float, float, float] = (0.35, 0.25, 0.45)
    bucket_capacity: float = 1.0  # m3, heaped
    bucket_width: float = 1.2  # m, cutting edge
    dig_force: float = 100e3  # N, stick crowd force available at the tip
    # Soil (fundamental earthmoving equation, simplified; see soil.py).
    soil_unit_weight: float = 18e3  # N/m3
    soil_cohesion: float = 10e3  # Pa
    n_gamma: float = 1.5  # weight factor (Reece charts, rake ~45 deg, phi ~30 deg)
    n_c: float = 2.5  # cohesion factor
    min_speed_fraction: float = 0.05  # the tip never locks completely (v0 soil only)
    # Physics v1 (see hydraulics.py and digging.py).
    accel_max: tuple[float, float, float, float] = (0.6, 1.5, 1.75, 2.5)  # rad/s2
    pump_share: tuple[float, float, float, float] = (0.45, 0.95, 0.95, 0.45)
    swell: float = 1.25  # loose / bank volume (common earth, loam)

    def __post_init__(self) -> None:
        """Every field checked (``machine.<name>`` in the message); see :data:`LIMITS`."""
        for f in fields(self):
            name, value = f"machine.{f.name}", getattr(self, f.name)
            lo, hi, size = LIMITS[f.name]
            if size == 0:
                object.__setattr__(self, f.name, check_float(name, value, lo, hi))
                continue
            a = check_shape(name, value, (size,))
            if not ((a >= lo) & (a <= hi)).all():
                raise ArgumentError(f"{name} must be {size} numbers in [{lo}, {hi}], got {value!r}")
            object.__setattr__(self, f.name, tuple(float(v) for v in a))
        if any(lo >= hi for lo, hi in zip(self.q_min, self.q_max, strict=True)):
            raise ArgumentError(
                f"machine.q_min must be below machine.q_max joint by joint, got {self.q_min!r} "
                f"and {self.q_max!r}"
            )

    @property
    def dh(self) -> np.ndarray:
        """Modified-DH rows ``(alpha_{i-1}, a_{i-1}, d_i)`` for i = 1..4, shape (4, 3)."""
        return np.array(
            [
                [0.0, -self.L0, self.d1],
                [math.pi / 2, self.L1, self.d2],
                [0.0, self.L2, 0.0],
                [0.0, self.L3, 0.0],
            ]
        )

    @property
    def reach(self) -> float:
        """Maximum ground-level reach of the tip from the swing axis (m), joint limits ignored."""
        arm = self.L2 + self.L3 + self.L4
        return self.L1 + math.sqrt(max(arm**2 - self.d1**2, 0.0))

    def as_dict(self) -> dict:
        """Plain numbers, for reports."""
        return {
            "L0": self.L0,
            "d1": self.d1,
            "L1": self.L1,
            "d2": self.d2,
            "L2": self.L2,
            "L3": self.L3,
            "L4": self.L4,
            "q_min": list(self.q_min),
            "q_max": list(self.q_max),
            "rate_max": list(self.rate_max),
            "bucket_capacity": self.bucket_capacity,
            "bucket_width": self.bucket_width,
            "dig_force": self.dig_force,
        }


# (low, high, size) per field: size 0 is a scalar; lengths bounded to keep the
# machine on the 25 m x 22 m ground map, radii and forces positive.
LIMITS: dict[str, tuple[float, float, int]] = {
    "L0": (-5.0, 5.0, 0),
    "d1": (0.0, 5.0, 0),
    "L1": (-2.0, 2.0, 0),
    "d2": (-2.0, 2.0, 0),
    "L2": (0.5, 10.0, 0),
    "L3": (0.5, 10.0, 0),
    "L4": (0.3, 3.0, 0),
    "q_min": (-math.pi, math.pi, 4),
    "q_max": (-math.pi, math.pi, 4),
    "rate_max": (1e-3, 5.0, 4),
    "q_rest": (-math.pi, math.pi, 4),
    "q_ready": (-math.pi, math.pi, 4),
    "link_radius": (0.01, 1.5, 3),
    "bucket_capacity": (0.05, 10.0, 0),
    "bucket_width": (0.1, 4.0, 0),
    "dig_force": (1.0, 1e7, 0),
    "soil_unit_weight": (1.0, 1e6, 0),
    "soil_cohesion": (0.0, 1e7, 0),
    "n_gamma": (0.0, 100.0, 0),
    "n_c": (0.0, 100.0, 0),
    "min_speed_fraction": (0.0, 1.0, 0),
    "accel_max": (1e-3, 100.0, 4),
    "pump_share": (0.0, 4.0, 4),
    "swell": (1.0, 2.0, 0),
}

DEFAULT_MACHINE = Machine()


def machine_from_kwargs(machine: dict | Machine | None) -> Machine:
    """A :class:`Machine` from ``None`` (the default), an instance, or overrides."""
    if machine is None:
        return DEFAULT_MACHINE
    if isinstance(machine, Machine):
        return machine
    if not isinstance(machine, dict):
        raise ArgumentError(
            f"machine must be None, a dict of overrides or a Machine, got {machine!r}"
        )
    valid = set(Machine.__dataclass_fields__)
    unknown = sorted(set(machine) - valid, key=str)
    if unknown:
        raise ArgumentError(f"unknown machine parameter(s) {unknown}; valid: {sorted(valid)}")
    return Machine(**machine)
