"""`hsgplan report RUN_DIR`: an `eval` run folder as one self-contained HTML page.

The page holds the run's tables (results beside the paper's, the failure taxonomy, the time
per level), its plot, and for a sample of failed episodes a GIF of the rollout, re-simulated
from the episode's seed with each decision written on the frame, with the symbolic scene
graphs before and after the failing step; asked for, a rerun recording of each rollout
(`episode.rrd`: the true scene and the belief, the cameras, every decision). Rollouts are kept
in `RUN_DIR/report/` as they are made: a report interrupted and started again makes only those
still missing.
"""

from __future__ import annotations

import json
import shutil
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path

from hsgplan.domain.checks import read_json
from hsgplan.domain.errors import InvalidInputError, a
from hsgplan.domain.goals import parse_goal
from hsgplan.domain.scene_file import default_world
from hsgplan.evaluation.ablation import ABLATION_KIND
from hsgplan.evaluation.config import world_of_file
from hsgplan.evaluation.episode import EpisodeRecord
from hsgplan.evaluation.observers import make_observer
from hsgplan.evaluation.protocol import EVAL_KIND, PAPER, checkpoints, read_eval_config
from hsgplan.evaluation.summary import FAILED_EXECUTION, failure_class
from hsgplan.evaluation.table1 import TABLE_KIND, goals_words, label, tables
from hsgplan.files import write_atomically
from hsgplan.runner.run_folder import CONFIG, logged_rows
from hsgplan.viz.html_page import heading, image, page, paragraph, table

REPORT = "report.html"
ROLLOUTS = "report"
GIF_SCALE = 0.5  # the rollouts' frames at half the demo's size: the page stays small
FRAME_EVERY = 24
RECORDING = "episode.rrd"


@dataclass(frozen=True)
class Rollout:
    """A failed episode re-simulated: as logged, as re-run, and where its pictures are."""

    method: str
    logged: EpisodeRecord
    rerun: EpisodeRecord
    folder: Path

    @property
    def failing_step(self) -> int:
        """The first step whose primitive failed in execution (where the episode went wrong),
        else the last step (0: none was taken)."""
        failed = [s.step for s in self.rerun.steps if s.status in FAILED_EXECUTION]
        return failed[0] if failed else len(self.rerun.steps)

    @property
    def reproduced(self) -> bool:
        a, b = self.logged, self.rerun
        statuses = [(s.action, s.status) for s in a.steps] == [
            (s.action, s.status) for s in b.steps
        ]
        return a.success == b.success and a.failure == b.failure and statuses


def _not_a_world_run(run_dir: Path) -> str:
    """Why a folder without summary.json has no page: another command's run, or an eval world
    run not finished yet."""
    page = "report makes a page of an 'eval world' run folder"
    for marker, what in _OTHER_FOLDERS:
        if (run_dir / marker).is_file():
            return f"holds {what}; {page}"
    saved = run_dir / CONFIG
    kind = read_json(saved, "run configuration").get("kind") if saved.is_file() else None
    if isinstance(kind, str) and kind not in (EVAL_KIND, TABLE_KIND, ABLATION_KIND):
        return f"holds {a(kind)} run; {page}"
    if kind is None:
        return f"holds no run of 'eval world'; {page}"
    return "holds no summary.json: an 'eval world' run not finished (run it again to finish it)"


# what other commands leave in a folder, by the file each always writes
_OTHER_FOLDERS = (
    ("episode.json", "one episode of 'hsgplan demo' (episode.json, episode.gif, graphs/)"),
    ("trainings.json", "the trainings of 'hsgplan train … --seeds' (a folder per seed)"),
    ("train_config.json", "a network of 'hsgplan train'"),
)


