"""The paper's Table 1 from our episodes: success / subgoal completion per problem size and
motion generator, the paper's numbers beside ours, the spread over repeats, the failure
taxonomy, the time per level, and a plot.

`run_table` runs one evaluation per method (each in a run folder of its own under the table's
folder, resumable as every evaluation is) and writes `table1.md`, `table1.png` and
`summary.json` beside them.
"""

from __future__ import annotations

import json
from collections.abc import Callable
from dataclasses import asdict, dataclass, replace
from pathlib import Path

from hsgplan.domain.recovery import RECOVERING
from hsgplan.evaluation.config import OBSERVERS, TABLES, EvalConfig
from hsgplan.evaluation.episode import EpisodeRecord
from hsgplan.evaluation.protocol import (
    check_runs,
    check_world,
    episode_specs,
    run_evaluation,
    trained,
    training_dir,
)
from hsgplan.evaluation.seeds import is_tuning, marked, seed_words
from hsgplan.evaluation.summary import EXECUTION, OVERSTEP, PERCEPTION, summarize_trainings
from hsgplan.files import write_atomically
from hsgplan.runner.run_folder import check_claim, claim, read_timing, sittings

# Table 1 of the paper (success rate, subgoal completion), by motion generator and size.
PAPER_TABLE1: dict[str, dict[int, tuple[float, float]]] = {
    "random": {2: (0.71, 0.84), 3: (0.60, 0.81), 4: (0.50, 0.78), 5: (0.35, 0.67), 6: (0.18, 0.56)},
    "mlp": {2: (0.85, 0.91), 3: (0.75, 0.87), 4: (0.69, 0.84), 5: (0.56, 0.76), 6: (0.44, 0.67)},
    "gnn": {2: (0.92, 0.95), 3: (0.89, 0.95), 4: (0.84, 0.92), 5: (0.73, 0.87), 6: (0.67, 0.84)},
}
LABELS = {
    "gnn": "GNN",
    "gnn-checked": "GNN (dry runs)",
    "gnn-next-checked": "GNN (place for push, dry runs)",
    "mlp": "MLP",
    "random": "Random",
}


@dataclass(frozen=True)
class Method:
    """One column of the table: its name there, the agent that runs it and what it sees with
    (`EvalConfig.perception`)."""

    name: str
    agent: str
    perception: str = "gt"


TABLE_KIND = "eval-table"
COUNTED = ("failed_primitives", "overstep_after_failures")  # a failure table's last columns


def where(report: dict) -> str:
    """Where a run's episodes ran, for a title: "" in the kitchen without a scene file."""
    scenes = report.get("scenes", [])
    if len(scenes) > 1:
        return f", in each of {len(scenes)} scene files"
    return f", in {scenes[0]}" if scenes else ""


def label(method: str) -> str:
    # a column seeing with f_p (`--perception rgb`): the longest name first (rgb-latest, rgb)
    for observer in sorted(set(OBSERVERS) - {"gt"}, key=len, reverse=True):
        if method.endswith(f"-{observer}"):
            return f"{label(method.removesuffix(f'-{observer}'))} ({observer})"
    return LABELS.get(method, method)


def table_settings(config: EvalConfig) -> dict:
    """What a table folder is claimed with: the configuration less what differs by method (as
    JSON gives it back; the default protocol left out, as before protocols were named)."""
    per_method = ("agent", "perception")
    table = {
        k: v
        for k, v in asdict(config).items()
        if k not in per_method and not (k == "perception_checkpoint" and v is None)
    } | {"sizes": list(config.sizes), "rules_off": list(config.rules_off)}
    if config.protocol == RECOVERING and not config.rules_off:
        del table["protocol"], table["rules_off"]
    if config.split is None:  # as tables were claimed before splits
        del table["split"]
    for rules in ("perception_rules", "plan_rules"):  # as tables were claimed before rules were set
        if not getattr(config, rules):
            del table[rules]
        else:
            table[rules] = list(getattr(config, rules))
    return table


