"""Agents are a task planner and a motion generator, looked up by name."""

import pytest

from hsgplan.agents.hierarchical import HierarchicalAgent
from hsgplan.agents.registry import (
    AGENTS,
    MOTION_GENERATORS,
    TASK_PLANNERS,
    agent_name,
    agent_parts,
    make_agent,
)
from hsgplan.domain.actions import Pick, Place, Push
from hsgplan.domain.errors import InvalidInputError
from hsgplan.domain.goals import parse_goal
from hsgplan.domain.kitchen import KITCHEN
from hsgplan.domain.parameters import PickParams, PlaceParams, PushParams
from hsgplan.domain.predicates import in_grasp, inside, on
from hsgplan.motion.generator import RandomMotion
from hsgplan.planning.base import TaskDecision
from hsgplan.scene_graph.symbolic import SymbolicSceneGraph
from hsgplan.sim.outcome import Outcome, Status


def test_every_registered_agent_names_registered_parts():
    for planner, motion in AGENTS.values():
        assert planner in TASK_PLANNERS and motion in MOTION_GENERATORS
    assert agent_parts("oracle") == ("fd", "sampler")
    assert agent_parts("regression+gnn") == ("regression", "gnn")
    assert agent_name("regression", motion="mlp") == "regression+mlp"
    assert agent_name("oracle") == "oracle"


@pytest.mark.parametrize("bad", ["wizard", "regression+wand", "magic+gnn"])
def test_unknown_names_are_refused_in_one_line(bad):
    with pytest.raises(InvalidInputError, match="unknown") as e:
        make_agent(bad)
    assert "\n" not in str(e.value)


def test_the_parts_are_composed_and_reset_together():
    agent = make_agent("regression+random")
    assert isinstance(agent, HierarchicalAgent) and agent.name == "regression+random"
    assert agent.planner.name == "regression" and agent.motion.name == "random"


def _scene_graph(shift: float = 0.0):
    """Three objects standing on the table (poses only: no physics is needed to choose bins);
    `shift` moves the last one along x."""
    from hsgplan.scene_graph.geometric import GeometricSceneGraph
    from hsgplan.scene_graph.geometry import Pose

    spots = {"cherries": (0.42, 0.05), "butter": (0.55, -0.10), "popcorn": (0.36 + shift, -0.12)}
    return GeometricSceneGraph.from_poses(
        {
            name: Pose.from_xyz_yaw(x, y, KITCHEN.object_type(name).height / 2, 0.0)
            for name, (x, y) in spots.items()
        },
        world=KITCHEN,
    )


class _Script:
    """A task planner that answers from a list: the composition, not the planning, is tested."""

    name = "script"

    def __init__(self, decisions):
        self.decisions, self.resets = list(decisions), []

    def reset(self, goal, seed):
        self.resets.append(seed)

    def next_action(self, state, goal):
        return self.decisions.pop(0)


def test_the_agent_passes_the_subgoal_and_the_action_to_the_motion_level():
    sg = _scene_graph()
    obj = sg.objects[0]
    decisions = [
        TaskDecision(Pick(obj), in_grasp(obj), 0.001),
        TaskDecision(Place(obj, "shelf_a"), on(obj, "shelf_a"), 0.002),
        TaskDecision(Push(obj, "shelf_a"), inside(obj, "shelf_a"), 0.003),
        TaskDecision(None, None, 0.004, "regression stuck"),
    ]
    agent = HierarchicalAgent("test", _Script(decisions), RandomMotion())
    goal = parse_goal(f"On({obj}, shelf_a)", world=KITCHEN)
    agent.reset(goal, 7)
    assert agent.planner.resets == [7]
    state = SymbolicSceneGraph.initial(sg.objects, world=KITCHEN)
    pick = agent.decide(sg, state, goal)
    assert pick.params == PickParams(obj) and pick.subgoal == in_grasp(obj)
    place = agent.decide(sg, state, goal)
    assert isinstance(place.params, PlaceParams) and place.params.target == "shelf_a"
    assert place.task_seconds == 0.002 and place.subgoal == on(obj, "shelf_a")
    agent.observe(place.params, Outcome(Status.NO_IK, "", 0.0))
    push = agent.decide(sg, state, goal)
    assert isinstance(push.params, PushParams) and push.subgoal == inside(obj, "shelf_a")
    stuck = agent.decide(sg, state, goal)
    assert stuck.action is None and stuck.params is None and stuck.note == "regression stuck"


def test_a_generator_does_not_propose_again_what_failed_in_the_same_scene():
    sg = _scene_graph()
    obj = sg.objects[0]
    motion = RandomMotion()
    motion.reset(3)
    first = motion.propose(sg, Place(obj, "shelf_b"))
    motion.observe(first, Outcome(Status.NO_PATH, "", 0.0))
    motion.reset(3)  # the same episode seed: the same order...
    assert motion.propose(sg, Place(obj, "shelf_b")) == first
    motion.observe(first, Outcome(Status.NO_PATH, "", 0.0))
    motion.rng.seed("random-motion-3")  # ...and after a failure, the next in that order
    second = motion.propose(sg, Place(obj, "shelf_b"))
    assert second != first
    # a failure that may pass when tried again is not remembered
    motion.observe(second, Outcome(Status.DROPPED, "", 0.0))
    motion.rng.seed("random-motion-3")
    assert motion.propose(sg, Place(obj, "shelf_b")) == second
    # in a scene where something moved, what failed elsewhere may be proposed again
    moved = _scene_graph(shift=0.03)
    motion.rng.seed("random-motion-3")
    assert motion.propose(moved, Place(obj, "shelf_b")) == first


