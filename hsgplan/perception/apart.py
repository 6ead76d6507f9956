"""One object found twice is kept once: detections that fill one space."""

from __future__ import annotations

from hsgplan.domain.world import Kind, World
from hsgplan.perception.detection import Detection
from hsgplan.perception.settle import same_place


def apart(
    detections: list[Detection], world: World, found_again_can: bool = True
) -> list[Detection]:
    """Two objects cannot fill one space. Detections that fill one (`settle.same_place`) are
    one object found twice, mostly once in each look-alike type's maps; the one whose type the
    colour network is surest of, among every type, is kept (then the stronger). Choosing among
    the types of its kind alone fails: a box the keypoint network saw where a soup stands, the
    likeliest box by a soup's colour, could win over the soup (symbolic match on 500 scenes of
    seeds 1 to 5, 3 scenes better). But a can a single view saw where a can of its type that
    several views saw stands is that can found again, whatever the colour: the lower of two
    cans stacked, which all five views saw, lost to one view's duplicate surer of its colour
    by a hair, the upper can fell to the shelf, and the agent placed it again until the step
    limit (Table 1 rgb, seed 40033; on seeds 1 to 5, one scene better, none worse). A lone
    view's thin box stays: it may be the lower of a stack the others saw as one blob. Nor is
    a lone view's detection of the other kind than one several views saw in its space: a soup
    under a butter shows the butter's yellow at its centroid's pixel in the views from above,
    so its type's mean probability is low, while one view's duplicate of the butter, found too
    low (a single view's depth is its weak axis), filled the soup's space surer of its colour,
    and the soup was lost (2 of 6 look-alikes on 300 tuning scenes, seeds 900 to 902).
    (`found_again_can` off: a lone can is told from the other by colour, as any detection.)"""
    several = [d for d in detections if d.views > 1]
    kept: list[Detection] = []
    for d in sorted(detections, key=lambda d: (-d.type_confidence, -d.score)):
        if d.views == 1 and any(_found_again(d, k, world, found_again_can) for k in several):
            continue
        if not any(_same_place(d, k, world) for k in kept):
            kept.append(d)
    return kept


def _same_place(d: Detection, k: Detection, world: World) -> bool:
    a, b = world.object_type(d.type_name), world.object_type(k.type_name)
    return same_place(a, d.pose, b, k.pose)


def _found_again(d: Detection, k: Detection, world: World, cans: bool = True) -> bool:
    """Whether a lone view's `d` is `k`, which several views saw, found again: in its space, a
    can of its type or anything of the other kind."""
    if not _same_place(d, k, world):
        return False
    kind = world.object_type(d.type_name).kind
    if kind is not world.object_type(k.type_name).kind:
        return True
    return cans and kind is Kind.CAN and k.type_name == d.type_name
