"""The symbol mapping f_m: geometric scene graph (+ grasp state) -> symbolic scene graph.

Geometric heuristics with stated tolerances decide each object's one placement literal:

1. the held object is `InGrasp`, wherever it is;
2. an object fallen off the table, or toppled, is placed by where its centre lies and reported;
3. every other (upright) object gets the closest support that touches its bottom: another
   object's top face (`On(o, b)`), a shelf's top board (`On(o, shelf)`), or the table inside a
   shelf's interior (`In(o, shelf)`) or a region (`On(o, region)`). Supports are matched
   greedily, best contact first, so that each object carries at most one other and stacks
   never close a cycle, which are the structural rules `SymbolicSceneGraph` enforces;
4. an upright object left without a support is mapped to the nearest region and reported.

The result is built with `limits=False`: an observation may exceed the planning limits
(capacities, tower height, what fits or carries), and f_m reports what is there. `Clear` is
derived by `SymbolicSceneGraph` itself. Each object gets at most one anomaly, the first that
applies in the order above.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from enum import StrEnum

from hsgplan.domain.predicates import Literal, in_grasp, inside, on
from hsgplan.domain.scene import Kind, Rect, World
from hsgplan.scene_graph.geometric import GeometricNode, GeometricSceneGraph
from hsgplan.scene_graph.symbolic import SymbolicSceneGraph


@dataclass(frozen=True)
class MappingTolerances:
    """How far geometry may stray from the ideal resting pose and still read as a predicate."""

    # |bottom of o - top of its support|. Settled contacts in simulation sit within a few mm;
    # 1.5 cm also absorbs pose-estimation noise, yet stays below the thinnest object's height
    # (butter, 2.4 cm), so an object on a butter is never read as resting on the table beneath.
    contact_z: float = 0.015
    # How far past a surface's, region's or carrier's top-face edge a centre may be. A centre
    # past a carrier's edge would tip off, so this only absorbs noise; 1 cm is also under half
    # the 4 cm gap between open_space and the prepush regions, so widened regions never overlap.
    xy_margin: float = 0.01
    # Radians (about 14 deg). Settling leaves < 0.02 rad; the least stable type (popcorn,
    # 3.8 x 12.6 cm upright) tips past atan(0.038 / 0.126) = 0.29 rad, so anything leaning
    # further cannot be resting, and below it the upright bottom height stays within contact_z.
    tilt_max: float = 0.25
    # A centre below this height cannot be on the table: the lowest resting centre is butter's,
    # 1.2 cm above the table top, and the deepest plausible sinking is a few mm.
    off_table_z: float = -0.05


DEFAULT_TOLERANCES = MappingTolerances()

# In a support's match cost, how much the horizontal offset (from a carrier's centre, or past a
# surface's edge) weighs against the contact height gap: contact height decides, and a 1 cm
# offset weighs like 1 mm of height, enough to break near-ties (two carriers of equal height).
_XY_WEIGHT = 0.1


class AnomalyKind(StrEnum):
    TOPPLED = "toppled"  # tilted past tilt_max; placed by where its centre lies
    OFF_TABLE = "off_table"  # centre below off_table_z or outside the world's table; nearest region
    OFF_REGION = "off_region"  # on the table but outside every region and interior
    UNSUPPORTED = "unsupported"  # not held and resting on nothing the state can name
    SHARED_CARRIER = "shared_carrier"  # rests on an object that a better match already occupies


@dataclass(frozen=True)
class Anomaly:
    obj: str
    kind: AnomalyKind
    detail: str


@dataclass(frozen=True)
class SymbolMapping:
    """The symbolic state f_m(s_g), and what in s_g did not map cleanly onto it."""

    state: SymbolicSceneGraph
    anomalies: tuple[Anomaly, ...]


@dataclass(frozen=True)
class _Support:
    """One way an upright object may rest: the literal, its match cost, and the carrier object
    (None for a shelf top, interior or region, which hold any number of objects)."""

    literal: Literal
    cost: float
    carrier: str | None


def map_symbols(
    sg: GeometricSceneGraph, tol: MappingTolerances = DEFAULT_TOLERANCES
) -> SymbolMapping:
    """The symbolic scene graph a geometric one shows; never raises on a physical configuration.

    Raises ValueError only if `sg.held` names an object that is not in the scene (an input
    error, not a configuration), and InfeasibleError only for more objects than a scene holds.
    """
    if sg.held is not None and sg.held not in sg.objects:
        raise ValueError(f"the held object '{sg.held}' is not in the scene")
    world = sg.world
    place: dict[str, Literal] = {}
    anomalies: dict[str, Anomaly] = {}
    upright: list[GeometricNode] = []
    for node in sg.nodes:
        x, y, z = node.pose.position
        if node.name == sg.held:
            place[node.name] = in_grasp(node.name)
        elif not (z >= tol.off_table_z and world.table.contains(x, y)):  # `not >=`: NaN too
            place[node.name] = on(node.name, _nearest_region(world, x, y))
            anomalies[node.name] = Anomaly(
                node.name, AnomalyKind.OFF_TABLE, f"centre at ({x:.3f}, {y:.3f}, {z:.3f})"
            )
        elif node.pose.tilt > tol.tilt_max:
            place[node.name] = _by_centre(world, node, tol)
            anomalies[node.name] = Anomaly(
                node.name,
                AnomalyKind.TOPPLED,
                f"tilted {node.pose.tilt:.2f} rad (more than {tol.tilt_max:.2f})",
            )
        else:
            upright.append(node)

    # Only upright, unheld objects on the table carry others: a held object carries nothing
    # (the symbolic rules forbid it; what sits on it is in the air with it), and a toppled
    # object's top face no longer faces up.
    options = {n.name: _supports(world, n, upright, tol) for n in upright}
    below: dict[str, str] = {}  # object -> the object it rests on
    carrying: dict[str, str] = {}  # carrier -> the object resting on it
    ranked = sorted(
        ((s, name) for name, ss in options.items() for s in ss),
        key=lambda p: (p[0].cost, p[1], p[0].literal),
    )
    for support, name in ranked:
        c = support.carrier
        if name in place or (c is not None and (c in carrying or _reaches(below, c, name))):
            continue
        if c is not None:
            below[name], carrying[c] = c, name
        place[name] = support.literal

    for node in upright:
        if node.name not in place:
            x, y, _ = node.pose.position
            place[node.name] = on(node.name, _nearest_region(world, x, y))
            anomalies[node.name] = _why_unplaced(node, options[node.name], carrying, tol)

    state = SymbolicSceneGraph.from_literals(sg.objects, place.values(), limits=False, world=world)
    return SymbolMapping(state, tuple(anomalies[o] for o in state.objects if o in anomalies))


def _supports(
    world: World, node: GeometricNode, upright: list[GeometricNode], tol: MappingTolerances
) -> list[_Support]:
    """Every support whose surface meets the object's bottom and holds its centre."""
    name, bottom = node.name, node.bottom_z
    x, y, z = node.pose.position
    out = []
    for b in upright:
        dz = abs(bottom - b.top_z)
        if b.name == name or not dz <= tol.contact_z:
            continue
        offset = _top_face_offset(b, x, y, tol.xy_margin)
        if offset is not None:
            out.append(_Support(on(name, b.name), dz + _XY_WEIGHT * offset, b.name))
    surfaces: list[tuple[Literal, Rect]] = []
    tops = [s for s in world.shelf_list if abs(bottom - s.top.z) <= tol.contact_z]
    surfaces += [(on(name, s.name), s.top) for s in tops]
    # At table height: inside a shelf (under its top board), or on a region. A centre within
    # margin of both a prepush region and the interior behind it goes to the nearer, by cost.
    if abs(bottom) <= tol.contact_z:
        surfaces += [
            (inside(name, s.name), s.interior)
            for s in world.shelf_list
            if s.interior is not None and z < s.clearance
        ]
        surfaces += [(on(name, r), rect) for r, rect in world.region_list]
    for lit, rect in surfaces:
        d = _rect_distance(rect, x, y)
        if d <= tol.xy_margin:
            dz = abs(bottom - rect.z)
            out.append(_Support(lit, dz + _XY_WEIGHT * d, None))
    return out


