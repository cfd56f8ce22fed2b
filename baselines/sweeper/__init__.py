"""Scripted reference policies for the sweeper world (paper 003, Park & Lee 1998)."""

from __future__ import annotations

_SWEEPER_POLICIES = {
    "psa-cwa": "motiongym.baselines.sweeper.psa_cwa:PsaCwaPolicy",
    "psa-cwa-nearest": "motiongym.baselines.sweeper.psa_cwa:PsaCwaNearestPolicy",
    "wall-follow": "motiongym.baselines.sweeper.wall_follow:WallFollowPolicy",
}
# The same policies on v0 (see-through window) and v1 (line of sight: they keep
# v1's unknown cells unknown until sensed).
POLICIES: dict[str, dict[str, str]] = {
    "motiongym/Sweeper-v0": dict(_SWEEPER_POLICIES),
    "motiongym/Sweeper-v1": {
        **_SWEEPER_POLICIES,
        # a teacher for learned agents (a function of the maps and pose; not the paper's)
        "nearest-unswept": "motiongym.baselines.sweeper.nearest:NearestUnsweptPolicy",
        # the field's classical coverage references, online on the robot's own map
        "boustrophedon": "motiongym.baselines.sweeper.boustrophedon:BoustrophedonPolicy",
        "ba-star": "motiongym.baselines.sweeper.ba_star:BaStarPolicy",
        "spiral-stc": "motiongym.baselines.sweeper.spiral_stc:SpiralStcPolicy",
    },
}

# Planning times of `motiongym bench`: label -> ("module:function", goal in s). PSA + CWA
# plans online, while it senses: its "plan" is a whole run, timed through the one episode
# loop (agents.sweeper_runs; a name the bench resolves, not an import of this package).
PLANNERS: dict[str, tuple[str, float | None]] = {
    "PSA + CWA, full run on the maze": ("motiongym.agents.reproduce.sweeper_runs:sweep", 2.0),
}
