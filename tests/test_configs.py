"""Every configuration a user can write or a command builds is checked by the one validator
(`domain.checks.check_fields`): a seed out of its bounds is refused in one line, whichever."""

import pytest

from hsgplan.collect.images import ImagesConfig
from hsgplan.collect.motion import CollectConfig
from hsgplan.domain.errors import InvalidInputError
from hsgplan.domain.parameters import MotionPrimitive
from hsgplan.evaluation.config import EvalConfig
from hsgplan.motion.train import MotionTrainConfig
from hsgplan.perception.colour import ColourConfig
from hsgplan.perception.train import PerceptionTrainConfig
from hsgplan.planning.regression.train import TaskTrainConfig

BUILDERS = {
    "eval": lambda seed: EvalConfig("oracle", (2,), 1, seed),
    "collect": lambda seed: CollectConfig(MotionPrimitive.PLACE, 1, seed=seed),
    "images": lambda seed: ImagesConfig(1, seed=seed),
    "colour": lambda seed: ColourConfig(seed=seed),
    "task training": lambda seed: TaskTrainConfig(seed=seed),
    "motion training": lambda seed: MotionTrainConfig(seed=seed),
    "perception training": lambda seed: PerceptionTrainConfig(seed=seed),
}


@pytest.mark.parametrize("name", BUILDERS)
def test_a_seed_out_of_bounds_is_refused_in_one_line(name):
    BUILDERS[name](0)
    for bad in (-1, 2**40, "0", 1.5, True):
        with pytest.raises(InvalidInputError, match="seed") as e:
            BUILDERS[name](bad)
        assert "\n" not in str(e.value)
