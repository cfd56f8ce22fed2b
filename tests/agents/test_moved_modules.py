"""The module paths from before agents/ was arranged in rooms import for one release,
with a warning that names the new path."""

from __future__ import annotations

import importlib
import subprocess
import sys

import pytest

from motiongym.agents import MOVED
from motiongym.envs.checks import MotiongymDeprecationWarning


def test_every_moved_path_points_at_a_module_that_exists():
    for new in MOVED.values():
        importlib.import_module(f"motiongym.agents.{new}")


@pytest.mark.parametrize(
    ("old", "new"), [("evaluate", "evaluation.episodes"), ("ship", "models.ship")]
)
def test_an_old_path_is_the_new_module_and_warns(old, new):
    code = (
        "import warnings; warnings.simplefilter('error')\n"
        "import motiongym.agents\n"
        "try:\n"
        f"    import motiongym.agents.{old}\n"
        "except Exception as error:\n"
        "    print(type(error).__name__, error)\n"
        "warnings.simplefilter('ignore')\n"
        f"import motiongym.agents.{old} as old, motiongym.agents.{new} as new\n"
        "print(old is new)\n"
    )
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    warning, same = out.stdout.strip().splitlines()
    assert warning == (
        f"{MotiongymDeprecationWarning.__name__} motiongym.agents.{old} is now "
        f"motiongym.agents.{new}; the old path goes in the next release"
    )
    assert same == "True"


def test_a_path_that_never_existed_is_not_found():
    with pytest.raises(ModuleNotFoundError):
        importlib.import_module("motiongym.agents.no_such_module")
