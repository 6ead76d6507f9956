"""Trials: primitives run in the scene and taken back, the scene left as it would have been."""

import numpy as np

from hsgplan.domain.parameters import PickParams, PlaceParams
from hsgplan.sim.lookahead import Lookahead
from hsgplan.sim.primitives import execute


def _positions(scene) -> np.ndarray:
    return np.array([scene.pose(n).position for n in scene.objects])


def test_a_trial_is_undone_and_the_world_then_runs_as_the_trial_did(scene):
    start, rng = _positions(scene), scene.rng.bit_generator.state
    dry_runs = []
    look = Lookahead(lambda: scene, lambda p: dry_runs.append(p) or True)
    assert look(PickParams("butter")) and dry_runs == [PickParams("butter")]
    with look.trial() as trial:
        picked = trial.run(PickParams("butter"))
        assert picked.ok and scene.held() == "butter"
        in_hand = scene.pose("butter").position
        mark = trial.mark()
        assert trial.run(PlaceParams("butter", "shelf_a", 2, 3)).ok
        assert scene.held() is None
        trial.back(mark)  # back to the object in the hand, the grasp made again
        assert scene.held() == "butter"
        np.testing.assert_allclose(scene.pose("butter").position, in_hand, atol=1e-6)
    assert scene.held() is None
    np.testing.assert_allclose(_positions(scene), start, atol=1e-6)
    assert scene.rng.bit_generator.state == rng
    # the pick tried is the pick executed: same random draws, same physics
    again = execute(scene, PickParams("butter"))
    assert again.status == picked.status
    np.testing.assert_allclose(scene.pose("butter").position, in_hand, atol=1e-6)
