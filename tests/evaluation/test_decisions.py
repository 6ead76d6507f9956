"""The record of choices cites no test seed, and says where a choice made on a reporting seed
stands."""

from pathlib import Path

import pytest
from typer.testing import CliRunner

from hsgplan.cli import app
from hsgplan.domain.errors import InvalidInputError
from hsgplan.evaluation.decisions import cited_test_seeds, misfiled, read_decisions
from hsgplan.evaluation.split_check import drawn_by_test
from hsgplan.evaluation.splits import TEST

ROOT = Path(__file__).resolve().parents[2]
RECORD = ROOT / "configs" / "decisions.toml"


def _row(name="R", chosen_on="tune", seeds="[900]", status="chosen on tune") -> str:
    return (
        f'[[decision]]\nname = "{name}"\nwhat = "w"\nwhere = "hsgplan"\n'
        f'chosen_on = "{chosen_on}"\nseeds = {seeds}\nmeasurement = "m"\nstatus = "{status}"\n'
    )


def test_the_shipped_record_cites_no_test_seed_and_files_each_tuning_seed_as_one():
    decisions = read_decisions(RECORD)
    assert len(decisions) >= 20
    episodes = frozenset(d.seed for d in drawn_by_test())
    assert [d.name for d in decisions if cited_test_seeds(d, episodes)] == []
    assert [d.name for d in decisions if misfiled(d)] == []
    for d in decisions:
        assert (ROOT / d.where.split(":")[0].split(" ")[0]).exists(), d.where


def test_a_row_that_cites_a_test_seed_fails_the_check(tmp_path):
    episode = drawn_by_test([3])[0].seed
    record = tmp_path / "d.toml"
    record.write_text(
        _row("run", "reporting", f"[{TEST.seeds.start}]", "to choose again on tune")
        + _row("episode", "reporting", f"[{episode}]", "kept on tune (seed 900)")
        + _row("fine")
    )
    decisions = {d.name: d for d in read_decisions(record)}
    episodes = frozenset(d.seed for d in drawn_by_test())
    assert cited_test_seeds(decisions["run"]) == [TEST.seeds.start]
    assert cited_test_seeds(decisions["episode"], episodes) == [episode]
    assert cited_test_seeds(decisions["fine"], episodes) == []
    r = CliRunner().invoke(app, ["splits", "decisions", "--record", str(record)])
    assert r.exit_code == 1 and "cites test seed" in r.stdout
    record.write_text(_row("fine"))
    assert CliRunner().invoke(app, ["splits", "decisions", "--record", str(record)]).exit_code == 0


def test_a_tuning_row_on_a_seed_that_reports_is_misfiled(tmp_path):
    record = tmp_path / "d.toml"
    record.write_text(_row("r", "tune", "[0, 900]"))
    assert misfiled(read_decisions(record)[0]) == [0]


@pytest.mark.parametrize(
    ("text", "why"),
    [
        (_row(chosen_on="somewhere"), "chosen_on 'somewhere'"),
        (_row(chosen_on="reporting", status="fine"), "its status must begin"),
        (_row() + _row(), "recorded twice"),
        ('[[decision]]\nname = "x"\n', "has no what"),
    ],
)
def test_a_malformed_record_is_refused_in_one_line(tmp_path, text, why):
    record = tmp_path / "d.toml"
    record.write_text(text)
    with pytest.raises(InvalidInputError, match=why):
        read_decisions(record)


def test_a_rows_standing_is_printed_where_its_split_does_not_say_it(tmp_path):
    from hsgplan.evaluation.decisions import rows

    record = tmp_path / "d.toml"
    record.write_text(
        _row("plain") + _row("old", "reporting", "[0, 900]", "kept on tune (seed 900)")
    )
    plain, old = rows(read_decisions(record))
    assert plain[2] == "tune (900)"
    assert old[2] == "reporting (0, 900); kept on tune (seed 900)"


def test_the_record_renders_as_a_list_an_item_a_choice(tmp_path):
    from hsgplan.evaluation.decisions import markdown

    record = tmp_path / "d.toml"
    record.write_text(
        _row("plain") + _row("old", "reporting", "[0, 900]", "kept on tune (seed 900)")
    )
    lines = markdown(read_decisions(record)).splitlines()
    assert [line.split(":")[0] for line in lines] == ["- `plain`", "- `old`"]
    assert "reporting (0, 900); kept on tune (seed 900). By " in lines[1]
