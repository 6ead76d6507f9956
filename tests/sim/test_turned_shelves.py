"""Under physics, in the example scene of shelves turned 0, 30 and 90 degrees: a can placed on
a turned top and pushed into a turned shelf ends where f_m says it was meant to."""

from hsgplan.domain.parameters import PickParams, PlaceParams
from hsgplan.domain.predicates import inside, on
from hsgplan.domain.scene_file import read_world
from hsgplan.motion.sampler import push_candidates
from hsgplan.paths import SCENES, home
from hsgplan.scene_graph.geometry import Pose
from hsgplan.scene_graph.symbol_mapping import map_symbols
from hsgplan.sim.primitives import execute
from hsgplan.sim.scene import Scene

WORLD = read_world(home() / SCENES / "examples" / "three-shelves.toml")


def test_cans_go_onto_a_turned_top_and_into_turned_shelves():
    cans = ("tomato_soup", "alphabet_soup")
    x, y = WORLD.regions["open_space"].center
    poses = {
        c: Pose.from_xyz_yaw(x, y + 0.1 * k - 0.05, WORLD.object_type(c).height / 2 + 0.001, 0.0)
        for k, c in enumerate(cans)
    }
    with Scene(list(cans), seed=0, poses=poses, world=WORLD) as scene:
        scene.settle()
        assert execute(scene, PickParams("tomato_soup")).ok
        assert execute(scene, PlaceParams("tomato_soup", "shelf_b", 5, 5)).ok  # 30 degrees
        assert map_symbols(scene.scene_graph()).state.holds(on("tomato_soup", "shelf_b"))
        for can, shelf in zip(cans, ("shelf_c", "shelf_b"), strict=True):  # 90, 30 degrees
            assert execute(scene, PickParams(can)).ok
            prepush = WORLD.shelves[shelf].prepush
            assert execute(scene, PlaceParams(can, prepush, 5, 5)).ok
            out = execute(scene, push_candidates(scene.scene_graph(), can, shelf)[0])
            assert out.ok, out
            assert map_symbols(scene.scene_graph()).state.holds(inside(can, shelf))
            assert WORLD.shelves[shelf].interior.contains(*scene.pose(can).position[:2])
