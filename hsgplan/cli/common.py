"""What every command shares: consoles, the bad-input guard, argument parsing, tables."""

from __future__ import annotations

import dataclasses
import functools
import sys
from enum import StrEnum
from pathlib import Path
from typing import Annotated

import typer
from rich.console import Console
from rich.markup import escape
from rich.table import Table
from rich.text import Text
from typer.core import TyperGroup

from hsgplan.agents.registry import AGENT_NAMES, CHECKED_PLANNERS, MOTION_GENERATORS, TASK_PLANNERS
from hsgplan.domain.checks import BOUNDS, check_output, read_json
from hsgplan.domain.errors import InvalidInputError
from hsgplan.domain.recovery import PROTOCOLS

out = Console()
err = Console(stderr=True)
PIPED_WIDTH = 200


class Summaries(TyperGroup):
    """A group whose command list gives each command's first paragraph as one line: Rich keeps
    the docstring's line breaks there, which broke the list into ragged lines."""

    def get_command(self, ctx, cmd_name):
        command = super().get_command(ctx, cmd_name)
        if command is not None and command.short_help is None and command.help:
            command.short_help = " ".join(command.help.split("\n\n")[0].split())
        if command is not None:
            plain_metavars(command)
        return command


# what `--help` shows for a value of each Python type (Typer's default is `<str>`, `<Path>`)
METAVARS = {str: "TEXT", Path: "PATH", int: "N", float: "X"}


def plain_metavars(command) -> None:
    """Give every option without a metavar of its own a plain one: a flag (and `--help`)
    none, a value its type's word in capitals. Once per command: a group hands the same
    command out on every lookup."""
    if getattr(command, "plain_metavars", False):
        return
    command.plain_metavars = True
    for param in command.params:
        if isinstance(param, typer.core.TyperArgument):  # its name says it (RUN_DIR)
            param.metavar = param.metavar or param.name.upper()
            param.display_type_rich = lambda ctx: None
            continue
        if param.metavar is not None:
            continue
        if getattr(param, "is_flag", False):
            param.metavar = ""
            continue
        annotation = getattr(getattr(param, "type_descriptor", None), "annotation", None)
        word = METAVARS.get(annotation)
        if word is not None:
            param.metavar = word
    help_option = command.get_help_option

    def quiet_help(ctx):
        option = help_option(ctx)
        if option is not None:
            option.metavar = ""
        return option

    command.get_help_option = quiet_help


class OneLineErrors(Summaries):
    """The top-level group: a usage error (an unknown choice, a malformed number) is one line on
    stderr and exit code 2, like every other refusal, instead of click's framed box; so is an
    older spelling of a command or option (`cli/renamed.py`), with the new one."""

    def main(self, args=None, *rest, standalone_mode: bool = True, **kwargs):
        from hsgplan.cli.renamed import hint

        older = hint(sys.argv[1:] if args is None else list(args))
        if older is not None:
            print_error(older)
            if standalone_mode:
                sys.exit(2)
            return 2
        plain_metavars(self)
        try:
            code = super().main(args, *rest, standalone_mode=False, **kwargs)
        except typer.TyperException as e:  # click's exceptions, as typer ships them
            if type(e).__name__ == "NoArgsIsHelpError":
                e.show()
            else:
                print_error(" ".join(e.format_message().split()))
            code = e.exit_code
        except typer.Abort:
            err.print("aborted")
            code = 1
        code = code if isinstance(code, int) else 0
        if standalone_mode:
            sys.exit(code)
        return code


def bounded_option(concept: str, help: str, **more) -> typer.models.OptionInfo:
    """An option for a count or a seed, its bounds those the configurations hold it to
    (`domain.checks.BOUNDS[concept]`)."""
    bounds = BOUNDS[concept]
    return _bounded(help, bounds["lo"], bounds["hi"], "SEED" if concept == "seed" else "N", more)


def _bounded(help: str, lo, hi, metavar: str, more: dict) -> typer.models.OptionInfo:
    """An option held to [lo, hi]. `--help` shows the lower bound only: the upper ones (up to
    2**32 - 1 for a seed) would take the width of the descriptions at 80 columns; a value
    above is refused in the parser's own words."""
    return typer.Option(help=help, min=lo, metavar=metavar, callback=at_most(hi), **more)


def at_most(hi):
    """A parser callback refusing a value above `hi` (None: no bound); `.hi` tells the bound."""

    def check(value):
        if hi is not None and value is not None and value > hi:
            raise typer.BadParameter(f"Input should be less than or equal to {hi}")
        return value

    check.hi = hi
    return check


