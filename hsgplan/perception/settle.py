"""Estimated poses made to rest, as objects in this world do: a physical prior after PnP.

Objects here stand upright where they were set down, on the table, a shelf's top board or
another object. PnP on a few pixels of keypoints leaves the pose a little tilted and floating
or sunk by a centimetre or two, which f_m's tolerances (1.5 cm of contact, 14 degrees of tilt)
can read as another support or a toppled object. So each estimate within `UPRIGHT_TILT` of
upright is turned upright about its own yaw, and then moved onto the support under its centre
whose top is nearest its bottom, if within `SNAP_Z`: the table, a shelf's top board, or an
object settled before it (lowest first). An estimate that fits none is left as it is: what f_p
saw, for f_m to report.
"""

from __future__ import annotations

import math

import numpy as np

from hsgplan.domain.objects import object_type
from hsgplan.domain.world import SHELVES, TABLE
from hsgplan.scene_graph.geometry import Pose

UPRIGHT_TILT = math.radians(25)
SNAP_Z = 0.025  # m between an estimate's bottom and a support's top
EDGE = 0.01  # m past a support's top face that a centre may lie


def upright(pose: Pose) -> Pose:
    """The pose turned upright about its yaw (up to the cuboid's half turn about x), if its
    axis is within `UPRIGHT_TILT` of vertical; else the pose."""
    r = pose.rotation
    if abs(r[2, 2]) < math.cos(UPRIGHT_TILT):
        return pose
    if r[2, 2] < 0:  # upside down: the same cuboid turned half way about its x axis
        r = r @ np.diag([1.0, -1.0, -1.0])
    yaw = math.atan2(r[1, 0], r[0, 0])
    return Pose.from_xyz_yaw(*pose.position, yaw)


def settle(types: list[str], poses: list[Pose]) -> list[Pose]:
    """Each pose (of an object of `types[i]`) made to rest, lowest first (see the module)."""
    out = [upright(p) for p in poses]
    heights = [object_type(t).size[2] for t in types]
    order = sorted(range(len(out)), key=lambda i: out[i].position[2] - heights[i] / 2)
    settled: list[int] = []
    for i in order:
        x, y, z = out[i].position
        if out[i].rotation[2, 2] < math.cos(UPRIGHT_TILT):
            continue  # not upright: nothing to rest on
        bottom = z - heights[i] / 2
        tops = _surfaces(x, y) + [
            out[k].position[2] + heights[k] / 2
            for k in settled
            if _on_top_face(x, y, types[k], out[k])
        ]
        near = [t for t in tops if abs(t - bottom) <= SNAP_Z]
        if near:
            top = min(near, key=lambda t: abs(t - bottom))
            out[i] = Pose((x, y, top + heights[i] / 2), out[i].orientation)
        settled.append(i)
    return out


def _surfaces(x: float, y: float) -> list[float]:
    tops = [TABLE.z] if TABLE.contains(x, y, EDGE) else []
    return tops + [s.top.z for s in SHELVES.values() if s.top.contains(x, y, EDGE)]


def _on_top_face(x: float, y: float, carrier: str, pose: Pose) -> bool:
    sx, sy, _ = object_type(carrier).size
    cx, cy, _ = pose.position
    r = pose.rotation
    dx, dy = x - cx, y - cy
    u, v = r[0, 0] * dx + r[1, 0] * dy, r[0, 1] * dx + r[1, 1] * dy
    return abs(u) <= sx / 2 + EDGE and abs(v) <= sy / 2 + EDGE