def check_table(methods: list[Method], config: EvalConfig, out: Path) -> tuple[dict, str]:
    """Every refusal of a table's run folders before anything is written (the table's own,
    then each method's); what the table folder is claimed with and its refusal."""
    table = table_settings(config)
    refusal = f"'{out}' holds a table of another configuration or goal file; use another --out"
    check_claim(out, TABLE_KIND, table, refusal)
    check_runs(config, out, {m.name: (m.agent, m.perception) for m in methods})
    return table, refusal


def run_table(
    methods: list[Method],
    config: EvalConfig,
    out: Path,
    workers: int = 2,
    ray: str | None = None,
    on_episode: Callable[[EpisodeRecord], None] | None = None,
) -> dict:
    """Every method's episodes (`config` with the method's agent) into `out/METHOD/`; the
    summary, also written as `summary.json`, `table1.md` and `table1.png` in `out`."""
    table, refusal = check_table(methods, config, out)
    for m in methods:  # an agent refused a scene is refused before the folder is claimed
        for c in trained(replace(config, agent=m.agent, perception=m.perception)).values():
            check_world(c)
    claim(out, TABLE_KIND, table, refusal)
    runs: dict[str, dict[int | None, list[EpisodeRecord]]] = {}
    for m in methods:
        method = replace(config, agent=m.agent, perception=m.perception)
        runs[m.name] = {
            seed: run_evaluation(c, training_dir(out / m.name, seed), workers, on_episode, ray)
            for seed, c in trained(method).items()
        }
    report = {
        "protocol": config.protocol,
        "rules_off": list(config.rules_off),
        "methods": {
            m.name: {"agent": m.agent, "perception": m.perception}
            | _timing(out / m.name, runs[m.name])
            | summarize_trainings(runs[m.name])
            for m in methods
        },
        # with a goals file, the goals it held of each size asked for, not the `goals` setting
        "goals": None if config.goals_file else config.goals,
        "goals_file": config.goals_file,
        **({"goals_by_size": _goals_by_size(config)} if config.goals_file else {}),
        "repeats": config.repeats,
        "seed": config.seed,
        "split": config.split,
        "tuning_seed": is_tuning(config.seed),
        "run": str(out),
        **({"scenes": [str(p) for p in config.worlds()]} if config.scene else {}),
    }
    write_atomically(out / "summary.json", json.dumps(report, indent=2) + "\n")
    write_atomically(out / "table1.md", markdown(report) + "\n")
    from hsgplan.viz.plots import plot_success_by_size

    plot_success_by_size(
        {
            label(m): {int(n): (v["success_rate"], _spread(v)) for n, v in s["by_size"].items()}
            for m, s in report["methods"].items()
        },
        {
            label(m): {n: sr for n, (sr, _) in PAPER_TABLE1[m].items()}
            for m in report["methods"]
            if m in PAPER_TABLE1
        },
        out / "table1.png",
    )
    return report


def _timing(run_dir: Path, runs: dict) -> dict:
    """A method's wall clock: its folder's, or the sum of its trainings' folders'."""
    timings = [read_timing(training_dir(run_dir, seed)) for seed in runs]
    return {
        "wall_seconds": sum(t["wall_seconds"] for t in timings),
        "sittings": [s for t in timings for s in t["sittings"]],
    }


def total_episodes(methods: list[Method], config: EvalConfig) -> int:
    return sum(
        len(trained(replace(config, agent=m.agent))) * len(episode_specs(config)) for m in methods
    )


def cell(v: dict) -> str:
    """Success rate (its 95% interval, or ± its spread over repeats in summaries from before
    intervals) / subgoal completion."""
    sr, sc = f"{v['success_rate']:.2f}", f"{v['subgoal_completion']:.2f}"
    if v.get("success_ci") is not None:
        lo, hi = v["success_ci"]
        sr += f" ({lo:.2f}–{hi:.2f})"
    elif v.get("success_std") is not None:
        sr += f" ± {v['success_std']:.2f}"
    return f"{sr} / {sc}"


def _kinds(counts: dict[str, int]) -> str:
    total = sum(counts.values())
    if not total:
        return "0"
    inner = ", ".join(f"{k} {c}" for k, c in sorted(counts.items(), key=lambda x: (-x[1], x[0])))
    return f"{total} ({inner})"


