"""The documentation site builds with warnings as errors, a page per ID from its docstring
(skipped where the ``docs`` extra is not installed; ``make docs`` installs it)."""

from __future__ import annotations

import importlib.util
import subprocess
import sys
from pathlib import Path

import pytest

from motiongym.envs import ENV_IDS

ROOT = Path(__file__).parents[1]
MISSING = [m for m in ("sphinx", "furo", "myst_parser") if importlib.util.find_spec(m) is None]


@pytest.mark.skipif(bool(MISSING), reason=f"docs extra not installed ({', '.join(MISSING)})")
def test_docs_build_without_warnings_with_a_page_per_id(tmp_path):
    out = tmp_path / "html"
    command = [sys.executable, "-m", "sphinx", "-W", "--keep-going", "-q", "-b", "html"]
    result = subprocess.run(
        [*command, str(ROOT / "docs" / "site"), str(out)], capture_output=True, text=True
    )
    assert result.returncode == 0, result.stderr[-3000:]
    for env_id in ENV_IDS:
        page = (out / "environments" / f"{env_id.split('/')[-1]}.html").read_text()
        assert f'gym.make("{env_id}")' in page.replace("&quot;", '"')
    sweeper = (out / "environments" / "Sweeper-v0.html").read_text()
    assert "every reachable free cell" in sweeper and "Sweeper-v0_psa-cwa_seed1.gif" in sweeper
    assert "Park" in (out / "papers.html").read_text()
    from motiongym.systems import declared

    names = {name for policies in declared("baselines", "POLICIES").values() for name in policies}
    assert sorted(p.stem for p in (out / "policies").glob("*.html")) == sorted([*names, "index"])
    field = _text(out / "policies" / "potential-field.html")
    # the paper, the policy module's docstring and the algorithm modules' equations
    assert "Ryu" in field and "eq. 7" in field and "theta_dot = J* X_dot" in field
    tutorials = sorted(p.stem for p in (out / "tutorials").glob("*.html"))
    scripts = sorted(p.stem for p in (ROOT / "docs" / "tutorials").glob("*.py"))
    assert tutorials == sorted([*scripts, "index"]) and len(scripts) == 3
    assert "class FixedDelayPolicy(ScriptedPolicy)" in _text(
        out / "tutorials" / "scripted_policy.html"
    )


def _text(page: Path) -> str:
    """A page's text without its markup (highlighted code is split into spans)."""
    import html
    import re

    return html.unescape(re.sub(r"<[^>]+>", "", page.read_text()))
