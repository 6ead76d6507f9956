"""An episode as a rerun recording (`.rrd`): the true scene, the robot's belief beside it, the
cameras and every decision, on a `step` timeline and a `frame` timeline (arm waypoints).

Entity paths (docs/recordings.md):

- `world/arena/...`: the table, the shelves' boards and the regions (static; known exactly).
- `world/true/NAME`: each object as its box or cylinder in its colour, at the simulator's pose.
- `world/believed/NAME`: where the robot believes each object is, in its colour when the
  belief is sure of it and orange when unsure (seen by one view, or not this time); objects
  never seen are left out. Seeing with the ground truth, the belief is the truth.
- `robot/links/LINK/...`: the arm's meshes at every recorded frame; `robot/path`: the hand's
  path as planned for the step (transit, approach, push line).
- `cameras/NAME`: a camera's pose and intrinsics, `cameras/NAME/image` its picture at each
  look, with f_p's keypoints (`.../keypoints`) and detected cuboids (`.../detections`).
- `plan/subgoal`, `plan/primitive`, `plan/graph` (the symbolic scene graph, nodes and edges),
  `plan/literals`; `log/steps`: each step's primitive, outcome and what it truly disturbed.

rerun-sdk is an optional extra (`pip install 'hsgplan[rerun]'`); `available()` says whether it
is installed. Recording changes nothing in the episode: the same seed gives the same record.
"""

from __future__ import annotations

import importlib.util
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from hsgplan.agents.base import Decision
from hsgplan.domain.world import Kind, ObjectType, World
from hsgplan.perception.draw import EDGES, cuboid_pixels
from hsgplan.perception.keypoints import PinholeCamera
from hsgplan.scene_graph.geometry import Pose
from hsgplan.sim.render import DEMO_CAMERAS, Camera
from hsgplan.sim.scene import Scene
from hsgplan.sim.sensing import CameraObserver, Look, Seen
from hsgplan.sim.visuals import BOX, CYLINDER, SPHERE, VisualPart, link_pose, links_of, visual_parts

if TYPE_CHECKING:
    from hsgplan.evaluation.episode import StepRecord
    from hsgplan.sim.env import KitchenStorageEnv, Observation

APP = "hsgplan"
EVERY = 3  # arm waypoints between two recorded frames
UNSURE = (255, 140, 0, 255)
JPEG = 85


def available() -> bool:
    return importlib.util.find_spec("rerun") is not None


def _rgba(c) -> list[int]:
    return [round(255 * v) for v in c]


def _transform(pose: Pose):
    import rerun as rr

    return rr.Transform3D(
        translation=pose.position, quaternion=rr.Quaternion(xyzw=pose.orientation)
    )


def _shape(part: VisualPart):
    """The rerun archetype drawing one visual part in its own frame."""
    import rerun as rr

    colour = _rgba(part.rgba)
    if part.kind == BOX:
        return rr.Boxes3D(
            half_sizes=[np.asarray(part.size) / 2], colors=[colour], fill_mode="solid"
        )
    if part.kind == CYLINDER:
        return rr.Cylinders3D(
            lengths=[part.size[0]], radii=[part.size[1]], colors=[colour], fill_mode="solid"
        )
    if part.kind == SPHERE:
        return rr.Ellipsoids3D(half_sizes=[[part.size[0]] * 3], colors=[colour], fill_mode="solid")
    return rr.Asset3D(path=part.mesh, albedo_factor=colour)


def _object_shape(t: ObjectType, colour, label: str | None = None):
    """An object as its type's box or cylinder, centred on its pose."""
    import rerun as rr

    labels = None if label is None else [label]
    if t.kind is Kind.CAN:
        return rr.Cylinders3D(
            lengths=[t.size[2]],
            radii=[t.size[0] / 2],
            colors=[colour],
            labels=labels,
            fill_mode="solid",
        )
    return rr.Boxes3D(
        half_sizes=[np.asarray(t.size) / 2], colors=[colour], fill_mode="solid", labels=labels
    )


