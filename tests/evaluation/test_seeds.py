"""Seeds that choose rules are told apart from seeds that report numbers."""

from hsgplan.evaluation.seeds import TUNING, is_tuning, marked


def test_tuning_seeds_are_one_declared_range_apart_from_the_reporting_defaults():
    assert is_tuning(900) and is_tuning(999) and not is_tuning(1000)
    assert not is_tuning(0)  # Table 1's seed
    assert min(TUNING) > 100  # the evaluations' reporting seeds are small


def test_perception_keeps_the_seeds_its_rules_were_chosen_on():
    assert is_tuning(3, perception=True) and not is_tuning(3)
    assert not is_tuning(6, perception=True)  # a check seed, never tuned on


def test_a_tuning_run_says_so_in_its_title():
    assert marked("Table", 0).startswith("Table (exploration")
    assert "a tuning seed" in marked("Table", 950)
    assert "a tuning seed" in marked("f_p", 43, perception=True)
