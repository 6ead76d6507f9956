"""The symbol mapping f_m on constructed scenes: exact literals (Clear included) and anomalies."""

import math
import random

import pytest

from hsgplan.domain.kitchen import KITCHEN
from hsgplan.domain.objects import objects_for_types
from hsgplan.domain.predicates import Predicate
from hsgplan.domain.world import Kind
from hsgplan.scene_graph.geometric import GeometricSceneGraph
from hsgplan.scene_graph.geometry import Pose
from hsgplan.scene_graph.symbol_mapping import (
    DEFAULT_TOLERANCES,
    AnomalyKind,
    MappingTolerances,
    SymbolMapping,
    map_symbols,
)

TOP = KITCHEN.shelves["shelf_a"].top.z
CONTACT = DEFAULT_TOLERANCES.contact_z
MARGIN = DEFAULT_TOLERANCES.xy_margin
R_CAN = KITCHEN.object_types["cherries"].size[0] / 2
H_BUTTER = KITCHEN.object_types["butter"].height
H_CHERRIES = KITCHEN.object_types["cherries"].height


def h(name: str) -> float:
    return KITCHEN.object_type(name).height


def rest(name, x, y, bottom=0.0, yaw=0.0, tilt=0.0):
    """An object with its bottom at `bottom`, turned by yaw (deg) and tilted about x (rad)."""
    q = Pose.from_xyz_yaw(0, 0, 0, math.radians(yaw)).orientation
    if tilt:
        q = Pose((0, 0, 0), q).compose(Pose((0, 0, 0), _tilt_quat(tilt))).orientation
    return name, Pose((x, y, bottom + h(name) / 2), q)


def lying(name, x, y, z, tilt=math.pi / 2):
    """A toppled object with its centre at (x, y, z), turned `tilt` rad about its x axis."""
    return name, Pose((x, y, z), _tilt_quat(tilt))


def _tilt_quat(t):
    return (math.sin(t / 2), 0.0, 0.0, math.cos(t / 2))


def mapped(objs, held=None, tol=DEFAULT_TOLERANCES) -> SymbolMapping:
    return map_symbols(GeometricSceneGraph.from_poses(dict(objs), held, world=KITCHEN), tol)


def case(id_, objs, expected, anomalies="", held=None):
    return pytest.param(objs, held, expected, anomalies, id=id_)


def _lits(m: SymbolMapping) -> set[str]:
    return {str(lit) for lit in m.state.literals}


def _anoms(m: SymbolMapping) -> set[str]:
    return {f"{a.obj}:{a.kind}" for a in m.anomalies}


def oc(name: str, surface: str) -> str:
    """`name` rests on `surface` with nothing on it."""
    return f"On({name}, {surface}) & Clear({name})"


def _split(text: str, sep: str = "&") -> set[str]:
    return {t.strip() for t in text.split(sep) if t.strip()}


