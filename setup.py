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

# Folders of data files, not of code. Python would import them as namespace packages,
# so setuptools wants them named: listed here, their files go in as package data.
DATA_PACKAGES = [
    "motiongym.agents.models.pretrained",  # shipped models: pretrained/<ID>/<label>/
    "motiongym.configs.rllib",  # RLlib's settings
    "motiongym.configs.zoo",  # rl-zoo3's settings
]

packages = list(PACKAGE_DIRS)
for name, folder in PACKAGE_DIRS.items():
    packages += [f"{name}.{sub}" for sub in find_packages(folder)]
packages += DATA_PACKAGES

setup(
    packages=packages,
    package_dir=PACKAGE_DIRS,
    package_data={
        "motiongym": ["py.typed"],
        "": ["*.txt", "*.png", "*.yml", "*.yaml", "*.json", "*.zip", "*.npz"],
        "motiongym.agents.models.pretrained": ["*/*/*"],
        "motiongym.configs.rllib": ["*.yml"],
        "motiongym.configs.zoo": ["*.yml"],
    },
)
