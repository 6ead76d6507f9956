"""Goals: sets of literals, their text syntax, and goal files.

Syntax (CLI, files, tests): literals such as `On(butter, cherries)`, `In(tomato_soup, shelf_a)`,
`Clear(popcorn)`, optionally negated with `not` or `!`, separated by `&`, `;` or new lines.
Predicate and entity names are case-insensitive and may be CamelCase (`AlphabetSoup`).
A goal file holds one goal per line; blank lines and lines starting with `#` are skipped.
"""

from __future__ import annotations

import itertools
import re
from collections.abc import Iterable
from dataclasses import dataclass, field
from pathlib import Path

from hsgplan.domain.checks import MAX_GOAL_FILE_BYTES, MAX_GOAL_FILE_GOALS, read_text
from hsgplan.domain.errors import GoalSyntaxError, InvalidInputError, UnknownNameError
from hsgplan.domain.feasibility import check_literals
from hsgplan.domain.predicates import PREDICATES, Literal, Predicate
from hsgplan.domain.scene import World
from hsgplan.files import write_atomically

MAX_GOAL_CHARS = 10_000

_LITERAL = re.compile(
    r"^(?:(?P<neg>not\s+|!\s*))?(?P<pred>[A-Za-z_][A-Za-z0-9_]*)\s*\((?P<args>[^()]*)\)$"
)
_NAME = re.compile(r"^[A-Za-z][A-Za-z0-9_]*$")
_PREDICATE_BY_KEY = {p.value.lower(): p for p in PREDICATES} | {"in_grasp": Predicate.IN_GRASP}


@dataclass(frozen=True)
class Goal:
    """A conjunction of literals. Its problem size is the number of objects it names.

    Attributes:
        world: the world whose names the literals use (goals over the same literals in two
            worlds compare equal).
    """

    literals: frozenset[Literal]
    world: World = field(compare=False, hash=False, repr=False)

    @property
    def objects(self) -> tuple[str, ...]:
        w = self.world
        return w.sort_objects(o for lit in self.literals for o in lit.objects(w))

    @property
    def size(self) -> int:
        return len(self.objects)

    def sorted_literals(self) -> list[Literal]:
        order = {o: i for i, o in enumerate(self.objects)}
        return sorted(
            self.literals,
            key=lambda x: (order[x.subject], PREDICATES.index(x.predicate), x.args, x.positive),
        )

    def satisfied_by(self, state) -> bool:
        """Whether every literal holds in a `SymbolicSceneGraph`."""
        return all(state.holds(lit) for lit in self.literals)

    def unsatisfied(self, state) -> list[Literal]:
        return [lit for lit in self.sorted_literals() if not state.holds(lit)]

    def __str__(self) -> str:
        return " & ".join(str(lit) for lit in self.sorted_literals())

    def readings(self) -> list[Goal]:
        """The goal with the instances of each type it names twice or more (`cherries`,
        `cherries_2`) swapped in every way, itself first: to a robot that tells objects apart
        by how they look alone, look-alikes are one another, and a goal over them is reached
        when any reading holds."""
        return [self.renamed(names) for names in self.renamings()]

    def renamings(self) -> list[dict[str, str]]:
        """The renamings `readings` applies, the identity first."""
        by_type: dict[str, list[str]] = {}
        for o in self.objects:
            by_type.setdefault(self.world.split_instance(o)[0], []).append(o)
        groups = [names for names in by_type.values() if len(names) > 1]
        names = [o for g in groups for o in g]
        return [
            dict(zip(names, itertools.chain(*orders), strict=True))
            for orders in itertools.product(*(itertools.permutations(g) for g in groups))
        ]

    def without(self, objects) -> Goal | None:
        """The goal's literals that name none of `objects`; None if none is left."""
        gone = set(objects)
        kept = frozenset(lit for lit in self.literals if not gone & set(lit.objects(self.world)))
        return Goal(kept, self.world) if kept else None

    def renamed(self, names: dict[str, str]) -> Goal:
        """The goal with each object named in `names` called by its value instead."""
        return Goal(
            frozenset(
                Literal(lit.predicate, tuple(names.get(a, a) for a in lit.args), lit.positive)
                for lit in self.literals
            ),
            self.world,
        )


def _snake(name: str) -> str:
    """`AlphabetSoup` -> `alphabet_soup`, `shelfA` -> `shelf_a`, `Cherries_2` -> `cherries_2`."""
    return re.sub(r"(?<=[a-z0-9])(?=[A-Z])", "_", name).lower()


