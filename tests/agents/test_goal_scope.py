"""Goals an agent is for: a learned task planner takes positive On and In literals, the rules'
planners any literal; every goal names 2 to 12 objects; a goal outside is refused in one line
with exit code 2 before a run folder is written."""

import pytest
from typer.testing import CliRunner

from hsgplan.agents.goal_scope import LEARNED_GOALS, PLANNED_GOALS, check_goal, scope_of
from hsgplan.cli import app
from hsgplan.domain.errors import InvalidInputError
from hsgplan.domain.goals import parse_goal
from hsgplan.domain.kitchen import KITCHEN

runner = CliRunner()
POSITIVE = "On(butter, shelf_b) & In(cherries, shelf_a)"
HELD = "InGrasp(butter) & On(cherries, shelf_a)"
NEGATED = "On(butter, shelf_b) & !On(cherries, open_space)"


def _goal(text):
    return parse_goal(text, world=KITCHEN)


def test_each_agent_has_its_scope():
    assert scope_of("learned") is LEARNED_GOALS
    assert scope_of("regression-ahead-clearing+gnn-checked") is LEARNED_GOALS
    assert scope_of("forward+sampler") is LEARNED_GOALS
    assert scope_of("oracle") is PLANNED_GOALS
    assert scope_of("fd+gnn") is PLANNED_GOALS
    assert scope_of("stream-goal") is PLANNED_GOALS


@pytest.mark.parametrize(
    ("text", "why"), [(HELD, "InGrasp literals"), (NEGATED, "negated literals")]
)
def test_a_learned_agent_refuses_what_it_never_learned_and_points_at_the_oracle(text, why):
    check_goal("oracle", _goal(text))  # the rules' planner takes it
    with pytest.raises(InvalidInputError, match=why) as refused:
        check_goal("learned", _goal(text))
    assert "'oracle'" in str(refused.value) and "\n" not in str(refused.value)


def test_every_agent_takes_positive_on_and_in_goals_of_2_to_12_objects():
    for agent in ("learned", "oracle", "regression+mlp"):
        check_goal(agent, _goal(POSITIVE))
        with pytest.raises(InvalidInputError, match="between 2 and 12 objects"):
            check_goal(agent, _goal("On(butter, shelf_b)"))


def test_commands_refuse_such_a_goal_before_writing(tmp_path):
    goals = tmp_path / "goals.txt"
    goals.write_text(f"{POSITIVE}\n{NEGATED}\n")
    cases = [
        ("demo", "--goal", HELD, "--out", str(tmp_path / "demo")),
        (
            "demo",
            "--goal",
            "On(butter, shelf_b)",
            "--agent",
            "oracle",
            "--out",
            str(tmp_path / "d"),
        ),
        ("eval", "world", "--goals-file", str(goals), "--sizes", "2", "--out", str(tmp_path / "w")),
        ("eval", "task", "--goals-file", str(goals), "--sizes", "2", "--out", str(tmp_path / "t")),
    ]
    for args in cases:
        r = runner.invoke(app, list(args))
        assert r.exit_code == 2, (args, r.output)
        assert "Traceback" not in r.output
    assert sorted(p.name for p in tmp_path.iterdir()) == ["goals.txt"]
