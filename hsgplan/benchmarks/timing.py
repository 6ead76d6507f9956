"""The paper's Table 2: seconds of task planning and of motion per episode, our agent
(the learned regression planner and the motion GNN) against a search-based baseline, in one
run and on the same goals and start scenes. The baseline is one of `SEARCH_BASELINES`
(`agents/registry.py`):
`search` (`agents/search.py`: Fast Downward on the abstract domain, its plan refined by trials)
or one of the PDDLStream-style ones (`agents/stream.py`: PDDLStream's incremental or focused
algorithm over poses, grasps, configurations and pushes).

Each agent's episodes go into a run folder of its own (`ours/`, and `search/` or `stream/`),
resumable as every evaluation is; `table2.md`, `table2.png` and `summary.json` are written
beside them. Times per episode are sums over its steps: the task level's seconds, and the
motion level's (choosing parameters, the baseline's stream evaluation or trials included, and
executing them).
"""

from __future__ import annotations

import json
import statistics
from collections.abc import Callable, Sequence
from dataclasses import replace
from pathlib import Path

from hsgplan.agents.registry import DEFAULT_SEARCH, SEARCH_BASELINES
from hsgplan.domain.errors import InvalidInputError
from hsgplan.evaluation.config import EvalConfig
from hsgplan.evaluation.episode import EpisodeRecord
from hsgplan.evaluation.failures import Failure
from hsgplan.evaluation.protocol import check_runs, episode_specs, run_evaluation
from hsgplan.evaluation.seeds import marked, seed_words
from hsgplan.evaluation.table1 import TextTable
from hsgplan.files import write_atomically
from hsgplan.runner.run_folder import check_claim, claim
from hsgplan.viz.plots import plot_times_by_size

# Table 2 of the paper (seconds per episode: task, motion), by solver and size.
PAPER_TABLE2: dict[str, dict[int, tuple[float, float]]] = {
    "pddlstream": {
        2: (127.9, 23.5),
        3: (251.7, 35.7),
        4: (251.2, 62.9),
        5: (322.2, 107.0),
        6: (424.2, 276.9),
    },
    "paper": {2: (0.15, 18.1), 3: (0.13, 27.2), 4: (0.22, 36.5), 5: (0.29, 42.9), 6: (0.32, 49.4)},
}
LABELS = {
    "ours": "ours",
    "search": "search",
    "stream": "stream (PDDLStream-style)",
    "stream-goal": "stream-goal (PDDLStream-style, goal-directed streams)",
    "stream-focused": "stream-focused (PDDLStream-style, focused algorithm)",
    "stream-focused-goal": "stream-focused-goal (PDDLStream-style, focused, goal-directed)",
    "pddlstream": "PDDLStream (paper)",
    "paper": "theirs (paper)",
}


def timing_agents(search: str = DEFAULT_SEARCH) -> dict[str, str]:
    """column (and run folder) -> registered agent: ours, and the search baseline asked for."""
    if search not in SEARCH_BASELINES:
        raise InvalidInputError(
            f"--search '{search}': the search baseline is one of {', '.join(SEARCH_BASELINES)}"
        )
    return {"ours": "learned", search: search}


def _quartiles(values: list[float]) -> dict[str, float]:
    if len(values) == 1:
        return {"median": values[0], "q1": values[0], "q3": values[0]}
    q1, median, q3 = statistics.quantiles(values, n=4, method="inclusive")
    return {"median": median, "q1": q1, "q3": q3}


def timing_summary(records: Sequence[EpisodeRecord]) -> dict:
    """Medians and quartiles of an agent's seconds per episode, and its success rate, over the
    episodes whose start scene could be sampled (the others are counted apart)."""
    tried = [r for r in records if r.failure != Failure.UNSAMPLED]
    if not tried:
        raise InvalidInputError(
            f"no start scene could be sampled for any of {len(records)} goals of "
            f"{records[0].size} objects"
        )
    unsampled = len(records) - len(tried)
    records = tried
    task = [r.task_seconds for r in records]
    motion = [r.motion_seconds for r in records]
    t, m = _quartiles(task), _quartiles(motion)
    return {
        "task_s": t["median"],
        "task_q1": t["q1"],
        "task_q3": t["q3"],
        "motion_s": m["median"],
        "motion_q1": m["q1"],
        "motion_q3": m["q3"],
        "success_rate": sum(r.success for r in records) / len(records),
        "episodes": len(records),
        "unsampled_scenes": unsampled,
    }


TIMING_KIND = "bench-timing"


def check_timing_folder(
    sizes: Sequence[int],
    goals: int,
    seed: int,
    out: Path,
    search: str = DEFAULT_SEARCH,
    scene: str | None = None,
    split: str | None = None,
) -> tuple[dict, str]:
    """Every refusal of the run folders before anything is written; what the top folder is
    claimed with and its refusal."""
    agents = timing_agents(search)
    config = EvalConfig("", tuple(sizes), goals, seed, scene=scene, split=split)
    table = {"sizes": list(config.sizes), "goals": goals, "seed": seed}
    if split is not None:  # folders from before splits keep their claim
        table["split"] = split
    if search != "search":  # folders made before there was a choice timed `search`, unnamed
        table["search"] = search
    if scene is not None:  # folders of the kitchen keep the claim they had before scenes
        table["scene"] = scene
    refusal = (
        f"'{out}' holds a timing run with other sizes, goals, seed or search baseline; "
        "use another --out"
    )
    check_claim(out, TIMING_KIND, table, refusal)
    check_runs(config, out, {name: (agent, "gt") for name, agent in agents.items()})
    return table, refusal


