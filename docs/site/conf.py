"""Sphinx configuration of the motiongym documentation site (``make docs``).

The environment pages are generated here, before reading, from the registry:
one page per registered ID with its registration (entry point, keywords, step
limit), its scripted policies, the world's GIF from ``docs/media`` and the
class docstring, which is the environment's full specification (its Markdown
``## Title`` lines are read as headings). So are a page
per scripted policy (its paper, its module's and class's docstrings and those
of the algorithm modules the module names) and a page per tutorial of
``docs/tutorials`` (its docstring, then its code).
"""

from __future__ import annotations

import ast
import os
import re
import shutil
import sys
from pathlib import Path

os.environ.setdefault("MUJOCO_GL", "egl")

HERE = Path(__file__).parent
GENERATED = HERE / "environments"
POLICY_PAGES = HERE / "policies"
TUTORIAL_PAGES = HERE / "tutorials"
TUTORIALS = HERE.parent / "tutorials"
MEDIA = HERE.parent / "media"
# The paper of each system (motiongym.systems names), as on the papers page.
PAPERS = {
    "sweeper": 'Park & Lee, "A Sweeping Algorithm for an Autonomous Mobile Robot under '
    'the Unknown Environment" (1998)',
    "harvest-arm": 'Ryu, Kim, Park & Ryu, "Control Strategy for Obstacle Avoidance of an '
    'Agricultural Robot"',
    "dual-arm": 'Chang, Chung & Lee, "A Collision Avoidance Method for Two Articulated '
    'Robot Manipulators"',
    "excavator": 'Shin, Park, Lee & Hong, "Development of Optimal Path Planning for '
    'Automated Excavator"',
}

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
    gifs = sorted(MEDIA.glob(f"{name}_*.gif"))  # this ID's own: `make media` makes them
    if not gifs:
        raise FileNotFoundError(f"no GIF of {env_id} in {MEDIA}: run `make media`")
    shutil.copy2(gifs[0], GENERATED / gifs[0].name)
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
    (GENERATED / "index.rst").write_text(_toctree("Environments", names))


def _toctree(title: str, names: list[str]) -> str:
    lines = [title, "=" * len(title), "", ".. toctree::", "   :maxdepth: 1", ""]
    return "\n".join(lines + [f"   {name}" for name in names]) + "\n"


def _policy_page(name: str, declared: list[tuple[str, str]]) -> str:
    from motiongym.systems import SYSTEMS

    module, cls = declared[0][1].split(":")
    system = next(s for s in SYSTEMS if module.startswith(s.baselines + "."))
    ids = ", ".join(sorted({f"``{env_id}``" for env_id, _ in declared}))
    classes = ", ".join(sorted({f"``{path}``" for _, path in declared}))
    lines = [name, "=" * len(name), "", f"Paper: {PAPERS[system.name]} (:doc:`../papers`).", ""]
    lines += [f"Declared for {ids} (``make_policy(ID, {name!r}, ...)``); classes {classes}.", ""]
    lines += [f".. automodule:: {module}", "   :no-index:", ""]
    lines += [f".. autoclass:: {module}.{cls}", "   :no-index:", ""]
    doc = sys.modules[module].__doc__ or ""
    parts = [f"{system.baselines}.{m}" for m in dict.fromkeys(re.findall(r":mod:`\.(\w+)`", doc))]
    if parts:
        lines += ["The algorithm's modules", "-----------------------", ""]
    for part in parts:
        lines += [f".. automodule:: {part}", "   :no-index:", ""]
    return "\n".join(lines)


def write_policy_pages() -> None:
    import importlib

    from motiongym.systems import declared

    by_name: dict[str, list[tuple[str, str]]] = {}
    for env_id, policies in declared("baselines", "POLICIES").items():
        for name, path in policies.items():
            by_name.setdefault(name, []).append((env_id, path))
    POLICY_PAGES.mkdir(exist_ok=True)
    for name, found in by_name.items():
        importlib.import_module(found[0][1].split(":")[0])
        (POLICY_PAGES / f"{name}.rst").write_text(_policy_page(name, found))
    (POLICY_PAGES / "index.rst").write_text(_toctree("Scripted policies", list(by_name)))


def write_tutorial_pages() -> None:
    TUTORIAL_PAGES.mkdir(exist_ok=True)
    names = []
    for script in sorted(TUTORIALS.glob("*.py")):
        module = ast.parse(script.read_text())
        title, _, body = (ast.get_docstring(module) or script.stem).partition("\n")
        code_from = module.body[0].end_lineno + 1
        lines = [title, "=" * len(title), body, "", f"``docs/tutorials/{script.name}``:", ""]
        lines += [f".. literalinclude:: ../../tutorials/{script.name}", "   :language: python"]
        lines += [f"   :lines: {code_from}-", ""]
        (TUTORIAL_PAGES / f"{script.stem}.rst").write_text("\n".join(lines))
        names.append(script.stem)
    (TUTORIAL_PAGES / "index.rst").write_text(_toctree("Tutorials", names))


sys.path.insert(0, str(HERE))
write_environment_pages()
write_policy_pages()
write_tutorial_pages()


def _indent(line: str) -> int:
    return len(line) - len(line.lstrip())


def equations_as_literal_blocks(app, what, name, obj, options, lines: list[str]) -> None:
    """The docstrings write equations as plain text indented under a paragraph
    (``|v_d|``, ``X_{i+1}_dot``); reStructuredText would read them as a quote with
    substitutions. A block indented 4 or more past the paragraph before it, after a
    blank line, becomes a literal block (`` ::`` ends that paragraph)."""
    for i in range(len(lines) - 2, 0, -1):
        before, blank, block = lines[i - 1], lines[i], lines[i + 1]
        if blank.strip() or not before.strip() or not block.strip():
            continue
        if _indent(block) >= _indent(before) + 4 and not before.rstrip().endswith("::"):
            lines[i - 1] = before.rstrip() + " ::"


HEADING = re.compile(r"^(\s*)#{2,4} +(\S.*?)\s*$")


def markdown_headings_as_rubrics(app, what, name, obj, options, lines: list[str]) -> None:
    """The environments' docstrings title their parts Markdown's way (``## Reward``);
    inside an autodoc directive reStructuredText allows no section, so each becomes a
    rubric (a heading outside the table of contents), with blank lines around it."""
    out: list[str] = []
    for line in lines:
        match = HEADING.match(line)
        if not match:
            out.append(line)
            continue
        if out and out[-1].strip():
            out.append("")
        out += [f"{match[1]}.. rubric:: {match[2]}", ""]
    lines[:] = out


def setup(app) -> None:
    app.connect("autodoc-process-docstring", markdown_headings_as_rubrics)
    app.connect("autodoc-process-docstring", equations_as_literal_blocks)