class EpisodeRecording:
    """Writes one episode into `path` as it runs; `run_demo` calls it at the start, at every
    arm waypoint, at every decision and after every step, and the camera observer's looks
    reach it through `observe` (see `RecordedLooks`).

    Args:
        path: the `.rrd` file (written as the episode goes, whole at `close`).
        goal: the goal's text, shown as the recording's first log line.
        seed: the episode's seed.
        every: arm waypoints between two recorded frames.
    """

    def __init__(self, path: Path, goal: str, seed: int, every: int = EVERY) -> None:
        import rerun as rr

        path.parent.mkdir(parents=True, exist_ok=True)
        self.rec = rr.RecordingStream(APP, recording_id=f"episode-{seed}")
        self.rec.save(str(path))
        self.goal, self.seed, self.every = goal, seed, every
        self.frame = 0
        self.step = 0
        self.waypoints = 0
        self.env: KitchenStorageEnv | None = None
        self._links: tuple[int, ...] = ()
        self._kinematics: Scene | None = None  # a model of the arm, for planned paths
        self._believed: set[str] = set()

    # --- time -------------------------------------------------------------------------
    def _at(self) -> None:
        self.rec.set_time("step", sequence=self.step)
        self.rec.set_time("frame", sequence=self.frame)

    def _log(self, path: str, *archetypes, static: bool = False) -> None:
        self.rec.log(path, *archetypes, static=static)

    # --- hooks --------------------------------------------------------------------------
    def start(self, env: KitchenStorageEnv, obs: Observation) -> None:
        """The static scene (arena, object and robot shapes, cameras), then the start state."""
        import rerun as rr

        self.env = env
        scene = env.scene
        self.rec.send_blueprint(blueprint())
        self._log("/", rr.ViewCoordinates.RIGHT_HAND_Z_UP, static=True)
        for k, body in enumerate((*scene.arena.obstacles, *scene.arena.markers)):
            pose = link_pose(scene.bc, body, -1)
            for j, part in enumerate(visual_parts(scene.bc, body)):
                path = f"world/arena/body_{k}/part_{j}"
                self._log(path, _transform(_compose(pose, part.local)), _shape(part), static=True)
        for name in scene.objects:
            t = scene.world.object_type(name)
            self._log(f"world/true/{name}", _object_shape(t, _rgba(t.color), name), static=True)
        parts = visual_parts(scene.bc, scene.robot.body)
        self._links = links_of(parts)
        for j, part in enumerate(parts):
            path = f"robot/links/link_{part.link}/part_{j}"
            self._log(path, _transform(part.local), _shape(part), static=True)
        for name, camera in DEMO_CAMERAS.items():
            self._camera(f"demo_{name}", camera)
        if isinstance(env.observer, CameraObserver):
            for k, camera in enumerate(env.observer.cameras):
                self._camera(f"view_{k}", camera)
        self._at()
        self._log("log/steps", rr.TextLog(f"goal: {self.goal} (seed {self.seed})", level="INFO"))
        self._true_scene()
        self._state(obs)

    def on_frame(self) -> None:
        self.waypoints += 1
        if self.waypoints % self.every == 0:
            self.frame += 1
            self._at()
            self._true_scene()

    def decide(self, step: int, d: Decision, params: str) -> None:
        import rerun as rr

        self.step = step
        self.frame += 1
        self._at()
        self._log("plan/subgoal", rr.TextDocument(str(d.subgoal or "")))
        self._log("plan/primitive", rr.TextDocument(params))

    def stepped(self, record: StepRecord, obs: Observation) -> None:
        import rerun as rr

        self.frame += 1
        self._at()
        moved = ", ".join(
            f"{m.obj} {100 * m.moved:.1f} cm" + (f" ({m.phase})" if m.phase else "")
            for m in record.disturbed
        )
        line = f"step {record.step}: {record.params} -> {record.status}"
        line += f" ({record.detail})" if record.detail else ""
        line += f"; disturbed {moved}" if moved else ""
        line += f"; dragged {100 * record.dragged:.1f} cm after release" if record.dragged else ""
        level = "INFO" if record.status == "success" else "WARN"
        self._log("log/steps", rr.TextLog(line, level=level))
        self._path()
        self._true_scene()
        self._state(obs)

    def observe(self, look: Look, seen: Seen, detections) -> None:
        """A camera observer's look: each view's image, f_p's keypoints and detections."""
        import rerun as rr

        self._at()
        world = seen.scene_graph.world
        for k, (image, camera) in enumerate(zip(look.images, look.cameras, strict=True)):
            base = f"cameras/view_{k}/image"
            self._log(base, rr.Image(image).compress(jpeg_quality=JPEG))
            pinhole = PinholeCamera.of(camera)
            points, labels, strips = [], [], []
            for d in detections:
                for v in d.keypoints:
                    if np.allclose(v.camera.world_to_camera, pinhole.world_to_camera):
                        seen_px = v.pixels[~np.isnan(v.pixels).any(axis=1)]
                        points.extend(seen_px.tolist())
                        labels.extend([d.type_name] * len(seen_px))
                px = cuboid_pixels(world.object_type(d.type_name), d.pose, pinhole)
                if px is not None:
                    strips.extend([px[a], px[b]] for a, b in EDGES)
            self._log(f"{base}/keypoints", rr.Points2D(points, labels=labels or None, radii=2.0))
            self._log(f"{base}/detections", rr.LineStrips2D(strips, colors=[40, 220, 60]))

    def close(self) -> None:
        if self._kinematics is not None:
            self._kinematics.close()
        self.rec.flush()
        self.rec.disconnect()

    # --- what is logged -------------------------------------------------------------------
    def _camera(self, name: str, camera: Camera) -> None:
        import rerun as rr

        pinhole = PinholeCamera.of(camera)
        to_world = np.linalg.inv(pinhole.world_to_camera)
        self._log(
            f"cameras/{name}",
            rr.Transform3D(translation=to_world[:3, 3], mat3x3=to_world[:3, :3]),
            static=True,
        )
        self._log(
            f"cameras/{name}/image",
            rr.Pinhole(
                image_from_camera=pinhole.matrix,
                resolution=[camera.width, camera.height],
                camera_xyz=rr.ViewCoordinates.RDF,
                image_plane_distance=0.15,
            ),
            static=True,
        )

    def _true_scene(self) -> None:
        scene = self.env.scene
        for name, pose in scene.poses().items():
            self._log(f"world/true/{name}", _transform(pose))
        for link in self._links:
            pose = link_pose(scene.bc, scene.robot.body, link)
            self._log(f"robot/links/link_{link}", _transform(pose))

    def _state(self, obs: Observation) -> None:
        """The belief and the symbolic scene graph after a step (or at the start); the demo
        views' pictures."""
        import rerun as rr

        unsure = set(obs.uncertain)
        now = set()
        for node in obs.scene_graph.nodes:
            t = obs.scene_graph.world.object_type(node.name)
            colour = UNSURE if node.name in unsure else _rgba(t.color)
            label = f"{node.name} (unsure)" if node.name in unsure else node.name
            path = f"world/believed/{node.name}"
            self._log(path, _transform(node.pose), _object_shape(t, colour, label))
            now.add(node.name)
        for gone in self._believed - now:
            self._log(f"world/believed/{gone}", rr.Clear(recursive=True))
        self._believed = now
        state = obs.symbols.state
        self._log("plan/literals", rr.TextDocument("\n".join(map(str, state.sorted_literals()))))
        nodes, edges = _graph(state)
        self._log(
            "plan/graph",
            rr.GraphNodes(node_ids=nodes, labels=nodes),
            rr.GraphEdges(edges=edges, graph_type="directed"),
        )
        for name, camera in DEMO_CAMERAS.items():
            image = self.env.render(camera)
            self._log(f"cameras/demo_{name}/image", rr.Image(image).compress(jpeg_quality=JPEG))

    def _path(self) -> None:
        """The hand's planned path for the step just run, by the arm's kinematics."""
        import rerun as rr

        plan = self.env.last_plan
        if plan is None:
            self._log("robot/path", rr.Clear(recursive=False))
            return
        if self._kinematics is None:
            self._kinematics = Scene((), visuals=False, world=self.env.scene.world)
        robot = self._kinematics.robot
        joints = (*plan.path, plan.q_above, *plan.descent, plan.q_at, *plan.line)
        points = []
        for q in joints:
            robot.set_q(np.asarray(q))
            points.append(robot.tcp().position)
        self._log("robot/path", rr.LineStrips3D([points], colors=[[30, 120, 255]], radii=0.004))


