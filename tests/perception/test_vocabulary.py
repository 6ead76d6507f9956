"""f_p's vocabulary travels with its data and its checkpoint: a collection staged among new
groceries trains networks that name them, and a checkpoint folder says what it learned. How
well such a network sees is measured by `hsgplan eval perception`, not here."""

from dataclasses import replace

import numpy as np
import pytest
from typer.testing import CliRunner

from hsgplan.cli import app
from hsgplan.collect.images import ImagesConfig, collect_images
from hsgplan.domain.errors import InvalidInputError
from hsgplan.domain.kitchen import KITCHEN
from hsgplan.domain.layouts import random_layout
from hsgplan.domain.scene_write import scene_data, to_toml
from hsgplan.evaluation.config import unseeable
from hsgplan.paths import PERCEPTION_CHECKPOINT
from hsgplan.perception.estimator import PoseEstimator
from hsgplan.perception.images import collection_vocabulary, load_chunks
from hsgplan.perception.model import load_perception_net
from hsgplan.perception.train import PerceptionTrainConfig, train_perception
from hsgplan.perception.vocabulary import (
    TRAINING_SCENE,
    Vocabulary,
    kitchen_vocabulary,
    read_vocabulary,
    write_vocabulary,
)

LAYOUT = random_layout(KITCHEN, 3, 0)
NEW = random_layout(KITCHEN, 3, 0, new_objects=True)


def test_a_checkpoint_without_a_training_scene_learned_the_kitchens_types(tmp_path):
    assert read_vocabulary(tmp_path) == kitchen_vocabulary()
    assert read_vocabulary(PERCEPTION_CHECKPOINT).types == tuple(KITCHEN.object_types)
    write_vocabulary(tmp_path, kitchen_vocabulary())  # the kitchen's needs no file
    assert not (tmp_path / TRAINING_SCENE).exists()


def test_a_vocabulary_kept_beside_a_checkpoint_reads_back_with_its_types_and_cameras(tmp_path):
    write_vocabulary(tmp_path, Vocabulary(NEW))
    back = read_vocabulary(tmp_path)
    assert back.types == tuple(NEW.object_types) != kitchen_vocabulary().types
    assert back.views == Vocabulary(NEW).views and back.same_looks(Vocabulary(NEW))
    (tmp_path / TRAINING_SCENE).write_text("name = [")
    with pytest.raises(InvalidInputError, match="not valid TOML"):
        read_vocabulary(tmp_path)


def test_looks_are_names_kinds_and_colours_in_channel_order_seen_by_the_same_cameras():
    kitchen = kitchen_vocabulary()
    assert kitchen.same_looks(Vocabulary(LAYOUT))  # resized groceries, moved shelves
    assert not kitchen.same_looks(Vocabulary(NEW))
    swapped = replace(KITCHEN, type_list=(*KITCHEN.type_list[1::-1], *KITCHEN.type_list[2:]))
    assert not kitchen.same_looks(Vocabulary(swapped))  # the channels would name others
    moved = replace(KITCHEN.cameras[0], eye=(1.5, 0.0, 1.0))
    assert not kitchen.same_looks(Vocabulary(replace(KITCHEN, cameras=(moved,))))
    assert kitchen.unseen_looks(LAYOUT) is None
    assert "has not learned the look of" in kitchen.unseen_looks(NEW)
    assert Vocabulary(NEW).unseen_looks(NEW) is None
    assert "has not learned the look of" in Vocabulary(NEW).unseen_looks(KITCHEN)


@pytest.mark.slow
def test_images_of_new_groceries_train_an_f_p_that_names_them_and_may_look_at_them(tmp_path):
    scene = tmp_path / "new.toml"
    scene.write_text(to_toml(scene_data(NEW)))
    images = tmp_path / "images"
    collect_images(ImagesConfig(samples=2, chunk=2, views=1, scene=str(scene)), images, workers=1)
    assert collection_vocabulary(images).types == tuple(NEW.object_types)
    data = load_chunks(images)
    present = data["types"] >= 0
    sizes = [NEW.object_type(NEW.type_list[t].name).size for t in data["types"][present]]
    assert present.any() and np.allclose(data["sizes"][present], sizes)
    config = PerceptionTrainConfig(images=str(images), epochs=1, width=4, stages=1, threads=1)
    net = tmp_path / "net"
    train_perception(config, net)
    assert read_vocabulary(net).types == tuple(NEW.object_types)
    assert load_perception_net(net)[1].types == len(NEW.object_types)
    estimator = PoseEstimator.load(net)
    assert estimator.types == tuple(NEW.object_types)
    assert estimator.colour is not None and estimator.colour.objects == len(NEW.object_types)
    assert unseeable([NEW], scene, net) is None
    assert "has not learned the look of" in unseeable([NEW], scene)  # the shipped f_p's
    # the command that scores an f_p takes it in its own world
    args = ["eval", "perception", "--scenes", "1", "--views", "1", "--scene", str(scene)]
    r = CliRunner().invoke(app, [*args, "--perception-checkpoint", str(net), "--json"])
    assert r.exit_code == 0, r.output
    r = CliRunner().invoke(app, [*args, "--perception-checkpoint", str(net), "--loop"])
    assert r.exit_code == 0, r.output
    # images of other groceries join neither its collection nor its network
    kitchen = tmp_path / "kitchen"
    collect_images(ImagesConfig(samples=1, chunk=1, views=1), kitchen, workers=1)
    for bad, why in (
        (replace(config, images=f"{images},{kitchen}"), "other groceries or cameras"),
        (replace(config, images=str(kitchen), init=str(net)), "learned other groceries"),
    ):
        with pytest.raises(InvalidInputError, match=why):
            train_perception(bad, tmp_path / "other")
        assert not (tmp_path / "other").exists()


def test_networks_of_another_count_of_types_than_their_vocabulary_are_refused(tmp_path):
    import shutil

    folder = tmp_path / "f_p"
    shutil.copytree(PERCEPTION_CHECKPOINT, folder)
    fewer = replace(NEW, type_list=NEW.type_list[:3])  # six channels, three types named
    write_vocabulary(folder, Vocabulary(fewer))
    with pytest.raises(InvalidInputError, match="name 6 and 6 types, its vocabulary 3"):
        PoseEstimator.load(folder)


@pytest.mark.slow
def test_one_command_renders_a_scenes_images_and_trains_an_f_p_of_its_groceries(tmp_path):
    scene = tmp_path / "new.toml"
    scene.write_text(to_toml(scene_data(NEW)))
    config = tmp_path / "tiny.json"
    config.write_text('{"epochs": 1, "width": 4, "stages": 1, "threads": 1}')
    net = tmp_path / "net"
    args = ["train", "perception", "--scene", str(scene), "--samples", "2", "--workers", "1",
            "--config", str(config), "--out", str(net)]  # fmt: skip
    r = CliRunner().invoke(app, args)
    assert r.exit_code == 0, r.output
    assert collection_vocabulary(tmp_path / "net-images").types == tuple(NEW.object_types)
    assert read_vocabulary(net).types == tuple(NEW.object_types)
    both = CliRunner().invoke(app, [*args, "--images", str(tmp_path / "net-images")])
    assert both.exit_code == 2 and "give it or --images" in both.output