TS, BOX_Y = "tomato_soup", 0.104 / 2
SCENES = [
    # --- single objects on every surface -------------------------------------------------
    case("open_space", [rest("cherries", 0.45, 0.0)], oc("cherries", "open_space")),
    case("prepush_a", [rest("butter", 0.30, 0.38)], oc("butter", "prepush_a")),
    case("prepush_b_yawed", [rest("butter", 0.30, -0.38, yaw=90)], oc("butter", "prepush_b")),
    case("shelf_a_top", [rest(TS, 0.49, 0.38, TOP)], oc("tomato_soup", "shelf_a")),
    case("shelf_b_top", [rest("popcorn", 0.49, -0.38, TOP)], oc("popcorn", "shelf_b")),
    case("inside_shelf_a", [rest("alphabet_soup", 0.48, 0.38)], "In(alphabet_soup, shelf_a)"),
    case("inside_shelf_b", [rest("butter", 0.48, -0.38)], "In(butter, shelf_b)"),
    # --- stacks ----------------------------------------------------------------------------
    case(
        "can_on_box",
        [rest("cream_cheese", 0.45, 0.0), rest("cherries", 0.45, 0.0, h("cream_cheese"))],
        "On(cream_cheese, open_space) & On(cherries, cream_cheese) & Clear(cherries)",
    ),
    case(
        "box_on_can",
        [rest(TS, 0.45, 0.0), rest("butter", 0.45, 0.0, h(TS), yaw=30)],
        "On(tomato_soup, open_space) & On(butter, tomato_soup) & Clear(butter)",
    ),
    case(
        "can_on_can_duplicates_on_shelf_top",
        [rest("cherries", 0.49, 0.38, TOP), rest("cherries_2", 0.49, 0.38, TOP + H_CHERRIES)],
        "On(cherries, shelf_a) & On(cherries_2, cherries) & Clear(cherries_2)",
    ),
    case(
        "tower_of_three_on_prepush_b",
        [rest(f"cherries{s}", 0.30, -0.38, i * H_CHERRIES) for i, s in enumerate(["", "_2", "_3"])],
        "On(cherries, prepush_b) & On(cherries_2, cherries) & On(cherries_3, cherries_2) & "
        "Clear(cherries_3)",
    ),
    case(
        "stack_inside_shelf",
        [rest("butter", 0.48, 0.38), rest("cherries", 0.48, 0.38, H_BUTTER)],
        "In(butter, shelf_a) & On(cherries, butter) & Clear(cherries)",
    ),
    case(
        "narrow_popcorn_carries_past_the_planning_limits",
        [rest("popcorn", 0.45, 0.0), rest("cherries", 0.45, 0.0, h("popcorn"))],
        "On(popcorn, open_space) & On(cherries, popcorn) & Clear(cherries)",
    ),
    # --- yaw: cream cheese is 5.3 cm along its x, 10.4 cm along its y ------------------------
    *[
        case(
            f"yaw{yaw}_can_at_{axis}",
            [rest("cream_cheese", 0.45, 0.0, yaw=yaw), rest("cherries", *xy, 0.024)],
            "On(cream_cheese, open_space) & On(cherries, cream_cheese) & Clear(cherries)"
            if ok
            else f"{oc('cream_cheese', 'open_space')} & {oc('cherries', 'open_space')}",
            "" if ok else "cherries:unsupported",
        )
        for yaw, axis, xy, ok in [
            (0, "long_end", (0.45, 0.045), True),
            (0, "past_short_edge", (0.495, 0.0), False),
            (90, "long_end", (0.495, 0.0), True),
            (90, "past_short_edge", (0.45, 0.045), False),
        ]
    ],
    # --- grasp -----------------------------------------------------------------------------
    case(
        "held_in_air_above_another",
        [rest("cherries", 0.45, 0.0, 0.30), rest("butter", 0.45, 0.0)],
        "InGrasp(cherries) & On(butter, open_space) & Clear(butter)",
        held="cherries",
    ),
    case(
        "held_while_still_on_top_of_another",
        [rest("butter", 0.45, 0.0), rest("cherries", 0.45, 0.0, H_BUTTER)],
        "InGrasp(cherries) & On(butter, open_space) & Clear(butter)",
        held="cherries",
    ),
    case(
        "what_rests_on_the_held_object_is_unsupported",
        [rest("butter", 0.30, 0.38, 0.20), rest("cherries", 0.30, 0.38, 0.20 + H_BUTTER)],
        "InGrasp(butter) & On(cherries, prepush_a) & Clear(cherries)",
        "cherries:unsupported",
        held="butter",
    ),
    # --- toppled ---------------------------------------------------------------------------
    *[
        case(f"toppled_{id_}", [lying(n, x, y, z)], expected, f"{n}:toppled")
        for id_, n, (x, y, z), expected in [
            ("can_on_open_space", "cherries", (0.45, 0.05, R_CAN), oc("cherries", "open_space")),
            ("box_inside_shelf_b", "popcorn", (0.48, -0.38, 0.085 / 2), "In(popcorn, shelf_b)"),
            ("can_on_shelf_a_top", TS, (0.49, 0.38, TOP + 0.035), oc(TS, "shelf_a")),
            ("can_off_regions", "cherries", (0.05, 0.0, R_CAN), oc("cherries", "open_space")),
        ]
    ],
    case(
        "toppled_box_carries_nothing",
        [lying("butter", 0.45, 0.0, BOX_Y), rest("cherries", 0.45, 0.0, 2 * BOX_Y)],
        f"{oc('butter', 'open_space')} & {oc('cherries', 'open_space')}",
        "butter:toppled, cherries:unsupported",
    ),
    *[
        case(
            f"tilt_{t}",
            [rest("cherries", 0.45, 0.0, tilt=t, yaw=40)],
            oc("cherries", "open_space"),
            "" if t < DEFAULT_TOLERANCES.tilt_max else "cherries:toppled",
        )
        for t in (0.24, 0.26)
    ],
    # --- tolerances, both sides --------------------------------------------------------------
    *[
        case(
            f"table_gap_{dz:+.3f}",
            [rest("cherries", 0.45, 0.0, dz)],
            oc("cherries", "open_space"),
            "" if abs(dz) <= CONTACT else "cherries:unsupported",
        )
        for dz in (CONTACT - 0.001, CONTACT + 0.001, -CONTACT + 0.001, -CONTACT - 0.001)
    ],
    *[
        case(
            f"carrier_gap_{dz:+.3f}",
            [rest("butter", 0.45, 0.0), rest("cherries", 0.45, 0.0, H_BUTTER + dz)],
            "On(butter, open_space) & On(cherries, butter) & Clear(cherries)"
            if abs(dz) <= CONTACT
            else f"{oc('butter', 'open_space')} & {oc('cherries', 'open_space')}",
            "" if abs(dz) <= CONTACT else "cherries:unsupported",
        )
        for dz in (CONTACT - 0.001, CONTACT + 0.001)
    ],
    *[
        case(
            f"can_on_can_offset_{d:.4f}",
            [rest("cherries", 0.45, 0.0), rest("cherries_2", 0.45 + d, 0.0, H_CHERRIES)],
            "On(cherries, open_space) & On(cherries_2, cherries) & Clear(cherries_2)"
            if d <= R_CAN + MARGIN
            else f"{oc('cherries', 'open_space')} & {oc('cherries_2', 'open_space')}",
            "" if d <= R_CAN + MARGIN else "cherries_2:unsupported",
        )
        for d in (R_CAN + MARGIN - 0.001, R_CAN + MARGIN + 0.001)
    ],
    *[
        case(
            f"region_edge_{d:+.3f}",
            [rest("butter", KITCHEN.regions["open_space"].x_max + d, 0.0)],
            oc("butter", "open_space"),
            "" if d <= MARGIN else "butter:off_region",
        )
        for d in (MARGIN - 0.001, MARGIN + 0.001)
    ],
    case(
        "shelf_top_edge_inside_margin",
        [rest(TS, 0.49, KITCHEN.shelves["shelf_a"].top.y_max + MARGIN - 0.001, TOP)],
        oc("tomato_soup", "shelf_a"),
    ),
    case(
        "shelf_top_edge_past_margin_floats",
        [rest(TS, 0.49, KITCHEN.shelves["shelf_a"].top.y_max + MARGIN + 0.001, TOP)],
        oc("tomato_soup", "prepush_a"),
        "tomato_soup:unsupported",
    ),
    case("shelf_front_nearer_interior", [rest("cherries", 0.3795, 0.38)], "In(cherries, shelf_a)"),
    case(
        "shelf_front_nearer_prepush",
        [rest("cherries", 0.3705, 0.38)],
        oc("cherries", "prepush_a"),
    ),
    case(
        "behind_shelf_off_region",
        [rest("cherries", 0.65, 0.40)],
        oc("cherries", "open_space"),
        "cherries:off_region",
    ),
    # --- off the table, floating ----------------------------------------------------------------
    case(
        "fallen_to_the_floor",
        [lying("cherries", 0.30, -0.30, -0.70)],
        oc("cherries", "prepush_b"),
        "cherries:off_table",
    ),
    case(
        "past_the_table_edge",
        [rest("butter", KITCHEN.table.x_max + 0.05, -0.40, -0.02)],
        oc("butter", "open_space"),
        "butter:off_table",
    ),
    case(
        "floating_above_prepush_b",
        [rest("cherries", 0.30, -0.40, 0.25)],
        oc("cherries", "prepush_b"),
        "cherries:unsupported",
    ),
    # --- competition and crowding --------------------------------------------------------------
    *[
        case(
            f"two_cans_one_box_{winner}_wins",
            [
                rest("cream_cheese", 0.45, 0.0),
                rest("cherries", 0.45, y1, 0.024),
                rest("cherries_2", 0.45, y2, 0.024),
            ],
            f"On(cream_cheese, open_space) & {oc(winner, 'cream_cheese')} & "
            f"{oc(loser, 'open_space')}",
            f"{loser}:shared_carrier",
        )
        for winner, loser, y1, y2 in [
            ("cherries", "cherries_2", 0.0, 0.03),
            ("cherries_2", "cherries", 0.03, -0.005),
        ]
    ],
    case(
        "box_across_two_cans_takes_the_closer",
        [
            rest("cherries", 0.45, -0.035),
            rest("cherries_2", 0.45, 0.037),
            rest("butter", 0.45, 0.0, H_CHERRIES, yaw=90),
        ],
        f"On(cherries, open_space) & {oc('cherries_2', 'open_space')} & {oc('butter', 'cherries')}",
    ),
    case(
        "interpenetrating_boxes_both_on_the_table",
        [rest("butter", 0.45, 0.0), rest("butter_2", 0.45, 0.0)],
        f"{oc('butter', 'open_space')} & {oc('butter_2', 'open_space')}",
    ),
    case(
        "crowded_shelf_top_past_capacity",
        [
            rest(n, x, y, TOP)
            for n, (x, y) in zip(
                objects_for_types(["cherries"] * 7, world=KITCHEN),
                [(x, y) for x in (0.42, 0.56) for y in (0.26, 0.34, 0.42, 0.50)],
                strict=False,
            )
        ],
        " & ".join(oc(n, "shelf_a") for n in objects_for_types(["cherries"] * 7, world=KITCHEN)),
    ),
    case(
        "crowded_interior_past_capacity",
        [
            rest(n, 0.45, 0.27 + 0.07 * i)
            for i, n in enumerate(objects_for_types(["cherries"] * 4, world=KITCHEN))
        ],
        " & ".join(f"In({n}, shelf_a)" for n in objects_for_types(["cherries"] * 4, world=KITCHEN)),
    ),
]