def read_summary(run_dir: Path) -> dict:
    path = run_dir / "summary.json"
    if not run_dir.is_dir():
        raise InvalidInputError(f"'{run_dir}' is not a folder")
    if not path.exists():
        raise InvalidInputError(f"'{run_dir}' {_not_a_world_run(run_dir)}")
    summary = read_json(path, "eval summary")
    if not isinstance(summary.get("methods"), dict):
        raise InvalidInputError(f"'{path}' is not an eval summary (no methods)")
    try:  # the tables read every field the page shows: a summary they cannot read is refused
        tables(summary)
        for m, s in summary["methods"].items():
            if not isinstance(s["agent"], str):
                raise TypeError(f"method {m}'s agent")
    except (KeyError, TypeError, ValueError, AttributeError, IndexError) as e:
        what = f"missing {e}" if isinstance(e, KeyError) else " ".join(str(e).split())
        raise InvalidInputError(f"'{path}' is not an eval summary ({what})") from None
    return summary


def sample_failures(
    run_dir: Path, methods: list[str], count: int
) -> list[tuple[str, EpisodeRecord]]:
    """Up to `count` failed episodes, taken in turn from each method and, within one, from each
    kind of failure in turn (the commonest first), so that the sample shows as many kinds as
    it can."""
    queues: list[list[tuple[str, EpisodeRecord]]] = []
    for m in methods:
        by_kind: dict[tuple[str, str], list[tuple[str, EpisodeRecord]]] = {}
        # a method run under several trainings logs each in `METHOD/seed-S`
        folders = [m] + [f"{m}/{p.name}" for p in sorted((run_dir / m).glob("seed-*"))]
        records = []
        for folder in folders:
            for r in logged_rows(run_dir / folder):
                try:
                    records.append((folder, EpisodeRecord.from_json(r["result"])))
                except (KeyError, TypeError, ValueError):
                    continue  # a damaged row is not shown (the eval would run it again)
        for folder, r in sorted(records, key=lambda fr: (fr[1].size, fr[1].seed, fr[0])):
            if c := failure_class(r):
                by_kind.setdefault(c, []).append((folder, r))
        queues.append(_round_robin(sorted(by_kind.values(), key=lambda v: -len(v))))
    return _round_robin(queues)[:count]


def _round_robin(lists: list[list]) -> list:
    """The first item of every list, then the second of every list that has one, and so on."""
    return [x[i] for i in range(max(map(len, lists), default=0)) for x in lists if i < len(x)]


def rollout(
    run_dir: Path, method: str, agent: str, record: EpisodeRecord, recording: bool = False
) -> Rollout:
    """The episode re-simulated with the method's agent and checkpoints (made once, kept;
    made again where a `recording` is asked for and the kept one has none)."""
    from hsgplan.agents.registry import make_agent
    from hsgplan.evaluation.demo import run_demo

    folder = run_dir / ROLLOUTS / f"{method}-{record.size}-{record.seed}"
    done = folder / "episode.json"
    if not done.exists() or (recording and not (folder / RECORDING).exists()):
        config = read_eval_config(run_dir / method)
        partial = folder.with_name(folder.name + ".partial")
        shutil.rmtree(partial, ignore_errors=True)
        run_demo(
            make_agent(agent, *checkpoints(config), config.rules()),
            parse_goal(
                record.goal,
                world=world_of_file(record.scene) if record.scene else default_world(),
            ),
            record.seed,
            partial,
            scale=GIF_SCALE,
            frame_every=FRAME_EVERY,
            observer=make_observer(
                config.perception, config.perception_checkpoint, config.perception_rules
            ),
            end_at_failure=config.protocol == PAPER,
            recording=partial / RECORDING if recording else None,
        )
        shutil.rmtree(folder, ignore_errors=True)
        partial.rename(folder)
    rerun = EpisodeRecord.from_json(json.loads(done.read_text()))
    return Rollout(method, record, rerun, folder)


