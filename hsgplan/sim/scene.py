"""A kitchen-storage scene built from parts: arena, robot, objects, in one physics client.

The client is created here and passed to every part; nothing in the package keeps a global one.
"""

from __future__ import annotations

import contextlib
import os
import sys
from collections.abc import Iterable, Iterator

import numpy as np
import pybullet
from pybullet_utils.bullet_client import BulletClient

from hsgplan.domain.scene import World
from hsgplan.scene_graph.geometric import GeometricSceneGraph
from hsgplan.scene_graph.geometry import Pose
from hsgplan.sim.actuation import rests_in_hand
from hsgplan.sim.arena import Arena, build_arena
from hsgplan.sim.bodies import spawn_object
from hsgplan.sim.collision import CollisionChecker
from hsgplan.sim.hand_ghost import HandGhost
from hsgplan.sim.motion import MotionPlanner
from hsgplan.sim.plan_rules import SHIPPED as PLAN_RULES
from hsgplan.sim.robot import Panda

TIME_STEP = 1.0 / 240.0
REST_SPEED = 0.01  # m/s: below this every object counts as at rest
MAX_SETTLE_STEPS = 480


@contextlib.contextmanager
def _quiet_stdout() -> Iterator[None]:
    """PyBullet's C code prints `argv[0]=` to the process's stdout when it connects, which
    would corrupt a command's JSON output: stdout is pointed at /dev/null meanwhile."""
    sys.stdout.flush()
    saved = os.dup(1)
    devnull = os.open(os.devnull, os.O_WRONLY)
    try:
        os.dup2(devnull, 1)
        yield
    finally:
        os.dup2(saved, 1)
        os.close(devnull)
        os.close(saved)


class FastClient(BulletClient):
    """A `BulletClient` that keeps the functions it hands out: the base class builds a new
    `functools.partial` on every attribute lookup, which measured about a tenth of a place
    primitive's time (collision checks call it hundreds of thousands of times)."""

    def __getattr__(self, name: str):
        attribute = super().__getattr__(name)
        if name != "disconnect" and callable(attribute):
            setattr(self, name, attribute)
        return attribute