def parse_literal(text: str, world: World) -> Literal:
    """One literal; raises an InvalidInputError naming it and the reason."""
    src = text.strip()
    m = _LITERAL.match(src)
    if not m:
        raise GoalSyntaxError(f"'{src}' is not a literal like On(butter, shelf_a)")
    key = _snake(m.group("pred"))
    pred = _PREDICATE_BY_KEY.get(key) or _PREDICATE_BY_KEY.get(key.replace("_", ""))
    if pred is None:
        raise UnknownNameError(
            f"'{src}': unknown predicate '{m.group('pred')}' (known: On, In, InGrasp, Clear)"
        )
    raw_args = [a.strip() for a in m.group("args").split(",")]
    if raw_args == [""]:
        raw_args = []
    if len(raw_args) != pred.arity:
        raise GoalSyntaxError(
            f"'{src}': {pred.value} takes {pred.arity} argument(s), got {len(raw_args)}"
        )
    args = []
    for i, raw in enumerate(raw_args):
        if not _NAME.match(raw):
            raise GoalSyntaxError(f"'{src}': '{raw}' is not a name")
        name = _snake(raw)
        try:
            kind = world.kind_of(name)
        except UnknownNameError as e:
            raise UnknownNameError(f"'{src}': {e}") from None
        if kind not in pred.signature[i]:
            allowed = " or ".join(sorted(k.value for k in pred.signature[i]))
            raise GoalSyntaxError(
                f"'{src}': argument {i + 1} of {pred.value} must be a {allowed}, "
                f"'{name}' is a {kind.value}"
            )
        args.append(name)
    return Literal(pred, tuple(args), positive=m.group("neg") is None)


def split_literals(text: str) -> list[str]:
    """The literal texts of a goal, separated by `&`, `;` or new lines.

    Blank lines are skipped, but an `&` or `;` must stand between two literals: one at the
    start or the end of the goal, or two in a row, is refused (`GoalSyntaxError`).
    """
    literals = []
    parts = re.split(r"([&;])", text)
    for i in range(0, len(parts), 2):
        lines = [line.strip() for line in parts[i].split("\n") if line.strip()]
        if not lines and len(parts) > 1:
            before = parts[i - 1] if i > 0 else None
            after = parts[i + 1] if i + 1 < len(parts) else None
            if before is None:
                raise GoalSyntaxError(f"the goal starts with '{after}', not with a literal")
            if after is None:
                raise GoalSyntaxError(f"the goal ends with '{before}', not with a literal")
            raise GoalSyntaxError(f"no literal between '{before}' and '{after}'")
        literals += lines
    return literals


def parse_goal(text: str, validate: bool = True, *, world: World) -> Goal:
    """Parse goal text; with `validate`, also refuse contradictory or impossible goals."""
    if len(text) > MAX_GOAL_CHARS:
        raise GoalSyntaxError(f"the goal is {len(text)} characters long; at most {MAX_GOAL_CHARS}")
    if not re.sub(r"[&;\s]", "", text):
        raise GoalSyntaxError("the goal is empty")
    goal = Goal(frozenset(parse_literal(part, world) for part in split_literals(text)), world)
    if validate:
        check_literals(goal.literals, world=world)
    return goal


def goal_of(literals: Iterable[Literal], world: World) -> Goal:
    """A checked goal from literals."""
    goal = Goal(frozenset(literals), world)
    check_literals(goal.literals, world=world)
    return goal


def write_goal_file(path: Path, goals: Iterable[Goal], header: str = "") -> None:
    """One goal per line, after optional `#` comment lines."""
    lines = [f"# {h}" for h in header.splitlines()] + [str(g) for g in goals]
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    write_atomically(path, "\n".join(lines) + "\n")  # an existing file is replaced or kept


def read_goal_file(path: Path, world: World) -> list[Goal]:
    """Every goal in a goal file; a bad line raises with its line number. A file larger than
    `MAX_GOAL_FILE_BYTES` or holding more than `MAX_GOAL_FILE_GOALS` goals is refused before
    any goal is parsed (parsing a million would take minutes with nothing shown)."""
    lines = [
        (n, text)
        for n, line in enumerate(
            read_text(Path(path), "goal file", MAX_GOAL_FILE_BYTES).splitlines(), start=1
        )
        if (text := line.strip()) and not text.startswith("#")
    ]
    if len(lines) > MAX_GOAL_FILE_GOALS:
        raise InvalidInputError(
            f"goal file '{path}' holds {len(lines)} goals; at most {MAX_GOAL_FILE_GOALS}"
        )
    goals = []
    for n, text in lines:
        try:
            goals.append(parse_goal(text, world=world))
        except InvalidInputError as e:
            raise type(e)(f"{path}:{n}: {e}") from None
    if not goals:
        raise InvalidInputError(f"goal file '{path}' holds no goal")
    return goals
