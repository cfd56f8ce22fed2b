"""motiongym: four classic robot motion problems as Gymnasium environments.

Importing the package registers every environment under the ``motiongym/``
namespace (see :mod:`motiongym.envs.registration`), so that
``gym.make("motiongym:motiongym/Sweeper-v0")`` works without an import.
"""

from __future__ import annotations

from motiongym.envs import ENV_IDS

__version__ = "0.1.0"
__all__ = ["ENV_IDS", "__version__"]
