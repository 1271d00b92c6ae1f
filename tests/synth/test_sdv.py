"""The SDV boundary: lazy imports, explicit metadata, seeding that leaves no global trace."""

from __future__ import annotations

import numpy as np
import pytest

from joulepath.errors import MissingDependency
from joulepath.synth import _sdv


def test_metadata_declares_every_column_numerical():
    meta = _sdv.metadata_dict(["q1", "dq1", "E"])
    assert meta["METADATA_SPEC_VERSION"] == "V2"
    columns = meta["tables"][_sdv.TABLE_NAME]["columns"]
    assert columns == {c: {"sdtype": "numerical"} for c in ("q1", "dq1", "E")}


@pytest.mark.parametrize("method", _sdv.METHODS)
def test_make_model_uses_explicit_metadata(method):
    model = _sdv.make_model(
        method, ["a", "b"], epochs=3, batch_size=20, verbose=False, enforce_min_max_values=True
    )
    assert not _sdv.is_fitted(model)
    assert model.get_metadata().to_dict()["tables"][_sdv.TABLE_NAME]["columns"] == {
        "a": {"sdtype": "numerical"},
        "b": {"sdtype": "numerical"},
    }
    params = model.get_parameters()
    assert params["enforce_rounding"] is False
    if method in _sdv.NEURAL_METHODS:
        assert params["epochs"] == 3 and params["batch_size"] == 20 and params["enable_gpu"] is False


def test_missing_sdv_names_the_extra(monkeypatch):
    import builtins

    real_import = builtins.__import__

    def fake_import(name, *args, **kwargs):
        if name.split(".")[0] == "sdv":
            raise ImportError(f"No module named {name!r}")
        return real_import(name, *args, **kwargs)

    monkeypatch.setattr(builtins, "__import__", fake_import)
    monkeypatch.setattr("importlib.import_module", lambda name: fake_import(name))
    with pytest.raises(MissingDependency, match=r"pip install 'joulepath\[synth\]'"):
        _sdv.make_model("tvae", ["a"], epochs=1, batch_size=2, verbose=False, enforce_min_max_values=True)


def test_seeded_restores_global_state_and_threads():
    import torch

    np_before = np.random.get_state()[1].copy()  # noqa: NPY002
    torch_before = torch.get_rng_state().clone()
    threads = torch.get_num_threads()
    with _sdv.seeded(5, n_threads=1):
        a = np.random.random(3)  # noqa: NPY002
        ta = torch.rand(3)
        assert torch.get_num_threads() == 1
    with _sdv.seeded(5, n_threads=1):
        b = np.random.random(3)  # noqa: NPY002
        tb = torch.rand(3)
    assert (a == b).all() and torch.equal(ta, tb)
    assert (np.random.get_state()[1] == np_before).all()  # noqa: NPY002
    assert torch.equal(torch.get_rng_state(), torch_before)
    assert torch.get_num_threads() == threads


def test_seeded_restores_state_when_the_body_raises():
    np_before = np.random.get_state()[1].copy()  # noqa: NPY002
    with pytest.raises(RuntimeError, match="boom"), _sdv.seeded(1):
        raise RuntimeError("boom")
    assert (np.random.get_state()[1] == np_before).all()  # noqa: NPY002


def test_load_model_refuses_other_objects():
    import pickle

    with pytest.raises(TypeError, match="expected an SDV single-table synthesizer, got dict"):
        _sdv.load_model(pickle.dumps({"a": 1}))


def test_versions_lists_the_backends():
    assert set(_sdv.versions()) == {"sdv", "sdmetrics", "torch"}


def test_sdv_1x_is_refused_with_a_hint(monkeypatch):
    monkeypatch.setattr(_sdv, "versions", lambda: {"sdv": "1.17.0", "sdmetrics": "x", "torch": "x"})
    with pytest.raises(MissingDependency, match=r"needs sdv >= 2.0 .* sdv 1.17.0 is installed"):
        _sdv.make_model("tvae", ["a"], epochs=1, batch_size=2, verbose=False, enforce_min_max_values=True)