def test_a_pick_that_failed_is_offered_again_for_the_task_level_to_judge():
    sg = _scene_graph()
    obj = sg.objects[0]
    motion = RandomMotion()
    motion.reset(0)
    pick = motion.propose(sg, Pick(obj))
    motion.observe(pick, Outcome(Status.NO_IK, "", 0.0))
    assert motion.propose(sg, Pick(obj)) == pick  # its only choice: single shot, no None


def test_a_push_with_no_parameters_left_takes_the_object_up_to_put_it_elsewhere():
    # the oracle's recovery: no push works from where the can stands, so it is picked up and
    # the next place before a push keeps away from that spot
    from hsgplan.motion.sampler import AVOID_RADIUS, GeometricSampler, place_xy
    from hsgplan.scene_graph.geometric import GeometricSceneGraph
    from hsgplan.scene_graph.geometry import Pose

    can, spot = "alphabet_soup", (0.30, 0.38)
    standing = GeometricSceneGraph.from_poses(
        {can: Pose.from_xyz_yaw(*spot, KITCHEN.object_type(can).height / 2, 0.0)}, world=KITCHEN
    )
    push = TaskDecision(Push(can, "shelf_a"), inside(can, "shelf_a"), 0.001)
    sampler = GeometricSampler()
    agent = HierarchicalAgent("test", _Script([push] * 12), sampler)
    goal = parse_goal(f"In({can}, shelf_a)", world=KITCHEN)
    agent.reset(goal, 0)
    state = SymbolicSceneGraph.initial(standing.objects, world=KITCHEN)
    tried = []
    while isinstance((d := agent.decide(standing, state, goal)).params, PushParams):
        tried.append(d.params)
        agent.observe(d.params, Outcome(Status.NO_PATH, "the hand would hit something", 0.0))
    assert tried and len(set(tried)) == len(tried)  # every push once
    assert d.action == Pick(can) and d.params == PickParams(can) and d.subgoal == in_grasp(can)
    held = GeometricSceneGraph(standing.nodes, held=can, world=KITCHEN)
    place = sampler.propose(held, Place(can, "prepush_a"), Push(can, "shelf_a"))
    x, y = place_xy(can, "prepush_a", place.x_bin, place.y_bin, world=KITCHEN)
    assert ((x - spot[0]) ** 2 + (y - spot[1]) ** 2) ** 0.5 >= AVOID_RADIUS


def test_checkpoints_that_know_names_are_refused_a_scene_of_other_names(tmp_path):
    import json

    from hsgplan.agents.registry import check_reads
    from hsgplan.domain.layouts import random_layout

    new = random_layout(KITCHEN, 0, 0, new_objects=True)
    task, motion = tmp_path / "task", tmp_path / "place-gnn"
    (task / "preimage").mkdir(parents=True)
    motion.mkdir()
    (task / "preimage" / "config.json").write_text(json.dumps({"features": "geometry"}))
    (motion / "config.json").write_text(json.dumps({"model": "gnn"}))  # saved before features
    check_reads([task], new, "new.toml")
    check_reads([task, motion], KITCHEN, None)  # the kitchen's names: any network reads them
    with pytest.raises(InvalidInputError, match="place-gnn' know the kitchen's objects"):
        check_reads([task, motion], new, "new.toml")


def test_the_place_for_push_reads_the_gnns_folders_and_refuses_networks_not_on_every_trial(
    tmp_path,
):
    import shutil

    from hsgplan.agents.registry import agent_checkpoints, make_motion
    from hsgplan.paths import MOTION_CHECKPOINTS, shipped

    motion = shipped(MOTION_CHECKPOINTS)
    assert make_motion("gnn-next-checked", motion).place_for_push
    assert not make_motion("gnn", motion).place_for_push
    assert not make_motion("gnn-checked", motion).place_for_push
    from hsgplan.motion.interface import DRY_RUNS

    assert make_motion("gnn-next-checked", motion).dry_runs == DRY_RUNS
    assert make_motion("gnn-checked", motion).dry_runs == DRY_RUNS
    assert make_motion("gnn", motion).dry_runs == 0
    with pytest.raises(InvalidInputError, match="unknown motion generator 'gnn-next'"):
        make_motion("gnn-next", motion)  # no gain alone on the tune split: not offered
    reads = agent_checkpoints("regression+gnn-next-checked", motion_checkpoints=motion)
    assert reads[1:] == agent_checkpoints("regression+gnn", motion_checkpoints=motion)[1:]
    assert {p.name for p in reads[1:]} == {"place-gnn", "push-gnn"}
    # the paper's cross-entropy networks: scores are per-scene logits, no chances of success
    for kind in ("place", "push"):
        shutil.copytree(motion / f"{kind}-gnn", tmp_path / f"{kind}-gnn")
    shutil.rmtree(tmp_path / "place-gnn")
    shutil.copytree(motion / "place-gnn-paper", tmp_path / "place-gnn")
    with pytest.raises(InvalidInputError, match="trained with ce"):
        make_motion("gnn-next-checked", tmp_path)
    assert make_motion("gnn", tmp_path).name == "gnn"
