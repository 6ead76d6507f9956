"""What a lone view found, tested against the rest of the look on tiny hand-built looks: found
again in one space, missed by a view that would show it, doubted by the colour network, or in
the space of an object several views saw."""

from dataclasses import replace

import numpy as np

from hsgplan.domain.kitchen import KITCHEN
from hsgplan.perception.detection import Detection
from hsgplan.perception.fusion import Seen
from hsgplan.perception.keypoints import PinholeCamera, view_keypoints
from hsgplan.perception.phantoms import SURE, overlap, pruned
from hsgplan.perception.pnp import ViewKeypoints
from hsgplan.perception.vocabulary import kitchen_vocabulary
from hsgplan.scene_graph.geometry import Pose
from hsgplan.sim.sensing import Box

VIEWS = kitchen_vocabulary().views  # the shipped f_p's fixed cameras

TYPES = list(KITCHEN.object_types)
OPEN = Pose.from_xyz_yaw(0.45, 0.0, 0.0415, 0.0)  # a soup on the open table, in every view
EVERY = tuple(range(len(VIEWS)))
INSIDE = Pose.from_xyz_yaw(0.52, 0.38, 0.0415, 0.0)  # a soup deep inside shelf A


def _keypoints(name: str, pose: Pose, view: int) -> ViewKeypoints:
    camera = PinholeCamera.of(VIEWS[view])
    return ViewKeypoints(camera, view_keypoints(KITCHEN.object_type(name), pose, camera))


def _detection(name: str, pose: Pose, views: tuple[int, ...], confidence: float = 0.9):
    keypoints = tuple(_keypoints(name, pose, v) for v in views)
    return Detection(name, pose, 0.8, len(views), 0.0, (), confidence, keypoints)


def _instances(name: str, pose: Pose, views: tuple[int, ...]) -> list[Seen]:
    """What those views found: the object's instance in each."""
    return [Seen(TYPES.index(name), 0.8, v, _keypoints(name, pose, v)) for v in views]


def test_a_lone_view_no_other_view_backs_where_every_view_would_show_it_is_dropped():
    lone = _detection("tomato_soup", OPEN, (0,))
    assert pruned([lone], _instances("tomato_soup", OPEN, (0,)), VIEWS, KITCHEN) == []


def test_a_lone_views_detection_stays_where_another_view_found_something_there():
    lone = _detection("tomato_soup", OPEN, (0,))
    backed = _instances("tomato_soup", OPEN, (0,)) + _instances("alphabet_soup", OPEN, (1, 2, 3, 4))
    assert pruned([lone], backed, VIEWS, KITCHEN) == [lone]


def test_a_lone_views_detection_the_shelf_hides_from_the_others_stays():
    assert not any(_shows(INSIDE, v) for v in range(1, len(VIEWS)))  # the walls hide it
    lone = _detection("tomato_soup", INSIDE, (0,))
    assert pruned([lone], _instances("tomato_soup", INSIDE, (0,)), VIEWS, KITCHEN) == [lone]


def _shows(pose: Pose, view: int) -> bool:
    """Whether a view would show a good part of a soup at `pose`, the shelves painted."""
    from hsgplan.perception.visible import furniture, painted

    camera = PinholeCamera.of(VIEWS[view])
    alone = (painted([KITCHEN.object_type("tomato_soup")], [pose], camera) == 0).sum()
    shown = (
        painted([KITCHEN.object_type("tomato_soup")], [pose], camera, furniture(KITCHEN)) == 0
    ).sum()
    return alone > 0 and shown >= 0.5 * alone


def test_a_lone_views_detection_the_arm_hides_from_the_others_stays():
    lone = _detection("tomato_soup", OPEN, (0,))
    arm = tuple(  # a link between each other camera and the soup, as the kinematics put it
        Box(tuple(p - 0.05 for p in point), tuple(p + 0.05 for p in point))
        for point in (
            np.asarray(OPEN.position) + 0.4 * (np.asarray(c.eye) - OPEN.position) for c in VIEWS[1:]
        )
    )
    found = _instances("tomato_soup", OPEN, (0,))
    assert pruned([lone], found, VIEWS, KITCHEN) == []
    assert pruned([lone], found, VIEWS, KITCHEN, arm) == [lone]


def test_one_object_found_again_by_a_lone_view_in_the_same_space_is_kept_once():
    sure = _detection("tomato_soup", OPEN, EVERY)
    again = _detection("tomato_soup", Pose.from_xyz_yaw(0.455, 0.005, 0.0415, 0.0), (2,))
    found = _instances("tomato_soup", OPEN, EVERY)
    assert pruned([again, sure], found, VIEWS, KITCHEN) == [sure]


def test_a_lone_view_the_colour_network_doubts_is_dropped_and_several_views_are_not():
    found = _instances("tomato_soup", OPEN, EVERY)
    doubted = _detection("tomato_soup", OPEN, (0,), confidence=SURE / 2)
    several = _detection("tomato_soup", OPEN, (0, 1), confidence=SURE / 2)
    assert pruned([doubted], found, VIEWS, KITCHEN) == []
    assert pruned([several], found, VIEWS, KITCHEN) == [several]


def test_a_lone_views_box_in_a_sure_cans_space_is_dropped_not_in_an_unsure_ones():
    can = _detection("tomato_soup", OPEN, EVERY)
    box = _detection("butter", Pose.from_xyz_yaw(0.47, 0.01, 0.012, 0.3), (1,))
    found = _instances("tomato_soup", OPEN, EVERY)
    assert pruned([can, box], found, VIEWS, KITCHEN) == [can]
    unsure = replace(can, type_confidence=SURE / 2)
    assert pruned([unsure, box], found, VIEWS, KITCHEN) == [unsure, box]


def test_cuboids_overlap_in_one_space_not_side_by_side_nor_stacked():
    a = _detection("butter", Pose.from_xyz_yaw(0.45, 0.0, 0.012, 0.0), (0,))
    turned = _detection("cream_cheese", Pose.from_xyz_yaw(0.47, 0.02, 0.012, 1.2), (0,))
    beside = _detection("cream_cheese", Pose.from_xyz_yaw(0.45, 0.12, 0.012, 0.0), (0,))
    on_it = _detection("cream_cheese", Pose.from_xyz_yaw(0.45, 0.0, 0.036, 0.0), (0,))
    assert overlap(a, turned, KITCHEN) and overlap(turned, a, KITCHEN)
    assert not overlap(a, beside, KITCHEN)
    assert not overlap(a, on_it, KITCHEN)
    assert np.isclose(a.pose.position[2], 0.012)
