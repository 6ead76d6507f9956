"""f_p's decoding, PnP and fusion on a rendered scene, with a stand-in network that outputs
the scene's true maps: what the estimator makes of perfect maps, and how the evaluation
scores it. (The trained network's quality is measured by `hsgplan eval perception`.)"""

import math
from dataclasses import replace

import numpy as np
import pytest
import torch
from scipy.spatial.transform import Rotation

from hsgplan.domain.kitchen import KITCHEN
from hsgplan.evaluation.perception_eval import SceneResult, rotation_error, score_scene, summary
from hsgplan.perception.apart import apart
from hsgplan.perception.detection import Detection
from hsgplan.perception.estimator import PoseEstimator, _of_kind
from hsgplan.perception.fitting import fitted
from hsgplan.perception.keypoints import PinholeCamera, view_keypoints
from hsgplan.perception.maps import targets
from hsgplan.perception.model import STRIDE
from hsgplan.perception.pnp import ViewKeypoints
from hsgplan.perception.synthetic import render_sample
from hsgplan.perception.train import MIN_VISIBLE
from hsgplan.perception.vocabulary import kitchen_vocabulary
from hsgplan.scene_graph.geometry import Pose, matrix_to_quat

VIEWS = kitchen_vocabulary().views  # the shipped f_p's fixed cameras

TYPES = list(KITCHEN.object_types)


class _TrueMaps(torch.nn.Module):
    """Outputs the true maps of a sample's views, whatever the images."""

    stride = STRIDE

    def __init__(self, sample) -> None:
        super().__init__()
        views, height, width = sample.images.shape[:3]
        kinds = np.array([TYPES.index(KITCHEN.type_of(o)) for o in sample.objects])
        maps = []
        for v in range(views):
            seen = sample.visible[v] >= MIN_VISIBLE
            pinhole = PinholeCamera.of(sample.cameras[v])
            named = np.stack(  # as this view names them
                [
                    view_keypoints(
                        KITCHEN.object_type(o), Pose(tuple(p[:3]), tuple(p[3:])), pinhole
                    )
                    for o, p in zip(sample.objects, sample.poses.astype(float), strict=True)
                ]
            )
            maps.append(
                targets(
                    named[seen],
                    kinds[seen],
                    len(TYPES),
                    height // STRIDE,
                    width // STRIDE,
                )
            )
        self.beliefs = torch.from_numpy(np.stack([b for b, _ in maps]))
        self.fields = torch.from_numpy(np.stack([f for _, f in maps]))

    def forward(self, images):
        return [(self.beliefs, self.fields)]

    def last(self, images):  # what a look reads of a keypoint network
        return self(images)[-1]


def test_perfect_maps_give_the_scene_back_duplicates_and_all():
    sample = render_sample(0, 1, KITCHEN)  # twelve objects, five alphabet soups among them
    assert sample is not None and len(sample.objects) == 12
    detections = PoseEstimator(_TrueMaps(sample)).detect(sample.images, sample.cameras, KITCHEN)
    result = score_scene(sample, detections, KITCHEN)
    seen = (sample.visible >= MIN_VISIBLE).any(axis=0)
    assert result.found >= seen.sum() - 1
    assert np.median(result.translation_cm) < 0.5 and np.median(result.rotation_deg) < 3
    report = summary([result])
    assert report["scenes"] == 1 and report["translation_cm_median"] < 0.5
    assert result.detections == len(detections) >= result.found
    assert report["precision"] == result.found / len(detections)
    assert report["unmatched_detections"] == len(detections) - result.found


def test_rotation_error_counts_a_cuboid_symmetry_as_no_error():
    upright = Pose.from_xyz_yaw(0.5, 0.0, 0.02, 0.3)
    turned = Pose.from_xyz_yaw(0.5, 0.0, 0.02, 0.3 + math.pi)
    assert rotation_error("butter", upright, turned, KITCHEN) < 1e-4  # half a turn: the same cuboid
    assert (
        abs(
            rotation_error("butter", upright, Pose.from_xyz_yaw(0.5, 0, 0.02, 0.5), KITCHEN) - 11.46
        )
        < 0.1
    )
    assert rotation_error("cherries", upright, Pose.from_xyz_yaw(0.5, 0, 0.02, 2.0), KITCHEN) < 1e-4


def test_a_box_whose_rays_meet_a_centimetre_over_the_table_is_named_a_thin_one():
    probs = torch.tensor([0.0, 0.0, 0.0, 0.5, 0.3, 0.2])  # the colour says popcorn
    names = tuple(TYPES)
    assert _of_kind(KITCHEN, names, probs, "popcorn")[0] == "popcorn"
    low = np.array([0.5, 0.0, 0.012])
    best, confidence = _of_kind(KITCHEN, names, probs, "popcorn", low)
    assert best == "cream_cheese" and confidence == pytest.approx(0.3)
    assert _of_kind(KITCHEN, names, probs, "popcorn", np.array([0.5, 0.0, 0.063]))[0] == "popcorn"