def config_default(config: type, name: str):
    """The default of a configuration's field: what an option that sets the field defaults to,
    so that the value is written once, in the configuration."""
    return _field(config, name).default


def config_option(config: type, name: str, help: str, **more) -> typer.models.OptionInfo:
    """An option that sets a configuration's field, held to the field's bounds
    (`domain.checks.setting`)."""
    bounds = _field(config, name).metadata
    return _bounded(help, bounds.get("lo"), bounds.get("hi"), "N", more)


def _field(config: type, name: str) -> dataclasses.Field:
    (found,) = [f for f in dataclasses.fields(config) if f.name == name]
    return found


def shown(value) -> str:
    """User text (a path, a name) inside a Rich-markup message, shown as typed."""
    return escape(str(value))


def print_error(message: str) -> None:
    """The one error line. The message often echoes what the user typed: it is printed as
    text, never read as Rich markup (`--goal '[/]'` once crashed this printer)."""
    err.print(Text.assemble(("error:", "bold red"), " ", message), highlight=False, soft_wrap=True)


def refuses_bad_input(fn):
    """Bad input becomes one line on stderr and exit code 2, never a traceback. A place the
    system will not let us write (a full disk, a read-only folder) is told the same way: the
    checks at the door catch what they can foresee, this catches the rest."""

    @functools.wraps(fn)
    def wrapper(*args, **kwargs):
        try:
            return fn(*args, **kwargs)
        except InvalidInputError as e:
            print_error(str(e))
            raise typer.Exit(2) from None
        except OSError as e:
            where = f"'{e.filename}': " if e.filename else ""
            print_error(f"{where}{e.strerror or e}")
            raise typer.Exit(2) from None
        except KeyboardInterrupt:
            err.print("interrupted")
            raise typer.Exit(130) from None

    return wrapper


def _output(kind: str):
    def parse(text) -> Path:
        try:
            check_output(text, kind)
        except InvalidInputError as e:
            raise typer.BadParameter(str(e)) from None
        return Path(str(text)).expanduser()

    parse.__name__ = f"out_{kind}"
    return parse


# `parser=` of every --out option: refused at the door, before the command makes anything
out_folder = _output("folder")
out_file = _output("file")


# the --out of every resumable job (eval, eval task, bench timing)
RunFolder = Annotated[
    Path | None,
    typer.Option(
        "--out",
        help="Run folder (resumed if it exists; default: a folder under runs/ named after "
        "the run's settings).",
        parser=out_folder,
    ),
]


# --markdown of every command that prints a table
MarkdownFlag = Annotated[
    bool,
    typer.Option("--markdown", help="Print a Markdown table (for the README).", metavar=""),
]


# --workers and --ray of the jobs that can run on Ray (collections, eval)
CollectWorkers = Annotated[
    int,
    bounded_option("workers", "Processes (or Ray tasks in flight / 2)."),
]
RayAddress = Annotated[
    str | None, typer.Option(help="Run on Ray at this address ('local' starts one).")
]


def dash(value, spec: str) -> str:
    """A number formatted for a table, or a dash where there is none."""
    return "—" if value is None else format(value, spec)


def input_path(text) -> Path:
    """`parser=` of options naming something to read: an empty name is refused (a Path of ''
    would silently be the current folder)."""
    if not str(text).strip():
        raise typer.BadParameter("an empty path")
    return Path(str(text)).expanduser()


TaskCheckpoint = Annotated[
    Path | None,
    typer.Option(help="Task planner checkpoint (default: the shipped one).", parser=input_path),
]


MotionCheckpoints = Annotated[
    Path | None,
    typer.Option(
        help="Folder of motion networks, one folder each named PRIMITIVE-MODEL "
        "(place-gnn, push-gnn, place-mlp, ...), or a trainings folder of seed-S folders "
        "(default: the shipped checkpoints/motion).",
        parser=input_path,
    ),
]


SceneFiles = Annotated[
    Path | None,
    typer.Option(
        "--scene",
        help="The world: a scene file, or a folder of them, each run with the same goal seeds "
        "(default: scenes/kitchen.toml; docs/scenes.md).",
        parser=input_path,
    ),
]


def in_scene(scene: Path | None) -> str:
    """ ", in SCENE" for a table's title, where a scene was given."""
    return "" if scene is None else f", in {scene}"


def scene_worlds(scene: Path | None) -> list:
    """The worlds of a `--scene` file or folder (the kitchen without one), in file order, each
    read (and a bad one refused in one line) before anything runs."""
    from hsgplan.domain.scene_file import default_world, read_worlds

    return list(read_worlds(scene).values()) if scene else [default_world()]