class Scene:
    """The world of one episode.

    Args:
        objects: object instance names; bodies are created at `poses` (or parked off-scene
            until `set_pose`).
        seed: seeds inverse-kinematics restarts and motion planning.
        visuals: load the arm's visual meshes, for pictures of the scene (`Panda`); a scene
            nothing pictures builds faster without them and behaves the same.
        world: the table, shelves and object types it is built from.

    Its `plan_rules` (`sim.plan_rules`, the shipped ones unless a run sets them) are the
    motion planner's.
    """

    def __init__(
        self,
        objects: Iterable[str],
        seed: int = 0,
        poses: dict[str, Pose] | None = None,
        visuals: bool = True,
        *,
        world: World,
    ):
        self.world = world
        with _quiet_stdout():
            self.bc = FastClient(connection_mode=pybullet.DIRECT)
        self.bc.setGravity(0, 0, -9.81)
        self.bc.setTimeStep(TIME_STEP)
        self.arena: Arena = build_arena(self.bc, world)
        self.robot = Panda(self.bc, visuals)
        names = world.sort_objects(objects)
        poses = poses or {}
        self.bodies: dict[str, int] = {}
        for name in names:
            pose = poses.get(name, self._parking(name))
            self.bodies[name] = spawn_object(self.bc, world.object_type(name), pose)
        self.rng = np.random.default_rng(seed)
        self.seed = seed
        self.plan_rules = PLAN_RULES
        self._closed_hand: HandGhost | None = None

    @property
    def objects(self) -> tuple[str, ...]:
        return tuple(self.bodies)

    def close(self) -> None:
        self.bc.disconnect()

    def __enter__(self) -> Scene:
        return self

    def __exit__(self, *exc) -> None:
        self.close()

    # --- poses -----------------------------------------------------------------------------

    def pose(self, name: str) -> Pose:
        pos, orn = self.bc.getBasePositionAndOrientation(self.bodies[name])
        return Pose(tuple(pos), tuple(orn))

    def set_pose(self, name: str, pose: Pose) -> None:
        body = self.bodies[name]
        self.bc.resetBasePositionAndOrientation(body, pose.position, pose.orientation)
        self.bc.resetBaseVelocity(body, (0, 0, 0), (0, 0, 0))

    def _parking(self, name: str) -> Pose:
        i = len(self.bodies) if name not in self.bodies else list(self.bodies).index(name)
        return Pose.from_xyz_yaw(-0.6 - 0.15 * (i % 4), -0.4 + 0.2 * (i // 4), 0.5)

    def add_object(self, name: str) -> None:
        """Bring a new object instance into the scene, parked until `set_pose`."""
        if name in self.bodies:
            raise ValueError(f"'{name}' is already in the scene")
        self.bodies[name] = spawn_object(self.bc, self.world.object_type(name), self._parking(name))
        self.bodies = {n: self.bodies[n] for n in self.world.sort_objects(self.bodies)}

    def remove_object(self, name: str) -> None:
        if self.bodies.get(name) == self.robot.held_body:
            self.robot.detach()
        self.bc.removeBody(self.bodies.pop(name))

    def park(self, name: str) -> None:
        """Move an object out of the workspace (behind the robot, in the air, held still)."""
        self.set_pose(name, self._parking(name))

    def poses(self) -> dict[str, Pose]:
        return {n: self.pose(n) for n in self.bodies}

    def held(self) -> str | None:
        """The object that rose with the hand: fixed to it by the grasp's constraint, or
        lifted by friction alone and not yet slipped out (`feel_hold`)."""
        for name, body in self.bodies.items():
            if body == self.robot.held_body:
                return name
        return None

    def feel_hold(self) -> None:
        """After the arm moved under physics: an object the fingers lifted by friction alone
        that no longer rests in the hand has slipped out, and is held no more."""
        robot = self.robot
        body = robot.held_body
        if body is not None and robot.grasp_constraint is None and not rests_in_hand(robot, body):
            robot.detach()

    def scene_graph(self) -> GeometricSceneGraph:
        """s_g from the simulator's ground truth."""
        return GeometricSceneGraph.from_poses(self.poses(), held=self.held(), world=self.world)

    # --- physics ---------------------------------------------------------------------------

    def settle(self, max_steps: int = MAX_SETTLE_STEPS, min_steps: int = 24) -> int:
        """Step physics with the arm held still until every free object is at rest."""
        self.robot.hold_position()
        for step in range(1, max_steps + 1):
            self.bc.stepSimulation()
            if step >= min_steps and step % 12 == 0 and self.at_rest():
                return step
        return max_steps

    @contextlib.contextmanager
    def asleep(self, awake: Iterable[str]) -> Iterator[None]:
        """Every object but those named sleeps meanwhile: a resting object costs the solver as
        much as a moving one (measured: 6 resting objects quadruple a physics step), and a
        sleeping one nothing until something touches it, which wakes it. Afterwards all are
        awake and never sleep, PyBullet's default."""
        keep = set(awake)
        sleepers = [b for n, b in self.bodies.items() if n not in keep]
        for b in sleepers:
            self.bc.changeDynamics(b, -1, activationState=self.bc.ACTIVATION_STATE_ENABLE_SLEEPING)
            self.bc.changeDynamics(b, -1, activationState=self.bc.ACTIVATION_STATE_SLEEP)
        try:
            yield
        finally:
            for b in sleepers:
                self.bc.changeDynamics(b, -1, activationState=self.bc.ACTIVATION_STATE_WAKE_UP)
                self.bc.changeDynamics(
                    b, -1, activationState=self.bc.ACTIVATION_STATE_DISABLE_SLEEPING
                )

    def at_rest(self) -> bool:
        for body in self.bodies.values():
            if body == self.robot.held_body:
                continue
            lin, ang = self.bc.getBaseVelocity(body)
            if np.linalg.norm(lin) > REST_SPEED or np.linalg.norm(ang) > 10 * REST_SPEED:
                return False
        return True

    def snapshot(self) -> int:
        return self.bc.saveState()

    def restore(self, state: int) -> None:
        """Back to a snapshot; the motors, which a snapshot does not hold, hold still there.
        A restored body's collision shape is put where the state puts it: restoring leaves
        it where it was, which a body asleep meanwhile keeps (measured: closing fingers went
        through an object there)."""
        bc = self.bc
        bc.restoreState(state)
        self.robot.hold_position()
        for b in self.bodies.values():
            pose, velocity = bc.getBasePositionAndOrientation(b), bc.getBaseVelocity(b)
            bc.resetBasePositionAndOrientation(b, *pose)
            bc.resetBaseVelocity(b, *velocity)

    def back_to(self, state: int, grip: tuple[int | None, bool]) -> None:
        """Back to a snapshot with the hand's hold as `grip` (`Panda.grip`) says: a grasp's
        constraint is no part of a saved state, so the one made since is let go first and
        the snapshot's made again after."""
        self.robot.detach()
        self.restore(state)
        self.robot.regrip(grip)

    # --- planning queries --------------------------------------------------------------------

    def obstacles(self, ignore: Iterable[str] = ()) -> tuple[int, ...]:
        """The arena's bodies and every object's but those ignored."""
        skip = {self.bodies[n] for n in ignore}
        return self.arena.obstacles + tuple(b for b in self.bodies.values() if b not in skip)

    def checker(self, ignore: Iterable[str] = (), margin: float | None = None) -> CollisionChecker:
        """A collision checker against the arena and every object but those ignored."""
        obstacles = self.obstacles(ignore)
        if margin is None:
            return CollisionChecker(self.robot, obstacles)
        return CollisionChecker(self.robot, obstacles, margin)

    def motion_planner(self, ignore: Iterable[str] = ()) -> MotionPlanner:
        return MotionPlanner(self.checker(ignore))

    def closed_hand(self) -> HandGhost:
        """The hand with closed fingers on its own (made when first asked for: a scene that
        never pushes never has one)."""
        if self._closed_hand is None:
            self._closed_hand = HandGhost(self.robot, opening=0.0)
        return self._closed_hand
