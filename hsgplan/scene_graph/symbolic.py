"""The symbolic scene graph s_s: objects and fixtures as nodes, predicates as edges.

`On(o, x)` and `In(o, shelf)` are directed edges o -> x; `InGrasp(o)` and `Clear(o)` are self edges.
Shelves and regions are always nodes, so a graph's node set is its objects plus the fixtures.
The class is pure Python; `to_data` imports torch only when a network needs the graph.
"""

from __future__ import annotations

from collections.abc import Iterable
from dataclasses import dataclass, field
from typing import TYPE_CHECKING

from hsgplan.domain.errors import InfeasibleError
from hsgplan.domain.feasibility import check_literals
from hsgplan.domain.predicates import PREDICATES, Literal, Predicate, clear
from hsgplan.domain.scene import OPEN_SPACE, EntityKind, World

if TYPE_CHECKING:
    from torch_geometric.data import Data


@dataclass(frozen=True)
class SymbolicSceneGraph:
    """A symbolic state. Build it with `from_literals`, which checks it and derives `Clear`.

    Attributes:
        objects: the object instances, in canonical order.
        literals: the positive literals that hold; everything else is false.
        world: the world the state is of (its names, fixtures and limits); states of two
            worlds with the same literals compare equal.
    """

    objects: tuple[str, ...]
    literals: frozenset[Literal]
    _location: dict[str, Literal] = field(default=None, compare=False, hash=False, repr=False)
    world: World = field(kw_only=True, compare=False, hash=False, repr=False)

    @classmethod
    def from_literals(
        cls,
        objects: Iterable[str],
        literals: Iterable[Literal],
        limits: bool = True,
        *,
        world: World,
    ) -> SymbolicSceneGraph:
        """A checked state from the placement literals (On / In / InGrasp) of every object.

        `Clear` literals are derived; given ones must agree with the derivation. With
        `limits=False` (for observed scenes) the world's capacity, tower and fit limits are
        not enforced, only the structure (see `check_literals`).
        """
        objs = world.sort_objects(objects)
        lits = set(literals)
        for lit in lits:
            if not lit.positive:
                raise InfeasibleError(f"a state lists only true literals, not '{lit}'")
            for a in lit.args:
                if world.kind_of(a) is EntityKind.OBJECT and a not in objs:
                    raise InfeasibleError(f"'{lit}' names '{a}', which is not in the scene")
        placements = {lit for lit in lits if lit.predicate is not Predicate.CLEAR}
        graph = cls(objs, frozenset(placements | _derive_clear(objs, placements)), world=world)
        graph._check(limits)
        given_clear = {lit for lit in lits if lit.predicate is Predicate.CLEAR}
        wrong = given_clear - graph.literals
        if wrong:
            raise InfeasibleError(
                f"'{min(wrong)}' cannot hold: something rests on it, it is held, "
                "or it is in a shelf"
            )
        return graph

    @classmethod
    def initial(
        cls, objects: Iterable[str], region: str = OPEN_SPACE, *, world: World
    ) -> SymbolicSceneGraph:
        """Every object resting on one region, nothing held."""
        objs = world.sort_objects(objects)
        placed = (Literal(Predicate.ON, (o, region)) for o in objs)
        return cls.from_literals(objs, placed, world=world)

    # --- queries -----------------------------------------------------------------------

    @property
    def fixtures(self) -> tuple[str, ...]:
        return self.world.fixtures

    @property
    def nodes(self) -> tuple[str, ...]:
        return self.objects + self.world.fixtures

    def holds(self, literal: Literal) -> bool:
        return (literal.atom in self.literals) == literal.positive

    def location(self, obj: str) -> Literal:
        """The one placement literal of an object: On(obj, x), In(obj, s) or InGrasp(obj)."""
        if self._location is None:
            loc = {
                lit.subject: lit for lit in self.literals if lit.predicate is not Predicate.CLEAR
            }
            object.__setattr__(self, "_location", loc)
        return self._location[obj]

    def held(self) -> str | None:
        for o in self.objects:
            if self.location(o).predicate is Predicate.IN_GRASP:
                return o
        return None

    def resting_on(self, x: str) -> tuple[str, ...]:
        """Objects directly on x (a surface or an object)."""
        return tuple(o for o in self.objects if self.location(o) == Literal(Predicate.ON, (o, x)))

    def inside(self, shelf: str) -> tuple[str, ...]:
        return tuple(
            o for o in self.objects if self.location(o) == Literal(Predicate.IN, (o, shelf))
        )

    def moved(self, lit: Literal) -> SymbolicSceneGraph:
        """The state with `lit`'s object placed where `lit` (On, In or InGrasp) says, every other
        placement as it is: a state imagined, not checked (what rested on the object stays on
        it, a second object may be in the hand)."""
        kept = {self.location(o) for o in self.objects if o != lit.subject}
        placements = kept | {lit}
        return SymbolicSceneGraph(
            self.objects,
            frozenset(placements | _derive_clear(self.objects, placements)),
            world=self.world,
        )

    def level(self, obj: str) -> int:
        """1 for an object on a surface, one more for each object beneath it; 0 if not stacked."""
        loc = self.location(obj)
        if loc.predicate is not Predicate.ON:
            return 0
        below = loc.args[1]
        return 1 if self.world.kind_of(below) is not EntityKind.OBJECT else 1 + self.level(below)

    # --- text and tensors ------------------------------------------------------------------

    def __str__(self) -> str:
        """The literals in goal syntax, so a state can be read back as a goal or an `--init`."""
        return " & ".join(str(lit) for lit in self.sorted_literals())

    def sorted_literals(self) -> list[Literal]:
        order = {o: i for i, o in enumerate(self.objects)}
        return sorted(
            self.literals, key=lambda x: (order[x.subject], PREDICATES.index(x.predicate))
        )

    def to_text(self) -> str:
        """A node-and-edge listing, one object per line with its out-edges and self edges."""
        lines = []
        width = max((len(o) for o in self.objects), default=0)
        for o in self.objects:
            edges = []
            for lit in self.sorted_literals():
                if lit.subject != o:
                    continue
                if lit.predicate.arity == 2:
                    edges.append(f"-{lit.predicate.value}-> {lit.args[1]}")
                else:
                    edges.append(f"[{lit.predicate.value}]")
            lines.append(f"{o:<{width}}  {'  '.join(edges)}")
        return "\n".join(lines)

    def to_data(self) -> Data:
        """The graph as `torch_geometric.data.Data`.

        Shapes:
            x: [N, T] one-hot node type over the world's `entity_types`, N = objects + fixtures.
            edge_index: [2, E] source (subject) and target of each relation; self edges for
                unary predicates.
            edge_attr: [E, P] multi-hot over `PREDICATES` for each (source, target) pair.
            names: list of N node names.
        """
        import torch
        from torch_geometric.data import Data

        nodes = self.nodes
        index = {n: i for i, n in enumerate(nodes)}
        types = self.world.entity_types
        x = torch.zeros(len(nodes), len(types))
        for i, n in enumerate(nodes):
            x[i, types.index(self.world.type_of(n))] = 1.0
        pairs: dict[tuple[int, int], list[int]] = {}
        for lit in self.literals:
            src = index[lit.args[0]]
            dst = index[lit.args[-1]]
            pairs.setdefault((src, dst), [0] * len(PREDICATES))[PREDICATES.index(lit.predicate)] = 1
        keys = sorted(pairs)
        edge_index = torch.tensor(keys, dtype=torch.long).reshape(-1, 2).t().contiguous()
        edge_attr = torch.tensor([pairs[k] for k in keys], dtype=torch.float).reshape(
            -1, len(PREDICATES)
        )
        return Data(x=x, edge_index=edge_index, edge_attr=edge_attr, names=list(nodes))

    # --- consistency -------------------------------------------------------------------

    def _check(self, limits: bool) -> None:
        check_literals(self.literals, limits, world=self.world)
        placed = {lit.subject for lit in self.literals if lit.predicate is not Predicate.CLEAR}
        missing = [o for o in self.objects if o not in placed]
        if missing:
            raise InfeasibleError(f"'{missing[0]}' has no On, In or InGrasp literal")


def _derive_clear(objects: tuple[str, ...], placements: set[Literal]) -> set[Literal]:
    blocked = set()
    for lit in placements:
        if lit.predicate in (Predicate.IN_GRASP, Predicate.IN):
            blocked.add(lit.subject)
        elif lit.predicate is Predicate.ON:
            blocked.add(lit.args[1])
    return {clear(o) for o in objects if o not in blocked}
