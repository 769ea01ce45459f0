"""The package as a user installs it: a wheel built from the repository, installed into a
fresh virtual environment, run from an empty folder elsewhere (no checkout, no
PYTHONPATH), through the drake-standup command."""

from __future__ import annotations

import csv
import json
import os
import shutil
import subprocess
import sys
import venv
from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parent.parent


def _run(command: list, cwd: Path, env: dict, timeout: float) -> str:
    done = subprocess.run(
        command, cwd=cwd, env=env, capture_output=True, text=True, timeout=timeout, check=False
    )
    assert done.returncode == 0, f"{command}: {done.stderr[-2000:]}"
    return done.stdout


@pytest.mark.slow
def test_the_wheel_installs_and_runs_from_an_empty_folder(tmp_path):
    """pip wheel of the repository, installed into a new venv (the heavy dependencies
    come from this environment instead of a download); from
    an empty folder: run writes metrics.json and the figures, sweep writes its table,
    scenarios lists what the repository ships, and the package imported is the wheel's."""
    env = {k: v for k, v in os.environ.items() if k not in ("PYTHONPATH", "VIRTUAL_ENV")}
    # Built from a copy: setuptools leaves build/ behind, whose stale files a later build
    # of the repository itself would pack.
    source = tmp_path / "source"
    junk = ("out", "build", "*.egg-info", "__pycache__", ".*")
    shutil.copytree(REPO, source, ignore=shutil.ignore_patterns(*junk))
    wheels = tmp_path / "wheels"
    pip_wheel = [sys.executable, "-m", "pip", "wheel", "--no-deps", "-q", "-w", wheels, source]
    _run(pip_wheel, tmp_path, env, 600)
    (wheel,) = wheels.glob("drake_standup-*.whl")
    # The venv sees this environment's packages after its own (a .pth line: no download
    # of Drake), but not this environment's editable install of the repository.
    venv.create(tmp_path / "venv", with_pip=False)
    bin_dir = tmp_path / "venv" / "bin"
    purelib = "import sysconfig; print(sysconfig.get_paths()['purelib'])"
    site_dir = Path(_run([bin_dir / "python", "-c", purelib], tmp_path, env, 60).strip())
    outer = [p for p in sys.path if Path(p).name in ("site-packages", "dist-packages")]
    (site_dir / "outer_environment.pth").write_text("\n".join(outer) + "\n")
    pip = [sys.executable, "-m", "pip", "--python", bin_dir / "python", "install", "-q"]
    _run([*pip, "--no-deps", wheel], tmp_path, env, 600)
    env["PATH"] = f"{bin_dir}{os.pathsep}{env['PATH']}"
    work = tmp_path / "work"
    work.mkdir()

    where = _run(
        [bin_dir / "python", "-c", "import drake_standup; print(drake_standup.__file__)"],
        work,
        env,
        120,
    )
    assert Path(where.strip()).is_relative_to(tmp_path / "venv")

    _run(
        [
            "drake-standup",
            "run",
            "--scenario",
            "unassisted",
            "--duration",
            "4",
            "--no-recording",
            "--out",
            "X",
        ],
        work,
        env,
        900,
    )
    metrics = json.loads((work / "X" / "metrics.json").read_text())
    assert metrics["sim_time_s"] == pytest.approx(4.0, abs=0.01)
    for figure in ("figure_advancement.png", "figure_tracking.png"):
        assert (work / "X" / figure).stat().st_size > 10_000

    _run(["drake-standup", "sweep", "assistance", "--limit", "2", "--out", "Y"], work, env, 900)
    with (work / "Y" / "results.csv").open() as f:
        rows = list(csv.DictReader(f))
    assert [row["index"] for row in rows] == ["0", "1"]
    assert all(row["sim_time_s"] for row in rows)

    listed = _run(["drake-standup", "scenarios"], work, env, 120)
    shipped = sorted(
        p.stem for folder in ("scenarios", "sweeps") for p in (REPO / folder).glob("*.yaml")
    )
    assert (
        sorted(line.split()[0] for line in listed.splitlines() if line.startswith("  ")) == shipped
    )
    assert str(tmp_path / "venv") in listed  # read from the installed package, not the checkout
    assert sorted(p.name for p in work.iterdir()) == ["X", "Y"]


@pytest.mark.parametrize(("given", "expected"), [(None, "1"), ("3", "3")])
def test_one_blas_thread_per_process_unless_the_user_says(given, expected):
    """Importing drake_standup (before numpy) asks OpenBLAS for one thread, and a user's
    own OPENBLAS_NUM_THREADS wins (docs/performance.md: threads spun on a busy machine)."""
    env = {k: v for k, v in os.environ.items() if k != "OPENBLAS_NUM_THREADS"}
    if given is not None:
        env["OPENBLAS_NUM_THREADS"] = given
    code = "import drake_standup, os, numpy; print(os.environ['OPENBLAS_NUM_THREADS'])"
    assert _run([sys.executable, "-c", code], REPO, env, 60.0).strip() == expected
