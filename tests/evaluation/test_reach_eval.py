"""Sorting f_reach's held-out questions into the situations that decide them, and scoring."""

from hsgplan.domain.actions import Pick, Place, Push
from hsgplan.domain.kitchen import KITCHEN
from hsgplan.domain.predicates import in_grasp, inside, on
from hsgplan.evaluation.reach_eval import QuestionKind, Scores, _add, kind_of_question
from hsgplan.scene_graph.symbolic import SymbolicSceneGraph

OBJECTS = ["cherries", "butter", "tomato_soup", "alphabet_soup", "popcorn", "cream_cheese"]


def state(*literals):
    return SymbolicSceneGraph.from_literals(OBJECTS, literals, world=KITCHEN)


def test_each_situation_is_named():
    full_top = state(
        on("cherries", "shelf_a"),
        on("tomato_soup", "shelf_a"),
        on("popcorn", "shelf_a"),
        on("cream_cheese", "shelf_a"),  # four: shelf A's top is full
        in_grasp("butter"),
        on("alphabet_soup", "open_space"),
    )
    assert kind_of_question(full_top, Place("butter", "shelf_a")) is QuestionKind.SURFACE_FULL
    assert kind_of_question(full_top, Place("butter", "shelf_b")) is QuestionKind.ORDINARY
    assert kind_of_question(full_top, Pick("alphabet_soup")) is QuestionKind.HAND_FULL
    assert kind_of_question(full_top, Place("cherries", "shelf_b")) is QuestionKind.NOT_HELD
    stacked = state(
        on("cherries", "prepush_a"),
        on("butter", "cherries"),
        inside("tomato_soup", "shelf_a"),
        inside("alphabet_soup", "shelf_a"),
        on("popcorn", "prepush_a"),
        on("cream_cheese", "open_space"),
    )
    assert kind_of_question(stacked, Pick("cherries")) is QuestionKind.COVERED
    assert kind_of_question(stacked, Push("cherries", "shelf_a")) is QuestionKind.COVERED
    assert kind_of_question(stacked, Pick("butter")) is QuestionKind.ORDINARY


def test_scores_count_each_answer_once():
    s = Scores()
    for truth, said in [(True, True), (True, False), (False, True), (False, False), (False, False)]:
        s = _add(s, truth, said)
    j = s.as_json()
    assert j["questions"] == 5 and j["reachable"] == 2
    assert j["precision"] == 0.5 and j["recall"] == 0.5
    assert j["false_yes_rate"] == 1 / 3 and j["accuracy"] == 3 / 5
    assert Scores().as_json()["precision"] is None


def test_eval_reach_scores_the_shipped_planner_on_a_few_held_out_states(tmp_path):
    import json
    from pathlib import Path

    from typer.testing import CliRunner

    from hsgplan.cli import app

    held_out = Path(__file__).resolve().parents[2] / "data" / "reach" / "heldout"
    lines = (held_out / "episodes.jsonl").read_text().splitlines()[:5]
    (tmp_path / "episodes.jsonl").write_text("\n".join(lines) + "\n")
    (tmp_path / "config.json").write_bytes((held_out / "config.json").read_bytes())
    r = CliRunner().invoke(app, ["eval", "reach", "--data", str(tmp_path), "--json"])
    assert r.exit_code == 0, r.output
    report = json.loads(r.stdout)
    assert report["overall"]["questions"] == sum(v["questions"] for v in report["by_kind"].values())
    assert report["overall"]["questions"] > 0
    r = CliRunner().invoke(app, ["eval", "reach", "--data", str(tmp_path / "none")])
    assert r.exit_code == 2 and "no collection" in r.stderr