def test_a_scene_without_a_type_is_never_read_to_hold_one():
    without = replace(KITCHEN, type_list=tuple(t for t in KITCHEN.type_list if t.name != "popcorn"))
    probs = torch.tensor([0.0, 0.0, 0.0, 0.5, 0.3, 0.2])  # the colour says popcorn
    names = tuple(TYPES)
    assert _of_kind(without, names, probs, "cream_cheese")[0] == "cream_cheese"
    over = np.array([0.5, 0.0, 0.063])  # where a popcorn's centre would be, over the table
    assert _of_kind(without, names, probs, "butter", over)[0] == "cream_cheese"


def test_of_a_soup_and_a_box_found_in_one_place_the_colour_keeps_the_soup():
    probs = torch.tensor([0.1, 0.6, 0.2, 0.09, 0.005, 0.005])  # an alphabet soup's colour
    at = Pose.from_xyz_yaw(0.5, 0.0, 0.042, 0.0)
    found = []
    for kind in ("popcorn", "alphabet_soup"):
        best, confidence = _of_kind(KITCHEN, tuple(TYPES), probs, kind)
        found.append(Detection(best, at, 1.0, 2, 0.0, (), confidence))
    assert found[0].type_name == "popcorn"  # the likeliest box, though no box is likely
    assert [d.type_name for d in apart(found, KITCHEN)] == ["alphabet_soup"]


def test_a_lone_views_can_where_several_views_saw_one_of_its_type_is_that_can_again():
    lower = Pose.from_xyz_yaw(0.43, -0.37, 0.176, 0.0)  # under a cherries can at 0.251
    lone = Pose.from_xyz_yaw(0.425, -0.38, 0.169, 0.0)
    several = Detection("alphabet_soup", lower, 0.8, 5, 0.0, (), 0.830)
    again = Detection("alphabet_soup", lone, 0.46, 1, 0.0, (), 0.835)  # surer, by a hair
    on_it = Detection("cherries", Pose.from_xyz_yaw(0.43, -0.37, 0.251, 0.0), 0.86, 5, 0.0, (), 0.9)
    assert apart([on_it, again, several], KITCHEN) == [on_it, several]
    # a lone view's box is kept as before: it may be the lower of a stack seen as one blob
    box = Pose.from_xyz_yaw(0.5, 0.0, 0.036, 0.0)
    blob = Detection("butter", box, 0.8, 3, 0.0, (), 0.6)
    lone_box = Detection("butter", Pose.from_xyz_yaw(0.5, 0.005, 0.03, 0.0), 0.5, 1, 0.0, (), 0.7)
    assert apart([blob, lone_box], KITCHEN) == [lone_box]


def _views_of(name: str, pose: Pose) -> list[ViewKeypoints]:
    cameras = [PinholeCamera.of(c) for c in VIEWS]
    return [ViewKeypoints(c, view_keypoints(KITCHEN.object_type(name), pose, c)) for c in cameras]


def test_an_object_on_its_side_stays_toppled_and_a_noisy_upright_one_stands():
    on_side = Pose(
        (0.5, 0.1, 0.0355), matrix_to_quat(Rotation.from_euler("x", 90, degrees=True).as_matrix())
    )
    pose, error = fitted(
        KITCHEN.object_type("alphabet_soup"), _views_of("alphabet_soup", on_side), []
    )
    assert pose is not None and abs(pose.rotation[2, 2]) < 0.1 and error < 1.0
    # one view alone never says toppled
    lone, _ = fitted(
        KITCHEN.object_type("alphabet_soup"), _views_of("alphabet_soup", on_side)[:1], []
    )
    assert lone is not None and lone.rotation[2, 2] == pytest.approx(1.0)
    upright = Pose.from_xyz_yaw(0.45, -0.1, 0.012, 0.4)
    views = _views_of("butter", upright)
    noise = np.random.default_rng(0).normal(0, 1.5, size=(len(views), 9, 2))
    noisy = [ViewKeypoints(v.camera, v.pixels + n) for v, n in zip(views, noise, strict=True)]
    pose, _ = fitted(KITCHEN.object_type("butter"), noisy, [])
    assert pose is not None and pose.rotation[2, 2] == pytest.approx(1.0)


