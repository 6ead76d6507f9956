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


def _overlapping(fig, labels) -> list[tuple[str, str]]:
    fig.canvas.draw()
    renderer = fig.canvas.get_renderer()
    boxes = {n: t.get_window_extent(renderer) for n, t in labels.items()}
    names = sorted(boxes)
    return [
        (a, b) for i, a in enumerate(names) for b in names[i + 1 :] if boxes[a].overlaps(boxes[b])
    ]


def test_names_do_not_overlap_in_a_crowded_state_and_a_key_says_what_marks_mean():
    import random

    import matplotlib.pyplot as plt

    from hsgplan.domain.objects import objects_for_types
    from hsgplan.symbolic.generator import random_state
    from hsgplan.viz.scene_graph_drawing import figure

    objects = objects_for_types(list(KITCHEN.object_types) * 2, KITCHEN)  # twelve
    for seed in range(6):
        state = random_state(objects, random.Random(seed), world=KITCHEN)
        fig, labels = figure(state, "crowded")
        assert set(labels) == set(objects) | set(KITCHEN.fixtures)
        assert _overlapping(fig, labels) == [], seed
        key = [t.get_text() for t in fig.axes[0].get_legend().get_texts()]
        assert {"Clear", "InGrasp"} <= set(key)
        plt.close(fig)


def test_held_and_shelved_objects_keep_their_names_apart():
    import matplotlib.pyplot as plt

    from hsgplan.domain.predicates import in_grasp
    from hsgplan.viz.scene_graph_drawing import figure

    cans = ["cherries", "tomato_soup", "alphabet_soup"]  # a row inside shelf A
    literals = [inside(c, "shelf_a") for c in cans] + [on("butter", "shelf_a"), in_grasp("popcorn")]
    state = SymbolicSceneGraph.from_literals([*cans, "butter", "popcorn"], literals, world=KITCHEN)
    fig, labels = figure(state)
    assert _overlapping(fig, labels) == []
    plt.close(fig)
