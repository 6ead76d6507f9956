"""KitchenStorageEnv is a real Gymnasium env: spaces, seeding, the checker, registration, and
the typed path the agents use."""

import gymnasium
import numpy as np
import pytest
from gymnasium.utils.env_checker import check_env

from hsgplan.domain.goals import parse_goal
from hsgplan.domain.kitchen import KITCHEN
from hsgplan.domain.parameters import PickParams
from hsgplan.domain.world import MAX_OBJECTS
from hsgplan.sim.env import ENV_ID, KitchenStorageEnv, ResetOptions
from hsgplan.sim.gym_spaces import decode, encode, entity_names

GOAL = "On(butter, shelf_a) & In(cherries, shelf_a)"


def _same(a: dict, b: dict) -> bool:
    return a.keys() == b.keys() and all(np.array_equal(a[k], b[k]) for k in a)


@pytest.mark.slow
# A bare env has no spec, so the checker cannot try other render modes; `made` below does.
@pytest.mark.filterwarnings("ignore:.*alternative render modes")
def test_check_env_passes():
    env = KitchenStorageEnv(world=KITCHEN)
    try:
        check_env(env)
    finally:
        env.close()
    made = gymnasium.make(ENV_ID, render_mode="rgb_array").unwrapped  # with a spec and renders
    try:
        check_env(made)
    finally:
        made.close()


def test_reset_without_arguments_and_with_a_seed():
    env = KitchenStorageEnv(world=KITCHEN)
    try:
        obs, info = env.reset()
        assert env.observation_space.contains(obs) and env.goal is not None
        first, info = env.reset(seed=0)
        again, info_again = env.reset(seed=0)
        assert _same(first, again) and info["seed"] == info_again["seed"] == 0
        assert env.goal.size == 3  # a random goal of `objects` objects
        other, _ = env.reset(seed=1)
        assert not _same(first, other)
    finally:
        env.close()


def test_the_numeric_observation_says_what_the_typed_one_does():
    env = KitchenStorageEnv(world=KITCHEN)
    try:
        obs, info = env.reset(seed=3, options={"goal": GOAL})
        typed = info["observation"]
        objects = env.goal.objects  # butter, cherries: slots 0 and 1 (canonical order)
        assert obs["types"][: len(objects)].all() and not obs["types"][len(objects) :].any()
        assert _same(obs, encode(objects, typed.scene_graph, typed.symbols.state))
        on_or_in = obs["on"][: len(objects)].sum(1) + obs["inside"][: len(objects)].sum(1)
        assert (on_or_in == 1).all()  # every object rests on or in exactly one thing
        assert obs["on"].shape == (MAX_OBJECTS, MAX_OBJECTS + len(KITCHEN.fixtures))
    finally:
        env.close()


def test_a_sampled_action_steps_and_an_empty_slot_is_an_invalid_step():
    env = KitchenStorageEnv(world=KITCHEN)
    try:
        env.reset(seed=0, options=ResetOptions(parse_goal(GOAL, world=KITCHEN)))
        env.action_space.seed(0)
        obs, reward, terminated, truncated, info = env.step(env.action_space.sample())
        assert env.observation_space.contains(obs) and env.steps == 1
        assert isinstance(reward, float) and not truncated
        empty = env.action_space.sample() | {"object": MAX_OBJECTS - 1}
        obs, _, _, _, info = env.step(empty)
        assert (
            info["outcome"].status.value == "invalid"
            and f"slot {MAX_OBJECTS - 1} is empty" in info["outcome"].detail
        )
    finally:
        env.close()


def test_actions_decode_to_the_papers_primitives():
    objects = ("cherries", "butter")
    base = {"object": 1, "target": 0, "place_bins": np.array([3, 4]), "push_bins": [5, 6]}
    assert decode(objects, base | {"primitive": 0}, KITCHEN) == PickParams("butter")
    stacked = decode(objects, base | {"primitive": 1}, KITCHEN)
    assert (stacked.obj, stacked.target, stacked.x_bin) == ("butter", "cherries", None)
    shelf_a = entity_names(objects, world=KITCHEN).index("shelf_a")
    shelf = decode(objects, base | {"primitive": 1, "target": shelf_a}, KITCHEN)
    assert (shelf.target, shelf.x_bin, shelf.y_bin) == ("shelf_a", 3, 4)
    push = decode(objects, base | {"primitive": 2}, KITCHEN)
    assert (push.obj, push.angle_bin, push.dist_bin) == ("butter", 5, 6)


def test_the_typed_path_of_the_agents_still_works():
    env = KitchenStorageEnv(world=KITCHEN)
    try:
        _, info = env.reset(seed=0, options=ResetOptions(parse_goal(GOAL, world=KITCHEN)))
        before = info["observation"].scene_graph
        _, _, _, _, info = env.step(PickParams("butter"))
        assert info["outcome"].ok, info["outcome"]
        assert info["observation"].scene_graph.held == "butter" != before.held
        # the one judge's verdict rides in info, and is the outcome under the ground truth
        assert info["verdict"].status is info["outcome"].status
        assert env.verdicts == [info["verdict"]]
    finally:
        env.close()


def test_registered_with_gymnasium():
    env = gymnasium.make(ENV_ID, objects=2)
    try:
        obs, _ = env.reset(seed=5)
        assert env.observation_space.contains(obs)
        assert env.unwrapped.goal.size == 2
    finally:
        env.close()


def test_reward_and_termination_are_what_the_observer_sees_and_the_truth_is_in_info():
    from hsgplan.scene_graph.geometric import GeometricSceneGraph
    from hsgplan.scene_graph.geometry import Pose
    from hsgplan.sim.observer import Seen

    top = KITCHEN.surface_rect("shelf_a")
    on_top = ((top.x_min + top.x_max) / 2, (top.y_min + top.y_max) / 2)
    on_top += (top.z + KITCHEN.object_type("butter").height / 2,)

    class Fooled:  # sees the butter on shelf A's top, wherever it is
        name = "fooled"

        def reset(self, scene) -> None:
            pass

        def observe(self, scene) -> Seen:
            sg = scene.scene_graph()
            poses = {n.name: n.pose for n in sg.nodes}
            poses["butter"] = Pose(on_top, poses["butter"].orientation)
            return Seen(GeometricSceneGraph.from_poses(poses, held=sg.held, world=KITCHEN))

    env = KitchenStorageEnv(observer=Fooled(), world=KITCHEN)
    try:
        goal = parse_goal("On(butter, shelf_a) & On(cherries, open_space)", world=KITCHEN)
        env.reset(seed=4, options=ResetOptions(goal))
        _, reward, terminated, truncated, info = env.step(PickParams("alphabet_soup"))
        assert info["outcome"].status.value == "invalid"  # not in the scene: nothing moved
        assert (reward, terminated, truncated) == (1.0, True, False)
        assert info["goal_truly_holds"] is False
    finally:
        env.close()
