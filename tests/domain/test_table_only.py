"""A scene of no shelves: goals fill the regions its file names, no goal goes inside anything,
and every part that counted shelves reads it."""

import copy
import re
import tomllib

import pytest

from hsgplan.domain.errors import InvalidInputError
from hsgplan.domain.predicates import Predicate
from hsgplan.domain.scene_file import read_world, world_of
from hsgplan.domain.scene_write import scene_data, to_toml
from hsgplan.paths import SCENES, home
from hsgplan.symbolic.generator import random_goals

TABLE = home() / SCENES / "examples" / "table-only.toml"
DATA = tomllib.loads(TABLE.read_text())


def test_a_table_of_trays_reads_with_its_goal_regions_and_no_interior():
    w = read_world(TABLE)
    assert w.shelves == {} and w.goal_surfaces == ("tray_a", "tray_b")
    assert w.goal_interior is None and w.interior_capacity == {}
    assert world_of(tomllib.loads(to_toml(scene_data(w)))) == w


@pytest.mark.parametrize(
    "goals, says",
    [
        ({"shelf_tops": [], "regions": ["open_space"]}, "goals.regions ['open_space']"),
        ({"shelf_tops": []}, "goals: need a shelf top or a region for goals to fill"),
        ({"regions": ["tray_a"], "interior": "tray_b"}, "goals.interior 'tray_b'"),
    ],
)
def test_goals_that_name_no_surface_or_the_wrong_one_are_refused(goals, says):
    data = copy.deepcopy(DATA)
    data["goals"] = goals
    with pytest.raises(InvalidInputError, match=re.escape(says)):
        world_of(data)


def test_its_goals_fill_the_trays_and_stack_and_go_inside_nothing():
    w = read_world(TABLE)
    goals = random_goals(4, 20, 0, world=w)
    literals = [lit for g in goals for lit in g.literals]
    assert all(lit.predicate is Predicate.ON for lit in literals)
    assert {lit.args[1] for lit in literals} & {"tray_a", "tray_b"}
    assert all(lit.args[1] != "open_space" for lit in literals)


def test_its_observations_keep_one_empty_inside_column():
    from hsgplan.sim.gym_spaces import encode, observation_space
    from hsgplan.sim.sampler import sample_scene

    w = read_world(TABLE)
    goal = random_goals(3, 1, 0, world=w)[0]
    scene, state = sample_scene(goal.objects, seed=0, visuals=False, world=w)
    with scene:
        obs = encode(goal.objects, scene.scene_graph(), state)
    assert obs["inside"].shape == (12, 1) and not obs["inside"].any()
    assert observation_space(w).contains(obs)


def test_pushes_are_not_collected_where_there_is_nothing_to_push_into(tmp_path):
    from typer.testing import CliRunner

    from hsgplan.cli import app

    out = tmp_path / "push"
    args = ["collect", "push", "--samples", "10", "--scene", str(TABLE), "--out", str(out)]
    r = CliRunner().invoke(app, args)
    assert r.exit_code == 2 and "has no shelf interior to push into" in r.output, r.output
    assert not out.exists()


def test_its_images_draw_no_can_inside_and_its_motion_eval_runs_no_push(tmp_path):
    import random

    from typer.testing import CliRunner

    from hsgplan.cli import app
    from hsgplan.perception.synthetic import draw_state

    w = read_world(TABLE)
    for k in range(5):
        state = draw_state(random.Random(k), 0.3, w)
        assert all(lit.predicate is not Predicate.IN for lit in state.literals)
    args = ["eval", "motion", "--scene", str(TABLE), "--trials", "2", "--out", str(tmp_path / "m")]
    args += ["--motion-checkpoints", "checkpoints/motion-geometry"]
    r = CliRunner().invoke(app, args)
    assert r.exit_code == 2 and "no shelf interior to push into" in r.output, r.output


def test_a_surface_named_twice_in_the_goals_is_refused():
    data = copy.deepcopy(DATA)
    data["goals"]["regions"] = ["tray_a", "tray_a"]
    with pytest.raises(InvalidInputError, match="names a surface twice"):
        world_of(data)