@dataclass(frozen=True)
class TextTable:
    title: str
    header: tuple[str, ...]
    rows: tuple[tuple[str, ...], ...]

    def markdown(self) -> str:
        return "\n".join(
            [
                self.title,
                "",
                "| " + " | ".join(self.header) + " |",
                "|" + "---:|" * len(self.header),
                *("| " + " | ".join(r) + " |" for r in self.rows),
            ]
        )


def tables(report: dict, which: tuple[str, ...] = TABLES) -> list[TextTable]:
    """Results beside the paper's, the failure taxonomy, the time per level (those `which`
    names)."""
    made = {"success": _results, "failures": _failures, "time": _times}
    return [made[name](report) for name in TABLES if name in which]


def markdown(report: dict) -> str:
    return "\n\n".join(t.markdown() for t in tables(report))


def _sizes(methods: dict) -> list[int]:
    return sorted({int(n) for s in methods.values() for n in s["by_size"]})


def protocol_name(report: dict) -> str:
    """The protocol's name as the tables say it, with any recovery rule switched off."""
    protocol = report.get("protocol", RECOVERING)
    off = report.get("rules_off") or []
    return f"{protocol} protocol" + (f", without {', '.join(off)}" if off else "")


def _results(report: dict) -> TextTable:
    methods = report["methods"]
    header = ["objects"]
    for m in methods:
        header += [label(m)] + ([f"{label(m)} (paper)"] if m in PAPER_TABLE1 else [])
    rows = []
    for n in _sizes(methods):
        row = [str(n)]
        for m, s in methods.items():
            v = s["by_size"].get(str(n))
            row.append(cell(v) if v else "—")
            if m in PAPER_TABLE1:
                paper = PAPER_TABLE1[m].get(n)
                row.append(f"{paper[0]:.2f} / {paper[1]:.2f}" if paper else "—")
        rows.append(tuple(row))
    source = goals_words(report)
    repeats = runs_words(report)
    title = (
        f"Success rate / subgoal completion ({protocol_name(report)}): {source}{repeats}, "
        f"{seed_words(report['seed'], report.get('split'))}{where(report)}"
    )
    if unsampled := _unsampled(report):
        title += (
            f"; {unsampled} episode(s) whose start scene could not be sampled are left out "
            "(the failure table)"
        )
    title = marked(title, report["seed"], split=report.get("split"))
    return TextTable(title, tuple(header), tuple(rows))


def _spread(v: dict) -> tuple[float, float] | None:
    """What a size's error bar spans: its interval, else the rate ± its standard deviation
    over repeats, else nothing."""
    if v.get("success_ci"):
        return (v["success_ci"][0], v["success_ci"][1])
    if v.get("success_std") is not None:
        return (v["success_rate"] - v["success_std"], v["success_rate"] + v["success_std"])
    return None


def _goals_by_size(config: EvalConfig) -> dict[str, int]:
    """How many goals of each size a goals file gave the run (in its first scene)."""
    from hsgplan.evaluation.protocol import episode_specs

    specs = [s for s in episode_specs(config) if s.repeat == 0 and s.scene == _first(config)]
    return {str(n): sum(1 for s in specs if s.size == n) for n in sorted({s.size for s in specs})}


def _first(config: EvalConfig) -> str | None:
    return next(iter(config.worlds()))


def goals_words(report: dict) -> str:
    """Where a run's goals came from: the goals file and how many of each size it gave, or
    the random goals per size."""
    if not report.get("goals_file"):
        return f"{report['goals']} random goals per size"
    counts = report.get("goals_by_size")
    if not counts:  # a summary from before the counts were kept
        return str(report["goals_file"])
    held = ", ".join(f"{c} of {n} objects" for n, c in counts.items())
    return f"the goals of {report['goals_file']} ({held})"


