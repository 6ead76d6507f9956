"""Checkpoint folders shared by the trainers."""

import pytest
import torch

from hsgplan import training
from hsgplan.domain.errors import InvalidInputError


def _model_and_optim():
    model = torch.nn.Linear(3, 2)
    return model, torch.optim.Adam(model.parameters())


def test_progress_is_saved_and_resumed(tmp_path):
    model, optim = _model_and_optim()
    training.save_progress(tmp_path, model, optim, 5)
    other, other_optim = _model_and_optim()
    assert training.resume(tmp_path, other, other_optim) == 5
    assert torch.equal(other.weight, model.weight)


def test_corrupted_progress_is_refused_in_one_line_and_left_in_place(tmp_path):
    (tmp_path / training.PROGRESS).write_bytes(b"not a checkpoint")
    model, optim = _model_and_optim()
    with pytest.raises(InvalidInputError, match="delete it to train from the start") as e:
        training.resume(tmp_path, model, optim)
    assert "\n" not in str(e.value)
    assert (tmp_path / training.PROGRESS).read_bytes() == b"not a checkpoint"
