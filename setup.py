"""What pyproject.toml cannot say: the wheel's packages are found (every subpackage of
drake_standup), and the top-level folders models/ (its SDF, OBJ and YAML files),
scenarios/, sweeps/ and recordings/ ship inside the package as drake_standup/data/<folder>
(read by drake_standup/config/resources.py). Everything else is in pyproject.toml."""

from setuptools import find_packages, setup

FOLDERS = ("models", "scenarios", "sweeps", "recordings")
DATA = {f"drake_standup.data.{folder}": folder for folder in FOLDERS}

setup(
    packages=find_packages(include=["drake_standup", "drake_standup.*"]) + list(DATA),
    package_dir=DATA,
    package_data={package: ["*.yaml", "*.sdf", "*.obj", "*.csv"] for package in DATA},
)
