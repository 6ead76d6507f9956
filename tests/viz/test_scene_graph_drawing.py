"""The symbolic scene graph drawing, in the kitchen and in a world of other names."""

from pathlib import Path

from hsgplan.domain.goals import parse_goal
from hsgplan.domain.kitchen import KITCHEN
from hsgplan.domain.predicates import inside, on
from hsgplan.domain.scene_file import read_world
from hsgplan.scene_graph.symbolic import SymbolicSceneGraph
from hsgplan.viz.scene_graph_drawing import draw_symbolic, fixture_x

NEW = read_world(Path(__file__).parents[2] / "scenes/new-objects/new-objects-000.toml")


def test_fixtures_stand_left_to_right_as_the_robot_sees_them():
    x = fixture_x(KITCHEN)
    assert sorted(x, key=x.get) == ["shelf_a", "prepush_a", "open_space", "prepush_b", "shelf_b"]


def test_a_state_of_new_objects_is_drawn(tmp_path):
    state = SymbolicSceneGraph.from_literals(
        ["peaches", "tuna", "rice"],
        [on("peaches", "shelf_a"), inside("tuna", "shelf_a"), on("rice", "peaches")],
        world=NEW,
    )
    goal = parse_goal("On(rice, shelf_b)", world=NEW)
    draw_symbolic(state, tmp_path / "s.png", "a title", goal)
    assert (tmp_path / "s.png").read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
