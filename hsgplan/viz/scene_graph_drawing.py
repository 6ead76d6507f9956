"""Drawings of symbolic scene graphs (matplotlib, written as PNG).

Fixtures stand in a row at the bottom; each object is drawn above what it rests on (stacks as
columns), inside a shelf below it, and in the gripper at the top. Edges carry their predicate;
`Clear` is a green ring, `InGrasp` a gripper box. Goal literals that do not hold yet are listed.
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

COLUMN = 0.9
FIXTURE_STEP = 2.25  # between two fixtures' columns


def fixture_x(world: World) -> dict[str, float]:
    """Each shelf's and region's column, left to right as the robot sees them (by y); a shelf
    level with a region stands outside it (its prepush region, in front of it)."""

    def key(name: str) -> tuple[float, bool]:
        shelf = name in world.shelves
        y = (world.shelves[name].outer if shelf else world.regions[name]).center[1]
        return -round(y, 3), shelf == (y < 0)

    order = sorted(world.fixtures, key=key)
    return {name: FIXTURE_STEP * i for i, name in enumerate(order)}


def _layout(state: SymbolicSceneGraph) -> dict[str, tuple[float, float]]:
    columns_x = fixture_x(state.world)
    pos = {name: (x, 0.0) for name, x in columns_x.items()}
    columns: dict[str, int] = {}
    for o in sorted(state.objects, key=state.level):
        loc = state.location(o)
        if loc.predicate is Predicate.IN_GRASP:
            pos[o] = (max(columns_x.values()) / 2, 4.2)
        elif loc.predicate is Predicate.IN:
            k = columns.get(loc.args[1] + "/in", 0)
            columns[loc.args[1] + "/in"] = k + 1
            pos[o] = (columns_x[loc.args[1]] + (k - 1) * COLUMN, -1.3)
        elif state.world.kind_of(loc.args[1]) is EntityKind.OBJECT:
            bx, by = pos[loc.args[1]]
            pos[o] = (bx, by + 1.1)
        else:
            k = columns.get(loc.args[1], 0)
            columns[loc.args[1]] = k + 1
            offset = ((k + 1) // 2) * (1 if k % 2 else -1) * COLUMN
            pos[o] = (columns_x[loc.args[1]] + offset, 1.2)
    return pos


def draw_symbolic(
    state: SymbolicSceneGraph, path: Path, title: str = "", goal: Goal | None = None
) -> None:
    """Write a PNG drawing of the state (and of the goal literals it still misses)."""
    pos = _layout(state)
    fig, ax = plt.subplots(figsize=(8, 5), dpi=80)
    for lit in state.literals:
        if lit.predicate.arity != 2:
            continue
        (x0, y0), (x1, y1) = pos[lit.args[0]], pos[lit.args[1]]
        ax.annotate("", (x1, y1), (x0, y0), arrowprops={"arrowstyle": "->", "color": "0.4"})
        ax.text((x0 + x1) / 2, (y0 + y1) / 2, lit.predicate.value, fontsize=7, color="0.25")
    for name in state.world.fixtures:
        x, y = pos[name]
        ax.add_patch(plt.Rectangle((x - 0.7, y - 0.25), 1.4, 0.5, color="#c8b89a"))
        ax.text(x, y, name, ha="center", va="center", fontsize=8)
    for o in state.objects:
        x, y = pos[o]
        ax.scatter([x], [y], s=700, color=state.world.object_type(o).color[:3], zorder=3)
        if state.holds(Literal(Predicate.CLEAR, (o,))):
            ax.scatter(
                [x], [y], s=950, facecolors="none", edgecolors="green", linewidths=2, zorder=2
            )
        if state.held() == o:
            ax.add_patch(plt.Rectangle((x - 0.6, y - 0.5), 1.2, 1.0, fill=False, lw=2, ec="k"))
        ax.text(x + 0.3, y, o, ha="left", va="center", fontsize=7, zorder=4)
    if goal is not None:
        missing = goal.unsatisfied(state)
        text = "goal holds" if not missing else "to do: " + ", ".join(map(str, missing))
        ax.text(-0.8, 5.0, text, fontsize=8, va="top", wrap=True)
    ax.set_xlim(-1.2, max(pos[n][0] for n in state.world.fixtures) + 1.2)
    ax.set_ylim(-2.2, 5.4)
    ax.axis("off")
    ax.set_title(title, fontsize=10)
    fig.tight_layout()
    save_figure(fig, path)