def test_the_evaluation_sees_from_the_first_views_asked_for():
    from hsgplan.evaluation.perception_eval import evaluate

    class Counting:
        def __init__(self):
            self.views = []

        def detect(self, images, cameras, world):
            assert len(images) == len(cameras)
            self.views.append(len(cameras))
            return []

    for views in (3, len(VIEWS)):
        estimator = Counting()
        results = evaluate(estimator, 2, 1, views=views, worlds=(KITCHEN,))
        assert estimator.views == [views] * len(results) and results
        assert all(r.found == 0 and not r.symbolic_match for r in results)


def test_the_evaluation_stages_scene_k_in_the_kth_world_and_f_p_is_given_that_world():
    from hsgplan.domain.layouts import random_layout
    from hsgplan.evaluation.perception_eval import evaluate

    layouts = (random_layout(KITCHEN, 3, 0), random_layout(KITCHEN, 3, 1))

    class Told:
        def __init__(self):
            self.worlds = []

        def detect(self, images, cameras, world):
            self.worlds.append(world)
            return []

    told = Told()
    results = evaluate(told, 4, 1, views=1, worlds=layouts)
    assert len(results) == 4 and told.worlds == [layouts[0], layouts[1]] * 2


def test_a_scene_of_objects_f_p_never_saw_is_refused_in_one_line(tmp_path):
    from typer.testing import CliRunner

    from hsgplan.cli import app
    from hsgplan.domain.layouts import random_layout
    from hsgplan.domain.scene_write import scene_data, to_toml

    scene = tmp_path / "new.toml"
    scene.write_text(to_toml(scene_data(random_layout(KITCHEN, 3, 0, new_objects=True))))
    r = CliRunner().invoke(app, ["eval", "perception", "--scenes", "1", "--scene", str(scene)])
    assert r.exit_code == 2 and len(r.output.strip().splitlines()) == 1, r.output
    assert "f_p cannot see scene" in r.output and "has not learned the look of" in r.output


@pytest.mark.slow
def test_scenes_from_inside_the_loop_are_scored_without_the_object_in_the_hand():
    from hsgplan.evaluation.loop_scenes import loop_scenes
    from hsgplan.evaluation.perception_eval import evaluate_loop

    cameras = VIEWS[:1]
    first = list(loop_scenes(2, 3, cameras, (KITCHEN,)))
    again = list(loop_scenes(2, 3, cameras, (KITCHEN,)))
    assert [s.truth for s in first] == [s.truth for s in again]  # the same seed, the same scenes
    assert all(s.step >= 1 and s.images.shape[0] == 1 for s in first)
    for s in first:
        assert s.held is None or all(p != s.held for p in s.truth.values())

    class Oracle:
        """Detects every object at its true pose, and the held one in the hand."""

        vocabulary = kitchen_vocabulary()

        def __init__(self, scenes):
            self.scenes = iter(scenes)

        def detect(self, images, cams, world, arm=()):
            s = next(self.scenes)
            found = [Detection(KITCHEN.type_of(o), p, 1.0, 2, 0.0) for o, p in s.truth.items()]
            if s.held is not None:
                found.append(Detection("cherries", s.held, 1.0, 2, 0.0))
            return found

    results = evaluate_loop(Oracle(first), 2, 3, views=1, worlds=(KITCHEN,))
    # every object found where it is, the hand's detection not counted against precision
    assert all(r.found == r.objects == r.detections and r.symbolic_match for r in results)


def test_a_lone_views_box_in_the_space_of_a_can_several_views_saw_is_not_kept():
    soup = Detection("alphabet_soup", Pose.from_xyz_yaw(0.54, -0.14, 0.042, 0.0), 0.8, 5, 0.0)
    soup = Detection(soup.type_name, soup.pose, 0.8, 5, 0.0, (), 0.51)  # a butter on it, above
    lone = Detection("butter", Pose.from_xyz_yaw(0.54, -0.13, 0.06, 0.0), 0.5, 1, 0.0, (), 0.95)
    assert apart([lone, soup], KITCHEN) == [soup]
    several = Detection(lone.type_name, lone.pose, 0.5, 2, 0.0, (), 0.95)
    assert apart([several, soup], KITCHEN) == [
        several
    ]  # two views against five: the colour decides


def test_the_share_off_the_targets_counts_either_error_per_type():
    result = SceneResult(
        objects=4,
        found=4,
        translation_cm=(0.3, 1.5, 0.2, 0.4),  # the butter 1.5 cm off
        rotation_deg=(2.0, 1.0, 35.0, 0.0),  # the popcorn turned 35 degrees
        types=("butter", "butter", "popcorn", "cherries"),
        symbolic_match=True,
        detections=4,
    )
    report = summary([result])
    assert report["off_targets"] == 0.5
    assert report["by_type"]["butter"]["off_targets"] == 0.5
    assert report["by_type"]["popcorn"]["off_targets"] == 1.0
    assert report["by_type"]["cherries"]["off_targets"] == 0.0
