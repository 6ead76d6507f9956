"""The layer contracts catch what they promise: a module of f_p or of an agent that imports
PyBullet, or the simulated scene, breaks `make lint` (`lint-imports`); the unchanged package
keeps them, so the breaks are the added lines'."""

import shutil
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
LINT = Path(sys.executable).with_name("lint-imports")


def _lint_with(tmp_path: Path, module: str, line: str) -> subprocess.CompletedProcess:
    """lint-imports on a copy of the package where `module` gained `line`."""
    shutil.copytree(ROOT / "hsgplan", tmp_path / "hsgplan", ignore=shutil.ignore_patterns("*.pyc"))
    shutil.copy(ROOT / "pyproject.toml", tmp_path / "pyproject.toml")
    path = tmp_path / (module.replace(".", "/") + ".py")
    path.write_text(path.read_text() + f"\n{line}\n")
    return subprocess.run(
        [str(LINT), "--no-cache"],
        cwd=tmp_path,
        env={"PYTHONPATH": str(tmp_path), "PATH": str(LINT.parent)},
        capture_output=True,
        text=True,
        timeout=300,
    )


@pytest.mark.slow
@pytest.mark.parametrize(
    ("module", "line", "forbidden"),
    [
        ("hsgplan.perception.estimator", "import pybullet", "pybullet"),
        ("hsgplan.agents.hierarchical", "import pybullet_data", "pybullet_data"),
        ("hsgplan.planning.heuristic", "from hsgplan.sim.scene import Scene", "hsgplan.sim.scene"),
        ("hsgplan.motion.generator", "from hsgplan.sim import env", "hsgplan.sim.env"),
        # the stream baseline's named exceptions (its model's scene, robot and plans) are no
        # licence for the rest of the simulator
        (
            "hsgplan.agents.streams",
            "from hsgplan.sim.env import KitchenStorageEnv",
            "hsgplan.sim.env",
        ),
        (
            "hsgplan.agents.streams",
            "from hsgplan.sim.sampler import sample_scene",
            "hsgplan.sim.sampler",
        ),
        # the kitchen is the commands' to name: not even an evaluation may import it
        (
            "hsgplan.evaluation.protocol",
            "from hsgplan.domain.kitchen import KITCHEN",
            "hsgplan.domain.kitchen",
        ),
    ],
)
def test_touching_the_simulator_from_the_decision_path_breaks_the_lint(
    tmp_path, module, line, forbidden
):
    if not LINT.exists():
        pytest.skip("lint-imports is not installed beside this Python")
    done = _lint_with(tmp_path, module, line)
    assert done.returncode != 0, done.stdout
    package = ".".join(module.split(".")[:2])
    assert f"{package} is not allowed to import {forbidden}" in done.stdout


@pytest.mark.slow
def test_the_package_as_it_is_keeps_every_contract(tmp_path):
    if not LINT.exists():
        pytest.skip("lint-imports is not installed beside this Python")
    done = _lint_with(tmp_path, "hsgplan.agents.streams", "")
    assert done.returncode == 0, done.stdout