def blueprint():
    """The viewer's layout: the truth and the belief side by side in 3D (the arena and the
    robot in both), the cameras' pictures, the plan and the log beneath."""
    import rerun.blueprint as rrb

    shared = ["world/arena/**", "robot/**"]
    return rrb.Blueprint(
        rrb.Vertical(
            rrb.Horizontal(
                rrb.Spatial3DView(name="truth", contents=["world/true/**", *shared]),
                rrb.Spatial3DView(name="belief", contents=["world/believed/**", *shared]),
            ),
            rrb.Horizontal(
                rrb.Spatial2DView(name="front", origin="cameras/demo_front/image"),
                rrb.Vertical(
                    rrb.Spatial2DView(name="shelf A's side", origin="cameras/demo_side_a/image"),
                    rrb.Spatial2DView(name="shelf B's side", origin="cameras/demo_side_b/image"),
                ),
                rrb.GraphView(name="symbolic scene graph", origin="plan/graph"),
                rrb.Vertical(
                    rrb.TextDocumentView(name="subgoal", origin="plan/subgoal"),
                    rrb.TextDocumentView(name="primitive", origin="plan/primitive"),
                    rrb.TextLogView(name="steps", origin="log"),
                ),
            ),
            row_shares=[3, 2],
        ),
        collapse_panels=True,
    )


def _compose(frame: Pose, local: Pose) -> Pose:
    return Pose.from_matrix(frame.matrix() @ local.matrix())


def _graph(state) -> tuple[list[str], list[tuple[str, str]]]:
    """The symbolic scene graph's nodes and its edges (On, In: object to what holds it;
    InGrasp: object to the gripper)."""
    nodes: list[str] = []
    edges: list[tuple[str, str]] = []
    for lit in state.sorted_literals():
        args = list(lit.args)
        if lit.predicate.value == "InGrasp":
            args.append("gripper")
        for a in args:
            if a not in nodes:
                nodes.append(a)
        if len(args) == 2:
            edges.append((args[0], args[1]))
    return nodes, edges


class RecordedLooks:
    """A camera observer whose looks are also written into a recording: the images, and
    f_p's keypoints and detections where the observer keeps them (`detections`)."""

    def __init__(self, observer: CameraObserver, recording: EpisodeRecording) -> None:
        self.inner = observer
        self.recording = recording
        self.name = observer.name
        self.cameras = observer.cameras

    def start(self, objects: tuple[str, ...], world: World) -> None:
        self.inner.start(objects, world)

    def look(self, look: Look) -> Seen:
        seen = self.inner.look(look)
        self.recording.observe(look, seen, getattr(self.inner, "detections", ()))
        return seen
