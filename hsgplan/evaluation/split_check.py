"""`hsgplan splits check`: is the test split sealed from everything that learned or chose?

It reads what every collection and tuning run under the folders it is given drew (each row
records its goal and its start scene's seed), draws the test split's episodes as a published
run draws them, and compares, goals in their canonical text (`splits.canonical`):
- a (goal, start scene) pair the test shares with any collection or tuning run fails it;
- so does a goal shared at a size whose goal space is cut (`SHARED_SIZES` are not); there
  it says how many distinct goals the space holds and how many of the test's are shared.

Collections are `collect visited` folders and demonstration sets; tuning runs are `eval`
folders on the tune split or a tuning seed. Test-split runs found add their episodes to the
test's. Nothing is written.
"""

from __future__ import annotations

import json
import random
import re
from collections.abc import Iterable, Iterator
from dataclasses import dataclass, field
from functools import cache
from pathlib import Path

from hsgplan.domain.errors import InvalidInputError
from hsgplan.domain.goals import parse_goal
from hsgplan.domain.scene_file import default_world
from hsgplan.evaluation.seeds import GOAL_SEEDS, episode_seed, is_tuning
from hsgplan.evaluation.splits import SHARED_SIZES, TEST, TUNE, canonical, split_goals

# what a published run draws from the test split: the sizes of the tables, goals and repeats
TEST_SIZES = (2, 3, 4, 5, 6, 8, 10, 12)
TEST_GOALS = 100
TEST_REPEATS = 5


@dataclass(frozen=True)
class Draw:
    """One episode's goal (canonical text), size and start scene's seed, and where it was."""

    goal: str
    size: int
    seed: int
    source: str


@dataclass
class SizeReport:
    size: int
    test_goals: set[str] = field(default_factory=set)
    shared_training: set[str] = field(default_factory=set)
    shared_tuning: set[str] = field(default_factory=set)
    shared_pairs: list[tuple[Draw, Draw]] = field(default_factory=list)
    space: int | None = None  # distinct goals in a shared size's space

    @property
    def sealed(self) -> bool:
        apart = self.size in SHARED_SIZES or not (self.shared_training or self.shared_tuning)
        return apart and not self.shared_pairs


def _canonical(text: str) -> tuple[str, int]:
    """A goal's canonical text and size; a goal in names the kitchen lacks (another world's),
    its literals sorted: it cannot be a kitchen goal."""
    try:
        goal = parse_goal(text, validate=False, world=default_world())
        return canonical(goal), goal.size
    except InvalidInputError:
        literals = sorted(part.strip() for part in text.split("&"))
        names = {a.strip() for lit in literals for a in lit[lit.find("(") + 1 : -1].split(",")}
        return " & ".join(literals), len(names)


def _rows(folder: Path, name: str) -> Iterator[dict]:
    path = folder / name
    if not path.is_file():
        return
    for line in path.read_text(errors="replace").splitlines():
        try:
            yield json.loads(line)
        except json.JSONDecodeError:
            continue  # a line cut short by an interruption: its episode runs again


def _read_json(path: Path) -> dict | None:
    try:
        value = json.loads(path.read_text())
    except (OSError, ValueError):
        return None
    return value if isinstance(value, dict) else None


def _visited(folder: Path) -> Iterator[Draw]:
    for row in _rows(folder, "episodes.jsonl"):
        result = row.get("result", {})
        if "goal" not in result:
            continue
        goal, size = _canonical(result["goal"])
        seed = result.get("seed")
        if seed is None:  # rows from before they recorded it: the seed their key names
            run, n, index = (int(x) for x in row["key"].split("/"))
            seed = GOAL_SEEDS.start + episode_seed(run, n, index)
        yield Draw(goal, size, seed, str(folder))


def _demos(folder: Path) -> Iterator[Draw]:
    for row in _rows(folder, "demos.jsonl"):
        goal, size = _canonical(row["goal"])
        yield Draw(goal, size, int(row["seed"]), str(folder))


def _episodes(folder: Path) -> Iterator[Draw]:
    for row in _rows(folder, "episodes.jsonl"):
        result = row.get("result", {})
        if "goal" in result and "seed" in result:
            goal, size = _canonical(result["goal"])
            yield Draw(goal, size, int(result["seed"]), str(folder))


@dataclass
class Found:
    training: list[Draw] = field(default_factory=list)
    tuning: list[Draw] = field(default_factory=list)
    test: list[Draw] = field(default_factory=list)
    folders: dict[str, int] = field(default_factory=dict)  # kind -> folders read
    # the layout seed of every generated scene file a folder names, by folder
    layouts: dict[str, set[int]] = field(default_factory=dict)  # collections and tuning runs
    test_layouts: dict[str, set[int]] = field(default_factory=dict)  # test-split runs

    def leaks(self) -> list[str]:
        """Where layouts cross: a collection or tuning run in a test layout, or a test run in
        one of another split."""
        found = [
            f"{folder} ran in test-split layouts (seeds {sorted(s & set(TEST.layouts))[:3]})"
            for folder, s in sorted(self.layouts.items())
            if s & set(TEST.layouts)
        ]
        return found + [
            f"{folder}, a test-split run, ran in layouts of seeds {sorted(s)[:3]}: not the test's"
            for folder, s in sorted(self.test_layouts.items())
            if s - set(TEST.layouts)
        ]


