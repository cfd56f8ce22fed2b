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
    """Joint rates (rad/s) after the pump-flow and acceleration limits (see the module).

    Written out for the four functions: a step calls it once.
    """
    (r0, r1, r2, r3), (s0, s1, s2, s3) = m.rate_max, m.pump_share
    v0, v1, v2, v3 = values
    c0 = (1.0 if v0 > 1.0 else -1.0 if v0 < -1.0 else v0) * r0
    c1 = (1.0 if v1 > 1.0 else -1.0 if v1 < -1.0 else v1) * r1
    c2 = (1.0 if v2 > 1.0 else -1.0 if v2 < -1.0 else v2) * r2
    c3 = (1.0 if v3 > 1.0 else -1.0 if v3 < -1.0 else v3) * r3
    demand = sum((abs(c0) / r0 * s0, abs(c1) / r1 * s1, abs(c2) / r2 * s2, abs(c3) / r3 * s3))
    if demand > 1.0:
        c0, c1, c2, c3 = c0 / demand, c1 / demand, c2 / demand, c3 / demand
    (a0, a1, a2, a3), (w0, w1, w2, w3) = m.accel_max, qdot
    a0, a1, a2, a3 = a0 * dt, a1 * dt, a2 * dt, a3 * dt  # the most change of a rate
    return [
        w0 + a0 if c0 - w0 > a0 else w0 - a0 if w0 - c0 > a0 else c0,
        w1 + a1 if c1 - w1 > a1 else w1 - a1 if w1 - c1 > a1 else c1,
        w2 + a2 if c2 - w2 > a2 else w2 - a2 if w2 - c2 > a2 else c2,
        w3 + a3 if c3 - w3 > a3 else w3 - a3 if w3 - c3 > a3 else c3,
    ]
