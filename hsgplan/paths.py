"""Where the shipped checkpoints and datasets are, wherever a command runs.

The shipped files live in the repository beside the package (`checkpoints/`, `data/`). Their
home is, in this order: the folder named by the environment variable `HSGPLAN_HOME`; the
folder above the installed package when it holds `checkpoints/` (a checkout, or an editable
install); the current folder. A relative path a user gives (`--checkpoint`, a training
configuration's `demos`) is read from the current folder when it exists there, and otherwise
from the home, so `checkpoints/task` means the shipped planner from any folder.

Run folders (`runs/...`) are not shipped: they are made where the user runs the command, or
wherever `--out` says.
"""

from __future__ import annotations

import os
from pathlib import Path

HOME_VARIABLE = "HSGPLAN_HOME"
CHECKPOINTS = Path("checkpoints")
DATA = Path("data")
TASK_CHECKPOINT = CHECKPOINTS / "task"
PAPER_TASK_CHECKPOINT = CHECKPOINTS / "task-paper"  # the paper's recipe: 18 demonstrations alone
MOTION_CHECKPOINTS = CHECKPOINTS / "motion"
PERCEPTION_CHECKPOINT = CHECKPOINTS / "perception"  # f_p's keypoint network
# The networks that read kind and size, not names: the default in a scene of other objects
TASK_GEOMETRY_CHECKPOINT = CHECKPOINTS / "task-geometry"
MOTION_GEOMETRY_CHECKPOINTS = CHECKPOINTS / "motion-geometry"
DEMOS = DATA / "demos" / "v1"
MOTION_DATA = DATA / "motion"
REACH_DATA = DATA / "reach" / "v1"  # primitives executed in the simulated world: f_reach's labels
REACH_HELD_OUT = DATA / "reach" / "heldout"  # the same, another seed: f_reach is scored on it
RUNS = Path("runs")
SCENES = Path("scenes")
# The default world. Read beside the package, not from `home()`: the world is the code's, and a
# home that holds another user's checkpoints must not change it.
KITCHEN_SCENE = Path(__file__).resolve().parent.parent / SCENES / "kitchen.toml"


def home() -> Path:
    """The folder that holds `checkpoints/` and `data/`."""
    if value := os.environ.get(HOME_VARIABLE):
        return Path(value).expanduser()
    beside_package = Path(__file__).resolve().parent.parent
    if (beside_package / CHECKPOINTS).is_dir():
        return beside_package
    return Path.cwd()


def shipped(path: Path | str) -> Path:
    """A path as the user meant it: as given when absolute or present here, else in `home()`."""
    path = Path(path).expanduser()
    if path.is_absolute() or os.path.lexists(path):  # a link here, even a broken one, is meant
        return path
    return home() / path


def perception_folder(checkpoint: str | Path | None) -> Path:
    """f_p's checkpoint folder: `checkpoint`, or the shipped one."""
    return Path(checkpoint or PERCEPTION_CHECKPOINT)