_LAYOUT_SEED = re.compile(r"^# hsgplan scenes .*--seed (\d+)")


def layout_seeds(scene: str | Path) -> set[int]:
    """The layout seeds of the generated scene files at `scene` (a file or a folder of them),
    read from the command each names in its first line; hand-written scenes have none."""
    path = Path(scene)
    files = sorted(path.glob("*.toml")) if path.is_dir() else [path]
    seeds = set()
    for f in files:
        try:
            first = f.read_text().splitlines()[0]
        except (OSError, IndexError):
            continue
        if m := _LAYOUT_SEED.match(first):
            seeds.add(int(m.group(1)))
    return seeds


def find(roots: Iterable[Path]) -> Found:
    """Every collection, tuning run and test run under `roots`."""
    found = Found()
    for root in roots:
        if not root.exists():
            raise InvalidInputError(f"'{root}' does not exist")
        for path in sorted(root.rglob("*.json")):
            if path.name not in ("config.json", "meta.json"):
                continue
            data = _read_json(path) or {}
            folder = path.parent
            if scene := data.get("scene"):
                test_run = data.get("kind") == "eval" and data.get("split") == TEST.name
                into = found.test_layouts if test_run else found.layouts
                tuning = data.get("split") == TUNE.name or is_tuning(int(data.get("seed", -1)))
                if data.get("kind") != "eval" or test_run or tuning:
                    into.setdefault(str(folder), set()).update(layout_seeds(scene))
            if data.get("format") == "hsgplan-demos":
                kind, draws = "demonstrations", found.training
                draws += _demos(folder)
            elif data.get("kind") == "reach" and data.get("unit") == "visited episode":
                kind, draws = "visited collections", found.training
                draws += _visited(folder)
            elif data.get("kind") == "eval" and data.get("split") == TEST.name:
                kind = "test runs"
                found.test += _episodes(folder)
            elif data.get("kind") == "eval" and (
                data.get("split") == TUNE.name or is_tuning(int(data.get("seed", -1)))
            ):
                kind = "tuning runs"
                found.tuning += _episodes(folder)
            else:
                continue
            found.folders[kind] = found.folders.get(kind, 0) + 1
    return found


def drawn_by_test(sizes: Iterable[int] = TEST_SIZES) -> list[Draw]:
    """The test split's episodes in the kitchen as a published run draws them."""
    return list(_drawn_by_test(tuple(sizes)))


@cache
def _drawn_by_test(sizes: tuple[int, ...]) -> tuple[Draw, ...]:
    """`drawn_by_test`, drawn once a process: every check asks for the same draws, and drawing
    the goals of every size takes seconds."""
    seed = TEST.seeds.start
    draws = []
    for n in sizes:
        goals = split_goals(TEST, n, TEST_GOALS, seed, stacking=n > 2, world=default_world())
        for i, g in enumerate(goals):
            text = canonical(g)
            draws += [
                Draw(text, n, episode_seed(seed, n, i, r), "test split")
                for r in range(TEST_REPEATS)
            ]
    return tuple(draws)


def goal_space(n: int, draws: int = 3000) -> int:
    """How many distinct goals of n objects the generator draws (a shared size's whole
    space: the 2-object one is reached within a few hundred draws)."""
    rng_seed = random.Random(f"space-{n}").randrange(2**31)
    drawn = split_goals(None, n, draws, rng_seed, n > 2, world=default_world())
    return len({canonical(g) for g in drawn})


def check(
    roots: Iterable[Path], sizes: Iterable[int] = TEST_SIZES
) -> tuple[list[SizeReport], Found]:
    found = find(roots)
    test = drawn_by_test(sizes) + found.test
    reports = {n: SizeReport(n) for n in sorted({d.size for d in test})}
    by_pair: dict[tuple[str, int], Draw] = {}
    for d in found.training + found.tuning:
        by_pair.setdefault((d.goal, d.seed), d)
    training_goals = {d.goal for d in found.training}
    tuning_goals = {d.goal for d in found.tuning}
    for d in test:
        r = reports[d.size]
        r.test_goals.add(d.goal)
        if d.goal in training_goals:
            r.shared_training.add(d.goal)
        if d.goal in tuning_goals:
            r.shared_tuning.add(d.goal)
        if (other := by_pair.get((d.goal, d.seed))) is not None:
            r.shared_pairs.append((d, other))
    for r in reports.values():
        if r.size in SHARED_SIZES:
            r.space = goal_space(r.size)
    return list(reports.values()), found
