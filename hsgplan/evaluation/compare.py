"""Finished `eval world` runs side by side, one row each: a ladder from one recipe to another,
one change per row; or finished `eval task` runs (the symbolic loop) the same way.

The runs must be like for like (protocol, goals, repeats, seed, sizes, rules switched off; for
`eval task` runs, the protocol and the very same episodes): only what the agent reads (its
checkpoints, and for a ladder its task planner's loop) may differ, so a row's gain over the
row above is the change that row names.
"""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path

from hsgplan.domain.checks import read_json
from hsgplan.domain.errors import InvalidInputError
from hsgplan.domain.recovery import RECOVERING
from hsgplan.evaluation.intervals import separate, training_goal_interval
from hsgplan.evaluation.report import read_summary
from hsgplan.evaluation.seeds import marked, seed_words
from hsgplan.evaluation.table1 import (
    PAPER_TABLE1,
    TextTable,
    cell,
    label,
    protocol_name,
    runs_words,
    where,
)
from hsgplan.runner.run_folder import CONFIG, logged_rows

# the key to `marked_rows`' marks, in a title
MARKS = "; ▲ (▼): the interval lies wholly above (below) the row above's"
MARKS_FIRST = "; ▲ (▼): the interval lies wholly above (below) the first row's"
# what rows must share; the checkpoints are what a ladder's rows change
LIKE_FOR_LIKE = (
    "protocol",
    "rules_off",
    "perception_rules",
    "plan_rules",
    "goals",
    "goals_file",
    "repeats",
    "seed",
    "split",
    "sizes",
    "scene",
)
# what runs of one agent in different worlds may differ in besides the scene: the goals per scene
# file (a folder of 20 scenes with 5 goals each against the kitchen's 100), as long as every
# size has as many episodes in each run
ACROSS_SCENES = ("scene", "goals")
# what a ladder of rules changes from row to row (`across_rules`)
RULES = ("rules_off", "perception_rules", "plan_rules")


def compare(
    runs: Sequence[Path],
    names: Sequence[str],
    methods: Sequence[str],
    across_scenes: bool = False,
    across_rules: bool = False,
) -> TextTable:
    """One row per run folder (`names[i]` for `runs[i]`): its method's success rate and subgoal
    completion per size (`methods`: one for every run, or one per run), and the paper's row
    where it reports the one method compared. With `across_scenes`, the runs may have run in
    different scenes (and so with different goals per scene file), as many episodes per size;
    with `across_rules`, under different recovery rules switched off (a ladder of rules, each
    row's named in its name; the title then names none).

    Raises InvalidInputError for a folder that is no finished eval world run, one without its
    method, or runs that are not like for like (the first setting that differs is named)."""
    if len(names) != len(runs):
        raise InvalidInputError(f"{len(runs)} runs and {len(names)} names: name each run once")
    if len(methods) not in (1, len(runs)):
        raise InvalidInputError(f"{len(runs)} runs and {len(methods)} methods: one, or one per run")
    methods = list(methods) * len(runs) if len(methods) == 1 else list(methods)
    summaries = [read_summary(run) for run in runs]
    settings = [_settings(run) for run in runs]
    for run, summary, s, method in zip(runs, summaries, settings, methods, strict=True):
        if method not in summary["methods"]:
            known = ", ".join(summary["methods"])
            raise InvalidInputError(f"'{run}' holds no method '{method}' (it holds {known})")
        for key in LIKE_FOR_LIKE:
            if (across_scenes and key in ACROSS_SCENES) or (across_rules and key in RULES):
                continue
            if s.get(key) != settings[0].get(key):
                raise InvalidInputError(
                    f"'{run}' and '{runs[0]}' differ in {key} ({s.get(key)} against "
                    f"{settings[0].get(key)}): a comparison's rows must be like for like"
                )
    by_run = [s["methods"][m]["by_size"] for s, m in zip(summaries, methods, strict=True)]
    sizes = sorted({int(n) for by_size in by_run for n in by_size})
    if across_scenes:
        _check_episodes(runs, by_run)
    rows = []
    for name, by_size in zip(names, by_run, strict=True):
        rows.append((name, *(cell(by_size[str(n)]) if str(n) in by_size else "—" for n in sizes)))
    intervals = [[by_size.get(str(n), {}).get("success_ci") for n in sizes] for by_size in by_run]
    rows = marked_rows(rows, intervals, against_first=across_scenes)
    one = len(set(methods)) == 1
    method = methods[0] if one else ""
    if one and (paper := PAPER_TABLE1.get(method)):
        cells = (f"{paper[n][0]:.2f} / {paper[n][1]:.2f}" if n in paper else "—" for n in sizes)
        rows.append((f"{label(method)} (paper)", *cells))
    first = summaries[0]
    source = first["goals_file"] or f"{first['goals']} random goals per size"
    repeats = runs_words(first).removeprefix(", ")
    what = label(method) if one else "each run's method"
    if across_scenes:
        episodes = next(iter(by_run[0].values()))["episodes"]
        source, by, place = f"{episodes} episodes per size in each run's scenes", "scene", ""
    else:
        by, place = "run", where(first)
    protocol = protocol_name({**first, "rules_off": []} if across_rules else first)
    title = (
        f"Success rate / subgoal completion of {what} "
        f"by {by} ({protocol}{', rules by row' if across_rules else ''}): "
        f"{source}, {repeats}, {seed_words(first['seed'], first.get('split'))}{place}"
        + ((MARKS_FIRST if across_scenes else MARKS) if any(map(any, intervals)) else "")
    )
    header = ("run", *(f"{n} objects" for n in sizes))
    return TextTable(marked(title, first["seed"], split=first.get("split")), header, tuple(rows))


