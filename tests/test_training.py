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
    model(torch.ones(4, 3)).sum().backward()
    optim.step()  # the optimiser now has state: moments and a step count per parameter
    training.save_progress(tmp_path, model, optim, 5, "data-a")
    other, other_optim = _model_and_optim()
    assert training.resume(tmp_path, other, other_optim, "data-a") == 5
    assert torch.equal(other.weight, model.weight)
    saved, loaded = optim.state_dict(), other_optim.state_dict()
    assert loaded["param_groups"] == saved["param_groups"]
    for k, moments in saved["state"].items():
        for name, value in moments.items():
            assert torch.equal(loaded["state"][k][name], value)


def test_what_a_trainer_keeps_beside_the_weights_comes_back(tmp_path):
    """A trainer choosing its epoch keeps the best weights so far and the losses of every
    epoch: an interrupted training resumes with them."""
    model, optim = _model_and_optim()
    best = {k: v + 1 for k, v in model.state_dict().items()}
    history = [{"epoch": 1, "loss": 0.5, "validation_loss": 0.75}]
    training.save_progress(tmp_path, model, optim, 1, "data-a", {"best": best, "history": history})
    other, other_optim = _model_and_optim()
    epoch, extra = training.resume_with(tmp_path, other, other_optim, "data-a")
    assert epoch == 1 and extra["history"] == history
    assert all(torch.equal(extra["best"][k], v) for k, v in best.items())
    assert training.resume_with(tmp_path / "none", other, other_optim, "data-a") == (0, {})


def test_progress_is_data_not_a_pickle(tmp_path):
    from safetensors import safe_open

    model, optim = _model_and_optim()
    training.save_progress(tmp_path, model, optim, 3, "data-a")
    assert [p.name for p in tmp_path.iterdir()] == [training.PROGRESS]
    assert not (tmp_path / training.PROGRESS).read_bytes().startswith(b"PK")  # no torch zip
    with safe_open(tmp_path / training.PROGRESS, framework="pt") as f:
        assert "state.model.weight" in f.keys()  # noqa: SIM118


def test_a_pickle_given_as_progress_is_refused_without_unpickling(tmp_path, capfd):
    model, optim = _model_and_optim()
    torch.save({"model": model.state_dict()}, tmp_path / training.PROGRESS)
    with pytest.raises(InvalidInputError, match="not usable training progress"):
        training.resume(tmp_path, *_model_and_optim(), "data-a")
    assert capfd.readouterr().err == ""  # no pickle warning printed before the refusal


def test_corrupted_progress_is_refused_in_one_line_and_left_in_place(tmp_path):
    (tmp_path / training.PROGRESS).write_bytes(b"not a checkpoint")
    model, optim = _model_and_optim()
    with pytest.raises(InvalidInputError, match="delete it to train from the start") as e:
        training.resume(tmp_path, model, optim, "data-a")
    assert "\n" not in str(e.value)
    assert (tmp_path / training.PROGRESS).read_bytes() == b"not a checkpoint"


def test_progress_on_other_data_is_refused(tmp_path):
    model, optim = _model_and_optim()
    training.save_progress(tmp_path, model, optim, 5, "data-a")
    with pytest.raises(InvalidInputError, match="other training data"):
        training.resume(tmp_path, *_model_and_optim(), "data-b")


def test_nan_weights_are_refused_at_save_and_at_load(tmp_path):
    model, _ = _model_and_optim()
    with torch.no_grad():
        model.weight[0, 0] = float("nan")
    with pytest.raises(InvalidInputError, match="NaN or infinity"):
        training.finish(tmp_path, model, {})
    assert not any(tmp_path.iterdir())  # nothing saved
    from safetensors.torch import save_file

    from hsgplan.checkpoint import load_trained, write_manifest

    save_file(model.state_dict(), tmp_path / "model.safetensors")  # written by hand
    (tmp_path / "config.json").write_text("{}")
    write_manifest(tmp_path)
    with pytest.raises(InvalidInputError, match="NaN or infinite"):
        load_trained(tmp_path, lambda d: d, lambda c: torch.nn.Linear(3, 2), "network")


def test_a_damaged_or_replaced_checkpoint_file_is_not_finished(tmp_path):
    model, _ = _model_and_optim()
    training.finish(tmp_path, model, {"a": 1})
    assert training.finished(tmp_path)
    weights = tmp_path / "model.safetensors"
    weights.write_bytes(weights.read_bytes()[:-8])  # truncated
    assert not training.finished(tmp_path)
    training.finish(tmp_path, model, {"a": 1})
    (tmp_path / "config.json").unlink()
    assert not training.finished(tmp_path)


def test_a_configuration_saved_before_a_setting_existed_counts_as_its_default(tmp_path):
    model, optim = _model_and_optim()
    training.claim(tmp_path, {"lr": 0.1})
    training.save_progress(tmp_path, model, optim, 1, "data-a")
    training.claim(tmp_path, {"lr": 0.1, "stride": 4}, {"lr": 0.2, "stride": 4})
    (tmp_path / training.TRAIN_CONFIG).write_text('{"lr": 0.1}')  # saved before stride existed
    with pytest.raises(InvalidInputError, match="another configuration"):
        training.claim(tmp_path, {"lr": 0.1, "stride": 2}, {"lr": 0.1, "stride": 4})
