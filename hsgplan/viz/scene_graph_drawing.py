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
from hsgplan.domain.objects import EntityKind, kind_of, object_type  # noqa: E402
from hsgplan.domain.predicates import Literal, Predicate  # noqa: E402
from hsgplan.scene_graph.symbolic import SymbolicSceneGraph  # noqa: E402
from hsgplan.viz.plots import save_figure  # noqa: E402

FIXTURE_X = {"shelf_a": 0.0, "prepush_a": 2.0, "open_space": 4.5, "prepush_b": 7.0, "shelf_b": 9.0}
COLUMN = 0.9


def _layout(state: SymbolicSceneGraph) -> dict[str, tuple[float, float]]:
    pos = {name: (x, 0.0) for name, x in FIXTURE_X.items()}
    columns: dict[str, int] = {}
    for o in sorted(state.objects, key=state.level):
        loc = state.location(o)
        if loc.predicate is Predicate.IN_GRASP:
            pos[o] = (4.5, 4.2)
        elif loc.predicate is Predicate.IN:
            k = columns.get(loc.args[1] + "/in", 0)
            columns[loc.args[1] + "/in"] = k + 1
            pos[o] = (FIXTURE_X[loc.args[1]] + (k - 1) * COLUMN, -1.3)
        elif kind_of(loc.args[1]) is EntityKind.OBJECT:
            bx, by = pos[loc.args[1]]
            pos[o] = (bx, by + 1.1)
        else:
            k = columns.get(loc.args[1], 0)
            columns[loc.args[1]] = k + 1
            offset = ((k + 1) // 2) * (1 if k % 2 else -1) * COLUMN
            pos[o] = (FIXTURE_X[loc.args[1]] + offset, 1.2)
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
    for name in FIXTURE_X:
        x, y = pos[name]
        ax.add_patch(plt.Rectangle((x - 0.7, y - 0.25), 1.4, 0.5, color="#c8b89a"))
        ax.text(x, y, name, ha="center", va="center", fontsize=8)
    for o in state.objects:
        x, y = pos[o]
        ax.scatter([x], [y], s=700, color=object_type(o).color[:3], zorder=3)
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
    ax.set_xlim(-1.2, 10.2)
    ax.set_ylim(-2.2, 5.4)
    ax.axis("off")
    ax.set_title(title, fontsize=10)
    fig.tight_layout()
    save_figure(fig, path)