def marked_rows(
    rows: list[tuple[str, ...]], intervals: list[list], against_first: bool = False
) -> list[tuple[str, ...]]:
    """Each row's cells marked ▲ (▼) where its success interval lies wholly above (below) the
    row above's (the first row's, `against_first`): the only difference called a gain (or a
    loss)."""
    out = rows[:1]
    for k in range(1, len(rows)):
        cells = list(rows[k])
        base = intervals[0 if against_first else k - 1]
        for j, (now, before) in enumerate(zip(intervals[k], base, strict=True)):
            if separate(now, before):
                cells[j + 1] += " ▲" if now[0] > before[1] else " ▼"
        out.append(tuple(cells))
    return out


def _check_episodes(runs: Sequence[Path], by_run: list[dict]) -> None:
    """Runs in different scenes stand side by side only with as many episodes of every size."""
    for run, by_size in zip(runs, by_run, strict=True):
        for n, size in by_size.items():
            theirs = by_run[0].get(n, {}).get("episodes")
            if size["episodes"] != theirs:
                raise InvalidInputError(
                    f"'{run}' ran {size['episodes']} episodes of {n} objects and '{runs[0]}' "
                    f"{theirs or 0}: runs in different scenes compare on as many episodes"
                )


def only_method(runs: Sequence[Path]) -> str:
    """The one method every eval world run holds (an agent's run holds `learned`, an ablation's
    variants theirs), else `gnn`, Table 1's column."""
    if not all((run / "summary.json").is_file() for run in runs):
        return "gnn"  # a folder that is no run is refused with its reason where it is read
    held = {tuple(read_summary(run)["methods"]) for run in runs}
    only = held.pop() if len(held) == 1 else ()
    return only[0] if len(only) == 1 else "gnn"


def _settings(run: Path) -> dict:
    # a recovering run with every rule on records neither (`table1.table_settings`)
    defaults = {"protocol": RECOVERING, "rules_off": []}
    return defaults | read_json(run / CONFIG, "run configuration")


def all_task_runs(runs: Sequence[Path]) -> bool:
    """Whether every folder is an `eval task` run (compared by `compare_task`)."""
    configs = [run / CONFIG for run in runs]
    return all(
        c.is_file() and read_json(c, "run configuration").get("kind") == "eval-task"
        for c in configs
    )


def compare_task(runs: Sequence[Path], names: Sequence[str]) -> TextTable:
    """One row per `eval task` run folder: success and subgoal completion per size. The runs
    must hold the same episodes (goals and seeds) under the same protocol."""
    if len(names) != len(runs):
        raise InvalidInputError(f"{len(runs)} runs and {len(names)} names: name each run once")
    protocol, per_size, summaries = task_summaries(runs)
    sizes = sorted({int(n) for s in summaries for n in s})
    rows = [
        (name, *(_task_cell(s.get(str(n))) for n in sizes))
        for name, s in zip(names, summaries, strict=True)
    ]
    # a folder of scenes runs the same goals in each; a run with a scene keys its episodes by
    # the scene file's stem first
    scenes = {str(row["key"]).split("/", 1)[0] for row in logged_rows(runs[0])}
    source = f"{per_size} goals per size"
    if _settings(runs[0]).get("scene") and len(scenes) > 1:
        source = f"{per_size // len(scenes)} goals per size in each of {len(scenes)} scenes"
    title = f"Success rate / subgoal completion in the symbolic loop by run ({protocol}): {source}"
    return TextTable(title, ("run", *(f"{n} objects" for n in sizes)), tuple(rows))


