"""Synthetic images for f_p: drawn from their seed alone, labelled consistently with the
camera model, collected in resumable chunks that are checked when read back."""

import numpy as np
import pytest

from hsgplan.collect.images import ImagesConfig, collect_images
from hsgplan.domain.errors import InvalidInputError
from hsgplan.domain.kitchen import KITCHEN
from hsgplan.perception.images import chunk_path, load_chunks
from hsgplan.perception.keypoints import PinholeCamera, in_world
from hsgplan.perception.synthetic import render_sample
from hsgplan.perception.vocabulary import kitchen_vocabulary
from hsgplan.scene_graph.geometry import Pose

VOCABULARY = kitchen_vocabulary()  # the shipped f_p's
VIEWS = VOCABULARY.views


def test_a_sample_is_its_seed_and_index_alone_and_its_keypoints_are_its_poses_projected():
    a, b = render_sample(0, 3, KITCHEN), render_sample(0, 3, KITCHEN)
    assert a is not None and b is not None
    assert a.objects == b.objects and np.array_equal(a.images, b.images)
    assert a.images.shape == (len(VIEWS), VIEWS[0].height, VIEWS[0].width, 3)
    assert not np.array_equal(a.images, render_sample(1, 3, KITCHEN).images)
    for v, camera in enumerate(a.cameras):
        pinhole = PinholeCamera.of(camera)
        for j, name in enumerate(a.objects):
            pose = Pose(tuple(map(float, a.poses[j, :3])), tuple(map(float, a.poses[j, 3:])))
            assert np.allclose(
                a.keypoints[v, j],
                pinhole.project(in_world(KITCHEN.object_type(name), pose)),
                atol=0.01,
            )
    assert (a.visible.max(axis=0) > 0).mean() >= 0.5  # most objects are in sight somewhere


def test_a_sample_staged_in_another_layout_is_labelled_with_that_layouts_sizes():
    from hsgplan.domain.layouts import random_layout

    layout = random_layout(KITCHEN, 3, 0)
    sample = next(s for i in range(5) if (s := render_sample(2, i, layout, views=1)))
    assert any(layout.object_type(n).size != KITCHEN.object_type(n).size for n in sample.objects)
    pinhole = PinholeCamera.of(sample.cameras[0])
    for j, name in enumerate(sample.objects):
        pose = Pose(tuple(map(float, sample.poses[j, :3])), tuple(map(float, sample.poses[j, 3:])))
        seen = pinhole.project(in_world(layout.object_type(name), pose))
        assert np.allclose(sample.keypoints[0, j], seen, atol=0.01)


def test_a_collection_resumes_without_rendering_again_and_refuses_a_damaged_chunk(tmp_path):
    config = ImagesConfig(samples=3, seed=0, chunk=2)
    rows = collect_images(config, tmp_path, workers=1)
    assert [r["chunk"] for r in rows] == [0, 1]
    stamps = [chunk_path(tmp_path, c).stat().st_mtime_ns for c in (0, 1)]
    again = collect_images(config, tmp_path, workers=1)
    assert again == rows
    assert [chunk_path(tmp_path, c).stat().st_mtime_ns for c in (0, 1)] == stamps
    data = load_chunks(tmp_path)
    kept = sum(r["samples"] for r in rows)
    assert data["images"].shape[0] == kept == len(data["index"])
    first = data["types"][0] >= 0
    assert np.isnan(data["poses"][0][~first]).all() and not np.isnan(data["poses"][0][first]).any()
    assert data["cameras"][0, 0, 6] == pytest.approx(VIEWS[0].fov)
    chunk_path(tmp_path, 1).write_bytes(b"not a chunk")
    with pytest.raises(InvalidInputError, match="not the chunk logged"):
        load_chunks(tmp_path)


def test_a_collection_may_ask_for_more_stacks_and_refuses_a_chance_outside_0_to_1():
    import random

    from hsgplan.perception.synthetic import draw_state

    def stacked(p: float) -> int:
        states = [draw_state(random.Random(f"stacks-{i}"), p, KITCHEN) for i in range(40)]
        return sum(len(s.resting_on(o)) > 0 for s in states for o in s.objects)

    assert stacked(0.85) > stacked(0.5) > stacked(0.0) == 0
    with pytest.raises(InvalidInputError, match="p_elsewhere"):
        ImagesConfig(samples=1, p_elsewhere=1.5)


