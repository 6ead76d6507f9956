import pytest

from hsgplan.domain.errors import UnknownNameError
from hsgplan.domain.kitchen import KITCHEN
from hsgplan.domain.objects import EntityKind, instance_name, objects_for_types


def test_instance_names():
    assert instance_name("cherries", 1, world=KITCHEN) == "cherries"
    assert instance_name("cherries", 3, world=KITCHEN) == "cherries_3"
    assert KITCHEN.split_instance("cherries_3") == ("cherries", 3)
    assert KITCHEN.split_instance("alphabet_soup") == ("alphabet_soup", 1)
    assert KITCHEN.split_instance("alphabet_soup_12") == ("alphabet_soup", 12)


@pytest.mark.parametrize(
    "bad", ["cherries_1", "cherries_0", "cherries_02", "cherries_13", "pear", "shelf_c", ""]
)
def test_bad_instance_names(bad):
    with pytest.raises(UnknownNameError):
        KITCHEN.split_instance(bad)


def test_kinds():
    assert KITCHEN.kind_of("shelf_a") is EntityKind.SHELF
    assert KITCHEN.kind_of("prepush_b") is EntityKind.REGION
    assert KITCHEN.kind_of("butter_2") is EntityKind.OBJECT


def test_duplicates_are_numbered_in_order_and_sorted_canonically():
    names = objects_for_types(
        ["butter", "cherries", "butter", "cherries", "cherries"], world=KITCHEN
    )
    assert names == ("butter", "cherries", "butter_2", "cherries_2", "cherries_3")
    assert KITCHEN.sort_objects(names) == (
        "cherries",
        "cherries_2",
        "cherries_3",
        "butter",
        "butter_2",
    )
