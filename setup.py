"""Package discovery for the repository layout of ARCHITECTURE.md.

The metadata lives in pyproject.toml; this file only maps the top-level code
folders into the one import name ``motiongym`` and finds their subpackages,
so that a new subpackage needs no edit here.
"""

from setuptools import find_packages, setup

PACKAGE_DIRS = {
    "motiongym": "src/motiongym",
    "motiongym.envs": "envs",
    "motiongym.baselines": "baselines",
    "motiongym.agents": "agents",
    "motiongym.configs": "configs",
}

packages = list(PACKAGE_DIRS)
for name, folder in PACKAGE_DIRS.items():
    packages += [f"{name}.{sub}" for sub in find_packages(folder)]

setup(
    packages=packages,
    package_dir=PACKAGE_DIRS,
    package_data={
        "motiongym": ["py.typed"],
        "": ["*.txt", "*.png", "*.yml", "*.yaml", "*.json", "*.zip", "*.npz"],
        # shipped models: pretrained/<ID>/<label>/ are folders, not packages
        "motiongym.agents.models": ["pretrained/*/*/*"],
        # folders of YAML files, not packages: rl-zoo3's and RLlib's settings
        "motiongym.configs": ["zoo/*.yml", "rllib/*.yml"],
    },
)
