"""Drawings of symbolic scene graphs (matplotlib, written as PNG).

Fixtures stand in a row at the bottom, each as wide as the objects side by side on it need;
each object is drawn above what it rests on (stacks as columns), inside a shelf below it, and
in the gripper above everything, its name under it. An arrow runs from an object to what it is
`On` (up) or `In` (down); `Clear` is a green ring, `InGrasp` a gripper box; a key says so. Goal
literals that do not hold yet are listed.
"""

from __future__ import annotations

from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

from hsgplan.domain.goals import Goal  # noqa: E402
from hsgplan.domain.predicates import Literal, Predicate  # noqa: E402
from hsgplan.domain.scene import EntityKind, World  # noqa: E402
from hsgplan.scene_graph.symbolic import SymbolicSceneGraph  # noqa: E402
from hsgplan.viz.plots import save_figure  # noqa: E402

COLUMN = 0.9  # between two objects side by side
LEVEL = 1.6  # between an object and the one it carries: room for the lower one's name
MIN_WIDTH = 1.6  # of a fixture's column, with nothing or one object on it
GAP = 0.65  # between two fixtures' columns
INCHES = 0.62  # of figure per unit across: a column is wider than a name of 6-point words


def fixture_order(world: World) -> list[str]:
    """The shelves and regions left to right as the robot sees them (by y); a shelf level with
    a region stands outside it (its prepush region, in front of it)."""

    def key(name: str) -> tuple[float, bool]:
        shelf = name in world.shelves
        y = (world.shelves[name].outer if shelf else world.regions[name]).center[1]
        return -round(y, 3), shelf == (y < 0)

    return sorted(world.fixtures, key=key)


def fixture_x(world: World, widths: dict[str, float] | None = None) -> dict[str, float]:
    """Each fixture's column centre, left to right, each as wide as `widths` says (what stands
    on it or in it, at least `MIN_WIDTH`) and `GAP` apart."""
    x, out = 0.0, {}
    for name in fixture_order(world):
        width = max(MIN_WIDTH, (widths or {}).get(name, 0.0))
        out[name] = x + width / 2
        x += width + GAP
    return out


def _layout(state: SymbolicSceneGraph) -> dict[str, tuple[float, float]]:
    # how many objects stand side by side on, and inside, each fixture
    side_by_side: dict[str, int] = {}
    for o in state.objects:
        loc = state.location(o)
        if loc.predicate is Predicate.IN_GRASP:
            continue
        if (
            loc.predicate is Predicate.IN
            or state.world.kind_of(loc.args[1]) is not EntityKind.OBJECT
        ):
            key = loc.args[1] + ("/in" if loc.predicate is Predicate.IN else "")
            side_by_side[key] = side_by_side.get(key, 0) + 1
    widths = {
        f: COLUMN * max(side_by_side.get(f, 0), side_by_side.get(f + "/in", 0))
        for f in state.world.fixtures
    }
    columns_x = fixture_x(state.world, widths)
    pos = {name: (x, 0.0) for name, x in columns_x.items()}
    placed: dict[str, int] = {}
    for o in sorted(state.objects, key=state.level):
        loc = state.location(o)
        if loc.predicate is Predicate.IN_GRASP:
            continue
        if state.world.kind_of(loc.args[1]) is EntityKind.OBJECT:
            bx, by = pos[loc.args[1]]
            pos[o] = (bx, by + LEVEL)
            continue
        key = loc.args[1] + ("/in" if loc.predicate is Predicate.IN else "")
        k, n = placed.get(key, 0), side_by_side[key]
        placed[key] = k + 1
        x = columns_x[loc.args[1]] + (k - (n - 1) / 2) * COLUMN  # centred on the fixture
        pos[o] = (x, -1.3 if loc.predicate is Predicate.IN else 1.2)
    top = max([y for y in (p[1] for p in pos.values())] + [1.2])
    for o in state.objects:  # the held object above every stack
        if state.location(o).predicate is Predicate.IN_GRASP:
            pos[o] = (max(columns_x.values()) / 2, top + LEVEL)
    return pos


def draw_symbolic(
    state: SymbolicSceneGraph, path: Path, title: str = "", goal: Goal | None = None
) -> None:
    """Write a PNG drawing of the state (and of the goal literals it still misses)."""
    fig, _ = figure(state, title, goal)
    save_figure(fig, path)


def figure(state: SymbolicSceneGraph, title: str = "", goal: Goal | None = None):
    """The drawing's figure, and the name label of each object and fixture (what must not
    overlap): each object's name sits under its dot, a word a line, so that neighbours a
    column apart keep theirs apart."""
    pos = _layout(state)
    right = max(pos[n][0] for n in state.world.fixtures) + MIN_WIDTH / 2
    # the figure grows with its columns, so that a name keeps its width beside a column's
    fig, ax = plt.subplots(figsize=(max(8.0, INCHES * (right + 0.8)), 5), dpi=80)
    labels = {}
    for lit in state.literals:
        if lit.predicate.arity != 2:
            continue
        (x0, y0), (x1, y1) = pos[lit.args[0]], pos[lit.args[1]]
        # an arrow up from a fixture is On, one down into it In (the key says so)
        ax.annotate("", (x1, y1), (x0, y0), arrowprops={"arrowstyle": "->", "color": "0.4"})
    for name in state.world.fixtures:
        x, y = pos[name]
        ax.add_patch(plt.Rectangle((x - 0.7, y - 0.25), 1.4, 0.5, color=FIXTURE))
        labels[name] = ax.text(x, y, name, ha="center", va="center", fontsize=8)
    for o in state.objects:
        x, y = pos[o]
        ax.scatter([x], [y], s=500, color=state.world.object_type(o).color[:3], zorder=3)
        if state.holds(Literal(Predicate.CLEAR, (o,))):
            ax.scatter([x], [y], s=700, facecolors="none", edgecolors=CLEAR, linewidths=2, zorder=2)
        if state.held() == o:
            ax.add_patch(plt.Rectangle((x - 0.6, y - 0.5), 1.2, 1.0, fill=False, lw=2, ec="k"))
        words = o.replace("_", "\n")
        labels[o] = ax.text(x, y - 0.3, words, ha="center", va="top", fontsize=6, zorder=4)
    top = max(y for _, y in pos.values()) + 1.0
    if goal is not None:
        missing = goal.unsatisfied(state)
        text = "goal holds" if not missing else "to do: " + ", ".join(map(str, missing))
        ax.text(-0.4, top + 0.8, text, fontsize=8, va="top", wrap=True)
    ax.legend(handles=_key(), loc="lower center", fontsize=6, frameon=False, ncol=5)
    ax.set_xlim(-0.4, right + 0.4)
    ax.set_ylim(-3.4, top + 1.0)
    ax.axis("off")
    ax.set_title(title, fontsize=10)
    fig.tight_layout()
    return fig, labels


FIXTURE = "#c8b89a"
CLEAR = "green"


def _key() -> list:
    """What the marks mean: the drawing's legend."""
    from matplotlib.lines import Line2D
    from matplotlib.patches import Patch

    return [
        Patch(color=FIXTURE, label="shelf or region"),
        Line2D([], [], marker="o", ls="", color="0.5", markersize=7, label="object"),
        Line2D(
            [], [], marker="o", ls="", mfc="none", mec=CLEAR, mew=2, markersize=9, label="Clear"
        ),  # fmt: skip
        Patch(fill=False, ec="k", lw=2, label="InGrasp"),
        Line2D([], [], color="0.4", marker=">", label="On (up to it) / In (down)"),
    ]
