"""`hsgplan bench sim`: oracle episodes timed in the kitchen or in a scene file's world."""

from pathlib import Path

import pytest
from typer.testing import CliRunner

from hsgplan.benchmarks.sim import bench_sim
from hsgplan.cli import app

SCENES = Path(__file__).resolve().parents[2] / "scenes"


@pytest.mark.slow
def test_episodes_run_in_each_scene_of_a_folder(tmp_path):
    for name in ("layout-000", "layout-003"):
        text = (SCENES / "layouts" / f"{name}.toml").read_text()
        (tmp_path / f"{name}.toml").write_text(text)
    seen = []
    rows = bench_sim([2], 1, 0, seen.append, scene=str(tmp_path))
    assert [r.scene and Path(r.scene).stem for r in seen] == ["layout-000", "layout-003"]
    assert rows[-1].what == "oracle episode, 2 objects" and rows[-1].samples == 2


def test_a_bad_scene_is_refused_in_one_line(tmp_path):
    r = CliRunner().invoke(app, ["bench", "sim", "--scene", str(tmp_path / "none.toml")])
    assert r.exit_code == 2 and len(r.stderr.strip().splitlines()) == 1
    assert "does not exist" in r.stderr
