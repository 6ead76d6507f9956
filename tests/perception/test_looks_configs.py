"""The two small f_p recipes of docs/perception.md ("An f_p of other groceries") differ in their
images only: the new groceries' network and its kitchen control."""

import json

from hsgplan.paths import home
from hsgplan.perception.train import PerceptionTrainConfig

LOOKS = home() / "configs" / "perception-looks"


def test_the_new_groceries_recipe_and_its_kitchen_control_differ_in_their_images_only():
    new, kitchen = (
        json.loads((LOOKS / f"{n}.json").read_text()) for n in ("new-objects-000", "kitchen")
    )
    for config in (new, kitchen):
        PerceptionTrainConfig.from_json(config)  # a configuration training takes
    assert set(new) == set(kitchen)
    assert {k for k in new if new[k] != kitchen[k]} == {"images"}