def default_networks(
    agent: str, worlds: list, checkpoint: Path | None, motion: Path | None
) -> tuple[Path | None, Path | None]:
    """The task and motion folders a command runs `agent` (or `PLANNER+MOTION`) with: those
    given, or, where none is given and a world names what the shipped networks do not know,
    the shipped networks that read kind and size (`registry.default_checkpoints`), said in
    one line on stderr. A folder not swapped comes back as given (None: the shipped one)."""
    from hsgplan.agents.registry import default_checkpoints
    from hsgplan.paths import shipped

    given = checkpoint and shipped(checkpoint), motion and shipped(motion)
    task, motion_folder, said = default_checkpoints(agent, worlds, *given)
    if not said:
        return checkpoint, motion
    err.print(said, highlight=False)
    return task, motion_folder


def scene_world(scene: Path | None):
    """The world of a `--scene` file (the kitchen without one), refused in one line if bad."""
    from hsgplan.domain.scene_file import scene_world as world_of_scene

    return world_of_scene(scene)


# a collection takes turns round a folder's scenes, so that a network learns round many
SceneRound = Annotated[
    Path | None,
    typer.Option(
        "--scene",
        help="The world: a scene file, or a folder of them taken in turn "
        "(default: scenes/kitchen.toml; docs/scenes.md).",
        parser=input_path,
    ),
]


SceneOption = Annotated[
    Path | None,
    typer.Option(
        "--scene",
        help="The world, as a scene file (default: scenes/kitchen.toml; docs/scenes.md).",
        parser=input_path,
        metavar="FILE",
    ),
]


def check_ray(address: str | None) -> None:
    """`--ray` checked at the door (see `hsgplan.runner.engines.check_ray_address`)."""
    from hsgplan.runner.engines import check_ray_address

    check_ray_address(address)


def choice(what: str, names) -> type[StrEnum]:
    """Names offered as choices, listed by `--help` and checked by the parser (its `.value` is
    the name)."""
    return StrEnum(what, {name: name for name in names})


AgentName = choice("AgentName", AGENT_NAMES)
PlannerName = choice("PlannerName", TASK_PLANNERS)
# the symbolic loop has no model of the scene for an agent to check actions in
SymbolicPlannerName = choice(
    "SymbolicPlannerName", [p for p in TASK_PLANNERS if p not in CHECKED_PLANNERS]
)
MotionName = choice("MotionName", MOTION_GENERATORS)
ProtocolName = choice("ProtocolName", PROTOCOLS)


def read_config(path: Path | None) -> dict:
    """The settings in a `--config` JSON file (none without a file), refused in one line."""
    return {} if path is None else read_json(path, "--config")


def parse_sizes(text: str) -> list[int]:
    """`2-6`, `2,4,6` or `3` as a list of sizes."""
    from hsgplan.symbolic.generator import check_size

    sizes: list[int] = []
    for part in text.split(","):
        lo, dash, hi = part.strip().partition("-")
        try:
            ends = (int(lo), int(hi if dash else lo))
        except ValueError:
            raise InvalidInputError(
                f"--sizes '{text}': expected a range like 2-6 or a list like 2,4,6"
            ) from None
        for n in ends:  # the ends first: a range to a billion is refused, not built
            check_size(n)
        sizes += [n for n in range(ends[0], ends[1] + 1) if n not in sizes]
    if not sizes:
        raise InvalidInputError(f"--sizes '{text}' names no size")
    return sizes


def print_table(title: str, header: tuple[str, ...], rows: list[tuple[str, ...]], markdown: bool):
    """A Rich table on the terminal, or a Markdown table that the README takes verbatim."""
    if markdown:
        print(f"{title}\n")
        print("| " + " | ".join(header) + " |")
        print("|" + "---:|" * len(header))
        for row in rows:
            print("| " + " | ".join(row) + " |")
        print()  # a table ends at a blank line: the next title is not one of its rows
        return
    table = Table()
    for col in header:
        table.add_column(col, justify="right")
    for row in rows:
        table.add_row(*row)
    # piped into a file or a pager, a table keeps its headers whole rather than fit 80 columns
    console = out if out.is_terminal else Console(width=PIPED_WIDTH)
    # the title above the table, as wide as the console: a narrow table would squeeze it
    console.print(title, style="italic", highlight=False, markup=False)
    console.print(table)


# f_p's checkpoint, where a command can see with it (--perception rgb)
PerceptionCheckpoint = Annotated[
    Path | None,
    typer.Option(help="f_p's checkpoint (default: the shipped one).", parser=input_path),
]
