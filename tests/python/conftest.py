"""Shared fixtures: the packaged FMUs (built through `cargo xtask fmu`, like every test that
needs them) and the masters' helper modules on the import path."""

import os
import pathlib
import subprocess
import sys

import pytest

ROOT = pathlib.Path(__file__).resolve().parents[2]
sys.path.insert(0, str(ROOT / "masters"))


def target_dir():
    t = os.environ.get("CARGO_TARGET_DIR")
    return pathlib.Path(t) if t else ROOT / "target"


@pytest.fixture(scope="session")
def fmus():
    """Packages the FMUs once per test session and returns {modelIdentifier: path}."""
    subprocess.run(["cargo", "xtask", "fmu"], cwd=ROOT, check=True)
    out = target_dir() / "fmu"
    return {p.stem: str(p) for p in out.glob("*.fmu")}


@pytest.fixture(scope="session")
def plant_fmu(fmus):
    return fmus["TowingPlant"]


@pytest.fixture(scope="session")
def controller_fmu(fmus):
    if "TowingController" not in fmus:
        pytest.fail(f"`cargo xtask fmu` did not package TowingController.fmu (packaged: {sorted(fmus)})")
    return fmus["TowingController"]


@pytest.fixture(scope="session")
def paper_scenario():
    return ROOT / "scenarios" / "paper.toml"


def pytest_configure(config):
    config.addinivalue_line(
        "markers",
        "closed_loop_long: 1200 s closed-loop acceptance runs of the paper scenario (minutes each); "
        'deselect with -m "not closed_loop_long"',
    )
