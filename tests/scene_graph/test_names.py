"""The names encodings' vocabulary, written into the package, is the kitchen scene file's: its
entities in the order the shipped networks' columns index them; f_p's channels and views too."""

from hsgplan.domain.kitchen import KITCHEN
from hsgplan.domain.layouts import random_layout
from hsgplan.perception import vocabulary
from hsgplan.scene_graph import names


def test_the_names_are_the_kitchen_files_in_its_order():
    assert tuple(KITCHEN.object_types) == names.TYPE_NAMES
    assert tuple(KITCHEN.shelves) == names.SHELF_NAMES
    assert tuple(KITCHEN.regions) == names.REGION_NAMES
    assert tuple(KITCHEN.entity_types) == names.ENTITY_NAMES
    assert names.names_world() == KITCHEN


def test_f_ps_channels_and_views_are_the_kitchens():
    assert vocabulary.kitchen_vocabulary().types == vocabulary.TYPES
    assert len(KITCHEN.cameras) == vocabulary.VIEW_COUNT
    assert vocabulary.training_world() == KITCHEN


def test_a_world_beyond_the_names_is_told():
    assert names.unnamed(KITCHEN) == []
    new = random_layout(KITCHEN, 3, 0, new_objects=True)
    beyond = [t for t in new.entity_types if t not in KITCHEN.entity_types]
    assert beyond and names.unnamed(new) == beyond
