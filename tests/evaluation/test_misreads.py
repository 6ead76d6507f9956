"""What a misread scene is classed by, on hand-built truths and detections."""

from hsgplan.domain.kitchen import KITCHEN
from hsgplan.evaluation.perception_eval import MISREADS, score, summary
from hsgplan.perception.detection import Detection
from hsgplan.scene_graph.geometry import Pose

TABLE_Z = 0.0


def _standing(name: str, x: float, y: float, z: float = TABLE_Z) -> Pose:
    return Pose.from_xyz_yaw(x, y, z + KITCHEN.object_type(name).height / 2, 0.0)


def _seen(type_name: str, pose: Pose) -> Detection:
    return Detection(type_name, pose, 1.0, 3, 1.0)


TRUTH = {"cherries": _standing("cherries", 0.45, 0.0), "butter": _standing("butter", 0.45, 0.25)}
STACK = {
    "cherries": _standing("cherries", 0.45, 0.0),
    "butter": _standing("butter", 0.45, 0.0, KITCHEN.object_type("cherries").height),
}


def test_a_scene_read_right_is_no_misread():
    result = score(TRUTH, [_seen(o, p) for o, p in TRUTH.items()], KITCHEN)
    assert result.symbolic_match and result.misread is None


def test_an_object_named_as_another_type_where_it_stands_is_a_look_alike():
    detections = [_seen("cherries", TRUTH["cherries"]), _seen("cream_cheese", TRUTH["butter"])]
    assert score(TRUTH, detections, KITCHEN).misread == "look_alike"


def test_an_object_nothing_was_found_at_is_unseen_or_a_stack_missed():
    assert score(TRUTH, [_seen("cherries", TRUTH["cherries"])], KITCHEN).misread == "unseen"
    assert score(STACK, [_seen("cherries", STACK["cherries"])], KITCHEN).misread == "stack_missed"


def test_every_object_found_and_a_stack_read_apart_is_a_stack_relation():
    beside = Pose.from_xyz_yaw(0.45, 0.06, KITCHEN.object_type("butter").height / 2, 0.0)
    detections = [_seen("cherries", STACK["cherries"]), _seen("butter", beside)]
    result = score(STACK, detections, KITCHEN)
    assert result.found == 2 and result.misread == "stack_relation"
    counted = summary([result, score(STACK, [_seen(o, p) for o, p in STACK.items()], KITCHEN)])
    assert counted["misreads"] == {"stack_relation": 1} and set(counted["misreads"]) <= set(
        MISREADS
    )
