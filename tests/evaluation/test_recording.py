"""A rerun recording of an episode: read back with rerun's own reader, it holds the true scene,
the belief, the robot, the cameras and every step; recording changes nothing in the episode."""

from __future__ import annotations

import shutil
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from hsgplan.domain.goals import parse_goal
from hsgplan.domain.kitchen import KITCHEN
from hsgplan.evaluation.recording import EpisodeRecording
from hsgplan.perception.detection import Detection
from hsgplan.perception.keypoints import PinholeCamera, in_world
from hsgplan.perception.pnp import ViewKeypoints
from hsgplan.perception.vocabulary import kitchen_vocabulary
from hsgplan.scene_graph.geometric import GeometricSceneGraph
from hsgplan.scene_graph.geometry import Pose
from hsgplan.sim.sensing import Look, Seen

rerun = pytest.importorskip("rerun")
from rerun.chunk import RrdReader  # noqa: E402

VIEWS = kitchen_vocabulary().views  # the shipped f_p's fixed cameras

GOAL = "On(butter, shelf_a) & On(cherries, butter)"
TIMES = ("seconds", "task_seconds", "motion_seconds", "execution_seconds")


def _entities(path: Path) -> dict[str, set[str]]:
    """Each entity path in the recording and the components logged to it."""
    chunks = RrdReader(path).store().stream().to_chunks()
    out: dict[str, set[str]] = {}
    for chunk in chunks:
        columns = chunk.to_record_batch().schema.names
        out.setdefault(str(chunk.entity_path), set()).update(columns)
    return out


def _steps(path: Path, entity: str) -> list[int]:
    """The `step` timeline's values at which `entity` was logged."""
    values: list[int] = []
    for chunk in RrdReader(path).store().stream().to_chunks():
        if str(chunk.entity_path) != entity:
            continue
        batch = chunk.to_record_batch()
        if "step" in batch.schema.names:
            values += [int(v) for v in batch.column("step").to_pylist()]
    return sorted(values)


def _untimed(record) -> dict:
    d = record.to_json()
    d["steps"] = [{k: v for k, v in s.items() if k not in TIMES} for s in d["steps"]]
    return {k: v for k, v in d.items() if k not in TIMES and "seconds" not in k}


@pytest.mark.slow
def test_an_episode_recorded_holds_truth_belief_robot_cameras_and_every_step(tmp_path):
    from hsgplan.evaluation.demo import run_demo

    goal = parse_goal(GOAL, world=KITCHEN)
    kw = {"scale": 0.25, "frame_every": 1000}
    rrd = tmp_path / "rec" / "episode.rrd"
    recorded = run_demo("oracle", goal, 4, tmp_path / "rec", recording=rrd, **kw)
    plain = run_demo("oracle", goal, 4, tmp_path / "plain", **kw)
    assert _untimed(recorded) == _untimed(plain)  # recording changes nothing
    assert recorded.steps

    entities = _entities(rrd)
    for obj in goal.objects:
        assert f"/world/true/{obj}" in entities
        assert f"/world/believed/{obj}" in entities
    assert any(e.startswith("/world/arena/") for e in entities)
    links = [e for e in entities if e.startswith("/robot/links/")]
    assert any("Asset3D:blob" in entities[e] for e in links)  # the arm's meshes
    assert any("Transform3D:translation" in entities[e] for e in links)  # and where they are
    assert "LineStrips3D:strips" in entities["/robot/path"]
    assert "EncodedImage:blob" in entities["/cameras/demo_front/image"]
    assert "Pinhole:image_from_camera" in entities["/cameras/demo_side_b/image"]
    assert "GraphEdges:edges" in entities["/plan/graph"]
    # one log line for the start and one for every step, on the step timeline
    assert _steps(rrd, "/log/steps") == list(range(len(recorded.steps) + 1))
    assert max(_steps(rrd, "/plan/primitive")) == len(recorded.steps)

    rerun_cli = shutil.which("rerun", path=str(Path(sys.executable).parent))
    if rerun_cli:
        done = subprocess.run([rerun_cli, "rrd", "verify", str(rrd)], capture_output=True)
        assert done.returncode == 0, done.stderr.decode()


def test_a_look_is_recorded_with_its_images_keypoints_and_detected_cuboids(tmp_path):
    rrd = tmp_path / "look.rrd"
    cameras = VIEWS[:2]
    pose = Pose((0.5, 0.0, 0.012))
    pinhole = PinholeCamera.of(cameras[0])
    pixels = pinhole.project(in_world(KITCHEN.object_type("butter"), pose))
    pixels[3] = np.nan  # a keypoint the network did not find: not drawn
    seen_by = ViewKeypoints(pinhole, pixels)
    detection = Detection("butter", pose, 0.9, 1, 0.5, keypoints=(seen_by,))
    images = np.zeros((2, cameras[0].height, cameras[0].width, 3), np.uint8)
    look = Look(images, cameras, np.zeros(7))
    seen = Seen(GeometricSceneGraph.from_poses({"butter": pose}, world=KITCHEN))

    recording = EpisodeRecording(rrd, "On(butter, shelf_a)", 0)
    recording.observe(look, seen, (detection,))
    recording.close()

    entities = _entities(rrd)
    for k in range(2):
        assert "EncodedImage:blob" in entities[f"/cameras/view_{k}/image"]
    chunk = next(
        c
        for c in RrdReader(rrd).store().stream().to_chunks()
        if str(c.entity_path) == "/cameras/view_0/image/keypoints"
    )
    points = chunk.to_record_batch().column("Points2D:positions").to_pylist()[0]
    assert len(points) == 8  # 9 keypoints, one not found
    strips = [
        c.to_record_batch().column("LineStrips2D:strips").to_pylist()[0]
        for c in RrdReader(rrd).store().stream().to_chunks()
        if str(c.entity_path).endswith("/detections")
    ]
    assert [len(s) for s in strips] == [12, 12]  # the cuboid's 12 edges in each view