def _top_face_offset(b: GeometricNode, x: float, y: float, margin: float) -> float | None:
    """The horizontal distance of (x, y) from b's centre if it lies on b's top face (its
    footprint turned by its yaw, widened by margin); None otherwise. A can's top is a disc."""
    t = b.type
    bx, by, _ = b.pose.position
    dx, dy = x - bx, y - by
    dist = math.hypot(dx, dy)
    if t.kind is Kind.CAN:
        return dist if dist <= t.size[0] / 2 + margin else None
    c, s = math.cos(b.pose.yaw), math.sin(b.pose.yaw)
    lx, ly = c * dx + s * dy, -s * dx + c * dy  # (dx, dy) in b's frame
    if abs(lx) <= t.size[0] / 2 + margin and abs(ly) <= t.size[1] / 2 + margin:
        return dist
    return None


def _by_centre(world: World, node: GeometricNode, tol: MappingTolerances) -> Literal:
    """Where a toppled object's centre lies: above a shelf's top board, under it inside the
    interior, or else the nearest region (a toppled object carries and rests on no object)."""
    x, y, z = node.pose.position
    for s in world.shelf_list:
        if z >= s.top.z and _rect_distance(s.top, x, y) <= tol.xy_margin:
            return on(node.name, s.name)
        inner = s.interior
        if inner is not None and z < s.clearance and _rect_distance(inner, x, y) <= tol.xy_margin:
            return inside(node.name, s.name)
    return on(node.name, _nearest_region(world, x, y))