def compare_task_trainings(runs: Sequence[Path], names: Sequence[str], trainings: int) -> TextTable:
    """One row per `trainings` consecutive `eval task` runs (a configuration trained that many
    times, each training run on the same episodes): the success rate's mean over trainings
    and goals with its 95% interval (a bootstrap drawing trainings and goals), and subgoal
    completion's mean, per size."""
    if trainings < 1 or len(runs) % trainings:
        raise InvalidInputError(
            f"{len(runs)} runs in rows of {trainings} trainings: give each row all its runs"
        )
    rows_of = [runs[k : k + trainings] for k in range(0, len(runs), trainings)]
    if len(names) != len(rows_of):
        raise InvalidInputError(f"{len(rows_of)} rows and {len(names)} names: name each row once")
    protocol, per_size, _ = task_summaries(runs)  # like for like, or refused
    sizes = sorted({e.size for e in task_episodes(runs[0])})
    table, intervals = [], []
    for k, name in enumerate(names):
        by_size = over_trainings(rows_of[k], sizes)
        cells = [
            f"{mean:.2f} ({low:.2f}–{high:.2f}) / {done:.2f}" for mean, (low, high), done in by_size
        ]
        table.append((name, *cells))
        intervals.append([ci for _, ci, _ in by_size])
    title = (
        f"Success rate / subgoal completion in the symbolic loop by configuration ({protocol}): "
        f"{per_size} goals per size, each run once under each of {trainings} trainings (in "
        f"brackets the 95% interval of a bootstrap that draws trainings and goals){MARKS}"
    )
    header = ("configuration", *(f"{n} objects" for n in sizes))
    return TextTable(title, header, tuple(marked_rows(table, intervals)))


def task_episodes(run: Path) -> list:
    """An eval task run's episodes."""
    from hsgplan.evaluation.task_eval import _episode

    return [_episode(r["result"]) for r in logged_rows(run)]


def over_trainings(runs: Sequence[Path], sizes: Sequence[int]) -> list[tuple]:
    """Per size, over eval task runs of one configuration's trainings on the same episodes:
    the success rate's mean over trainings and goals, its 95% interval (a bootstrap drawing
    trainings and goals) and subgoal completion's mean."""
    episodes = [task_episodes(run) for run in runs]
    out = []
    for n in sizes:
        won: dict = {}
        done = []
        for t, eps in enumerate(episodes):
            for e in (e for e in eps if e.size == n):
                won.setdefault((t, (e.goal, e.seed)), []).append(float(e.success))
                done.append(e.subgoal_completion)
        mean = sum(sum(v) / len(v) for v in won.values()) / len(won)
        ci = training_goal_interval(won) or (mean, mean)
        out.append((mean, ci, sum(done) / len(done)))
    return out


def task_summaries(runs: Sequence[Path]) -> tuple[str, int, list[dict]]:
    """The protocol's name, the goals per size, and each `eval task` run's summary by size.

    Raises InvalidInputError for a folder that is no eval task run or holds no episode, and
    for runs that differ in protocol or episodes (goals and seeds)."""
    from hsgplan.evaluation.task_eval import _episode, summarize_task

    settings = [_settings(run) for run in runs]
    episodes = []
    for run, s in zip(runs, settings, strict=True):
        if s.get("kind") != "eval-task":
            raise InvalidInputError(f"'{run}' is no eval task run")
        rows = logged_rows(run)
        if not rows:
            raise InvalidInputError(f"'{run}' holds no finished episode")
        episodes.append({row["key"]: _episode(row["result"]) for row in rows})
    for run, s, eps in zip(runs, settings, episodes, strict=True):
        if s.get("protocol") != settings[0].get("protocol") or eps.keys() != episodes[0].keys():
            what = "protocol" if s.get("protocol") != settings[0].get("protocol") else "episodes"
            raise InvalidInputError(
                f"'{run}' and '{runs[0]}' differ in {what}: a comparison's rows must be like "
                "for like"
            )
    summaries = [summarize_task(list(eps.values()))["by_size"] for eps in episodes]
    protocol = "paper protocol" if settings[0].get("protocol") == "paper" else "recovering"
    return protocol, len(episodes[0]) // len(summaries[0]), summaries


def _task_cell(size: dict | None) -> str:
    if size is None:
        return "—"
    return f"{size['success_rate']:.2f} / {size['subgoal_completion']:.2f}"
