"""Hydraulics of physics v1: a rate and an acceleration limit per function, one pump.

The four functions (swing motor; boom, stick and bucket cylinders) draw on
the main pumps of a 20 t machine: two variable pumps of about 215 L/min each,
430 L/min in all (Cat 320 / Komatsu PC210 class spec sheets: "main system
maximum flow" 2 x 210-220 L/min). At full rate a function draws the share
``pump_share`` of that flow: the boom and the stick are served by both pumps
(flow summation, 0.95 of the total at full rate), the swing and the bucket by
one (0.45). Per step:

1. commanded rates ``c_k = clip(a_k, -1, 1) * rate_max_k``;
2. shared flow: when ``D = sum_k |c_k| / rate_max_k * pump_share_k`` exceeds 1
   the pump cannot feed every function at once and every rate is scaled by
   ``1 / D`` (flow divides in proportion to demand);
3. acceleration: the rate moves toward ``c_k`` by at most ``accel_max_k dt``
   (valve opening and pressure build-up; the swing by its torque over the
   house's inertia: about 62 kNm over 1e5 kg m2 with the arm out, 0.6 rad/s2;
   boom, stick, bucket reach full rate in 0.4 s).

The numbers are :class:`Machine` fields (``accel_max``, ``pump_share``), so a
different machine is one override.
"""

from __future__ import annotations


def hydraulic_rates(values, qdot, m, dt: float) -> list[float]:
    """Joint rates (rad/s) after the pump-flow and acceleration limits (see the module)."""
    rate_max = m.rate_max
    cmd = [
        (1.0 if v > 1.0 else -1.0 if v < -1.0 else v) * r
        for v, r in zip(values, rate_max, strict=True)
    ]
    demand = sum([abs(c) / r * s for c, r, s in zip(cmd, rate_max, m.pump_share, strict=True)])
    if demand > 1.0:
        cmd = [c / demand for c in cmd]
    out = []
    for c, w, a in zip(cmd, qdot, m.accel_max, strict=True):
        step = a * dt
        out.append(w + step if c - w > step else w - step if w - c > step else c)
    return out