def runs_words(report: dict) -> str:
    """How often each goal ran, and what the spread beside a rate is."""
    methods = report["methods"].values()
    trained = max((len(s.get("trainings") or []) for s in methods), default=0)
    with_ci = any(v.get("success_ci") for s in methods for v in s["by_size"].values())
    words = f", each run {report['repeats']} times" if report["repeats"] > 1 else ", each run once"
    if trained:
        words += f" under each of {trained} trainings"
    if with_ci and trained > 1:
        return words + (
            " (in brackets the 95% interval of a bootstrap that draws trainings and goals, "
            "each goal's repeats kept together)"
        )
    if with_ci:
        return words + (
            " (in brackets the 95% interval of a bootstrap over goals, each goal's repeats "
            "kept together)"
        )
    if report["repeats"] > 1:
        return words + " (± the standard deviation of the success rate over the repeats)"
    return words


def _unsampled(report: dict) -> int:
    """Episodes of every method whose start scene could not be sampled (summaries from before
    this count existed have none)."""
    return sum(sum(s.get("unsampled_scenes", {}).values()) for s in report["methods"].values())


def _failures(report: dict) -> TextTable:
    # columns for perception where a method sees through f_p, or an observer got something wrong
    seen = any(s.get("perception", "gt") != "gt" for s in report["methods"].values()) or any(
        v["failure_classes"].get(PERCEPTION)
        for s in report["methods"].values()
        for v in s["by_size"].values()
    )
    unsampled = _unsampled(report) > 0
    rows = []
    for m, s in report["methods"].items():
        for n in _sizes(report["methods"]):
            if v := s["by_size"].get(str(n)):
                failed = v["episodes"] - round(v["success_rate"] * v["episodes"])
                skipped = s.get("unsampled_scenes", {}).get(str(n), 0)
                fc = v["failure_classes"]
                rows.append(
                    (label(m), str(n), str(v["episodes"]), str(failed))
                    + (_kinds(fc[EXECUTION]), _kinds(fc[OVERSTEP]))
                    + ((_kinds(fc.get(PERCEPTION, {})),) if seen else ())
                    # a summary from before these counts existed has none
                    + tuple(
                        str(v.get(k, "—"))
                        for k in (
                            "failed_primitives",
                            "overstep_after_failures",
                            "disturbing_steps",
                        )
                    )
                    + ((str(v.get("relooks", "—")),) if seen else ())
                    + ((str(v.get("misbelieved", {}).get("failed", "—")),) if seen else ())
                    + ((_misread(v),) if seen else ())
                    + ((str(skipped),) if unsampled else ())
                )
    # the columns are said once, in docs/failures.md (`evaluation.glossary.COLUMNS`)
    title = (
        f"Failures ({protocol_name(report)}), by what ended the episode; what each column counts: "
        "docs/failures.md"
    )
    header = ("method", "objects", "episodes", "failed", "execution", "overstep")
    header += (PERCEPTION,) if seen else ()
    header += ("failed primitives", "overstep after failures", "disturbing steps")
    header += ("relooks", "belief off", "misread") if seen else ()
    if unsampled:
        header += ("unsampled",)
    return TextTable(title, header, tuple(rows))


def _misread(v: dict) -> str:
    """The misread steps of one size, "seen ok / seen failed" (— in a summary from before the
    one judge)."""
    m = v.get("misread_steps")
    return "—" if m is None else f"{m['seen_ok_truly_failed']} / {m['seen_failed_truly_ok']}"


def _times(report: dict) -> TextTable:
    rows, walls = [], []
    for m, s in report["methods"].items():
        for n in _sizes(report["methods"]):
            if v := s["by_size"].get(str(n)):
                task_ms, motion_s = v["median_task_seconds"] * 1000, v["median_motion_seconds"]
                rows.append(
                    (label(m), str(n), str(v["episodes"]), f"{task_ms:.1f}", f"{motion_s:.2f}")
                )
        workers = "/".join(str(w) for w in sorted({x["workers"] for x in sittings(s)}))
        walls.append(f"{label(m)} {s['wall_seconds'] / 60:.1f} min ({workers or '?'} workers)")
    # the whole run's wall clock is one number per method: in the title, not a column of blanks
    title = (
        f"Time per episode ({protocol_name(report)}, medians): the task level's, and the motion "
        "level's (choosing parameters and executing them); wall clock of each method's whole "
        f"run: {', '.join(walls)}"
    )
    header = ("method", "objects", "episodes", "task ms", "motion s")
    return TextTable(title, header, tuple(rows))