@pytest.mark.parametrize("objs, held, expected, anomalies", SCENES)
def test_scene(objs, held, expected, anomalies):
    m = mapped(objs, held)
    assert _lits(m) == _split(expected)
    assert _anoms(m) == _split(anomalies, ",")


def test_anomaly_details_name_the_cause():
    objs = [rest("cream_cheese", 0.45, 0.0), rest("cherries", 0.45, 0.0, 0.024)]
    (a,) = mapped([*objs, rest("cherries_2", 0.45, 0.03, 0.024)]).anomalies
    assert a.kind is AnomalyKind.SHARED_CARRIER and a.obj == "cherries_2"
    assert "cream_cheese" in a.detail and "cherries" in a.detail


def test_stacking_cycle_degrades_instead_of_raising():
    # With a loose contact tolerance two interpenetrating floating boxes each "rest" on the
    # other; the first match wins and the second would close a cycle.
    tol = MappingTolerances(contact_z=0.05)
    m = mapped([rest("butter", 0.45, 0.0, 0.2), rest("butter_2", 0.45, 0.0, 0.2)], tol=tol)
    assert _lits(m) == {"On(butter, butter_2)", "On(butter_2, open_space)", "Clear(butter)"}
    (a,) = m.anomalies
    assert a.obj == "butter_2" and a.kind is AnomalyKind.UNSUPPORTED and "cycle" in a.detail