def run_timing(
    sizes: Sequence[int],
    goals: int,
    seed: int,
    out: Path,
    workers: int = 1,
    on_episode: Callable[[EpisodeRecord], None] | None = None,
    search: str = DEFAULT_SEARCH,
    ray: str | None = None,
    scene: str | None = None,
    split: str | None = None,
) -> dict:
    """Both agents' episodes into `out/AGENT/` (on Ray at `ray`, one core an episode as on
    the local pool); the summary, also written as `summary.json`, `table2.md` and
    `table2.png` in `out`.

    `{"by_size": {"2": {"ours": {"task_s", "motion_s", "success_rate", ...}, "search": {...}}},
    "search": "search", ...}`: the baseline's entries are under its name (`search` or
    `stream`), which `"search"` names.
    """
    config = EvalConfig("", tuple(sizes), goals, seed, scene=scene, split=split)
    table, refusal = check_timing_folder(sizes, goals, seed, out, search, scene, split)
    claim(out, TIMING_KIND, table, refusal)
    records = {
        key: run_evaluation(replace(config, agent=agent), out / key, workers, on_episode, ray)
        for key, agent in timing_agents(search).items()
    }
    report = {
        "by_size": {
            str(n): {k: timing_summary([r for r in rs if r.size == n]) for k, rs in records.items()}
            for n in sorted(set(sizes))
        },
        "search": search,
        "goals": goals,
        "seed": seed,
        "split": split,
        "workers": workers,
        "protocol": config.protocol,
        "run": str(out),
    } | ({} if scene is None else {"scene": scene})
    write_atomically(out / "summary.json", json.dumps(report, indent=2) + "\n")
    write_atomically(out / "table2.md", "\n\n".join(t.markdown() for t in tables(report)) + "\n")
    plot_times_by_size(_series(report), out / "table2.png")
    return report


def total_episodes(
    sizes: Sequence[int], goals: int, seed: int, scene: str | None = None, split: str | None = None
) -> int:
    config = EvalConfig("", tuple(sizes), goals, seed, scene=scene, split=split)
    return len(timing_agents()) * len(episode_specs(config))


def _series(report: dict) -> dict[str, dict[str, dict[int, float]]]:
    """label -> level ("task" / "motion") -> size -> median seconds, ours and the paper's."""
    series: dict[str, dict[str, dict[int, float]]] = {}
    for n, by_agent in report["by_size"].items():
        for k, v in by_agent.items():
            s = series.setdefault(LABELS[k], {"task": {}, "motion": {}})
            s["task"][int(n)], s["motion"][int(n)] = v["task_s"], v["motion_s"]
    for k, by_size in PAPER_TABLE2.items():
        series[LABELS[k]] = {
            "task": {n: t for n, (t, _) in by_size.items()},
            "motion": {n: m for n, (_, m) in by_size.items()},
        }
    return series


def _seconds(v: dict, level: str) -> str:
    return f"{v[f'{level}_s']:.3g} ({v[f'{level}_q1']:.3g}–{v[f'{level}_q3']:.3g})"


def tables(report: dict) -> list[TextTable]:
    rows = []
    name = report.get("search", "search")  # summaries from before the choice hold `search`
    for n, v in report["by_size"].items():
        ours, search = v["ours"], v[name]
        paper = {k: PAPER_TABLE2[k].get(int(n)) for k in PAPER_TABLE2}
        ratio = search["task_s"] / ours["task_s"] if ours["task_s"] > 0 else float("inf")
        rows.append(
            (
                n,
                _seconds(search, "task"),
                _seconds(ours, "task"),
                f"{ratio:,.0f}×",
                f"{search['motion_s']:.3g} / {ours['motion_s']:.3g}",
                f"{search['success_rate']:.2f} / {ours['success_rate']:.2f}",
                *(f"{p[0]:g} / {p[1]:g}" if p else "—" for p in paper.values()),
            )
        )
    # eight columns: the motion level's medians share one (its quartiles are in summary.json)
    header = (
        "objects",
        f"{name} task s",
        "ours task s",
        "task speed-up",
        f"motion s {name} / ours",
        f"success {name} / ours",
        "PDDLStream task / motion (paper)",
        "theirs task / motion (paper)",
    )
    title = (
        f"Seconds per episode, {report['goals']} goals per size, "
        f"{seed_words(report['seed'], report.get('split'))}, "
        + (f"in {report['scene']}, " if "scene" in report else "")
        + f"{report['workers']} worker(s): the search baseline ({LABELS[name]}) against ours, "
        "beside the paper's Table 2; task medians (quartiles), their ratio, motion medians"
        + (f"; success under the {report['protocol']} protocol" if "protocol" in report else "")
    )
    title = marked(title, report["seed"], split=report.get("split"))
    return [TextTable(title, header, tuple(rows))]