def build_report(
    run_dir: Path,
    failures: int = 6,
    on_rollout: Callable[[Rollout], None] | None = None,
    on_sample: Callable[[int], None] | None = None,
    recordings: bool = False,
) -> Path:
    """Write `RUN_DIR/report.html` (written whole or not at all) and return its path;
    `on_sample` hears how many failed episodes will be re-simulated, `on_rollout` each one;
    with `recordings`, each rollout is also a rerun recording, linked from the page."""
    summary = read_summary(run_dir)
    methods = list(summary["methods"])
    parts = [
        paragraph(
            f"Run folder {run_dir}: {goals_words(summary)}, "
            f"{summary.get('repeats')} repeat(s), seed {summary.get('seed')}; methods: "
            + ", ".join(f"{label(m)} ({summary['methods'][m]['agent']})" for m in methods),
            "caption",
        )
    ]
    for t in tables(summary):
        parts += [heading(2, t.title.split(":")[0]), paragraph(t.title, "caption")]
        parts.append(table(t.header, t.rows, text_columns=("method", "execution", "overstep")))
    if (run_dir / "table1.png").exists():
        parts.append(image(run_dir / "table1.png", "success rate by problem size"))
    sample = sample_failures(run_dir, methods, failures)
    if on_sample:
        on_sample(len(sample))
    parts.append(heading(2, f"Failed episodes ({len(sample)} shown)"))
    if not sample:
        parts.append(paragraph("No episode of this run failed."))
    for method, record in sample:
        agent = summary["methods"][method.split("/")[0]]["agent"]
        r = rollout(run_dir, method, agent, record, recordings)
        parts.append(_episode(r, run_dir))
        if on_rollout:
            on_rollout(r)
    path = run_dir / REPORT
    write_atomically(path, page(f"Evaluation report: {run_dir.name}", parts))
    return path


def _episode(r: Rollout, run_dir: Path) -> str:
    rec = r.logged
    cls, kind = failure_class(rec) or ("", "")
    k = r.failing_step
    parts = [
        '<div class="episode">',
        heading(3, f"{label(r.method)}, {rec.size} objects, seed {rec.seed}: {cls} ({kind})"),
        paragraph(f"goal: {rec.goal}"),
    ]
    if not r.reproduced:
        parts.append(
            paragraph(
                "The re-simulation ended otherwise than the logged episode "
                f"({r.rerun.failure or 'success'} after {len(r.rerun.steps)} steps; logged: "
                f"{rec.failure} after {len(rec.steps)}); "
                "the pictures show the re-simulation.",
                "warn",
            )
        )
    parts.append(image(r.folder / "episode.gif", f"rollout of seed {rec.seed}"))
    if (r.folder / RECORDING).exists():
        where = (r.folder / RECORDING).relative_to(run_dir)
        parts.append(
            paragraph(f"3D recording: {where} in the run folder (open it with `rerun FILE`)")
        )
    parts.append(
        table(
            ("step", "subgoal", "primitive", "outcome", "why", "task ms"),
            _collapsed(r.rerun.steps),
            text_columns=("subgoal", "primitive", "outcome", "why"),
        )
    )
    graphs = r.folder / "graphs"
    before, after = graphs / f"step_{max(k - 1, 0):02d}.png", graphs / f"step_{k:02d}.png"
    parts.append(paragraph(f"The symbolic scene graph before and after step {k}:", "caption"))
    parts.append(
        '<div class="graphs">'
        + "".join(image(p, p.stem) for p in (before, after) if p.exists())
        + "</div></div>"
    )
    return "".join(parts)


def _collapsed(steps) -> list[tuple[str, ...]]:
    """One row per step, a run of identical steps (the same primitive failing the same way)
    as one row naming its first and last step."""
    rows: list[tuple[str, ...]] = []
    run: list = []
    for s in [*steps, None]:
        if run and (s is None or not _same(run[0], s)):
            first, last = run[0], run[-1]
            label = str(first.step) if len(run) == 1 else f"{first.step}–{last.step} (×{len(run)})"
            ms = f"{first.task_seconds * 1000:.1f}"
            rows.append((label, first.subgoal, first.params, first.status, first.detail, ms))
            run = []
        if s is not None:
            run.append(s)
    return rows


def _same(a, b) -> bool:
    return (a.subgoal, a.params, a.status, a.detail) == (b.subgoal, b.params, b.status, b.detail)
