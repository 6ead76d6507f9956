"""`hsgplan bench start`: the start scenes of an evaluation's own episodes, drawn and counted."""

from typer.testing import CliRunner

from hsgplan.benchmarks.start_scenes import bench_start
from hsgplan.cli import app
from hsgplan.domain.errors import UnsampledSceneError
from hsgplan.domain.goals import parse_goal
from hsgplan.domain.kitchen import KITCHEN
from hsgplan.evaluation.config import EvalConfig
from hsgplan.evaluation.protocol import episode_specs
from hsgplan.sim import sampler
from hsgplan.sim.env_types import reset_options


def test_each_episode_of_the_run_is_drawn_once_and_counted(monkeypatch):
    drawn = []

    def count(objects, seed, p_elsewhere=0.3, visuals=True, *, world, repairs):
        drawn.append((tuple(sorted(objects)), seed))
        if len(drawn) == 2:
            raise UnsampledSceneError("none")
        return _Closed(), None, len(drawn)

    monkeypatch.setattr("hsgplan.benchmarks.start_scenes.drawn_scene", count)
    rows = bench_start([2, 3], 2, 900, split="tune")
    specs = episode_specs(EvalConfig("oracle", (2, 3), 2, 900, split="tune"))
    expected = [
        (
            tuple(
                sorted(
                    reset_options(
                        {"goal": parse_goal(s.goal, world=KITCHEN)}, None, s.seed, KITCHEN
                    ).objects()
                )
            ),
            s.seed,
        )
        for s in specs
    ]
    assert drawn == expected  # the very goals and seeds `eval world --split tune` runs
    assert all(r.repairs == sampler.REPAIRS for r in rows)  # the sampler's, unless told
    by_size = {r.objects: r for r in rows}
    assert by_size[2].scenes == 2 and by_size[2].unsampled == 1
    assert by_size[2].draws_total == 1 + sampler.ATTEMPTS  # an unsampled scene: every draw
    assert by_size[3].draws_total == 3 + 4 and by_size[3].draws_max == 4


class _Closed:
    def close(self) -> None:
        pass


def test_a_bad_size_is_refused_in_one_line():
    r = CliRunner().invoke(app, ["bench", "start", "--sizes", "1"])
    assert r.exit_code == 2 and len(r.stderr.strip().splitlines()) == 1
    assert "between 2 and 12" in r.stderr
