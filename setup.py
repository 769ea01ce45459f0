"""What pyproject.toml cannot say: the wheel's packages are found (every subpackage of
drake_standup), and the top-level folders models/ (its SDF, OBJ and YAML files),
scenarios/ and sweeps/ ship inside the package as drake_standup/data/<folder> (read by
drake_standup/config/resources.py). Everything else is in pyproject.toml."""

from setuptools import find_packages, setup

DATA = {f"drake_standup.data.{folder}": folder for folder in ("models", "scenarios", "sweeps")}

setup(
    packages=find_packages(include=["drake_standup", "drake_standup.*"]) + list(DATA),
    package_dir=DATA,
    package_data={package: ["*.yaml", "*.sdf", "*.obj"] for package in DATA},
)
