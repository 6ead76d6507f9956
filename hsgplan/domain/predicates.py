"""The paper's four predicates and the literals built from them."""

from __future__ import annotations

from dataclasses import dataclass
from enum import StrEnum

from hsgplan.domain.scene import EntityKind, World


class Predicate(StrEnum):
    """`On(o, x)`: o rests on x (a region, a shelf top or another object).
    `In(o, shelf)`: o is inside a shelf's interior.
    `InGrasp(o)`: o is held by the gripper.
    `Clear(o)`: nothing rests on o, it is not held and not inside a shelf, so it can be
    grasped or stacked on (an object in a shelf's interior can be neither, from above).
    """

    ON = "On"
    IN = "In"
    IN_GRASP = "InGrasp"
    CLEAR = "Clear"

    @property
    def arity(self) -> int:
        return 2 if self in (Predicate.ON, Predicate.IN) else 1

    @property
    def signature(self) -> tuple[frozenset[EntityKind], ...]:
        obj = frozenset({EntityKind.OBJECT})
        if self is Predicate.ON:
            return obj, frozenset(EntityKind)
        if self is Predicate.IN:
            return obj, frozenset({EntityKind.SHELF})
        return (obj,)


PREDICATES: tuple[Predicate, ...] = tuple(Predicate)


@dataclass(frozen=True, order=True)
class Literal:
    """A predicate applied to entity names, possibly negated (`not On(a, b)`)."""

    predicate: Predicate
    args: tuple[str, ...]
    positive: bool = True

    def __post_init__(self) -> None:
        if len(self.args) != self.predicate.arity:
            raise ValueError(
                f"{self.predicate.value} takes {self.predicate.arity} argument(s), "
                f"got {len(self.args)}"
            )

    @property
    def atom(self) -> Literal:
        """The positive form of this literal."""
        return self if self.positive else Literal(self.predicate, self.args)

    def negated(self) -> Literal:
        return Literal(self.predicate, self.args, not self.positive)

    @property
    def subject(self) -> str:
        return self.args[0]

    def objects(self, world: World) -> tuple[str, ...]:
        """The object instances this literal names (fixtures and regions excluded)."""
        return tuple(a for a in self.args if world.kind_of(a) is EntityKind.OBJECT)

    def __str__(self) -> str:
        return literal_text(self.predicate.value, self.args, self.positive)


def literal_text(predicate: str, args: tuple[str, ...], positive: bool = True) -> str:
    """A literal's text (`On(a, b)`, `not In(a, shelf_a)`), from its parts."""
    text = f"{predicate}({', '.join(args)})"
    return text if positive else f"not {text}"


def on(o: str, x: str) -> Literal:
    return Literal(Predicate.ON, (o, x))


def inside(o: str, shelf: str) -> Literal:
    return Literal(Predicate.IN, (o, shelf))


def in_grasp(o: str) -> Literal:
    return Literal(Predicate.IN_GRASP, (o,))


def clear(o: str) -> Literal:
    return Literal(Predicate.CLEAR, (o,))
