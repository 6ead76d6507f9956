"""The motion data's status codes stay what the shipped data was written with."""

from hsgplan.data.motion_store import STATUSES

# in the order `data/motion/*_trials.npz` index them
WRITTEN_WITH = (
    "success",
    "invalid",
    "no_ik",
    "no_path",
    "dropped",
    "knocked_over",
    "off_table",
    "disturbed",
    "effect_not_reached",
    "blocks_pick",
)


def test_every_status_the_shipped_data_holds_keeps_its_index():
    assert tuple(s.value for s in STATUSES[: len(WRITTEN_WITH)]) == WRITTEN_WITH