def _why_unplaced(
    node: GeometricNode, options: list[_Support], carrying: dict[str, str], tol: MappingTolerances
) -> Anomaly:
    carriers = [s.carrier for s in sorted(options, key=lambda s: s.cost) if s.carrier]
    if carriers and carriers[0] in carrying:
        c = carriers[0]
        return Anomaly(
            node.name,
            AnomalyKind.SHARED_CARRIER,
            f"rests on {c}, which carries {carrying[c]}, a better match (one object per carrier)",
        )
    if carriers:  # every carrier it touches would close a stacking cycle
        return Anomaly(
            node.name, AnomalyKind.UNSUPPORTED, f"resting on {carriers[0]} would close a cycle"
        )
    if abs(node.bottom_z) <= tol.contact_z:
        return Anomaly(node.name, AnomalyKind.OFF_REGION, "on the table outside every region")
    return Anomaly(
        node.name,
        AnomalyKind.UNSUPPORTED,
        f"bottom at z={node.bottom_z:.3f} touches no surface or object top",
    )


def _reaches(below: dict[str, str], start: str, target: str) -> bool:
    """Whether following `below` down from start reaches target (so target -> start would
    close a cycle)."""
    o: str | None = start
    while o is not None:
        if o == target:
            return True
        o = below.get(o)
    return False


def _rect_distance(rect: Rect, x: float, y: float) -> float:
    """Horizontal distance from (x, y) to a rectangle: 0 inside, inf for a NaN position."""
    x, y = rect.to_local(x, y)
    dx = max(rect.x_min - x, 0.0, x - rect.x_max)
    dy = max(rect.y_min - y, 0.0, y - rect.y_max)
    d = math.hypot(dx, dy)
    return math.inf if math.isnan(d) or math.isnan(x) or math.isnan(y) else d


def _nearest_region(world: World, x: float, y: float) -> str:
    """The region nearest to (x, y); the first listed on ties (and for a NaN position)."""
    return min(world.regions, key=lambda r: _rect_distance(world.regions[r], x, y))