def test_tolerances_change_the_reading():
    objs = [rest("butter", KITCHEN.regions["open_space"].x_max + 0.005, 0.0)]
    assert _anoms(mapped(objs)) == set()
    assert _anoms(mapped(objs, tol=MappingTolerances(xy_margin=0.0))) == {"butter:off_region"}


def test_held_object_must_be_in_the_scene():
    with pytest.raises(ValueError, match="popcorn"):
        mapped([rest("butter", 0.45, 0.0)], held="popcorn")


def test_default_tolerances_fit_the_world():
    """The reasons given for the defaults, checked against the world's constants."""
    tol = DEFAULT_TOLERANCES
    assert tol.contact_z < min(t.height for t in KITCHEN.object_types.values())
    space, pre_a, pre_b = (
        KITCHEN.regions["open_space"],
        KITCHEN.regions["prepush_a"],
        KITCHEN.regions["prepush_b"],
    )
    assert 2 * tol.xy_margin < min(pre_a.y_min - space.y_max, space.y_min - pre_b.y_max)
    boxes = [t for t in KITCHEN.object_types.values() if t.kind is Kind.BOX]
    assert tol.tilt_max < min(math.atan2(t.grasp_width, t.height) for t in boxes)
    assert tol.off_table_z < -tol.contact_z  # an object sunk within contact_z is on the table


def _random_scene(rng: random.Random):
    types = rng.choices(list(KITCHEN.object_types), k=rng.randint(1, 12))
    poses = {}
    for name in objects_for_types(types, world=KITCHEN):
        yaw, tilt = rng.uniform(-math.pi, math.pi), rng.choice([0.0, 0.0, rng.uniform(0, 3.2)])
        q = Pose.from_xyz_yaw(0, 0, 0, yaw).compose(Pose((0, 0, 0), _tilt_quat(tilt)))
        xy = (rng.uniform(-0.4, 1.1), rng.uniform(-0.9, 0.9))
        z = rng.choice([0.0, TOP, 0.024, 0.058, 0.083, 0.126]) + h(name) / 2
        poses[name] = Pose((*xy, z + rng.uniform(-0.02, 0.02)), q.orientation)
        if rng.random() < 0.3 and len(poses) > 1:  # stack onto an earlier object
            below = rng.choice(list(poses)[:-1])
            bx, by, bz = poses[below].position
            poses[name] = Pose((bx, by, bz + (h(below) + h(name)) / 2), q.orientation)
    held = rng.choice([None, *poses])
    return poses, held


@pytest.mark.parametrize("seed", range(300))
def test_never_raises_and_places_every_object_once(seed):
    poses, held = _random_scene(random.Random(seed))
    tol = MappingTolerances(contact_z=0.03 if seed % 2 else 0.015)
    m = map_symbols(GeometricSceneGraph.from_poses(poses, held, world=KITCHEN), tol)
    placements = [lit for lit in m.state.literals if lit.predicate is not Predicate.CLEAR]
    assert sorted(lit.subject for lit in placements) == sorted(poses)
    assert m.state.held() == held
    assert {a.obj for a in m.anomalies} <= set(poses)
    assert len({a.obj for a in m.anomalies}) == len(m.anomalies)
