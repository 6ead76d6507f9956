"""A step judged failed on a look unsure of its object is judged again from the rest pose
(the `relook` rule), under the paper's protocol too; with the rule off the robot's reading
stands, and the robot stops on it, while the judge reads the step on the simulator's state."""

from dataclasses import replace

import numpy as np
import pytest

from hsgplan.agents.registry import make_agent
from hsgplan.domain.goals import parse_goal
from hsgplan.domain.kitchen import KITCHEN
from hsgplan.domain.recovery import RecoveryRules
from hsgplan.evaluation.episode import run_episode
from hsgplan.perception.estimator import PoseEstimator
from hsgplan.scene_graph.geometric import GeometricSceneGraph
from hsgplan.sim.env import KitchenStorageEnv
from hsgplan.sim.robot import REST
from hsgplan.sim.sensing import Look, Seen
from tests.perception.test_observer import _SceneMaps, _Watching

HIDDEN = "butter"


class _HiddenByTheArm(_Watching):
    """Sees the butter where it started, unsure of it, whenever the arm is not at rest and
    does not hold it: as if the arm hid it from every view."""

    def look(self, look: Look) -> Seen:
        seen = super().look(look)
        if self.first is None:  # the episode's first look, from rest
            self.first = seen.scene_graph
        if np.allclose(look.q, REST, atol=1e-3) or look.holding == HIDDEN:
            return seen
        first = self.first.pose(HIDDEN)
        poses = {n.name: n.pose for n in seen.scene_graph.nodes} | {HIDDEN: first}
        graph = GeometricSceneGraph.from_poses(poses, seen.scene_graph.held, world=KITCHEN)
        uncertain = tuple(sorted({*seen.uncertain, HIDDEN}))
        return replace(seen, scene_graph=graph, unseen=(HIDDEN,), uncertain=uncertain)

    def start(self, objects, world) -> None:
        super().start(objects, world)
        self.first: GeometricSceneGraph | None = None


@pytest.mark.parametrize("relook", [True, False])
def test_a_place_judged_failed_while_the_arm_hides_its_object_is_judged_again_from_rest(relook):
    observer = _HiddenByTheArm(PoseEstimator(_SceneMaps()))
    # `relook_failed` would judge any failure again from rest: off, to see `relook` alone
    rules = replace(RecoveryRules(), relook=relook, relook_failed=False)
    env = KitchenStorageEnv(observer=observer, rules=rules, world=KITCHEN)
    observer.env = env
    goal = parse_goal(f"On({HIDDEN}, shelf_b)", world=KITCHEN)
    record = run_episode(env, make_agent("oracle"), goal, seed=4, end_at_failure=True)
    place = next(s for s in record.steps if s.action.startswith("place"))
    assert place.truth == "success"  # the judge reads the simulator: the place truly held
    if relook:
        assert record.success and place.status == "success" and place.relooks >= 1
    else:
        # the robot stops on the failure it saw; its goal truly holds, every step truly
        # succeeded: the episode is judged a success all the same
        assert place.status == "effect_not_reached" and place.relooks == 0
        assert record.success and record.steps[-1] == place


class _HiddenInTheShelf(_Watching):
    """Never finds the cherries once they are inside shelf A, as if its boards hid them."""

    def look(self, look: Look) -> Seen:
        x, y = self.env.scene.pose("cherries").position[:2]
        inside = KITCHEN.shelves["shelf_a"].interior
        hidden = inside.x_min <= x <= inside.x_max and inside.y_min <= y <= inside.y_max
        self.estimator.net.hidden = "cherries" if hidden else None
        return super().look(look)


def test_a_can_pushed_out_of_sight_is_believed_where_the_push_left_it():
    observer = _HiddenInTheShelf(PoseEstimator(_SceneMaps()))
    env = KitchenStorageEnv(
        observer=observer, rules=replace(RecoveryRules(), relook=False), world=KITCHEN
    )
    observer.env = env
    goal = parse_goal("In(cherries, shelf_a)", world=KITCHEN)
    seen = []
    record = run_episode(
        env,
        make_agent("oracle"),
        goal,
        seed=4,
        end_at_failure=True,
        on_step=lambda step, obs: seen.append(obs),
        others=("butter",),  # something in sight once the cherries are not
    )
    push = next(s for s in record.steps if s.action.startswith("push"))
    assert push.status == "success" and record.success
    assert "cherries" in seen[-1].unseen  # judged on where the stroke left it, not on a sighting
