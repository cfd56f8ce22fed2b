"""Sphinx configuration of the motiongym documentation site (``make docs``).

The environment pages are generated here, before reading, from the registry:
one page per registered ID with its registration (entry point, keywords, step
limit), its scripted policies, the world's GIF from ``docs/media`` and the
class docstring, which is the environment's full specification.
"""

from __future__ import annotations

import os
import shutil
import sys
from pathlib import Path

os.environ.setdefault("MUJOCO_GL", "egl")

HERE = Path(__file__).parent
GENERATED = HERE / "environments"
MEDIA = HERE.parent / "media"

project = "motiongym"
author = "motiongym contributors"
extensions = ["sphinx.ext.autodoc", "sphinx.ext.viewcode", "myst_parser"]
source_suffix = {".rst": "restructuredtext", ".md": "markdown"}
html_theme = "furo"
html_title = "motiongym"
exclude_patterns = ["_build"]
autodoc_member_order = "bysource"
autodoc_typehints = "none"  # the docstrings give types and units in words
suppress_warnings = ["myst.header"]


def _page(env_id: str) -> str:
    import gymnasium as gym

    from motiongym.baselines import scripted_policies

    spec = gym.spec(env_id)
    name = env_id.split("/")[-1]
    module, cls = spec.entry_point.split(":")
    policies = ", ".join(f"``{p}``" for p in scripted_policies(env_id)) or "none yet"
    kwargs = ", ".join(f"``{k}={v!r}``" for k, v in spec.kwargs.items()) or "none"
    lines = [
        name,
        "=" * len(name),
        "",
        f'``gym.make("{env_id}")``: :class:`{cls}` (``{module}``), '
        f"{spec.max_episode_steps} steps at most, registered keywords {kwargs}.",
        "",
        f"Scripted policies (the paper's first): {policies}; ``random`` for every ID.",
        "",
    ]
    gifs = sorted(MEDIA.glob(f"{name.split('-')[0]}-*.gif"))
    if gifs:
        target = GENERATED / gifs[0].name
        shutil.copy2(gifs[0], target)
        lines += [f".. image:: {gifs[0].name}", f"   :alt: one episode of {gifs[0].stem}", ""]
    lines += [f".. autoclass:: {module}.{cls}", "   :no-index:", ""]
    return "\n".join(lines)


def write_environment_pages() -> None:
    import motiongym  # noqa: F401  (registers the IDs)
    from motiongym.envs import ENV_IDS

    GENERATED.mkdir(exist_ok=True)
    names = []
    for env_id in ENV_IDS:
        name = env_id.split("/")[-1]
        (GENERATED / f"{name}.rst").write_text(_page(env_id))
        names.append(name)
    index = ["Environments", "============", "", ".. toctree::", "   :maxdepth: 1", ""]
    index += [f"   {name}" for name in names]
    (GENERATED / "index.rst").write_text("\n".join(index) + "\n")


sys.path.insert(0, str(HERE))
write_environment_pages()