def test_the_first_views_of_a_sample_do_not_change_when_views_are_added():
    three, every = render_sample(0, 3, KITCHEN, views=3), render_sample(0, 3, KITCHEN)
    assert three is not None and every is not None
    assert len(three.cameras) == 3 and len(every.cameras) == len(VIEWS) > 3
    assert np.array_equal(three.images, every.images[:3])
    assert three.cameras == every.cameras[:3]


def test_a_collection_of_fewer_views_records_them_and_a_count_past_the_views_is_refused(
    tmp_path,
):
    import json

    collect_images(ImagesConfig(samples=1, chunk=1, views=3), tmp_path, workers=1)
    assert load_chunks(tmp_path)["images"].shape[1] == 3
    saved = json.loads((tmp_path / "config.json").read_text())
    assert len(saved["views"]) == 3 and "count" in saved
    with pytest.raises(InvalidInputError, match="views"):
        ImagesConfig(samples=1, views=len(VIEWS) + 1)
    with pytest.raises(InvalidInputError, match="views"):
        ImagesConfig(samples=1, views=0)


def test_a_chunk_whose_draws_were_all_unstaged_packs_empty_arrays_of_its_views():
    from hsgplan.perception.images import pack

    empty = pack([], KITCHEN, views=3)
    assert empty["images"].shape == (0, 3, VIEWS[0].height, VIEWS[0].width, 3)
    assert empty["keypoints"].shape[:2] == (0, 3)


def test_fewer_than_three_views_render_the_first_ones_as_three_do():
    one, three = render_sample(0, 3, KITCHEN, views=1), render_sample(0, 3, KITCHEN, views=3)
    assert one is not None and three is not None
    assert np.array_equal(one.images, three.images[:1]) and one.cameras == three.cameras[:1]


def test_a_chunk_whose_arrays_break_the_format_is_named_damaged():
    from hsgplan.perception.images import chunk_problem, pack

    good = pack([render_sample(0, 0, KITCHEN)], KITCHEN)
    assert chunk_problem(good, 1, VOCABULARY) is None
    assert "samples" in chunk_problem(good, 2, VOCABULARY)
    bad_type = dict(good, types=good["types"].copy())
    bad_type["types"][0, 0] = 42
    assert "object type" in chunk_problem(bad_type, 1, VOCABULARY)
    swapped = dict(good, poses=good["keypoints"])
    assert "poses of shape" in chunk_problem(swapped, 1, VOCABULARY)
    assert "no cameras" in chunk_problem(
        {k: v for k, v in good.items() if k != "cameras"}, 1, VOCABULARY
    )


def test_a_collection_staged_in_a_layout_keeps_its_sizes_and_trains_on_them(tmp_path):
    from hsgplan.domain.layouts import random_layout
    from hsgplan.domain.scene_write import scene_data, to_toml
    from hsgplan.perception.train import examples

    layout = random_layout(KITCHEN, 3, 0)
    scene = tmp_path / "layout.toml"
    scene.write_text(to_toml(scene_data(layout)))
    config = ImagesConfig(samples=2, seed=0, chunk=2, views=1, scene=str(scene))
    collect_images(config, tmp_path / "run", workers=1)
    data = load_chunks(tmp_path / "run")
    names = list(KITCHEN.object_types)
    for types, sizes in zip(data["types"], data["sizes"], strict=True):
        for t, size in zip(types[types >= 0], sizes[types >= 0], strict=True):
            assert np.allclose(size, layout.object_type(names[t]).size)
    found = examples(data, VOCABULARY)
    checked = 0
    for k, every in enumerate(found.cuboids):  # labels: the stored keypoints, by the view's names
        present = data["types"][k][data["types"][k] >= 0]
        stored = data["keypoints"][k, 0][data["types"][k] >= 0]
        assert np.allclose(every[:, -1], stored[:, -1], atol=1e-3)  # the centroids
        boxes = [KITCHEN.object_type(names[t]).kind == "box" for t in present]
        # a box's corners named by the view are its own, in the order of a look-alike
        assert np.allclose(np.sort(every[boxes], axis=1), np.sort(stored[boxes], axis=1), atol=1e-3)
        checked += sum(boxes)
    assert checked > 0
    kitchen = ImagesConfig(samples=2, seed=0, chunk=2, views=1)
    collect_images(kitchen, tmp_path / "kitchen", workers=1)
    kept = load_chunks(tmp_path / "kitchen")  # no sizes in its chunks: its types' own
    present = kept["types"] >= 0
    own = [KITCHEN.object_type(names[t]).size for t in kept["types"][present]]
    assert np.allclose(kept["sizes"][present], own) and np.isnan(kept["sizes"][~present]).all()
