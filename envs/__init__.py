"""The worlds: Gymnasium and PettingZoo environments, one subpackage per system.

Importing this package registers every environment ID; ``ENV_IDS`` lists them.
"""

from __future__ import annotations

from motiongym.envs.registration import ENV_IDS, register_all

register_all()

__all__ = ["ENV_IDS"]
